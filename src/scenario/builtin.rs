//! The built-in scenario: its text, where it lives in the source tree,
//! and its circuit, compiled in so that they work wherever the binary is.

/// The text of the built-in scenario: a small signal relay switching an
/// MCU input. Exposed so that a command can write it out for the user to
/// edit.
pub const DEFAULT_SCENARIO_TOML: &str = include_str!("../../scenarios/default.toml");

/// The built-in scenario's origin, as the user names it (`base =
/// "default"`): what its messages name, never a path of the checkout the
/// binary was built in.
pub(super) const DEFAULT_SCENARIO_ORIGIN: &str = "default";

/// The name the built-in scenario's circuit goes by in messages and
/// reports. Its text is compiled in ([`DEFAULT_NETLIST`]): this name is
/// never read from disk.
pub(super) const DEFAULT_NETLIST_NAME: &str = "default:netlists/mcu_input.cir";

/// The built-in scenario's circuit (`netlists/mcu_input.cir`), compiled in
/// so that `run` with no scenario works wherever the binary is.
pub const DEFAULT_NETLIST: &str = include_str!("../../netlists/mcu_input.cir");

/// The built-in scenario's `circuit.netlist`, relative to its file.
pub(super) const DEFAULT_NETLIST_PATH: &str = "../netlists/mcu_input.cir";

/// The built-in circuit's name when `written` names it: the built-in
/// scenario's own `circuit.netlist` (at `origin`), or its name itself (as
/// a scenario on `base = "default"` carries it). It resolves to the
/// compiled-in text, not to a file.
pub(super) fn builtin_netlist(origin: &std::path::Path, written: &str) -> Option<&'static str> {
    let own =
        origin == std::path::Path::new(DEFAULT_SCENARIO_ORIGIN) && written == DEFAULT_NETLIST_PATH;
    (own || written == DEFAULT_NETLIST_NAME).then_some(DEFAULT_NETLIST_NAME)
}
