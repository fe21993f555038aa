//! The built-in scenario: its text, where it lives in the source tree,
//! and its circuit, compiled in so that they work wherever the binary is.

/// The text of the built-in scenario: a small signal relay switching an
/// MCU input. Exposed so that a command can write it out for the user to
/// edit.
pub const DEFAULT_SCENARIO_TOML: &str = include_str!("../../scenarios/default.toml");

/// Where the built-in scenario lives in the source tree. Its relative
/// `circuit.netlist` resolves against this directory.
pub(super) const DEFAULT_SCENARIO_ORIGIN: &str =
    concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/default.toml");

/// The built-in scenario's circuit (`netlists/mcu_input.cir`), compiled in
/// so that `run` with no scenario works wherever the binary is.
pub const DEFAULT_NETLIST: &str = include_str!("../../netlists/mcu_input.cir");

/// The built-in scenario's `circuit.netlist`, relative to its file.
pub(super) const DEFAULT_NETLIST_PATH: &str = "../netlists/mcu_input.cir";
