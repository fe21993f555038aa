//! `[arc]`: the contact arcs on power loads (the section's struct and its
//! materials are in [`crate::arc`]; this file checks its numbers).

use super::check::Check;
use super::error::ScenarioError;
use crate::arc::ArcSection;

impl Check<'_> {
    /// `[arc]`: every number positive and within the envelope.
    pub(super) fn arc(&self, a: &ArcSection) -> Result<(), ScenarioError> {
        for (key, value, ok, requirement) in [
            (
                "arc.v_min",
                a.v_min,
                a.v_min.is_some_and(|v| v > 0.0),
                "must be > 0: the minimum arc voltage, in V (silver: 12)",
            ),
            (
                "arc.i_min",
                a.i_min,
                a.i_min.is_some_and(|v| v > 0.0),
                "must be > 0: the minimum arc current, in A (silver: 0.4)",
            ),
            (
                "arc.field",
                a.field,
                a.field.is_some_and(|v| v >= 0.0),
                "must be ≥ 0: the arc column's voltage gradient, in V/m",
            ),
            (
                "arc.opening_speed",
                a.opening_speed,
                a.opening_speed.is_some_and(|v| v > 0.0),
                "must be > 0: how fast a measured record's contacts part, in m/s",
            ),
            (
                "arc.low_current",
                a.low_current,
                a.low_current.is_some_and(|v| v >= 0.0),
                "must be ≥ 0: Ayrton's low-current term C of the arc voltage, in V·A \
                 (0 makes the arc voltage independent of its current)",
            ),
            (
                "arc.low_current_gap",
                a.low_current_gap,
                a.low_current_gap.is_some_and(|v| v >= 0.0),
                "must be ≥ 0: the growth D of the low-current term with the gap, in V·A/m",
            ),
            (
                "arc.capacitance",
                a.capacitance,
                a.capacitance.is_some_and(|v| (0.0..=1e-6).contains(&v)),
                "must be ≥ 0 and at most 1 µF: the open contact's own capacitance, in F \
                 (about 1 pF; 0 leaves it out)",
            ),
        ] {
            if let Some(v) = value {
                self.number(key, v, ok, requirement)?;
                self.envelope(key, value)?;
            }
        }
        Ok(())
    }
}
