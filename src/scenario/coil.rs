//! `[coil]`: the magnetic drive of a coil-driven relay, instead of a step
//! force.

use serde::Deserialize;

use super::check::Check;
use super::error::ScenarioError;

/// `[coil]`: the magnetic drive of docs/model.md §7, instead of a step force.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoilSection {
    /// Ω
    pub resistance: f64,
    /// `coil.turns`: the number of turns of the winding, at least 1.
    pub turns: u32,
    /// m²
    pub pole_area: f64,
    /// m, armature air gap at rest.
    pub air_gap: f64,
    /// m, the iron path as an equivalent air gap.
    pub iron_gap: f64,
    /// V, the ideal DC step that `bounce` and `pwl` (and any command run
    /// without a circuit that holds the coil) put on the coil at t = 0, as
    /// a datasheet measures; without it, `datasheet.coil_voltage`.
    #[serde(default)]
    pub drive_voltage: Option<f64>,
}

impl Check<'_> {
    pub(super) fn coil(&self, c: &CoilSection, gap: f64) -> Result<(), ScenarioError> {
        self.number(
            "coil.resistance",
            c.resistance,
            c.resistance > 0.0,
            "must be > 0: the coil's DC resistance, in Ω",
        )?;
        if c.turns == 0 {
            return Err(self.invalid(
                "coil.turns",
                0.0,
                "must be at least 1: the number of turns of the coil",
            ));
        }
        self.number(
            "coil.pole_area",
            c.pole_area,
            c.pole_area > 0.0,
            "must be > 0: the pole face area, in m²",
        )?;
        self.number(
            "coil.air_gap",
            c.air_gap,
            c.air_gap > gap,
            format!(
                "must exceed `mechanics.gap` = {gap:?} m: a residual air gap must remain \
                 when the contacts close"
            ),
        )?;
        self.number(
            "coil.iron_gap",
            c.iron_gap,
            c.iron_gap >= 0.0,
            "must be ≥ 0: the iron path as an equivalent air gap, in m",
        )?;
        if let Some(v) = c.drive_voltage {
            self.number(
                "coil.drive_voltage",
                v,
                v > 0.0 && v <= 1e5,
                "must be > 0: the DC voltage stepped onto the coil at t = 0, in V",
            )?;
        }
        Ok(())
    }
}

/// The magnet of the section.
impl From<&CoilSection> for crate::coil::Coil {
    fn from(c: &CoilSection) -> Self {
        crate::coil::Coil {
            resistance: c.resistance,
            turns: f64::from(c.turns),
            pole_area: c.pole_area,
            air_gap: c.air_gap,
            iron_gap: c.iron_gap,
        }
    }
}
