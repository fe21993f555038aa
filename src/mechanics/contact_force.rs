//! The contact force over time, for the force-dependent (Holm) contact
//! resistance of the waveform stage (docs/model.md §5).
//!
//! The engine reports each contact's peak and minimum force; the waveform
//! needs the force at arbitrary instants inside the closures. Each contact
//! is replayed from its impact (x = g, ẋ = impact velocity), which is all
//! the state it depends on: Kelvin–Voigt in closed form, Hunt–Crossley by
//! the same integration as the engine with its dense output.

use crate::mechanics::linalg::Vector2;

use super::engine::kelvin_voigt_contact;
use super::error::MechanicsError;
use super::hunt_crossley::HcContact;
use super::integrate::{Dopri5, StepTolerance};
use super::linear::LinearPiece;
use super::parameters::Mechanics;
use super::surface::Surface;
use crate::chatter::Chatter;

/// The contact force (N, positive pressing the contacts together) at each
/// of `times` (s, non-decreasing) inside the closures: 0 before the first
/// impact, and for a time past a release the force at that release (the
/// waveform widens a touch shorter than its edge time to one edge, and
/// asks for the force at the end of that edge). A rigid surface has no force history: its touches are
/// impulses, so every closed instant gets the static force that holds the
/// contacts once closed, s·(f/s − g) with f net of preload, or the drive
/// f itself where that is not positive (the contacts would not stay shut).
pub fn contact_forces(
    m: &Mechanics,
    surface: &Surface,
    chatter: &Chatter,
    times: &[f64],
) -> Result<Vec<f64>, MechanicsError> {
    let mut out = vec![0.0; times.len()];
    let impacts = &chatter.impacts;
    let mut i = 0;
    while i < times.len() {
        // The impact at or before times[i]; all later times up to the next
        // impact belong to the same contact.
        let j = impacts.partition_point(|k| k.impact_time <= times[i]);
        if j == 0 {
            i += 1;
            continue;
        }
        let impact = &impacts[j - 1];
        let next_impact = impacts.get(j).map_or(f64::INFINITY, |k| k.impact_time);
        let n = times[i..].partition_point(|&t| t < next_impact);
        let group = i..i + n;
        let t_hit = impact.impact_time;
        // Local times, clamped to the release.
        let local: Vec<f64> = times[group.clone()]
            .iter()
            .map(|&t| match impact.release_time {
                Some(r) => (t.min(r) - t_hit).max(0.0),
                None => (t - t_hit).max(0.0),
            })
            .collect();
        let forces = replay(m, surface, impact.impact_velocity, &local)?;
        out[group].copy_from_slice(&forces);
        i += n.max(1);
    }
    Ok(out)
}

/// The force of one contact from its impact at `v_hit` (m/s), at local
/// times (s after the impact, non-decreasing).
fn replay(
    m: &Mechanics,
    surface: &Surface,
    v_hit: f64,
    local: &[f64],
) -> Result<Vec<f64>, MechanicsError> {
    let g = m.gap;
    let f_net = m.force - m.preload;
    match *surface {
        Surface::Rigid { .. } => {
            let held = m.stiffness * (f_net / m.stiffness - g);
            let force = if held > 0.0 { held } else { f_net.max(0.0) };
            Ok(vec![force; local.len()])
        }
        Surface::KelvinVoigt { stiffness, damping } => {
            let piece = LinearPiece::start(&kelvin_voigt_contact(m, stiffness, damping), g, v_hit);
            Ok(local
                .iter()
                .map(|&t| {
                    let (x, v) = piece.state(t);
                    stiffness * (x - g) + damping * v
                })
                .collect())
        }
        Surface::HuntCrossley {
            stiffness,
            exponent,
            chi,
        } => {
            let hc = HcContact::new(m, stiffness, exponent, chi);
            hunt_crossley_forces(&hc, v_hit, local)
        }
    }
}

/// Integrate the Hunt–Crossley contact (δ, δ̇) from touch and read the
/// force off the dense output at each local time.
fn hunt_crossley_forces(
    hc: &HcContact,
    v_hit: f64,
    local: &[f64],
) -> Result<Vec<f64>, MechanicsError> {
    let Some(&t_last) = local.last() else {
        return Ok(Vec::new());
    };
    let c = *hc;
    let rhs = move |_t: f64, y: &Vector2<f64>| {
        let (d, v) = (y[0], y[1]);
        let a = (c.force - c.damping * v - c.stiffness * (c.gap + d) - c.force_at(d, v)) / c.mass;
        Vector2::new(v, a)
    };
    // Same scales as the engine's integration: the depth the surface alone
    // would stop the impact at, and the time to get there.
    let n = hc.exponent;
    let depth =
        ((n + 1.0) * hc.mass * v_hit * v_hit / (2.0 * hc.surface_stiffness)).powf(1.0 / (n + 1.0));
    let rtol = 1e-9;
    let tol = StepTolerance {
        rtol,
        atol: Vector2::new(rtol * depth, rtol * v_hit),
    };
    let mut solver = Dopri5::new(
        rhs,
        0.0,
        Vector2::new(0.0, v_hit),
        1e-2 * depth / v_hit,
        tol,
    );
    let mut out = Vec::with_capacity(local.len());
    let mut k = 0;
    while k < local.len() && local[k] <= 0.0 {
        out.push(hc.force_at(0.0, v_hit));
        k += 1;
    }
    while k < local.len() {
        let step = solver.step(t_last)?;
        while k < local.len() && local[k] <= step.t1 {
            let y = step.at(local[k]);
            out.push(hc.force_at(y[0], y[1]));
            k += 1;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::{Settings, simulate};

    fn relay() -> Mechanics {
        Mechanics {
            mass: 1e-4,
            stiffness: 5000.0,
            damping: 0.07,
            force: 1.0,
            gap: 1.4e-4,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        }
    }

    /// Times across every contact of `chatter`, and the forces there.
    fn sampled(surface: &Surface) -> (Chatter, Vec<f64>, Vec<f64>) {
        let chatter = simulate(&relay(), surface, &Settings::default()).unwrap();
        let mut times = Vec::new();
        for k in &chatter.impacts {
            // The final contact: its first 0.2 ms, where the force rings.
            let end = k.release_time.unwrap_or(k.impact_time + 2e-4);
            times.extend(
                (0..=200).map(|j| k.impact_time + (end - k.impact_time) * j as f64 / 200.0),
            );
        }
        let forces = contact_forces(&relay(), surface, &chatter, &times).unwrap();
        (chatter, times, forces)
    }

    #[test]
    fn kelvin_voigt_forces_reach_the_engine_s_peak_and_minimum_and_settle() {
        let surface = Surface::KelvinVoigt {
            stiffness: 5e5,
            damping: 1.92,
        };
        let (chatter, times, forces) = sampled(&surface);
        for k in &chatter.impacts {
            let end = k.release_time.unwrap_or(k.impact_time + 2e-4);
            let inside: Vec<f64> = times
                .iter()
                .zip(&forces)
                .filter(|(t, _)| **t >= k.impact_time && **t <= end)
                .map(|(_, f)| *f)
                .collect();
            let max = inside.iter().copied().fold(f64::MIN, f64::max);
            let min = inside.iter().copied().fold(f64::MAX, f64::min);
            let peak = k.peak_force.unwrap();
            // 200 samples per contact find the peak to well within 1 %.
            assert!(
                max <= peak * (1.0 + 1e-9) && max > 0.99 * peak,
                "{max} vs {peak}"
            );
            assert!(min >= k.min_force.unwrap() - 1e-9 * peak, "{min}");
            // The force at impact is r0·v.
            assert!((inside[0] - 1.92 * k.impact_velocity).abs() < 1e-9 * peak);
        }
        // Settled: the spring and the surface share the overtravel,
        // δ = (f − s·g)/(s + s0), and the surface carries s0·δ.
        let settled = contact_forces(&relay(), &surface, &chatter, &[chatter.t_end]).unwrap();
        let expected = 5e5 * (1.0 - 5000.0 * 1.4e-4) / (5000.0 + 5e5);
        assert!(
            (settled[0] - expected).abs() < 1e-9,
            "{settled:?} vs {expected}"
        );
        // Before the first impact, nothing; past a release, the release's
        // force, which Kelvin–Voigt makes a pull (r0 times the release
        // velocity).
        let k = &chatter.impacts[0];
        let r = k.release_time.unwrap();
        let after = 0.5 * (r + chatter.impacts[1].impact_time);
        let f = contact_forces(
            &relay(),
            &surface,
            &chatter,
            &[0.5 * k.impact_time, r, after],
        )
        .unwrap();
        assert_eq!(f[0], 0.0);
        assert!(
            (f[1] - 1.92 * k.release_velocity.unwrap()).abs() < 1e-9,
            "{f:?}"
        );
        assert_eq!(f[2], f[1]);
    }

    #[test]
    fn hunt_crossley_forces_reach_the_engine_s_peak_and_are_never_negative() {
        let surface = Surface::HuntCrossley {
            stiffness: 1e9,
            exponent: 1.5,
            chi: 0.5,
        };
        let (chatter, times, forces) = sampled(&surface);
        assert!(chatter.impacts.len() > 1);
        assert!(forces.iter().all(|&f| f >= 0.0));
        let k = &chatter.impacts[0];
        let max = times
            .iter()
            .zip(&forces)
            .filter(|(t, _)| **t <= k.release_time.unwrap())
            .map(|(_, f)| *f)
            .fold(0.0, f64::max);
        let peak = k.peak_force.unwrap();
        assert!(
            max <= peak * (1.0 + 1e-6) && max > 0.99 * peak,
            "{max} vs {peak}"
        );
    }

    #[test]
    fn a_rigid_surface_holds_with_its_static_force() {
        let surface = Surface::Rigid { restitution: 0.5 };
        let (_, _, forces) = sampled(&surface);
        assert!(
            forces.iter().all(|&f| (f - 0.3).abs() < 1e-12),
            "{forces:?}"
        );
    }
}
