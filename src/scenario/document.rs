//! The scenario file as serde sees it ([`Document`]), and the order in
//! which validation checks every section of it.

use serde::Deserialize;

use super::calibration::{DatasheetSection, FitSection, ProvenanceSection};
use super::check::Check;
use super::circuit::CircuitSection;
use super::coil::CoilSection;
use super::contact::ContactSection;
use super::envelope::EnvelopeSection;
use super::error::ScenarioError;
use super::limits::LimitsSection;
use super::mechanics::MechanicsSection;
use super::probes::Probe;
use super::simulation::SimulationSection;
use super::surface::SurfaceSection;
use super::sweep::SweepSection;
use super::two_stage::{BladeSection, PoleFaceSection};
use crate::arc::ArcSection;
use crate::mechanics::Surface;

/// The file as serde sees it; `Scenario` adds the origin and the
/// resolved surface law.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Document {
    pub(super) mechanics: MechanicsSection,
    pub(super) coil: Option<CoilSection>,
    pub(super) surface: SurfaceSection,
    pub(super) back_stop: Option<SurfaceSection>,
    pub(super) blade: Option<BladeSection>,
    pub(super) pole_face: Option<PoleFaceSection>,
    #[serde(default)]
    pub(super) contact: ContactSection,
    #[serde(default)]
    pub(super) simulation: SimulationSection,
    pub(super) circuit: Option<CircuitSection>,
    #[serde(default)]
    pub(super) probe: Vec<Probe>,
    pub(super) limits: Option<LimitsSection>,
    pub(super) sweep: Option<SweepSection>,
    pub(super) datasheet: Option<DatasheetSection>,
    pub(super) fit: Option<FitSection>,
    pub(super) provenance: Option<ProvenanceSection>,
    pub(super) arc: Option<ArcSection>,
    pub(super) envelope: Option<EnvelopeSection>,
}

/// The sections the physics rules read, borrowed from a file being loaded
/// or from a scenario whose numbers a sweep or a fit has changed.
pub(super) struct Physics<'a> {
    pub(super) mechanics: &'a MechanicsSection,
    pub(super) coil: Option<&'a CoilSection>,
    pub(super) surface: &'a SurfaceSection,
    pub(super) back_stop: Option<&'a SurfaceSection>,
    pub(super) blade: Option<&'a BladeSection>,
    pub(super) pole_face: Option<&'a PoleFaceSection>,
    pub(super) contact: &'a ContactSection,
    pub(super) simulation: &'a SimulationSection,
}

impl Check<'_> {
    /// The physics rules, in the order the loader applies them: the
    /// mechanics and its drive, the surfaces, the blade and the pole face,
    /// the contact, the simulation. Returns the resolved surface laws of
    /// the contact and of the back stop.
    pub(super) fn physics(
        &self,
        p: Physics<'_>,
    ) -> Result<(Surface, Option<Surface>), ScenarioError> {
        self.mechanics(p.mechanics)?;
        self.drive(p.mechanics, p.coil)?;
        let surface = self.surface("surface", p.surface)?;
        let back_stop = self.back_stop(p.back_stop, p.coil.is_some())?;
        self.two_stage(p.blade, p.pole_face, p.surface, p.mechanics.gap)?;
        self.contact(p.contact)?;
        self.simulation(p.simulation)?;
        Ok((surface, back_stop))
    }

    /// Everything; returns the resolved surface laws of the contact and
    /// of the back stop.
    pub(super) fn all(&self, d: &Document) -> Result<(Surface, Option<Surface>), ScenarioError> {
        let (surface, back_stop) = self.physics(Physics {
            mechanics: &d.mechanics,
            coil: d.coil.as_ref(),
            surface: &d.surface,
            back_stop: d.back_stop.as_ref(),
            blade: d.blade.as_ref(),
            pole_face: d.pole_face.as_ref(),
            contact: &d.contact,
            simulation: &d.simulation,
        })?;
        if let Some(circuit) = &d.circuit {
            self.circuit(circuit)?;
            if circuit.nc_subckt.is_some() && d.coil.is_none() {
                return Err(ScenarioError::Conflict {
                    at: self.at("circuit.nc_subckt"),
                    key: "circuit.nc_subckt".to_owned(),
                    other: "mechanics.force".to_owned(),
                    why: "the normally-closed contact follows the armature back to its \
                          rest stop on release, which needs a [coil]",
                    advice: "give one or remove the key",
                });
            }
        }
        for (i, probe) in d.probe.iter().enumerate() {
            self.probe(i, probe)?;
        }
        if let Some(limits) = &d.limits {
            self.limits(limits)?;
            self.release_limits(limits, d.coil.is_some())?;
        }
        if let Some(arc) = &d.arc {
            self.arc(arc)?;
        }
        if let Some(datasheet) = &d.datasheet {
            self.datasheet(datasheet)?;
        }
        if let Some(envelope) = &d.envelope {
            self.envelope_ranges(envelope)?;
        }
        if let Some(limits) = d.limits.as_ref().filter(|_| d.arc.is_none()) {
            let given = [
                ("limits.max_arc_energy", limits.max_arc_energy.is_some()),
                ("limits.max_arc_count", limits.max_arc_count.is_some()),
                ("limits.max_arc_duration", limits.max_arc_duration.is_some()),
            ];
            if let Some((key, _)) = given.iter().find(|(_, set)| *set) {
                return Err(ScenarioError::MissingKey {
                    at: self.at(key),
                    key: "arc".to_owned(),
                    help: format!(
                        "`{key}` holds the arcs that [arc] models: add an [arc] section \
                         (e.g. material = \"Ag\") or remove the limit"
                    ),
                    source: None,
                });
            }
        }
        Ok((surface, back_stop))
    }
}
