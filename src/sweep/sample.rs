//! The sampler: which values sample `i` of a sweep gives each varied key.
//!
//! # Random sweeps (`[sweep.vary]`)
//! Sample `i`'s value of a key depends only on the seed, the key's name
//! and `i`: each (key, sample) pair reads its own ChaCha8 stream, whose
//! 256-bit key is the seed and an FNV-1a hash of the key's name and whose
//! stream number is `i`. So the values do not depend on how many jobs ran
//! the sweep, on which shard ran the sample, or on the other keys: adding
//! a key to `[sweep.vary]` leaves the others' draws as they were.
//!
//! - Uniform `r`: nominal·(1 + r·(2u − 1)), u uniform in [0, 1) with 53
//!   random bits.
//! - Normal `σ`: nominal·(1 + σ·z), z standard normal by Box–Muller.
//!   **Truncated by rejection**: a z with |z| > 4 is drawn again, so the
//!   distribution is the normal one cut at ±4σ and renormalised (nothing
//!   piles up at a clamp).
//!
//! Both keep the nominal's sign (the scenario requires r < 1 and σ < 0.25).
//! A key with an upper bound of its own (`surface.restitution` ≤ 1,
//! `contact.holm.exponent` ≤ 1) has a draw above it rejected and drawn
//! again too, so a restitution of 0.95 ± 10 % stays physical. Limits that
//! involve two keys (`mechanics.force` > `mechanics.preload`) are left to
//! the scenario's validation: such a sample is recorded as an error.
//!
//! # Grid sweeps (`[sweep.grid]`)
//! One key: sample `i` is its `i`-th value. Two keys (in sorted order, a
//! and b): sample `i` is a's value `i / steps_b` and b's value
//! `i % steps_b`, so a is the outer loop.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};

use crate::scenario::{GridAxis, Scenario, Tolerance};

use super::error::SweepError;

/// Random samples when neither the scenario nor the caller says.
pub const DEFAULT_SAMPLES: u64 = 100;

/// The most samples one sweep runs: a hundred million (about ten minutes
/// and 15 GB of CSV for the mechanics alone; the summary keeps 48 bytes
/// per sample, plus 16 per probe, in a temporary file, 5 GB at the cap,
/// and a few megabytes of memory). Larger studies are several sweeps.
pub const MAX_SAMPLES: u64 = 100_000_000;

/// The seed when neither the scenario nor the caller says.
pub const DEFAULT_SEED: u64 = 0;

/// Draws outside the truncation are redrawn; this many in a row means
/// the bounds leave (almost) nothing to draw from.
const MAX_REDRAWS: u32 = 10_000;

/// One randomly varied key.
#[derive(Debug, Clone, PartialEq)]
struct Varied {
    nominal: f64,
    tolerance: Tolerance,
    /// The key's own upper bound, if it has one.
    upper: Option<f64>,
    /// The ChaCha key of this (seed, key name).
    stream_key: [u8; 32],
}

#[derive(Debug, Clone, PartialEq)]
enum Kind {
    Random { seed: u64, varied: Vec<Varied> },
    Grid { axes: Vec<GridAxis> },
}

/// The values of every sample of a sweep: built once from the scenario's
/// `[sweep]`, then asked for sample `i` by any thread in any order.
#[derive(Debug, Clone, PartialEq)]
pub struct Sampler {
    keys: Vec<String>,
    kind: Kind,
    count: u64,
}

impl Sampler {
    /// The sampler of `scenario`'s `[sweep]`. `samples` and `seed` (the
    /// command line's) override the file's; `samples` is an error for a
    /// grid, which runs each of its points once.
    pub fn new(
        scenario: &Scenario,
        samples: Option<u64>,
        seed: Option<u64>,
    ) -> Result<Sampler, SweepError> {
        let path = || scenario.origin.clone();
        let sweep = scenario
            .sweep
            .as_ref()
            .filter(|s| !s.vary.is_empty() || !s.grid.is_empty())
            .ok_or_else(|| SweepError::NothingToVary { path: path() })?;
        if !sweep.grid.is_empty() {
            if let Some(samples) = samples {
                return Err(SweepError::SamplesWithGrid {
                    path: path(),
                    samples,
                });
            }
            let axes: Vec<GridAxis> = sweep.grid.values().copied().collect();
            let count = axes
                .iter()
                .try_fold(1u64, |n, a| n.checked_mul(u64::from(a.steps)))
                .unwrap_or(u64::MAX);
            if count > MAX_SAMPLES {
                return Err(SweepError::TooManySamples {
                    path: path(),
                    count,
                    what: "the product of the `[sweep.grid]` steps",
                    limit: MAX_SAMPLES,
                });
            }
            return Ok(Sampler {
                keys: sweep.grid.keys().cloned().collect(),
                kind: Kind::Grid { axes },
                count,
            });
        }
        let samples = samples.or(sweep.samples).unwrap_or(DEFAULT_SAMPLES);
        if samples == 0 {
            return Err(SweepError::NoSamples { path: path() });
        }
        if samples > MAX_SAMPLES {
            return Err(SweepError::TooManySamples {
                path: path(),
                count: samples,
                what: "`sweep.samples` (or --samples)",
                limit: MAX_SAMPLES,
            });
        }
        let seed = seed.or(sweep.seed).unwrap_or(DEFAULT_SEED);
        let mut varied = Vec::with_capacity(sweep.vary.len());
        for (key, tolerance) in &sweep.vary {
            // The loader checked that the key is a number the scenario has.
            let nominal = scenario.number(key)?.ok_or_else(|| SweepError::NoNominal {
                path: path(),
                key: key.clone(),
            })?;
            varied.push(Varied {
                nominal,
                tolerance: *tolerance,
                upper: upper_bound(key),
                stream_key: stream_key(seed, key),
            });
        }
        Ok(Sampler {
            keys: sweep.vary.keys().cloned().collect(),
            kind: Kind::Random { seed, varied },
            count: samples,
        })
    }

    /// The varied keys, in the order of [`Sampler::values`] (sorted).
    pub fn keys(&self) -> &[String] {
        &self.keys
    }

    /// The number of samples of the whole sweep.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Whether this is a grid sweep (else random).
    pub fn is_grid(&self) -> bool {
        matches!(self.kind, Kind::Grid { .. })
    }

    /// The seed of a random sweep.
    pub fn seed(&self) -> Option<u64> {
        match self.kind {
            Kind::Random { seed, .. } => Some(seed),
            Kind::Grid { .. } => None,
        }
    }

    /// The grid's steps per key, outer first; empty for a random sweep.
    pub fn grid_steps(&self) -> Vec<u32> {
        match &self.kind {
            Kind::Grid { axes } => axes.iter().map(|a| a.steps).collect(),
            Kind::Random { .. } => Vec::new(),
        }
    }

    /// Sample `index`'s value of each key into `out` (one per key, in
    /// [`Sampler::keys`] order). Allocates nothing.
    ///
    /// # Panics
    /// If `out` has the wrong length.
    pub fn values(&self, index: u64, out: &mut [f64]) -> Result<(), SweepError> {
        assert_eq!(out.len(), self.keys.len(), "one value per key");
        match &self.kind {
            Kind::Grid { axes } => {
                let mut rest = index;
                for (slot, axis) in out.iter_mut().zip(axes).rev() {
                    let steps = u64::from(axis.steps);
                    *slot = axis.value((rest % steps) as u32);
                    rest /= steps;
                }
                Ok(())
            }
            Kind::Random { varied, .. } => {
                for ((slot, v), key) in out.iter_mut().zip(varied).zip(&self.keys) {
                    *slot = v.draw(index).ok_or_else(|| SweepError::Truncation {
                        key: key.clone(),
                        index,
                    })?;
                }
                Ok(())
            }
        }
    }

    /// [`Sampler::values`] into a new vector.
    pub fn values_vec(&self, index: u64) -> Result<Vec<f64>, SweepError> {
        let mut out = vec![0.0; self.keys.len()];
        self.values(index, &mut out)?;
        Ok(out)
    }
}

impl Varied {
    fn draw(&self, index: u64) -> Option<f64> {
        let mut rng = ChaCha8Rng::from_seed(self.stream_key);
        rng.set_stream(index);
        for _ in 0..MAX_REDRAWS {
            let relative = match self.tolerance {
                Tolerance::Uniform(r) => r * (2.0 * unit(&mut rng) - 1.0),
                Tolerance::Normal(sigma) => {
                    let z = standard_normal(&mut rng);
                    if z.abs() > 4.0 {
                        continue;
                    }
                    sigma * z
                }
            };
            let value = self.nominal * (1.0 + relative);
            if self.upper.is_none_or(|upper| value <= upper) {
                return Some(value);
            }
        }
        None
    }
}

/// The physical upper bound of a key, where it has one of its own.
fn upper_bound(key: &str) -> Option<f64> {
    match key {
        "surface.restitution" | "contact.holm.exponent" => Some(1.0),
        _ => None,
    }
}

/// The ChaCha key of (seed, key name): the seed's 8 bytes, then the
/// name's FNV-1a hash, then zeros.
fn stream_key(seed: u64, key: &str) -> [u8; 32] {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for byte in key.bytes() {
        hash ^= u64::from(byte);
        hash = hash.wrapping_mul(0x0100_0000_01b3);
    }
    let mut out = [0u8; 32];
    out[..8].copy_from_slice(&seed.to_le_bytes());
    out[8..16].copy_from_slice(&hash.to_le_bytes());
    out
}

/// Uniform in [0, 1), from the top 53 bits of one draw.
fn unit(rng: &mut impl Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Standard normal by Box–Muller (the cosine half; one value per pair).
fn standard_normal(rng: &mut impl Rng) -> f64 {
    // 1 − u lies in (0, 1], so the logarithm is finite.
    let radius = (-2.0 * (1.0 - unit(rng)).ln()).sqrt();
    radius * (std::f64::consts::TAU * unit(rng)).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stream_keys_differ_by_seed_and_name() {
        assert_ne!(stream_key(1, "a"), stream_key(2, "a"));
        assert_ne!(stream_key(1, "a"), stream_key(1, "b"));
    }

    #[test]
    fn unit_is_in_range_and_normal_is_finite() {
        let mut rng = ChaCha8Rng::from_seed([7; 32]);
        for _ in 0..10_000 {
            let u = unit(&mut rng);
            assert!((0.0..1.0).contains(&u));
            assert!(standard_normal(&mut rng).is_finite());
        }
    }
}
