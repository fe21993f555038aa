//! The loaded scenario ([`Scenario`]) and what it converts into: the
//! library's mechanics, surface law and settings, its netlist, its coil's
//! DC step.

use std::path::PathBuf;

use super::calibration::{DatasheetSection, FitSection, ProvenanceSection};
use super::circuit::CircuitSection;
use super::coil::CoilSection;
use super::contact::ContactSection;
use super::envelope::EnvelopeSection;
use super::error::ScenarioError;
use super::limits::LimitsSection;
use super::mechanics::MechanicsSection;
use super::probes::Probe;
use super::simulation::SimulationSection;
use super::surface::{self, SurfaceSection};
use super::sweep::SweepSection;
use super::two_stage::{BladeSection, PoleFaceSection};
use crate::arc::ArcSection;
use crate::mechanics::{Mechanics, Settings, Surface};

/// A loaded and validated scenario file.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// The file it came from (for messages, and the base of relative paths).
    pub origin: PathBuf,
    /// `[mechanics]`: the moving contact and, without a `[coil]`, its step
    /// force.
    pub mechanics: MechanicsSection,
    /// `[coil]`: the magnetic drive of a coil-driven relay, instead of
    /// `mechanics.force`.
    pub coil: Option<CoilSection>,
    /// `[surface]`: the fixed contact's surface law as written; the
    /// resolved law is [`Scenario::surface`].
    pub surface: SurfaceSection,
    /// `[back_stop]`: the rest stop's own surface law, where the armature
    /// lands on release (the normally-closed contact). Only with `[coil]`:
    /// a step force never releases.
    pub back_stop: Option<SurfaceSection>,
    /// `[blade]`: the moving contact on its leaf spring, carried by the
    /// armature (a two-stage relay).
    pub blade: Option<BladeSection>,
    /// `[pole_face]`: the armature's stop past the contact (needs
    /// `[blade]`).
    pub pole_face: Option<PoleFaceSection>,
    /// `[contact]`: the contact as a resistor (the defaults when the file
    /// has no such section).
    pub contact: ContactSection,
    /// `[simulation]`: when to stop (the defaults when the file has no such
    /// section).
    pub simulation: SimulationSection,
    /// `[circuit]`: the netlist the contact switches, `circuit.netlist`
    /// already resolved against the scenario file's directory.
    pub circuit: Option<CircuitSection>,
    /// The `[[probe]]` tables, in file order.
    pub probes: Vec<Probe>,
    /// `[limits]`, for `check`.
    pub limits: Option<LimitsSection>,
    /// `[sweep]`, for `chatterspice sweep`.
    pub sweep: Option<SweepSection>,
    /// `[datasheet]`: the relay's published figures, for `fit`.
    pub datasheet: Option<DatasheetSection>,
    /// `[fit]`: which keys `fit` may move, and within what bounds.
    pub fit: Option<FitSection>,
    /// `[provenance]`: what a `fit` fitted this scenario to.
    pub provenance: Option<ProvenanceSection>,
    /// `[arc]`: the contact arcs at every opening (docs/arcs.md).
    pub arc: Option<ArcSection>,
    /// `[envelope]`: the ranges of the keys the datasheet does not fix,
    /// for `run --envelope` and `check --envelope`.
    pub envelope: Option<EnvelopeSection>,
    /// Computed once during validation: converting a Hunt–Crossley
    /// restitution into χ is a root solve that can fail.
    pub(super) resolved_surface: Surface,
    /// `[back_stop]`'s law, resolved as `resolved_surface`.
    pub(super) resolved_back_stop: Option<Surface>,
    /// The built-in scenario's circuit: its compiled-in text, used in
    /// place of any file.
    pub(super) embedded_netlist: Option<&'static str>,
}

impl Scenario {
    /// The `[circuit]` netlist: its path (for messages and relative
    /// includes) and its text. `None` when the scenario has no `[circuit]`.
    pub fn netlist(&self) -> Option<Result<(PathBuf, String), ScenarioError>> {
        let circuit = self.circuit.as_ref()?;
        let path = circuit.netlist.clone();
        Some(match self.embedded_netlist {
            Some(text) => Ok((path, text.to_owned())),
            None => crate::input::read_to_string(&path)
                .map(|text| (path.clone(), text))
                .map_err(|source| ScenarioError::NetlistRead {
                    path,
                    scenario: self.origin.clone(),
                    source,
                }),
        })
    }

    /// The step-force mechanics for the engine. Fails for a coil-driven
    /// scenario, which the engine does not simulate yet: silently running
    /// it with some other force would give a plausible but wrong answer.
    pub fn mechanics(&self) -> Result<Mechanics, ScenarioError> {
        let force = self
            .mechanics
            .force
            .ok_or_else(|| ScenarioError::CoilDriveUnsupported {
                path: self.origin.clone(),
            })?;
        Ok(Mechanics {
            force,
            ..self.armature()
        })
    }

    /// The armature's mechanics whatever drives it: [`Scenario::mechanics`]
    /// with the force of a coil-driven relay at 0 (its coil makes it).
    pub fn armature(&self) -> Mechanics {
        let m = &self.mechanics;
        Mechanics {
            mass: m.mass,
            stiffness: m.stiffness,
            damping: m.damping,
            force: m.force.unwrap_or(0.0),
            gap: m.gap,
            initial_position: m.initial_position,
            initial_velocity: m.initial_velocity,
            preload: m.preload,
        }
    }

    /// V, the ideal DC step a coil-driven relay gets without its driver
    /// circuit: `coil.drive_voltage`, else `datasheet.coil_voltage`;
    /// `None` without a `[coil]` or without either key.
    pub fn dc_step_voltage(&self) -> Option<f64> {
        self.coil.as_ref()?;
        self.coil
            .as_ref()
            .and_then(|c| c.drive_voltage)
            .or(self.datasheet.as_ref().and_then(|d| d.coil_voltage))
    }

    /// The surface law, with a Hunt–Crossley restitution already converted
    /// to χ.
    /// The SI unit of number key `key` in this scenario: as
    /// [`super::unit_of`], with a surface's stiffness in the unit its law
    /// gives it (N/m for Kelvin–Voigt and Hunt–Crossley with n = 1).
    pub fn unit_of_key(&self, key: &str) -> &'static str {
        let law = |s: Option<Surface>| match s {
            Some(Surface::KelvinVoigt { .. }) => Some("N/m"),
            Some(Surface::HuntCrossley { exponent: 1.0, .. }) => Some("N/m"),
            Some(Surface::HuntCrossley { exponent: 1.5, .. }) => Some("N/m^1.5"),
            _ => None,
        };
        let refined = match key {
            "surface.stiffness" => law(Some(self.surface())),
            "pole_face.stiffness" => law(self.two_stage().pole_face.map(|p| p.surface)),
            _ => None,
        };
        refined.unwrap_or_else(|| super::unit_of(key))
    }

    pub fn surface(&self) -> Surface {
        self.resolved_surface
    }

    /// The relay as built: `[blade]`, `[pole_face]` and the release rules
    /// (validated with the rest of the file). Without them, the one-mass
    /// model ([`crate::mechanics::two_stage::TwoStage::is_one_mass`]).
    pub fn two_stage(&self) -> crate::mechanics::two_stage::TwoStage {
        use crate::mechanics::two_stage::{Blade, PoleFace, TwoStage};
        let pole_face = self.pole_face.as_ref().map(|p| PoleFace {
            overtravel: p.overtravel,
            surface: surface::resolve(&p.surface()),
            release: p.release.unwrap_or_default().into(),
        });
        TwoStage {
            blade: self.blade.as_ref().map(|b| Blade {
                mass: b.mass,
                stiffness: b.stiffness,
                damping: b.damping,
            }),
            pole_face,
            release: self.surface.release.unwrap_or_default().into(),
        }
    }

    /// The back stop's law (`[back_stop]`), resolved like
    /// [`Scenario::surface`]; `None`: the armature lands inelastically.
    pub fn back_stop(&self) -> Option<Surface> {
        self.resolved_back_stop
    }

    /// The engine settings from `[simulation]`.
    pub fn settings(&self) -> Settings {
        let s = &self.simulation;
        Settings {
            t_end: s.t_end,
            min_open_time: s.min_open_time,
            min_gap: s.min_gap,
        }
    }

    /// The ideal DC step a coil-driven relay closes on without its driver
    /// circuit: its magnet and the source of [`Scenario::dc_step_voltage`]
    /// (no series resistance). `None` without a `[coil]` or a voltage.
    pub fn dc_step(&self) -> Option<(crate::coil::Coil, crate::coil::Source)> {
        let coil = crate::coil::Coil::from(self.coil.as_ref()?);
        let source = crate::coil::Source {
            voltage: self.dc_step_voltage()?,
            series_resistance: 0.0,
        };
        Some((coil, source))
    }
}
