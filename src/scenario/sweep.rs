//! `[sweep]`: Monte Carlo tolerances and grids over the scenario's numbers.

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;

/// `[sweep]`: a Monte Carlo or grid sweep over the scenario's numbers, for
/// `chatterspice sweep` (the sampling itself is the crate's `sweep` module).
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
    /// Dotted number key (see [`NUMBER_KEYS`](super::numbers::NUMBER_KEYS)) → its tolerance, sorted by key.
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
