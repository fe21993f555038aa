//! `[sweep]`: Monte Carlo tolerances and grids over the scenario's numbers.

use super::*;

/// `[sweep]`: a Monte Carlo or grid sweep over the scenario's numbers, for
/// `chatterspice sweep` (the sampling itself is [`crate::sweep`]).
///
/// ```toml
/// [sweep]
/// samples = 1000
/// seed = 7
/// [sweep.vary]
/// "mechanics.mass" = 0.1                # ±10 %, uniform
/// "surface.damping" = { normal = 0.05 } # σ = 5 %, normal
/// ```
/// or, instead of `vary`, a grid of one or two keys:
/// ```toml
/// [sweep.grid]
/// "mechanics.force" = { from = 0.5, to = 2.0, steps = 16 }
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSection {
    /// Random samples to draw; `None` leaves it to the command line or
    /// the sweep's default. Not with `grid`, which runs all its points.
    pub samples: Option<u64>,
    /// Seed of the random draws; `None` leaves it to the command line or 0.
    pub seed: Option<u64>,
    /// Dotted number key (see [`NUMBER_KEYS`]) → its tolerance, sorted by key.
    #[serde(default)]
    pub vary: BTreeMap<String, Tolerance>,
    /// One or two dotted number keys → the values they step through; the
    /// first key (in sorted order) is the outer loop.
    #[serde(default)]
    pub grid: BTreeMap<String, GridAxis>,
}

/// How far one number varies around its value in the scenario (the
/// nominal), relative to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// `0.1` or `{ uniform = 0.1 }`: uniform within nominal·(1 ± 0.1).
    /// Must lie in (0, 1), so that the value keeps its sign.
    Uniform(f64),
    /// `{ normal = 0.05 }`: normal with mean nominal and σ = 5 % of it,
    /// truncated at ±4σ. σ must lie in (0, 0.25), so that the value keeps
    /// its sign.
    Normal(f64),
}

impl<'de> Deserialize<'de> for Tolerance {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::{self, MapAccess, Visitor};
        struct ToleranceVisitor;
        impl<'de> Visitor<'de> for ToleranceVisitor {
            type Value = Tolerance;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a relative tolerance: a number (± uniform, 0.1 = ±10 %), \
                     { uniform = 0.1 } or { normal = 0.05 } (σ)",
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Tolerance, E> {
                Ok(Tolerance::Uniform(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Tolerance, E> {
                Ok(Tolerance::Uniform(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Tolerance, E> {
                Ok(Tolerance::Uniform(v as f64))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Tolerance, A::Error> {
                let mut found = None;
                while let Some(name) = map.next_key::<String>()? {
                    let value: f64 = map.next_value()?;
                    let tolerance = match name.as_str() {
                        "uniform" => Tolerance::Uniform(value),
                        "normal" => Tolerance::Normal(value),
                        // A custom message: serde's unknown-field error would be
                        // reported at the table, as if its key were the typo.
                        other => {
                            return Err(de::Error::custom(format!(
                                "`{other}` is not a distribution: give {{ uniform = r }} \
                                 or {{ normal = σ }}"
                            )));
                        }
                    };
                    if found.replace(tolerance).is_some() {
                        return Err(de::Error::custom(
                            "give one distribution: { uniform = r } or { normal = σ }, not both",
                        ));
                    }
                }
                found.ok_or_else(|| {
                    de::Error::custom("an empty table: give { uniform = r } or { normal = σ }")
                })
            }
        }
        deserializer.deserialize_any(ToleranceVisitor)
    }
}

/// One axis of `[sweep.grid]`: `steps` values from `from` to `to`, both
/// included, evenly spaced (geometrically with `log = true`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridAxis {
    /// `from`: the first value, in the key's unit; > 0 with `log`.
    pub from: f64,
    /// `to`: the last value, in the key's unit; > 0 with `log`. It may lie
    /// below `from`.
    pub to: f64,
    /// `steps`: how many values, at least 1 (1 gives `from` alone).
    pub steps: u32,
    /// Space the values geometrically (e.g. a stiffness over decades).
    #[serde(default)]
    pub log: bool,
}

impl GridAxis {
    /// The `j`-th value, `0 <= j < steps`; the ends are exact.
    pub fn value(&self, j: u32) -> f64 {
        if self.steps <= 1 || j == 0 {
            return self.from;
        }
        if j + 1 >= self.steps {
            return self.to;
        }
        let u = f64::from(j) / f64::from(self.steps - 1);
        if self.log {
            self.from * (self.to / self.from).powf(u)
        } else {
            self.from + (self.to - self.from) * u
        }
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
                    advice: "a grid steps its keys instead of drawing random samples; \
                             keep [sweep.grid] or [sweep.vary], and sweep the other in a second run",
                });
            }
            if sweep.samples.is_some() {
                return Err(ScenarioError::Conflict {
                    at: self.at("sweep.samples"),
                    key: "sweep.samples".to_owned(),
                    other: "sweep.grid".to_owned(),
                    advice: "a grid runs each of its points once; remove `samples` \
                             (the number of points is the product of the `steps`)",
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
