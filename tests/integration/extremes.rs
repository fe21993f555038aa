//! Bounded, always: scenarios with extreme numbers in any key load with a
//! clear error or simulate to an ending, never hang, never panic. The
//! values are the edges of what TOML and f64 can say, not random ones.

use std::path::Path;

use chatterspice::scenario::Scenario;
use chatterspice::{Outcome, simulate};
use proptest::prelude::*;

const EXTREMES: [f64; 14] = [
    0.0,
    -0.0,
    5e-324,
    1e-300,
    1e-12,
    1e-6,
    1.0,
    1e6,
    1e12,
    1e300,
    f64::MAX,
    -1.0,
    -1e300,
    f64::INFINITY,
];

const KEYS: [&str; 13] = [
    "mechanics.mass",
    "mechanics.stiffness",
    "mechanics.damping",
    "mechanics.force",
    "mechanics.gap",
    "mechanics.initial_position",
    "mechanics.initial_velocity",
    "mechanics.preload",
    "surface.stiffness",
    "surface.damping",
    "simulation.t_end",
    "simulation.min_open_time",
    "simulation.min_gap",
];

/// A Kelvin–Voigt or Hunt–Crossley relay with `key` set to `value`.
fn scenario(law: &str, key: &str, value: f64) -> String {
    let v = |k: &str, default: &str| {
        if k == key {
            if value.is_infinite() {
                if value > 0.0 {
                    "inf".to_owned()
                } else {
                    "-inf".to_owned()
                }
            } else {
                format!("{value:e}")
            }
        } else {
            default.to_owned()
        }
    };
    let surface = match law {
        "kelvin-voigt" => format!(
            "law = \"kelvin-voigt\"\nstiffness = {}\ndamping = {}\n",
            v("surface.stiffness", "1e6"),
            v("surface.damping", "2.0")
        ),
        _ => format!(
            "law = \"hunt-crossley\"\nstiffness = {}\nexponent = 1.5\nchi = 0.2\n",
            v("surface.stiffness", "1e9")
        ),
    };
    format!(
        "[mechanics]\nmass = {}\nstiffness = {}\ndamping = {}\nforce = {}\ngap = {}\n\
         initial_position = {}\ninitial_velocity = {}\npreload = {}\n\n[surface]\n{surface}\n\
         [simulation]\nt_end = {}\nmin_open_time = {}\nmin_gap = {}\n",
        v("mechanics.mass", "2e-4"),
        v("mechanics.stiffness", "800.0"),
        v("mechanics.damping", "0.01"),
        v("mechanics.force", "0.5"),
        v("mechanics.gap", "4.5e-4"),
        v("mechanics.initial_position", "0.0"),
        v("mechanics.initial_velocity", "0.0"),
        v("mechanics.preload", "0.0"),
        v("simulation.t_end", "0.02"),
        v("simulation.min_open_time", "1e-9"),
        v("simulation.min_gap", "1e-9"),
    )
}

/// Loads and simulates; an error must name the key it was given.
fn exercise(law: &str, key: &str, value: f64) -> Result<(), TestCaseError> {
    let text = scenario(law, key, value);
    match Scenario::parse(&text, Path::new("extreme.toml")) {
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(
                msg.contains(key) || msg.contains(key.rsplit('.').next().unwrap()),
                "{key} = {value:e}: {msg}"
            );
        }
        Ok(s) => {
            let m = s.mechanics().unwrap();
            match simulate(&m, &s.surface(), &s.settings()) {
                Ok(c) => {
                    prop_assert!(c.impacts.len() <= chatterspice::mechanics::MAX_EVENTS);
                    if c.impacts.len() == chatterspice::mechanics::MAX_EVENTS {
                        prop_assert_eq!(c.outcome, Outcome::EventLimit);
                    }
                }
                Err(e) => prop_assert!(!e.to_string().is_empty()),
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn extreme_values_in_any_key_end_with_a_result_or_a_clear_error(
        law in prop::sample::select(vec!["kelvin-voigt", "hunt-crossley"]),
        key in prop::sample::select(KEYS.to_vec()),
        value in prop::sample::select(EXTREMES.to_vec()),
    ) {
        exercise(law, key, value)?;
    }
}

/// Every (law, key, extreme) once, not only a sample of them.
#[test]
fn every_extreme_in_every_key() {
    for law in ["kelvin-voigt", "hunt-crossley"] {
        for key in KEYS {
            for value in EXTREMES {
                exercise(law, key, value).unwrap_or_else(|e| panic!("{law} {key} {value:e}: {e}"));
            }
        }
    }
}

/// No loss at all (both dampings 0) and a horizon of a million seconds:
/// the sequence stops at the event cap, with that outcome.
#[test]
fn a_lossless_relay_stops_at_the_event_cap() {
    let text = scenario("kelvin-voigt", "surface.damping", 0.0)
        .replace("damping = 0.01", "damping = 0.0")
        .replace("t_end = 0.02", "t_end = 1e6");
    let s = Scenario::parse(&text, Path::new("lossless.toml")).unwrap();
    let c = simulate(&s.mechanics().unwrap(), &s.surface(), &s.settings()).unwrap();
    assert_eq!(c.outcome, Outcome::EventLimit);
    assert_eq!(c.impacts.len(), chatterspice::mechanics::MAX_EVENTS);
    assert_eq!(c.settle_time, None);
}
