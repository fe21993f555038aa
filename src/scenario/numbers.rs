//! The scenario's numbers by dotted key: what sweeps vary and fits move.

/// The number keys that `Scenario::set_number` sets and `[sweep]`
/// varies, besides `probe[N].low` and `probe[N].high`. (`coil.turns` is an
/// integer and is left out.)
pub const NUMBER_KEYS: &[&str] = &[
    "mechanics.mass",
    "mechanics.stiffness",
    "mechanics.damping",
    "mechanics.force",
    "mechanics.gap",
    "mechanics.initial_position",
    "mechanics.initial_velocity",
    "mechanics.preload",
    "coil.resistance",
    "coil.pole_area",
    "coil.air_gap",
    "coil.iron_gap",
    "surface.stiffness",
    "surface.damping",
    "surface.restitution",
    "surface.exponent",
    "surface.chi",
    "surface.reference_velocity",
    "back_stop.stiffness",
    "back_stop.damping",
    "back_stop.restitution",
    "back_stop.exponent",
    "back_stop.chi",
    "back_stop.reference_velocity",
    "blade.mass",
    "blade.stiffness",
    "blade.damping",
    "pole_face.overtravel",
    "pole_face.stiffness",
    "pole_face.damping",
    "pole_face.restitution",
    "pole_face.exponent",
    "pole_face.chi",
    "pole_face.reference_velocity",
    "contact.r_closed",
    "contact.r_open",
    "contact.edge_time",
    "contact.holm.r_film",
    "contact.holm.r_ref",
    "contact.holm.f_ref",
    "contact.holm.exponent",
    "simulation.t_end",
    "simulation.min_open_time",
    "simulation.min_gap",
    "arc.v_min",
    "arc.i_min",
    "arc.field",
    "arc.opening_speed",
    "arc.low_current",
    "arc.low_current_gap",
    "arc.capacitance",
];

/// The unit of number key `key` (one of [`NUMBER_KEYS`] or `probe[N].low`
/// / `.high`), for tables in engineering units; `""` for a pure number
/// (restitution, exponents) or a key it does not know.
pub fn unit_of(key: &str) -> &'static str {
    let name = key.rsplit('.').next().unwrap_or(key);
    match name {
        "mass" => "kg",
        "force" | "preload" | "f_ref" => "N",
        "gap" | "initial_position" | "overtravel" | "pole_area" | "air_gap" | "iron_gap"
        | "min_gap" => "m",
        "initial_velocity" | "reference_velocity" | "opening_speed" => "m/s",
        "resistance" | "r_closed" | "r_open" | "r_film" | "r_ref" => "Ω",
        "t_end" | "min_open_time" | "edge_time" => "s",
        "damping" => "N·s/m",
        "chi" => "s/m",
        "v_min" | "low" | "high" => "V",
        "i_min" => "A",
        "field" => "V/m",
        "stiffness"
            if key.starts_with("surface.")
                || key.starts_with("back_stop.")
                || key.starts_with("pole_face.") =>
        {
            "N/mⁿ"
        }
        "stiffness" => "N/m",
        _ => "",
    }
}

/// Every number key, for messages.
pub(super) fn number_keys_described() -> String {
    let mut known = NUMBER_KEYS.join(", ");
    known.push_str(", probe[N].low, probe[N].high, circuit.params.NAME");
    known
}

/// The widest range of each number that still describes a relay, far
/// beyond any real one, so that every simulation stays finite and ends:
/// (key or key suffix, lowest, highest, unit). The other rules (> 0,
/// below the gap, ...) apply on top.
pub const ENVELOPE: &[(&str, f64, f64, &str)] = &[
    ("mechanics.mass", 0.0, 1e3, "kg"),
    ("mechanics.stiffness", 0.0, 1e12, "N/m"),
    ("mechanics.damping", 0.0, 1e9, "N·s/m"),
    ("mechanics.force", -1e9, 1e9, "N"),
    ("mechanics.gap", 0.0, 1.0, "m"),
    ("mechanics.initial_position", -1.0, 1.0, "m"),
    ("mechanics.initial_velocity", -1e4, 1e4, "m/s"),
    ("mechanics.preload", 0.0, 1e9, "N"),
    (".stiffness", 1e-6, 1e20, "N/m or N/mⁿ"),
    (".damping", 0.0, 1e12, "N·s/m"),
    (".chi", 0.0, 1e6, "s/m"),
    (".reference_velocity", 0.0, 1e4, "m/s"),
    ("simulation.t_end", 0.0, 1e6, "s"),
    ("simulation.min_open_time", 0.0, 1.0, "s"),
    ("simulation.min_gap", 0.0, 1.0, "m"),
    ("arc.v_min", 0.0, 1e4, "V"),
    ("arc.i_min", 0.0, 1e4, "A"),
    ("arc.field", 0.0, 1e8, "V/m"),
    ("arc.opening_speed", 0.0, 1e3, "m/s"),
    ("arc.low_current", 0.0, 1e6, "V·A"),
    ("arc.low_current_gap", 0.0, 1e10, "V·A/m"),
    ("arc.capacitance", 0.0, 1e-6, "F"),
];

/// Number keys under this prefix name a `.param` of the netlist.
pub(super) const PARAMS_PREFIX: &str = "circuit.params.";

/// A SPICE parameter name: a letter or `_`, then letters, digits, `_`.
pub(super) fn valid_param_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// `probe[N].low` → (N, true), `probe[N].high` → (N, false).
pub(super) fn probe_key(key: &str) -> Option<(usize, bool)> {
    let rest = key.strip_prefix("probe[")?;
    let (index, name) = rest.split_once("].")?;
    let index = index.parse().ok()?;
    match name {
        "low" => Some((index, true)),
        "high" => Some((index, false)),
        _ => None,
    }
}
