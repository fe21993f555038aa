//! Scenarios in code: [`Scenario::builder`] starts from the built-in
//! relay and changes it key by key, validated as a file would be.
//!
//! ```
//! use chatterspice::mechanics::Surface;
//! use chatterspice::scenario::Scenario;
//!
//! let scenario = Scenario::builder()
//!     .mass(1.0e-4)
//!     .stiffness(5000.0)
//!     .force(1.0)
//!     .surface(Surface::KelvinVoigt { stiffness: 5e5, damping: 1.92 })
//!     .probe("v(in)", 0.99, 2.31)
//!     .build()?;
//! assert_eq!(scenario.mechanics.mass, 1.0e-4);
//! assert_eq!(scenario.probes.len(), 1);
//! // A value the file would refuse is refused here, naming the key.
//! let err = Scenario::builder().mass(-1.0).build().unwrap_err();
//! assert!(err.to_string().contains("mechanics.mass"));
//! # Ok::<(), chatterspice::scenario::ScenarioError>(())
//! ```

use std::path::Path;

use super::error::ScenarioError;
use super::law::SurfaceLaw;
use super::model::Scenario;
use super::probes::Probe;
use super::surface::SurfaceSection;
use crate::mechanics::Surface;

/// Builds a [`Scenario`] from the built-in relay (`scenarios/default.toml`:
/// a 1.1 kHz signal relay on the MCU-input circuit, one probe), changed by
/// each call; [`ScenarioBuilder::build`] validates the result as a file is
/// validated and names the key of a bad value.
#[derive(Debug, Clone)]
#[must_use = "a builder does nothing until `build` is called"]
pub struct ScenarioBuilder {
    scenario: Scenario,
    numbers: Vec<(&'static str, f64)>,
    probes: Option<Vec<Probe>>,
}

impl Scenario {
    /// A builder starting from the built-in relay (see [`ScenarioBuilder`]).
    pub fn builder() -> ScenarioBuilder {
        ScenarioBuilder {
            scenario: Scenario::builtin_default(),
            numbers: Vec::new(),
            probes: None,
        }
    }
}

impl ScenarioBuilder {
    fn number(mut self, key: &'static str, value: f64) -> Self {
        self.numbers.push((key, value));
        self
    }

    /// `mechanics.mass`, kg: the moving mass.
    pub fn mass(self, kg: f64) -> Self {
        self.number("mechanics.mass", kg)
    }

    /// `mechanics.stiffness`, N/m: the return spring.
    pub fn stiffness(self, n_per_m: f64) -> Self {
        self.number("mechanics.stiffness", n_per_m)
    }

    /// `mechanics.damping`, N·s/m: the viscous damping of the armature.
    pub fn damping(self, n_s_per_m: f64) -> Self {
        self.number("mechanics.damping", n_s_per_m)
    }

    /// `mechanics.force`, N: the closing force, a step at t = 0.
    pub fn force(self, newtons: f64) -> Self {
        self.number("mechanics.force", newtons)
    }

    /// `mechanics.gap`, m: the contact gap at rest.
    pub fn gap(self, metres: f64) -> Self {
        self.number("mechanics.gap", metres)
    }

    /// `mechanics.preload`, N: the return spring's preload.
    pub fn preload(self, newtons: f64) -> Self {
        self.number("mechanics.preload", newtons)
    }

    /// `simulation.t_end`, s: how long the mechanics run.
    pub fn t_end(self, seconds: f64) -> Self {
        self.number("simulation.t_end", seconds)
    }

    /// The contact surface (`[surface]`), given as the law it resolves to.
    pub fn surface(mut self, surface: Surface) -> Self {
        self.scenario.surface = section_of(surface);
        self
    }

    /// `[circuit] netlist`: the circuit to run, read when the scenario
    /// runs (a relative path is relative to the current directory).
    pub fn netlist(mut self, path: impl AsRef<Path>) -> Self {
        if let Some(circuit) = &mut self.scenario.circuit {
            circuit.netlist = path.as_ref().to_path_buf();
        }
        self
    }

    /// A `[[probe]]` with Schmitt thresholds `low` < `high` (in the
    /// signal's unit); the first call replaces the built-in relay's probe,
    /// later calls add more.
    pub fn probe(mut self, signal: &str, low: f64, high: f64) -> Self {
        self.probes.get_or_insert_with(Vec::new).push(Probe {
            signal: signal.to_owned(),
            low,
            high,
            ..Probe::default()
        });
        self
    }

    /// The scenario, validated: a value a scenario file could not hold is
    /// an error naming its key.
    pub fn build(self) -> Result<Scenario, ScenarioError> {
        let mut scenario = self.scenario;
        let probes = self.probes.is_some();
        if let Some(list) = self.probes {
            scenario.probes = list;
        }
        let (surface, back_stop) = scenario.revalidate(probes)?;
        scenario.resolved_surface = surface;
        scenario.resolved_back_stop = back_stop;
        scenario.set_numbers(&self.numbers)?;
        Ok(scenario)
    }
}

/// The `[surface]` section that resolves to `surface`.
fn section_of(surface: Surface) -> SurfaceSection {
    let empty = SurfaceSection {
        law: SurfaceLaw::Rigid,
        stiffness: None,
        damping: None,
        restitution: None,
        exponent: None,
        chi: None,
        reference_velocity: None,
        release: None,
    };
    match surface {
        Surface::Rigid { restitution } => SurfaceSection {
            restitution: Some(restitution),
            ..empty
        },
        Surface::KelvinVoigt { stiffness, damping } => SurfaceSection {
            law: SurfaceLaw::KelvinVoigt,
            stiffness: Some(stiffness),
            damping: Some(damping),
            ..empty
        },
        Surface::HuntCrossley {
            stiffness,
            exponent,
            chi,
        } => SurfaceSection {
            law: SurfaceLaw::HuntCrossley,
            stiffness: Some(stiffness),
            exponent: Some(exponent),
            chi: Some(chi),
            ..empty
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_built_scenario_simulates_what_it_was_given() {
        let rigid = Scenario::builder()
            .surface(Surface::Rigid { restitution: 0.5 })
            .build()
            .unwrap();
        assert_eq!(rigid.surface(), Surface::Rigid { restitution: 0.5 });
        let hc = Surface::HuntCrossley {
            stiffness: 1e9,
            exponent: 1.5,
            chi: 0.3,
        };
        let built = Scenario::builder().surface(hc).t_end(0.02).build().unwrap();
        assert_eq!(built.surface(), hc);
        assert_eq!(built.settings().t_end, 0.02);
        let err = Scenario::builder()
            .surface(Surface::KelvinVoigt {
                stiffness: -1.0,
                damping: 1.0,
            })
            .build()
            .unwrap_err();
        assert!(err.to_string().contains("surface.stiffness"), "{err}");
        let err = Scenario::builder()
            .probe("v(x)", 2.0, 1.0)
            .build()
            .unwrap_err();
        assert!(err.to_string().contains("probe"), "{err}");
    }
}
