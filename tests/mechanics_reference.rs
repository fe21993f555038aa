//! The engine against the closed forms and the reference sequence of
//! model.md §3.

use chatterspice::{Mechanics, Outcome, Settings, Surface, simulate};

/// A dimensionless relay (m = s = 1 so τ = t) with the paper's surface
/// parameters: ζ, F = 1, k0, β, σ.
fn dimensionless(zeta: f64, k0: f64, beta: f64, sigma: f64) -> (Mechanics, Surface) {
    let m = Mechanics {
        mass: 1.0,
        stiffness: 1.0,
        damping: 2.0 * zeta,
        force: 1.0,
        gap: k0,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.0,
    };
    let s = Surface::KelvinVoigt {
        stiffness: beta - 1.0,
        damping: 2.0 * (sigma - zeta),
    };
    (m, s)
}

#[test]
fn reference_sequence_of_model_md() {
    let (m, s) = dimensionless(0.05, 0.9, 101.0, 0.5192);
    let settings = Settings {
        t_end: 100.0,
        ..Settings::default()
    };
    let c = simulate(&m, &s, &settings).unwrap();
    for (k, i) in c.impacts.iter().enumerate() {
        eprintln!(
            "{k:2} {:.6} {:.6} {:?} {:?}",
            i.impact_time, i.impact_velocity, i.release_time, i.release_velocity
        );
    }
    assert_eq!(c.outcome, Outcome::Stuck);
    assert_eq!(c.impacts.len(), 18);
    let first = &c.impacts[0];
    assert!(
        (first.impact_time - 1.51477).abs() < 1e-5,
        "{}",
        first.impact_time
    );
    assert!((first.impact_velocity - 0.92666).abs() < 1e-5);
    assert!((first.release_time.unwrap() - 1.83012).abs() < 1e-5);
    assert!((first.release_velocity.unwrap() + 0.78574).abs() < 1e-5);
    let last = c.impacts.last().unwrap();
    assert!(
        (last.impact_time - 32.6311).abs() < 1e-4,
        "{}",
        last.impact_time
    );
    assert!((last.impact_velocity - 0.005658).abs() < 1e-6);
    assert_eq!(c.settle_time, Some(last.impact_time));
    assert_eq!(c.bounce_count, 17);
}
