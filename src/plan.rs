//! The plan: a scenario resolved once into what every command runs.
//!
//! A [`Scenario`] is the file as written: sections with public fields that
//! a library user may change. A [`Plan`] is what runs: the scenario
//! validated again as it stands, its surface laws resolved (a
//! Hunt–Crossley restitution converted to χ, a root solve that can fail),
//! its engine settings, and its netlist's text read once. A plan cannot
//! drift from what was resolved: its fields are private, and a sweep or
//! an envelope that changes keys makes a new plan with
//! [`Plan::with_numbers`], which re-validates the changed scenario and
//! shares the netlist text instead of reading the file again.
//!
//! ```
//! use chatterspice::plan::Plan;
//! use chatterspice::scenario::Scenario;
//!
//! let plan = Plan::new(Scenario::builtin_default())?;
//! let stiffer = plan.with_numbers(&[("surface.stiffness", 1e6)])?;
//! assert_ne!(plan.surface(), stiffer.surface());
//! // The netlist was read once; both plans share its text.
//! assert_eq!(plan.netlist().unwrap().text, stiffer.netlist().unwrap().text);
//! # Ok::<(), chatterspice::scenario::ScenarioError>(())
//! ```

use std::path::PathBuf;
use std::sync::Arc;

use crate::mechanics::two_stage::TwoStage;
use crate::mechanics::{Mechanics, Settings, Surface};
use crate::scenario::{Scenario, ScenarioError};

/// The `[circuit]` netlist, read once.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Netlist {
    /// Where it was read from: named in messages, and the base of the
    /// relative paths of the files it includes.
    pub path: PathBuf,
    /// Its text.
    pub text: String,
}

/// A scenario resolved once (see the module overview).
#[derive(Debug, Clone)]
pub struct Plan {
    scenario: Scenario,
    surface: Surface,
    back_stop: Option<Surface>,
    two_stage: TwoStage,
    netlist: Option<Arc<Netlist>>,
}

impl Plan {
    /// Validates `scenario` as it stands (changed fields included),
    /// resolves its surface laws and reads its netlist.
    pub fn new(scenario: Scenario) -> Result<Plan, ScenarioError> {
        let (surface, back_stop) = scenario.revalidate(true)?;
        let netlist = match scenario.netlist() {
            Some(read) => {
                let (path, text) = read?;
                Some(Arc::new(Netlist { path, text }))
            }
            None => None,
        };
        Ok(Plan {
            two_stage: scenario.two_stage(),
            scenario,
            surface,
            back_stop,
            netlist,
        })
    }

    /// [`Plan::new`] without reading the netlist: for what runs no
    /// circuit (the mechanics alone), so that a netlist that cannot be
    /// read does not stop it; [`Plan::netlist`] is then `None`.
    pub fn without_circuit(scenario: Scenario) -> Result<Plan, ScenarioError> {
        let (surface, back_stop) = scenario.revalidate(true)?;
        Ok(Plan {
            two_stage: scenario.two_stage(),
            scenario,
            surface,
            back_stop,
            netlist: None,
        })
    }

    /// A new plan with the numbers `values` (`key`, value) set, each key as
    /// in a scenario file (`mechanics.mass`, `circuit.params.cf`, ...):
    /// validated again, the netlist's text shared, not read again.
    pub fn with_numbers(&self, values: &[(&str, f64)]) -> Result<Plan, ScenarioError> {
        let mut scenario = self.scenario.clone();
        scenario.set_numbers(values)?;
        let (surface, back_stop) = (scenario.surface(), scenario.back_stop());
        Ok(Plan {
            two_stage: scenario.two_stage(),
            scenario,
            surface,
            back_stop,
            netlist: self.netlist.clone(),
        })
    }

    /// Sets the numbers `values` in this plan, validated and resolved
    /// again as [`Plan::with_numbers`] does; on an error the plan is left
    /// as it was. For a loop that sets the same keys on every pass (a
    /// sweep's worker), where a new plan per pass would copy the whole
    /// scenario each time.
    pub fn renumber(&mut self, values: &[(&str, f64)]) -> Result<(), ScenarioError> {
        self.scenario.set_numbers(values)?;
        self.surface = self.scenario.surface();
        self.back_stop = self.scenario.back_stop();
        self.two_stage = self.scenario.two_stage();
        Ok(())
    }

    /// The scenario this plan was resolved from.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The contact's surface law, resolved.
    pub fn surface(&self) -> Surface {
        self.surface
    }

    /// The rest stop's surface law (`[back_stop]`), resolved; `None`: the
    /// armature lands inelastically.
    pub fn back_stop(&self) -> Option<Surface> {
        self.back_stop
    }

    /// The relay as built (`[blade]`, `[pole_face]`, the release rules),
    /// resolved.
    pub fn two_stage(&self) -> TwoStage {
        self.two_stage
    }

    /// The engine settings (`[simulation]`).
    pub fn settings(&self) -> Settings {
        self.scenario.settings()
    }

    /// The step-force mechanics; an error for a coil-driven relay.
    pub fn mechanics(&self) -> Result<Mechanics, ScenarioError> {
        self.scenario.mechanics()
    }

    /// The `[circuit]` netlist, read when the plan was made; `None`
    /// without a `[circuit]`.
    pub fn netlist(&self) -> Option<&Netlist> {
        self.netlist.as_deref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A changed section is what runs: the plan re-validates and
    /// re-resolves it, so a stale law cannot be simulated, and an invalid
    /// change is an error naming the key.
    #[test]
    fn a_plan_resolves_the_scenario_as_it_stands() {
        let mut scenario = Scenario::builtin_default();
        let before = Plan::new(scenario.clone()).unwrap();
        scenario.surface.damping = Some(3.0);
        let after = Plan::new(scenario.clone()).unwrap();
        match (before.surface(), after.surface()) {
            (Surface::KelvinVoigt { damping: a, .. }, Surface::KelvinVoigt { damping: b, .. }) => {
                assert_eq!((a, b), (1.92, 3.0))
            }
            other => panic!("{other:?}"),
        }
        scenario.mechanics.mass = -1.0;
        let err = Plan::new(scenario).unwrap_err().to_string();
        assert!(err.contains("mechanics.mass"), "{err}");
        let err = before
            .with_numbers(&[("surface.damping", -1.0)])
            .unwrap_err()
            .to_string();
        assert!(err.contains("surface.damping"), "{err}");
    }
}
