//! `[envelope]`: the ranges of the keys the evidence (the datasheet) does
//! not fix, over which every relay the datasheet allows is sampled.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::check::Check;
use super::error::ScenarioError;

/// `[envelope]`: for each number key the datasheet does not fix, the range
/// real relays of the class take, and where those ranges come from.
///
/// ```toml
/// [envelope]
/// "surface.damping" = { min = 1.0, max = 4.0 }
/// "blade.stiffness" = { min = 1500.0, max = 5000.0, log = true }
/// source = "class ranges: ..."
/// ```
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EnvelopeSection {
    /// One sentence on where the ranges come from, shown in reports.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
    /// The ranges, by number key (`surface.damping`, `mechanics.mass`, …).
    #[serde(flatten)]
    pub ranges: BTreeMap<String, EnvelopeRange>,
}

/// One key's range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvelopeRange {
    /// The smallest value, in the key's unit.
    pub min: f64,
    /// The largest value, in the key's unit (above `min`).
    pub max: f64,
    /// Sampled evenly in the logarithm (for ranges over decades); both
    /// ends then positive.
    #[serde(default)]
    pub log: bool,
}

impl EnvelopeRange {
    /// The value at `u` ∈ [0, 1] of the range: linear, or geometric with
    /// `log`.
    pub fn at(&self, u: f64) -> f64 {
        if self.log {
            (self.min.ln() + u * (self.max.ln() - self.min.ln())).exp()
        } else {
            self.min + u * (self.max - self.min)
        }
    }
}

impl Check<'_> {
    /// Each range is a real range (finite, `min` < `max`, positive ends
    /// with `log`).
    pub(super) fn envelope_ranges(&self, e: &EnvelopeSection) -> Result<(), ScenarioError> {
        for (key, r) in &e.ranges {
            let at = |field: &str| format!("envelope.\"{key}\".{field}");
            self.number(&at("min"), r.min, true, "")?;
            self.number(&at("max"), r.max, true, "")?;
            if r.max <= r.min {
                return Err(self.invalid(
                    &at("max"),
                    r.max,
                    format!(
                        "must exceed `min` = {}: a range that is a point gives no band",
                        r.min
                    ),
                ));
            }
            if r.log && r.min <= 0.0 {
                return Err(self.invalid(
                    &at("min"),
                    r.min,
                    "must be > 0 with `log = true` (sampled in the logarithm)",
                ));
            }
        }
        if e.ranges.is_empty() {
            return Err(ScenarioError::MissingKey {
                at: self.at("envelope"),
                key: "envelope".to_owned(),
                help: "an [envelope] needs at least one range, such as \
                       \"surface.damping\" = { min = 1.0, max = 4.0 }"
                    .to_owned(),
                source: None,
            });
        }
        Ok(())
    }
}
