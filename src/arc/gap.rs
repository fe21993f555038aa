//! gap(t): how far apart the contacts are at every moment of a run, from
//! the armature's own trajectory (a step force's exact flight pieces, or
//! a coil-driven relay's path), or, for a measured record of states that
//! carries no positions, from an opening speed.

use crate::chatter::{ContactState, Interval};
use crate::mechanics::Trajectory;

/// Samples per opening: spaced densely at both ends, where the gap and
/// the breakdown voltage change fastest relative to their size.
const SAMPLES_PER_OPENING: usize = 24;

/// (s, m) samples of the contact gap, in strictly increasing time; linear
/// in between, held before the first and after the last.
#[derive(Debug, Clone, PartialEq)]
pub struct GapProfile {
    samples: Vec<(f64, f64)>,
}

impl GapProfile {
    /// From samples (sorted by time; later duplicates of a time replace
    /// earlier ones, negative gaps count as touching).
    pub fn from_samples(samples: impl IntoIterator<Item = (f64, f64)>) -> GapProfile {
        let mut profile = GapProfile {
            samples: Vec::new(),
        };
        for (t, gap) in samples {
            profile.push(t, gap);
        }
        if profile.samples.is_empty() {
            profile.samples.push((0.0, 0.0));
        }
        profile
    }

    fn push(&mut self, t: f64, gap: f64) {
        let gap = if gap.is_finite() { gap.max(0.0) } else { 0.0 };
        match self.samples.last_mut() {
            Some(last) if t <= last.0 => {
                if t == last.0 {
                    last.1 = gap;
                }
            }
            _ => self.samples.push((t, gap)),
        }
    }

    /// The `(time, gap)` points (s, m), times strictly increasing, gaps ≥ 0.
    pub fn samples(&self) -> &[(f64, f64)] {
        &self.samples
    }

    /// m, the gap at `t`.
    pub fn at(&self, t: f64) -> f64 {
        let s = &self.samples;
        let k = s.partition_point(|&(ts, _)| ts <= t);
        if k == 0 {
            return s[0].1;
        }
        if k == s.len() {
            return s[k - 1].1;
        }
        let ((t0, g0), (t1, g1)) = (s[k - 1], s[k]);
        g0 + (g1 - g0) * (t - t0) / (t1 - t0)
    }

    /// m, the largest gap over [t0, t1].
    pub fn max_over(&self, t0: f64, t1: f64) -> f64 {
        self.samples
            .iter()
            .filter(|&&(t, _)| t > t0 && t < t1)
            .map(|&(_, g)| g)
            .fold(self.at(t0).max(self.at(t1)), f64::max)
    }

    /// The gap along an armature trajectory (a step force's exact
    /// pieces, or a driven cycle), sampled densely across every opening.
    pub fn from_trajectory(trajectory: &Trajectory) -> GapProfile {
        GapProfile::from_samples(trajectory.gap_samples(SAMPLES_PER_OPENING + 1))
    }

    /// A coil-driven relay: `path` is (s, m) of the armature, `travel` the
    /// rest-to-contact distance; gap = travel − x.
    pub fn from_path(travel: f64, path: &[(f64, f64)]) -> GapProfile {
        GapProfile::from_samples(path.iter().map(|&(t, x)| (t, travel - x)))
    }

    /// A measured record of states, which has no positions: each opening
    /// moves at `speed` (m/s) up to `travel` and back (the first opening
    /// only closes, a final one only opens).
    pub fn from_intervals(intervals: &[Interval], speed: f64, travel: f64) -> GapProfile {
        let mut samples = Vec::new();
        let last = intervals.len().saturating_sub(1);
        for (k, iv) in intervals.iter().enumerate() {
            match iv.state {
                ContactState::Closed => {
                    samples.push((iv.start, 0.0));
                    samples.push((iv.end, 0.0));
                }
                ContactState::Open => {
                    let opens = k > 0;
                    let closes = k < last;
                    let gap = |t: f64| {
                        let mut g = travel;
                        if opens {
                            g = g.min(speed * (t - iv.start));
                        }
                        if closes {
                            g = g.min(speed * (iv.end - t));
                        }
                        g
                    };
                    sample_opening(&mut samples, iv, gap);
                    // The corners where the gap reaches its travel.
                    let reach = travel / speed;
                    let mut corners = Vec::new();
                    if opens && iv.start + reach < iv.end {
                        corners.push(iv.start + reach);
                    }
                    if closes && iv.end - reach > iv.start {
                        corners.push(iv.end - reach);
                    }
                    samples.extend(corners.into_iter().map(|t| (t, gap(t))));
                }
            }
        }
        samples.sort_by(|a, b| a.0.total_cmp(&b.0));
        GapProfile::from_samples(samples)
    }
}

/// Samples of `gap(t)` over an opening, denser at both ends.
fn sample_opening(samples: &mut Vec<(f64, f64)>, iv: &Interval, gap: impl Fn(f64) -> f64) {
    let span = iv.end - iv.start;
    if span <= 0.0 {
        return;
    }
    for j in 0..=SAMPLES_PER_OPENING {
        let u = 0.5 * (1.0 - (std::f64::consts::PI * j as f64 / SAMPLES_PER_OPENING as f64).cos());
        let t = iv.start + span * u;
        samples.push((t, gap(t)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::cycle::Stops;
    use crate::mechanics::{Drive, Mechanics, Settings, Surface, simulate_drive};

    #[test]
    fn a_step_force_opening_follows_the_flight() {
        let m = Mechanics {
            mass: 2e-3,
            stiffness: 200.0,
            damping: 0.0,
            force: 1.0,
            gap: 0.4e-3,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        };
        let stops = Stops {
            make: Surface::Rigid { restitution: 0.6 },
            back: None,
        };
        let trajectory =
            simulate_drive(&m, &stops, &Settings::default(), Drive::Step).expect("simulates");
        let chatter = trajectory.chatter();
        assert!(chatter.bounce_count >= 2);
        let profile = GapProfile::from_trajectory(&trajectory);
        // Zero at every impact and release, the full gap at t = 0.
        assert_eq!(profile.at(0.0), m.gap);
        for i in &chatter.impacts[..3] {
            assert!(profile.at(i.impact_time) < 1e-12);
            let release = i.release_time.expect("releases");
            assert!(profile.at(release) < 1e-12);
            // Mid-opening: the flight's own apex, v²/(2a) for a free body
            // decelerated by (f − s·x)/m ≈ constant over a small gap.
            let v = -i.release_velocity.expect("releases");
            let next = chatter
                .impacts
                .iter()
                .find(|n| n.impact_time > release)
                .expect("recloses");
            let apex = profile.max_over(release, next.impact_time);
            let decel = (m.force - m.stiffness * m.gap) / m.mass;
            let want = v * v / (2.0 * decel);
            assert!((apex / want - 1.0).abs() < 0.05, "{apex} vs {want}");
        }
    }

    #[test]
    fn measured_openings_move_at_the_opening_speed() {
        let iv = |state, start, end| Interval { state, start, end };
        let intervals = [
            iv(ContactState::Open, 0.0, 1e-3),
            iv(ContactState::Closed, 1e-3, 2e-3),
            iv(ContactState::Open, 2e-3, 2.1e-3),
            iv(ContactState::Closed, 2.1e-3, 5e-3),
            iv(ContactState::Open, 5e-3, 20e-3),
        ];
        let p = GapProfile::from_intervals(&intervals, 0.5, 1e-3);
        assert_eq!(p.at(0.0), 0.5e-3);
        assert!((p.at(0.999e-3) - 0.5e-6).abs() < 1e-9);
        assert!((p.at(2.05e-3) - 25e-6).abs() < 1e-9);
        assert!((p.at(5.5e-3) - 0.25e-3).abs() < 1e-9);
        assert_eq!(p.at(19e-3), 1e-3);
        assert_eq!(p.at(1.5e-3), 0.0);
    }
}
