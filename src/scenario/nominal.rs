//! The rules that check a section against the rest of the loaded
//! scenario: `[sweep]`'s keys and tolerances, relative to the scenario's
//! own numbers, and `[envelope]`'s ranges, whose ends must be values the
//! scenario's keys may take.

use super::check::Check;
use super::error::ScenarioError;
use super::model::Scenario;
use super::sweep::{SweepSection, Tolerance};

impl Scenario {
    /// The `[sweep]` rules, which need the rest of the scenario (the
    /// nominal values the tolerances are relative to).
    pub(super) fn with_checked_sweep(self, check: &Check) -> Result<Scenario, ScenarioError> {
        if let Some(sweep) = &self.sweep {
            check.sweep(sweep, &self)?;
        }
        self.check_envelope(check)?;
        Ok(self)
    }

    /// The envelope's keys are numbers this scenario has, and both ends of
    /// each range are values the key may take.
    pub(super) fn check_envelope(&self, check: &Check<'_>) -> Result<(), ScenarioError> {
        let Some(e) = &self.envelope else {
            return Ok(());
        };
        for (key, r) in &e.ranges {
            let at = format!("envelope.\"{key}\"");
            if let Err(err) = self.number(key) {
                return Err(ScenarioError::Sweep {
                    at: check.at(&at),
                    key: at,
                    problem: format!(
                        "not a number of this scenario; an envelope ranges over number keys \
                         such as \"surface.damping\" ({err})"
                    ),
                });
            }
            for (end, v) in [("min", r.min), ("max", r.max)] {
                let mut probe = self.clone();
                if let Err(err) = probe.set_numbers(&[(key.as_str(), v)]) {
                    return Err(ScenarioError::Sweep {
                        at: check.at(&format!("{at}.{end}")),
                        key: format!("{at}.{end}"),
                        problem: format!("{v} is not a value `{key}` may take ({err})"),
                    });
                }
            }
        }
        Ok(())
    }
}

impl Check<'_> {
    pub(super) fn sweep_error(&self, key: &str, line_key: &str, problem: String) -> ScenarioError {
        ScenarioError::Sweep {
            at: self.at(line_key),
            key: key.to_owned(),
            problem,
        }
    }

    pub(super) fn sweep(
        &self,
        sweep: &SweepSection,
        scenario: &Scenario,
    ) -> Result<(), ScenarioError> {
        if sweep.samples == Some(0) {
            return Err(self.invalid(
                "sweep.samples",
                0.0,
                "must be at least 1: the number of random samples",
            ));
        }
        if !sweep.grid.is_empty() {
            if !sweep.vary.is_empty() {
                return Err(ScenarioError::Conflict {
                    at: self.at("sweep.grid"),
                    key: "sweep.grid".to_owned(),
                    other: "sweep.vary".to_owned(),
                    why: "a grid steps its keys instead of drawing random samples",
                    advice: "keep [sweep.grid] or [sweep.vary], and sweep the other in a \
                             second run",
                });
            }
            if sweep.samples.is_some() {
                return Err(ScenarioError::Conflict {
                    at: self.at("sweep.samples"),
                    key: "sweep.samples".to_owned(),
                    other: "sweep.grid".to_owned(),
                    why: "a grid runs each of its points once",
                    advice: "remove `samples` (the number of points is the product of the \
                             `steps`)",
                });
            }
            if sweep.grid.len() > 2 {
                return Err(self.sweep_error(
                    "sweep.grid",
                    "sweep.grid",
                    format!(
                        "has {} keys; a grid steps one or two (for a plot against them): \
                         remove the others, or vary them with [sweep.vary] in another run",
                        sweep.grid.len()
                    ),
                ));
            }
        }
        for (key, tolerance) in &sweep.vary {
            let line_key = format!("sweep.vary.{key}");
            let nominal = self.sweep_nominal(key, &line_key, "[sweep.vary]", scenario)?;
            let shown = format!("sweep.vary.\"{key}\"");
            if nominal == 0.0 {
                return Err(self.sweep_error(
                    &shown,
                    &line_key,
                    format!(
                        "`{key}` is 0 in the scenario, and a tolerance relative to 0 \
                         varies nothing: step it with [sweep.grid] instead"
                    ),
                ));
            }
            let (value, ok, requirement) = match *tolerance {
                Tolerance::Uniform(r) => (
                    r,
                    r > 0.0 && r < 1.0,
                    "must lie in (0, 1): the relative half-width, 0.1 for ±10 %",
                ),
                Tolerance::Normal(sigma) => (
                    sigma,
                    sigma > 0.0 && sigma < 0.25,
                    "must lie in (0, 0.25): σ relative to the nominal value, 0.05 for 5 % \
                     (draws are kept within ±4σ, which must not reach 0)",
                ),
            };
            if !(value.is_finite() && ok) {
                return Err(ScenarioError::Invalid {
                    at: self.at(&line_key),
                    key: shown,
                    value,
                    requirement: requirement.to_owned(),
                });
            }
        }
        for (key, axis) in &sweep.grid {
            let line_key = format!("sweep.grid.{key}");
            self.sweep_nominal(key, &line_key, "[sweep.grid]", scenario)?;
            let shown = |field: &str| format!("sweep.grid.\"{key}\".{field}");
            if axis.steps == 0 {
                return Err(ScenarioError::Invalid {
                    at: self.at(&format!("{line_key}.steps")),
                    key: shown("steps"),
                    value: 0.0,
                    requirement: "must be at least 1: the number of values from `from` to `to`"
                        .to_owned(),
                });
            }
            for (field, value) in [("from", axis.from), ("to", axis.to)] {
                let field_line = format!("{line_key}.{field}");
                let log_ok = !axis.log || value > 0.0;
                if !(value.is_finite() && log_ok) {
                    return Err(ScenarioError::Invalid {
                        at: self.at(&field_line),
                        key: shown(field),
                        value,
                        requirement: if axis.log {
                            "must be a finite number > 0 on a `log = true` grid".to_owned()
                        } else {
                            "must be a finite number".to_owned()
                        },
                    });
                }
                // Each end on its own, the other keys nominal: a grid that
                // leaves the valid range fails here, not after hours.
                let mut probe = scenario.clone();
                if let Err(e) = probe.set_number(key, value) {
                    return Err(self.sweep_error(
                        &shown(field),
                        &field_line,
                        format!("{value:?} is not a valid `{key}`: {e}"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The scenario's value of a key named in `[sweep.*]`, which must be
    /// a number it has.
    pub(super) fn sweep_nominal(
        &self,
        key: &str,
        line_key: &str,
        within: &'static str,
        scenario: &Scenario,
    ) -> Result<f64, ScenarioError> {
        let shown = format!("{}.\"{key}\"", &within[1..within.len() - 1]);
        match scenario.number(key) {
            Ok(Some(value)) => Ok(value),
            Ok(None) => Err(self.sweep_error(
                &shown,
                line_key,
                format!(
                    "the scenario gives no `{key}` to vary around (it is optional and not \
                     set, or not a key of this surface law): set it, or sweep another key"
                ),
            )),
            Err(ScenarioError::UnknownNumber { known, .. }) => Err(ScenarioError::UnknownNumber {
                at: self.at(line_key),
                key: key.to_owned(),
                within: if within == "[sweep.vary]" {
                    " (named in [sweep.vary])"
                } else {
                    " (named in [sweep.grid])"
                },
                known,
            }),
            Err(e) => Err(self.sweep_error(&shown, line_key, e.to_string())),
        }
    }
}
