//! `[circuit]` and `[circuit.params]`: the netlist the contact switches.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Deserialize;

use super::check::Check;
use super::error::ScenarioError;
use super::numbers::{PARAMS_PREFIX, valid_param_name};

/// `[circuit]`: the netlist the contact is placed into.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircuitSection {
    /// The netlist file. Relative paths in the file are resolved against
    /// the scenario file's directory when it is loaded; the file need not
    /// exist until a command runs the circuit.
    pub netlist: PathBuf,
    /// The subcircuit name the netlist instantiates for the contact.
    #[serde(default = "default_subckt")]
    pub subckt: String,
    /// The subcircuit name the netlist instantiates for the coil.
    #[serde(default = "default_coil_subckt")]
    pub coil_subckt: String,
    /// With a `[coil]`: the subcircuit name of the normally-closed
    /// contact (the armature on its rest stop), for a changeover relay
    /// whose NC side switches part of the circuit. `None`: there is none.
    pub nc_subckt: Option<String>,
    /// `[circuit.params]`: values for the netlist's own `.param` names,
    /// set in the run deck (the netlist file is never edited).
    #[serde(default)]
    pub params: BTreeMap<String, f64>,
}

impl CircuitSection {
    /// The `[circuit.params]` as (name, value) pairs, sorted by name.
    pub fn param_list(&self) -> Vec<(&str, f64)> {
        self.params.iter().map(|(k, v)| (k.as_str(), *v)).collect()
    }
}

pub(super) fn default_subckt() -> String {
    "CONTACT".to_owned()
}

pub(super) fn default_coil_subckt() -> String {
    "COIL".to_owned()
}

impl Check<'_> {
    pub(super) fn circuit(&self, c: &CircuitSection) -> Result<(), ScenarioError> {
        self.not_empty(
            "circuit.netlist",
            &c.netlist.to_string_lossy(),
            "the netlist file, relative to the scenario file",
        )?;
        self.not_empty(
            "circuit.subckt",
            &c.subckt,
            "the subcircuit name the netlist uses for the contact",
        )?;
        self.not_empty(
            "circuit.coil_subckt",
            &c.coil_subckt,
            "the subcircuit name the netlist uses for the coil",
        )?;
        if let Some(nc) = &c.nc_subckt {
            self.not_empty(
                "circuit.nc_subckt",
                nc,
                "the subcircuit name the netlist uses for the normally-closed contact",
            )?;
            if nc.eq_ignore_ascii_case(&c.subckt) || nc.eq_ignore_ascii_case(&c.coil_subckt) {
                return Err(ScenarioError::Conflict {
                    at: self.at("circuit.nc_subckt"),
                    key: "circuit.nc_subckt".to_owned(),
                    other: "circuit.subckt".to_owned(),
                    why: "the normally-closed contact needs a subcircuit name of its own",
                    advice: "rename it, e.g. CONTACT_NC",
                });
            }
        }
        for (name, &value) in &c.params {
            let key = format!("{PARAMS_PREFIX}{name}");
            if !valid_param_name(name) {
                return Err(self.invalid(
                    &key,
                    value,
                    format!(
                        "`{name}` is not a SPICE parameter name: a letter or `_`, then \
                         letters, digits or `_`, as in the netlist's `.param`"
                    ),
                ));
            }
            self.number(&key, value, true, "")?;
        }
        Ok(())
    }
}
