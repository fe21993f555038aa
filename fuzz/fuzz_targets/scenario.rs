//! Any text as a scenario file: `Scenario::parse` returns a scenario or an
//! error, never panics; a scenario it accepts resolves (mechanics, surface,
//! settings, every number key, the sweep's grid) without panicking, and
//! setting a number to the value it already has keeps it valid.
#![no_main]

use std::path::Path;

use chatterspice::scenario::{NUMBER_KEYS, Scenario};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // Relative paths (`circuit.netlist`) resolve against this; nothing here
    // reads them.
    let origin = Path::new("/nonexistent/chatterspice-fuzz/scenario.toml");
    let Ok(mut scenario) = Scenario::parse(text, origin) else {
        return;
    };
    let _ = scenario.mechanics();
    let _ = scenario.surface();
    let _ = scenario.back_stop();
    let _ = scenario.settings();
    if let Some(circuit) = &scenario.circuit {
        let _ = circuit.param_list();
    }
    if let Some(sweep) = &scenario.sweep {
        for axis in sweep.grid.values() {
            for j in [
                0,
                1,
                axis.steps / 2,
                axis.steps.saturating_sub(1),
                axis.steps,
            ] {
                let _ = axis.value(j);
            }
        }
    }
    let mut keys: Vec<String> = NUMBER_KEYS.iter().map(|k| (*k).to_owned()).collect();
    for i in 0..scenario.probes.len().min(4) {
        keys.push(format!("probe[{i}].low"));
        keys.push(format!("probe[{i}].high"));
    }
    keys.push(format!("probe[{}].low", scenario.probes.len()));
    for key in &keys {
        if let Ok(Some(value)) = scenario.number(key) {
            // The loader accepted this value: the same rules, run again by
            // set_number, accept it too.
            if let Err(e) = scenario.set_number(key, value) {
                panic!("set_number({key}, {value:?}) on a loaded scenario: {e}");
            }
        }
    }
});
