//! `[limits]`: what `check` holds the relay to.

use serde::Deserialize;

use super::check::Check;
use super::error::ScenarioError;

/// `[limits]`: what `check` holds the relay to. SI units; all optional.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSection {
    /// s, settle time − first impact.
    pub max_bounce_time: Option<f64>,
    /// Most bounces (openings after the first impact).
    pub max_bounces: Option<u64>,
    /// s, the operate time as datasheets define it: from the coil being
    /// energized (or the force step) to the first make, bounce excluded.
    pub max_operate_time: Option<f64>,
    /// s, the same figure as `max_operate_time` (its older name).
    pub max_first_make: Option<f64>,
    /// s, from the coil being energized (or the force step) to closed for
    /// good: operate plus bounce time.
    pub max_settle_time: Option<f64>,
    /// s, coil off → the NO contact's break, in every operation (a
    /// coil-driven relay only).
    pub max_release_time: Option<f64>,
    /// s, the bounce of the armature on its rest stop (the NC contact)
    /// after each release, first touch to last.
    pub max_nc_bounce_time: Option<f64>,
    /// Most NC bounces after each release.
    pub max_nc_bounces: Option<u64>,
    /// J, the most arc energy in one operation, all its arcs together
    /// (needs `[arc]` and a run).
    pub max_arc_energy: Option<f64>,
    /// The most arcs in one operation (needs `[arc]` and a run).
    pub max_arc_count: Option<u64>,
    /// s, the longest arc (needs `[arc]` and a run); an arc still burning
    /// when the run ends fails it.
    pub max_arc_duration: Option<f64>,
    /// A, the largest peak current of any make (the first or a re-make
    /// after a bounce; needs a run).
    pub max_making_current: Option<f64>,
    /// The least static-weld margin U_m/U of any make whose contact force
    /// the run knows (needs a run).
    pub min_weld_margin: Option<f64>,
    /// Operations: the least electrical life at the scenario's circuit,
    /// as `life` estimates it from `[datasheet] electrical_endurance`.
    pub min_electrical_life: Option<f64>,
    /// s, the contact's own debounce lockout in each closing: its last
    /// transition − its first make, what a debouncer reading the contact
    /// directly must ignore it for (the bounce time, named as a debouncer
    /// is sized).
    pub max_lockout: Option<f64>,
    /// s, the longest the contact stays in one state between two of its
    /// transitions during a closing's chatter: a debouncer that waits for
    /// a stable input must wait longer than this.
    pub max_stable_for: Option<f64>,
}

impl LimitsSection {
    /// Whether an arc limit is set: those need `[arc]` and the circuit run.
    pub fn has_arc_limits(&self) -> bool {
        self.max_arc_energy.is_some()
            || self.max_arc_count.is_some()
            || self.max_arc_duration.is_some()
    }

    /// Whether a making limit is set: those need the circuit run.
    pub fn has_making_limits(&self) -> bool {
        self.max_making_current.is_some() || self.min_weld_margin.is_some()
    }
}

impl Check<'_> {
    pub(super) fn limits(&self, l: &LimitsSection) -> Result<(), ScenarioError> {
        for (key, value, what) in [
            (
                "limits.max_bounce_time",
                l.max_bounce_time,
                "the longest bounce time allowed (first make → closed for good), in s",
            ),
            (
                "limits.max_operate_time",
                l.max_operate_time,
                "the longest operate time allowed (coil on → first make), in s",
            ),
            (
                "limits.max_first_make",
                l.max_first_make,
                "the longest operate time allowed (coil on → first make), in s",
            ),
            (
                "limits.max_settle_time",
                l.max_settle_time,
                "the longest time allowed from coil on to closed for good, in s",
            ),
            (
                "limits.max_release_time",
                l.max_release_time,
                "the longest release time allowed (coil off → the NO contact breaks), in s",
            ),
            (
                "limits.max_nc_bounce_time",
                l.max_nc_bounce_time,
                "the longest NC bounce allowed after a release, in s",
            ),
            (
                "limits.max_arc_energy",
                l.max_arc_energy,
                "the most arc energy allowed in one operation, in J",
            ),
            (
                "limits.max_arc_duration",
                l.max_arc_duration,
                "the longest arc allowed, in s",
            ),
            (
                "limits.max_making_current",
                l.max_making_current,
                "the largest peak current allowed at any make, in A",
            ),
            (
                "limits.min_weld_margin",
                l.min_weld_margin,
                "the least weld margin U_m/U allowed at any make (1: the spot just melts)",
            ),
            (
                "limits.min_electrical_life",
                l.min_electrical_life,
                "the least electrical life allowed at this circuit, in operations",
            ),
            (
                "limits.max_lockout",
                l.max_lockout,
                "the longest debounce lockout allowed (first make → last transition), in s",
            ),
            (
                "limits.max_stable_for",
                l.max_stable_for,
                "the longest stable stretch allowed between two transitions, in s",
            ),
        ] {
            if let Some(v) = value {
                self.number(key, v, v > 0.0, format!("must be > 0: {what}"))?;
            }
        }
        Ok(())
    }

    /// The release limits need a coil: a step force never releases.
    pub(super) fn release_limits(
        &self,
        l: &LimitsSection,
        coil: bool,
    ) -> Result<(), ScenarioError> {
        let given = [
            ("limits.max_release_time", l.max_release_time.is_some()),
            ("limits.max_nc_bounce_time", l.max_nc_bounce_time.is_some()),
            ("limits.max_nc_bounces", l.max_nc_bounces.is_some()),
        ];
        match given.iter().find(|(_, set)| *set) {
            Some((key, _)) if !coil => Err(ScenarioError::Conflict {
                at: self.at(key),
                key: (*key).to_owned(),
                other: "mechanics.force".to_owned(),
                why: "a release needs a coil that is switched off: with a step force the \
                      contact never releases",
                advice: "give a [coil] or remove the limit",
            }),
            _ => Ok(()),
        }
    }
}
