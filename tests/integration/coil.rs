//! The coupled coil–armature solvers against the reference case
//! of docs/model.md §7, closed forms, the limits in which they must become the
//! step-force engine, and conservation of energy. Each expected value is
//! computed here from its formula or taken from docs/model.md, independently of
//! the solvers.

use chatterspice::coil::{Coil, CoilError, Source, simulate_direct, simulate_forced};
use chatterspice::mechanics::surface::hunt_crossley_chi;
use chatterspice::{Chatter, Mechanics, Outcome, Settings, Surface, simulate};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// The reference relay of docs/model.md §7: 5 V onto a 70 Ω, 3000-turn coil.
fn coil() -> Coil {
    Coil {
        resistance: 70.0,
        turns: 3000.0,
        pole_area: 2e-5,
        air_gap: 0.6e-3,
        iron_gap: 0.05e-3,
    }
}

fn five_volts() -> Source {
    Source {
        voltage: 5.0,
        series_resistance: 0.0,
    }
}

fn armature() -> Mechanics {
    Mechanics {
        mass: 2e-4,
        stiffness: 800.0,
        damping: 0.04,
        force: 0.0,
        gap: 0.45e-3,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.1,
    }
}

fn kelvin_voigt() -> Surface {
    Surface::KelvinVoigt {
        stiffness: 8e4,
        damping: 0.37536,
    }
}

/// `value` rounds to `expected` at the number of decimals given (`step`
/// is one unit of the last digit).
fn rounds_to(value: f64, expected: f64, step: f64) -> bool {
    (value - expected).abs() <= 0.5 * step
}

#[test]
fn reference_case_of_model_md() {
    let run = simulate_direct(
        &coil(),
        &five_volts(),
        &armature(),
        &kelvin_voigt(),
        &Settings::default(),
    )
    .unwrap();
    let ev = run.events;
    let lift = ev.lift_off.unwrap();
    let make = ev.first_make.unwrap();
    let settle = ev.settle_time.unwrap();
    assert!(rounds_to(lift * 1e3, 1.5686, 1e-4), "lift-off {lift}");
    assert!(rounds_to(make * 1e3, 3.8137, 1e-4), "first make {make}");
    let v = ev.make_velocity.unwrap();
    assert!(rounds_to(v, 0.3205, 1e-4), "make velocity {v}");
    // docs/model.md: "the coil current dipped to 12.8 mA (it would be ~38 mA
    // with the armature held)". The current at the make is 12.887 mA, so
    // its "12.8" is truncated, not rounded.
    let i_make = ev.current_at_make.unwrap();
    assert!(
        (12.8e-3..12.9e-3).contains(&i_make),
        "current at make {i_make}"
    );
    let held = ev.held_current_at_make.unwrap();
    assert!(rounds_to(held * 1e3, 38.0, 1.0), "held current {held}");
    assert_eq!(run.chatter.outcome, Outcome::Stuck);
    assert_eq!(run.chatter.bounce_count, 4);
    assert_eq!(run.chatter.impacts.len(), 5);
    assert!(rounds_to(settle * 1e3, 5.8726, 1e-4), "settle {settle}");
    assert_eq!(run.chatter.first_impact, Some(make));
    // The run stops where sticking is decided, shortly after the last
    // impact: long before the current, still rising, would pull the
    // armature through the soft surface onto the pole (~9.5 ms).
    assert!(run.end_time() > settle && run.end_time() < settle + 1e-3);
}

#[test]
fn the_pull_in_dip_is_the_first_minimum_of_the_current() {
    let run = simulate_direct(
        &coil(),
        &five_volts(),
        &armature(),
        &kelvin_voigt(),
        &Settings::default(),
    )
    .unwrap();
    let ev = run.events;
    let dip = ev.pull_in_dip.unwrap();
    let first = &run.chatter.impacts[0];
    // The current falls all through the flight (back-EMF beats the
    // source) and on into the first contact, until the armature stops
    // inside the surface.
    assert!(dip.time > first.impact_time && dip.time < first.release_time.unwrap());
    assert!(dip.current < ev.current_at_make.unwrap());
    let before = run.state_at(dip.time - 1e-6).unwrap().current;
    let after = run.state_at(dip.time + 1e-6).unwrap().current;
    assert!(before > dip.current && after > dip.current);
    // Before the dip the current rises (held, then still after lift-off
    // while the armature is slow), peaks during the flight, and falls
    // monotonically from there to the dip.
    let before_dip: Vec<_> = run.current.iter().filter(|(t, _)| *t <= dip.time).collect();
    let (k_peak, &&(t_peak, i_peak)) = before_dip
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.1.total_cmp(&b.1.1))
        .unwrap();
    assert!(t_peak > ev.lift_off.unwrap() && t_peak < first.impact_time);
    assert!(i_peak > ev.current_at_make.unwrap());
    assert!(before_dip[..=k_peak].windows(2).all(|w| w[1].1 >= w[0].1));
    assert!(before_dip[k_peak..].windows(2).all(|w| w[1].1 <= w[0].1));

    // A rigid surface stops the armature at once: the dip is the make.
    let rigid = simulate_direct(
        &coil(),
        &five_volts(),
        &armature(),
        &Surface::Rigid { restitution: 0.6 },
        &Settings::default(),
    )
    .unwrap();
    let dip = rigid.events.pull_in_dip.unwrap();
    assert_eq!(Some(dip.time), rigid.events.first_make);
    assert_eq!(Some(dip.current), rigid.events.current_at_make);
}

/// While held, x = 0 and `i = V/R (1 − e^(−t R/L(0)))`; the pull
/// `½ i² L'(0)` beats the preload p when `i = √(2p/L'(0))`.
fn closed_form_lift_off(c: &Coil, s: &Source, p: f64) -> f64 {
    let r = c.resistance + s.series_resistance;
    let i_final = s.voltage / r;
    let i_lift = (2.0 * p / c.d_inductance(0.0)).sqrt();
    -(c.inductance(0.0) / r) * (-i_lift / i_final).ln_1p()
}

#[test]
fn lift_off_matches_the_closed_form() {
    let cases = [
        (five_volts(), 0.1),
        (five_volts(), 0.01),
        (
            Source {
                voltage: 12.0,
                series_resistance: 100.0,
            },
            0.3,
        ),
        (five_volts(), 0.14),
    ];
    for (source, preload) in cases {
        let m = Mechanics {
            preload,
            ..armature()
        };
        let run =
            simulate_direct(&coil(), &source, &m, &kelvin_voigt(), &Settings::default()).unwrap();
        let expected = closed_form_lift_off(&coil(), &source, preload);
        let got = run.events.lift_off.unwrap();
        assert!(
            rel(got, expected) < 1e-9,
            "p = {preload}: {got} vs {expected}"
        );
    }
}

#[test]
fn a_held_armature_draws_the_plain_rl_step() {
    // A preload no coil current here can beat: the armature never moves
    // and the coil is an RL circuit with L = L(0).
    let m = Mechanics {
        preload: 1e3,
        ..armature()
    };
    let run = simulate_direct(
        &coil(),
        &five_volts(),
        &m,
        &kelvin_voigt(),
        &Settings::default(),
    )
    .unwrap();
    assert_eq!(run.events.lift_off, None);
    assert_eq!(run.chatter.outcome, Outcome::NeverCloses);
    assert_eq!(run.chatter.shortfall, Some(armature().gap));
    let i_final = 5.0 / 70.0;
    let tau = coil().inductance(0.0) / 70.0;
    let rl = |t: f64| -i_final * (-t / tau).exp_m1();
    let mut worst = 0.0f64;
    for &(t, i) in &run.current {
        worst = worst.max((i - rl(t)).abs());
    }
    // Between the steps too: the dense output is what events are found on.
    for k in 0..=1000 {
        let t = 0.02 * k as f64 / 1000.0;
        let s = run.state_at(t).unwrap();
        worst = worst.max((s.current - rl(t)).abs());
        assert_eq!((s.position, s.velocity), (0.0, 0.0));
    }
    assert!(worst < 1e-9 * i_final, "worst {worst}");
    assert!(run.current.len() > 10);
}

#[test]
fn a_coil_too_weak_to_beat_the_preload_never_lifts() {
    // 1 V gives 14.3 mA at most; lifting needs 19.3 mA.
    let weak = Source {
        voltage: 1.0,
        series_resistance: 0.0,
    };
    let run = simulate_direct(
        &coil(),
        &weak,
        &armature(),
        &kelvin_voigt(),
        &Settings::default(),
    )
    .unwrap();
    assert_eq!(run.events.lift_off, None);
    assert_eq!(run.events.pull_in_dip, None);
    assert_eq!(run.chatter.outcome, Outcome::NeverCloses);
}

/// The exact limit of a stiff current source: V and the series resistance
/// grow with V/R = `i` fixed, so the back-EMF and the L/R lag vanish (both
/// ∝ 1/R) and the pull is `½ i² L'(x)` from t = 0 — what the forced solver
/// computes. The error must fall tenfold per decade of resistance.
#[test]
fn a_current_source_drive_tends_to_the_forced_solver() {
    let c = coil();
    let m = armature();
    let s = kelvin_voigt();
    let settings = Settings::default();
    let i = 0.025;
    let limit = simulate_forced(&m, &s, &settings, |_, x| c.force(i, x)).unwrap();
    let first = &limit.impacts[0];
    let mut errors = Vec::new();
    for rs in [1e5, 1e6, 1e7] {
        let source = Source {
            voltage: i * (c.resistance + rs),
            series_resistance: rs,
        };
        let run = simulate_direct(&c, &source, &m, &s, &settings).unwrap();
        let hit = &run.chatter.impacts[0];
        errors.push((
            rel(hit.impact_time, first.impact_time),
            rel(hit.impact_velocity, first.impact_velocity),
        ));
        if rs == 1e7 {
            assert_eq!(run.chatter.outcome, limit.outcome);
            assert_eq!(run.chatter.bounce_count, limit.bounce_count);
            assert!(rel(run.chatter.settle_time.unwrap(), limit.settle_time.unwrap()) < 1e-2);
        }
    }
    for w in errors.windows(2) {
        assert!(w[1].0 < w[0].0 / 8.0 && w[1].1 < w[0].1 / 8.0, "{errors:?}");
    }
    let (dt, dv) = errors[2];
    assert!(dt < 2e-4 && dv < 1e-3, "{errors:?}");
}

/// The step-force engine is the limit of a strong, fast coil: a current
/// source (as above) whose pull also stops depending on the position —
/// the air gap `a` grows with μ0N²A/a² (the pull at rest) fixed, so that
/// L'(x)/L'(0) = (a/(a − x))² → 1. Scaling a by λ, the turns by λ and the
/// series resistance by λ² (the L/R lag ∝ 1/λ), the first impact must
/// approach the engine's under the constant pull `½ i² L'(0)` by ~1/λ.
#[test]
fn a_strong_fast_coil_approaches_the_step_force_engine() {
    let base = coil();
    let m = armature();
    let s = kelvin_voigt();
    let settings = Settings::default();
    let i = 0.04;
    let engine = simulate(
        &Mechanics {
            force: base.force(i, 0.0),
            ..m
        },
        &s,
        &settings,
    )
    .unwrap();
    let target = &engine.impacts[0];
    let a0 = base.air_gap + base.iron_gap;
    let mut errors = Vec::new();
    for lambda in [10.0f64, 100.0, 1000.0] {
        let c = Coil {
            turns: base.turns * lambda,
            air_gap: a0 * lambda - base.iron_gap,
            ..base
        };
        assert!(rel(c.force(i, 0.0), base.force(i, 0.0)) < 1e-12);
        let rs = 1e3 * lambda * lambda;
        let source = Source {
            voltage: i * (c.resistance + rs),
            series_resistance: rs,
        };
        let run = simulate_direct(&c, &source, &m, &s, &settings).unwrap();
        let hit = &run.chatter.impacts[0];
        errors.push((
            rel(hit.impact_time, target.impact_time),
            rel(hit.impact_velocity, target.impact_velocity),
        ));
        if lambda == 1000.0 {
            assert_eq!(run.chatter.impacts.len(), engine.impacts.len());
        }
    }
    for w in errors.windows(2) {
        assert!(w[1].0 < w[0].0 / 5.0 && w[1].1 < w[0].1 / 5.0, "{errors:?}");
    }
    let (dt, dv) = errors[2];
    assert!(dt < 1e-3 && dv < 2e-3, "{errors:?}");
}

#[test]
fn energy_is_conserved_for_every_surface() {
    let hc = Surface::HuntCrossley {
        stiffness: 1e9,
        exponent: 1.5,
        chi: hunt_crossley_chi(0.8, 0.3).unwrap(),
    };
    for surface in [kelvin_voigt(), Surface::Rigid { restitution: 0.6 }, hc] {
        let run = simulate_direct(
            &coil(),
            &five_volts(),
            &armature(),
            &surface,
            &Settings::default(),
        )
        .unwrap();
        let e = run.energy;
        assert!(run.chatter.impacts.len() > 1, "{surface:?}");
        // Every term matters: the mechanical work is a third of the
        // source's energy, the losses are not negligible either.
        assert!(e.mechanical_work > 0.2 * e.source, "{e:?}");
        assert!(e.dissipated > 1e-3 * e.mechanical_work, "{e:?}");
        assert!(
            e.electrical_residual().abs() < 1e-9 * e.source,
            "{surface:?}: {e:?}"
        );
        assert!(
            e.mechanical_residual().abs() < 1e-9 * e.source,
            "{surface:?}: {e:?}"
        );
    }
}

#[test]
fn a_surface_too_soft_for_the_pull_lets_the_armature_reach_the_pole() {
    // The pull grows as 1/(residual gap)², far faster than a 2 kN/m
    // surface pushes back: the armature runs through to the pole face.
    let soft = Surface::KelvinVoigt {
        stiffness: 2e3,
        damping: 0.05,
    };
    let err = simulate_direct(
        &coil(),
        &five_volts(),
        &armature(),
        &soft,
        &Settings::default(),
    )
    .unwrap_err();
    match err {
        CoilError::ArmatureAtPole { position, pole, .. } => {
            assert_eq!(pole, coil().air_gap);
            assert!(rel(position, pole) < 1e-9, "{position}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn invalid_parameters_name_their_key() {
    let bad_coil = Coil {
        pole_area: -1.0,
        ..coil()
    };
    let err = simulate_direct(
        &bad_coil,
        &five_volts(),
        &armature(),
        &kelvin_voigt(),
        &Settings::default(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("coil.pole_area"), "{err}");
    let bad_mass = Mechanics {
        mass: 0.0,
        ..armature()
    };
    let err = simulate_direct(
        &coil(),
        &five_volts(),
        &bad_mass,
        &kelvin_voigt(),
        &Settings::default(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("mechanics.mass"), "{err}");
    let err = simulate_forced(
        &Mechanics {
            initial_position: -1e-4,
            ..armature()
        },
        &kelvin_voigt(),
        &Settings::default(),
        |_, _| 1.0,
    )
    .unwrap_err();
    assert!(err.to_string().contains("initial_position"), "{err}");
}

// --- the forced solver under a constant force is the engine -------------

/// Two chatter sequences agree: the same outcome and number of contacts,
/// every time to `time_tol` relative, every other quantity to `tol`
/// relative to the larger of its own size and 1e-3 of its first value
/// (the last bounces are thousands of times smaller than the first).
fn assert_same(a: &Chatter, b: &Chatter, time_tol: f64, tol: f64) {
    assert_eq!(a.outcome, b.outcome);
    assert_eq!(a.impacts.len(), b.impacts.len());
    assert_eq!(a.bounce_count, b.bounce_count);
    let close = |x: Option<f64>, y: Option<f64>, scale: f64, tol: f64, what: &str| match (x, y) {
        (Some(x), Some(y)) => {
            let err = if x == y {
                0.0
            } else {
                (x - y).abs() / y.abs().max(scale)
            };
            assert!(err <= tol, "{what}: {x} vs {y} ({err:e})");
        }
        (None, None) => {}
        _ => panic!("{what}: {x:?} vs {y:?}"),
    };
    let first = &b.impacts[0];
    let v_scale = 1e-3 * first.impact_velocity;
    let f_scale = 1e-3 * first.peak_force.unwrap_or(0.0).abs();
    let gap_scale = 1e-3 * first.max_gap_after.unwrap_or(0.0);
    for (p, q) in a.impacts.iter().zip(&b.impacts) {
        close(
            Some(p.impact_time),
            Some(q.impact_time),
            0.0,
            time_tol,
            "impact",
        );
        close(p.release_time, q.release_time, 0.0, time_tol, "release");
        close(p.contact_time, q.contact_time, 0.0, tol, "contact time");
        let v = |x: f64| Some(x);
        close(
            v(p.impact_velocity),
            v(q.impact_velocity),
            v_scale,
            tol,
            "v",
        );
        close(
            p.release_velocity,
            q.release_velocity,
            v_scale,
            tol,
            "v out",
        );
        close(p.restitution, q.restitution, 1e-3, tol, "e");
        close(p.peak_force, q.peak_force, f_scale, tol, "peak");
        close(p.min_force, q.min_force, f_scale, tol, "min");
        close(p.max_gap_after, q.max_gap_after, gap_scale, tol, "gap");
    }
    close(a.settle_time, b.settle_time, 0.0, time_tol, "settle");
    close(a.first_impact, b.first_impact, 0.0, time_tol, "first");
    close(
        a.accumulation_time,
        b.accumulation_time,
        0.0,
        time_tol,
        "tail",
    );
    close(a.shortfall, b.shortfall, 0.0, tol, "shortfall");
    assert_eq!(a.intervals.len(), b.intervals.len());
}

/// The dimensionless relay of docs/model.md §3 (m = s = 1, F = 1).
fn unit_relay(zeta: f64, k0: f64) -> Mechanics {
    Mechanics {
        mass: 1.0,
        stiffness: 1.0,
        damping: 2.0 * zeta,
        force: 1.0,
        gap: k0,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.0,
    }
}

fn long() -> Settings {
    Settings {
        t_end: 100.0,
        ..Settings::default()
    }
}

#[test]
fn a_constant_force_reproduces_the_engine_kelvin_voigt() {
    // docs/model.md §3's reference sequence: 18 contacts, stuck.
    let m = unit_relay(0.05, 0.9);
    let s = Surface::KelvinVoigt {
        stiffness: 100.0,
        damping: 2.0 * (0.5192 - 0.05),
    };
    let exact = simulate(&m, &s, &long()).unwrap();
    let forced = simulate_forced(&m, &s, &long(), |_, _| m.force).unwrap();
    assert_eq!(exact.outcome, Outcome::Stuck);
    assert_eq!(forced.impacts.len(), 18);
    assert_same(&forced, &exact, 1e-8, 1e-7);
    // With a preload the drive must beat it; the net force is the same.
    let pre = Mechanics {
        force: 1.3,
        preload: 0.3,
        ..m
    };
    let forced = simulate_forced(&pre, &s, &long(), |_, _| 1.3).unwrap();
    assert_same(&forced, &exact, 1e-8, 1e-7);
}

#[test]
fn a_constant_force_reproduces_the_engine_rigid() {
    // A Zeno sequence: resolved, with its accumulation time.
    let m = unit_relay(0.05, 0.9);
    let s = Surface::Rigid { restitution: 0.5 };
    let exact = simulate(&m, &s, &long()).unwrap();
    let forced = simulate_forced(&m, &s, &long(), |_, _| 1.0).unwrap();
    assert_eq!(exact.outcome, Outcome::Resolved);
    assert!(forced.impacts.len() > 10);
    assert_same(&forced, &exact, 1e-8, 1e-6);
    // e = 0: stuck at the first touch, held by the static overtravel.
    let s = Surface::Rigid { restitution: 0.0 };
    let exact = simulate(&m, &s, &long()).unwrap();
    let forced = simulate_forced(&m, &s, &long(), |_, _| 1.0).unwrap();
    assert_eq!(exact.outcome, Outcome::Stuck);
    assert_same(&forced, &exact, 1e-8, 1e-7);
}

#[test]
fn a_constant_force_reproduces_the_engine_hunt_crossley() {
    // Both integrate this contact; the engine's own tolerance (1e-9) is
    // what limits the agreement.
    let m = unit_relay(0.05, 0.9);
    let s = Surface::HuntCrossley {
        stiffness: 1e4,
        exponent: 1.5,
        chi: 0.3,
    };
    let exact = simulate(&m, &s, &long()).unwrap();
    let forced = simulate_forced(&m, &s, &long(), |_, _| 1.0).unwrap();
    assert_eq!(exact.outcome, Outcome::Stuck);
    assert_same(&forced, &exact, 1e-7, 1e-4);
}

#[test]
fn a_constant_force_reproduces_the_engine_s_open_endings() {
    let kv = Surface::KelvinVoigt {
        stiffness: 100.0,
        damping: 0.5,
    };
    // Beyond the overshoot (peak 1.855 for ζ = 0.05): never closes, with
    // the shortfall; between 1 and the peak: touched, ends open.
    for (k0, outcome) in [(2.5, Outcome::NeverCloses), (1.5, Outcome::EndsOpen)] {
        let m = unit_relay(0.05, k0);
        let exact = simulate(&m, &kv, &long()).unwrap();
        let forced = simulate_forced(&m, &kv, &long(), |_, _| 1.0).unwrap();
        assert_eq!(exact.outcome, outcome);
        assert_eq!(forced.outcome, outcome);
        if outcome == Outcome::NeverCloses {
            assert!(rel(forced.shortfall.unwrap(), exact.shortfall.unwrap()) < 1e-9);
        } else {
            assert_same(&forced, &exact, 1e-8, 1e-7);
        }
    }
    // Cut short while still chattering.
    let m = unit_relay(0.05, 0.9);
    let short = Settings {
        t_end: 6.0,
        ..Settings::default()
    };
    let exact = simulate(&m, &kv, &short).unwrap();
    let forced = simulate_forced(&m, &kv, &short, |_, _| 1.0).unwrap();
    assert_eq!(exact.outcome, Outcome::EndOfTime);
    assert_same(&forced, &exact, 1e-8, 1e-7);
}
