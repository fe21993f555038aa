//! `[simulation]`: when to stop, and what is too small to resolve.

use serde::Deserialize;

use super::check::Check;
use super::error::ScenarioError;
use crate::mechanics::Settings;

/// `[simulation]`: the engine's [`Settings`].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulationSection {
    /// s
    pub t_end: f64,
    /// s
    pub min_open_time: f64,
    /// m
    pub min_gap: f64,
}

impl Default for SimulationSection {
    /// The engine's own defaults, so that the file and the library agree.
    fn default() -> Self {
        let s = Settings::default();
        SimulationSection {
            t_end: s.t_end,
            min_open_time: s.min_open_time,
            min_gap: s.min_gap,
        }
    }
}

impl Check<'_> {
    pub(super) fn simulation(&self, s: &SimulationSection) -> Result<(), ScenarioError> {
        self.number(
            "simulation.t_end",
            s.t_end,
            s.t_end > 0.0,
            "must be > 0: the simulated horizon, in s",
        )?;
        self.number(
            "simulation.min_open_time",
            s.min_open_time,
            s.min_open_time >= 0.0,
            "must be ≥ 0: the shortest opening worth resolving, in s",
        )?;
        self.number(
            "simulation.min_gap",
            s.min_gap,
            s.min_gap >= 0.0,
            "must be ≥ 0: the smallest opening worth resolving, in m",
        )?;
        for (key, value) in [
            ("simulation.t_end", s.t_end),
            ("simulation.min_open_time", s.min_open_time),
            ("simulation.min_gap", s.min_gap),
        ] {
            self.envelope(key, Some(value))?;
        }
        Ok(())
    }
}
