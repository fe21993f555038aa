//! The engine against closed forms (docs/model.md §3) and the paper's
//! conclusions 1–4. Each expected value is computed here from its formula,
//! independently of the engine.

use std::f64::consts::PI;

use chatterspice::mechanics::surface::hunt_crossley_restitution;
use chatterspice::mechanics::{ResponseEnd, critical_impact_speed, impact_response};
use chatterspice::{Mechanics, Outcome, Settings, Surface, simulate};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// Dimensionless relay (m = s = 1, so τ = t and v is already v/ωn) with a
/// Kelvin–Voigt surface given by ζ, k0 (F = 1), β and ζ0.
fn kv(zeta: f64, k0: f64, beta: f64, zeta0: f64) -> (Mechanics, Surface) {
    (
        Mechanics {
            mass: 1.0,
            stiffness: 1.0,
            damping: 2.0 * zeta,
            force: 1.0,
            gap: k0,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        },
        Surface::KelvinVoigt {
            stiffness: beta - 1.0,
            damping: 2.0 * zeta0,
        },
    )
}

fn long() -> Settings {
    Settings {
        t_end: 1e3,
        ..Settings::default()
    }
}

#[test]
fn reference_sequence_of_model_md() {
    // σ = ζ + ζ0 = 0.5192.
    let (m, s) = kv(0.05, 0.9, 101.0, 0.5192 - 0.05);
    let settings = Settings {
        t_end: 100.0,
        ..Settings::default()
    };
    let c = simulate(&m, &s, &settings).unwrap();
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

#[test]
fn kelvin_voigt_k0_1_restitution_and_contact_time_over_a_grid() {
    let mut checked = 0;
    for &zeta in &[0.0, 0.01, 0.05, 0.2] {
        for &zeta0 in &[0.0, 0.1, 0.5, 2.0] {
            for &beta in &[2.0f64, 11.0, 101.0, 1001.0] {
                let sigma: f64 = zeta + zeta0;
                let zp = sigma / beta.sqrt();
                if zp >= 1.0 {
                    continue;
                }
                let e = (-PI * zp / (1.0 - zp * zp).sqrt()).exp();
                let tc = PI / (beta.sqrt() * (1.0 - zp * zp).sqrt());
                let (m, s) = kv(zeta, 1.0, beta, zeta0);
                for &v in &[1e-3, 0.3, 2.0] {
                    let r = impact_response(&m, &s, v, f64::INFINITY).unwrap();
                    let got_e = r.restitution(v).unwrap();
                    let got_tc = r.contact_time().unwrap();
                    assert!(
                        rel(got_e, e) < 1e-9,
                        "ζ={zeta} ζ0={zeta0} β={beta}: e {got_e} vs {e}"
                    );
                    assert!(
                        rel(got_tc, tc) < 1e-9,
                        "ζ={zeta} ζ0={zeta0} β={beta}: τc {got_tc} vs {tc}"
                    );
                    checked += 1;
                }
                // And inside a whole sequence: the first contact.
                let c = simulate(&m, &s, &long()).unwrap();
                let first = &c.impacts[0];
                assert!(rel(first.restitution.unwrap(), e) < 1e-9);
                assert!(rel(first.contact_time.unwrap(), tc) < 1e-9);
            }
        }
    }
    assert!(checked > 100);
}

#[test]
fn undamped_free_flight_first_impact() {
    for &k0 in &[0.05, 0.3, 0.9, 1.0, 1.5, 1.99] {
        let (m, s) = kv(0.0, k0, 101.0, 0.5);
        let c = simulate(&m, &s, &long()).unwrap();
        let first = &c.impacts[0];
        let tau1 = (1.0 - k0).acos();
        let v1 = (k0 * (2.0 - k0)).sqrt();
        assert!(rel(first.impact_time, tau1) < 1e-12, "k0={k0}");
        assert!(rel(first.impact_velocity, v1) < 1e-12, "k0={k0}");
    }
}

/// x(t) from rest for a damped oscillator under a unit step (F = 1),
/// written out per regime (the engine uses one unified formula).
fn step_response(zeta: f64, t: f64) -> f64 {
    if zeta < 1.0 {
        let wd = (1.0 - zeta * zeta).sqrt();
        1.0 - (-zeta * t).exp() * ((wd * t).cos() + zeta / wd * (wd * t).sin())
    } else if zeta == 1.0 {
        1.0 - (1.0 + t) * (-t).exp()
    } else {
        let r = (zeta * zeta - 1.0).sqrt();
        let (l1, l2) = (-zeta + r, -zeta - r);
        1.0 - (l2 * (l1 * t).exp() - l1 * (l2 * t).exp()) / (l2 - l1)
    }
}

#[test]
fn first_impact_in_every_damping_regime() {
    for &zeta in &[0.3, 0.999_999, 1.0, 1.000_001, 1.5, 4.0] {
        let k0 = 0.8;
        let (m, s) = kv(zeta, k0, 101.0, 0.5);
        let c = simulate(&m, &s, &long()).unwrap();
        let t1 = c.first_impact.unwrap();
        // Independent: bisection on the textbook formula.
        let (mut lo, mut hi) = (0.0, 1.0);
        while step_response(zeta, hi) < k0 {
            hi *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if step_response(zeta, mid) < k0 {
                lo = mid
            } else {
                hi = mid
            }
        }
        assert!(rel(t1, lo) < 1e-9, "ζ={zeta}: {t1} vs {lo}");
    }
}

#[test]
fn never_closes_reports_the_shortfall_and_ends_open_between_f_and_the_peak() {
    // Undamped: the peak reach is 2F.
    let (m, s) = kv(0.0, 2.5, 101.0, 0.5);
    let c = simulate(&m, &s, &long()).unwrap();
    assert_eq!(c.outcome, Outcome::NeverCloses);
    assert!(rel(c.shortfall.unwrap(), 0.5) < 1e-12);
    assert!(c.impacts.is_empty() && c.first_impact.is_none() && c.settle_time.is_none());
    // Damped: peak F(1 + exp(−πζ/√(1−ζ²))).
    let zeta: f64 = 0.1;
    let peak = 1.0 + (-PI * zeta / (1.0 - zeta * zeta).sqrt()).exp();
    let (m, s) = kv(zeta, peak * 1.01, 101.0, 0.5);
    let c = simulate(&m, &s, &long()).unwrap();
    assert_eq!(c.outcome, Outcome::NeverCloses);
    assert!(rel(c.shortfall.unwrap(), peak * 0.01) < 1e-9);
    let (m, s) = kv(zeta, 0.5 * (1.0 + peak), 101.0, 0.5);
    let c = simulate(&m, &s, &long()).unwrap();
    assert_eq!(c.outcome, Outcome::EndsOpen);
    assert!(!c.impacts.is_empty());
    assert_eq!(
        c.intervals.last().unwrap().state,
        chatterspice::ContactState::Open
    );
    assert_eq!(c.bounce_count, c.impacts.len());
}

/// The release test of docs/model.md §3, written from its formula: with
/// y(τ) = e^(−στ)[−d cos ωτ + ((v − σd)/ω) sin ωτ], the contact releases iff
/// the first swing y1 satisfies y1·exp(−πσ/ω) > d.
fn releases_by_formula(v: f64, d: f64, beta: f64, sigma: f64) -> bool {
    let w = (beta - sigma * sigma).sqrt();
    let b = (v - sigma * d) / w;
    let y = |t: f64| (-sigma * t).exp() * (-d * (w * t).cos() + b * (w * t).sin());
    // The first swing y1: the maximum over the first half-period, sampled
    // finely (an independent route from the engine's closed-form zeros).
    let best = (0..=20000)
        .map(|k| y(PI / w * k as f64 / 20000.0))
        .fold(f64::MIN, f64::max);
    best * (-PI * sigma / w).exp() > d
}

#[test]
fn critical_speed_is_proportional_to_overtravel_and_matches_the_reference() {
    let (beta, zeta, sigma) = (101.0, 0.05, 0.5192);
    let mut ratios = Vec::new();
    for &k0 in &[0.5, 0.8, 0.9, 0.99] {
        let (m, s) = kv(zeta, k0, beta, sigma - zeta);
        let vc = critical_impact_speed(&m, &s, 1e-12).unwrap();
        ratios.push(vc / (1.0 - k0));
        // Independent check with the formula on either side of v_c.
        let d = (1.0 - k0) / beta;
        assert!(releases_by_formula(vc * 1.001, d, beta, sigma));
        assert!(!releases_by_formula(vc * 0.999, d, beta, sigma));
    }
    for r in &ratios {
        assert!(rel(*r, 0.092518) < 1e-5, "v_c/(1−k0) = {r}");
        assert!(rel(*r, ratios[0]) < 1e-9);
    }
    // k0 = 1: never sticks.
    let (m, s) = kv(zeta, 1.0, beta, sigma - zeta);
    assert_eq!(critical_impact_speed(&m, &s, 1e-9).unwrap(), 0.0);
}

#[test]
fn restitution_rises_to_the_k0_1_value_and_falls_to_zero_at_vc() {
    let (beta, zeta, sigma): (f64, f64, f64) = (101.0, 0.05, 0.5192);
    let zp = sigma / beta.sqrt();
    let e1 = (-PI * zp / (1.0 - zp * zp).sqrt()).exp();
    let tc1 = PI / (beta.sqrt() * (1.0 - zp * zp).sqrt());
    let (m, s) = kv(zeta, 0.9, beta, sigma - zeta);
    let vc = critical_impact_speed(&m, &s, 1e-13).unwrap();
    let mut last_e = 0.0;
    let mut last_tc = f64::INFINITY;
    let mut curve = Vec::new();
    for k in 0..60 {
        let v = vc * (1.0 + 1e-9 * 10f64.powf(k as f64 * 0.25));
        let r = impact_response(&m, &s, v, f64::INFINITY).unwrap();
        let (e, tc) = (r.restitution(v).unwrap(), r.contact_time().unwrap());
        // Conclusion 1: e grows with v toward the k0 = 1 value.
        assert!(e > last_e && e < e1, "v={v}: e={e}");
        // Conclusion 2: contact time bounded below by the k0 = 1 value,
        // and falls as e rises (one to one).
        assert!(tc < last_tc && tc > tc1 * (1.0 - 1e-9), "v={v}: tc={tc}");
        curve.push((e, tc));
        last_e = e;
        last_tc = tc;
    }
    assert!(curve[0].0 < 0.05, "e near v_c: {}", curve[0].0);
    assert!(rel(last_e, e1) < 1e-3, "e at large v: {last_e} vs {e1}");
    // Just below v_c: sticks.
    let r = impact_response(&m, &s, vc * (1.0 - 1e-6), f64::INFINITY).unwrap();
    assert_eq!(r.end, ResponseEnd::Stuck);
}

#[test]
fn hunt_crossley_free_impact_obeys_the_exact_relation() {
    for &n in &[1.0, 1.5] {
        for &(k, mass) in &[(1e5, 1e-4), (3e8, 2e-3)] {
            for &chi_v in &[0.001, 0.01, 0.05, 0.1, 0.2, 0.4] {
                let v = 0.3;
                let chi = chi_v / v;
                // A free impact: no suspension spring or drive force.
                let hc = chatterspice::mechanics::hunt_crossley::HcContact {
                    mass,
                    damping: 0.0,
                    stiffness: 0.0,
                    force: 0.0,
                    gap: 0.0,
                    surface_stiffness: k,
                    exponent: n,
                    chi,
                };
                let out = hc.run(v, 1.0).unwrap();
                let chatterspice::mechanics::hunt_crossley::HcEnd::Released { velocity, .. } =
                    out.end
                else {
                    panic!("free impact must release")
                };
                let e = -velocity / v;
                // Residual of χv(1+e) = ln[(1+χv)/(1−χev)] at the engine's e.
                let residual = chi_v * (1.0 + e) - ((1.0 + chi_v) / (1.0 - chi_v * e)).ln();
                let exact = hunt_crossley_restitution(chi, v).unwrap();
                assert!(
                    rel(e, exact) < 1e-7,
                    "n={n} k={k} χv={chi_v}: e={e} exact={exact}"
                );
                assert!(residual.abs() < 1e-8);
                // First order: e ≈ 1 − (2/3)χv.
                if chi_v <= 0.01 {
                    assert!((e - (1.0 - 2.0 / 3.0 * chi_v)).abs() < chi_v * chi_v);
                }
            }
        }
    }
}

#[test]
fn hunt_crossley_restitution_falls_as_impact_speed_rises() {
    let m = Mechanics {
        mass: 2e-4,
        stiffness: 800.0,
        damping: 0.0,
        force: 0.5,
        gap: 4.5e-4,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.0,
    };
    let chi = chatterspice::mechanics::surface::hunt_crossley_chi(0.85, 0.3).unwrap();
    let s = Surface::HuntCrossley {
        stiffness: 1e9,
        exponent: 1.5,
        chi,
    };
    let mut last = 1.0;
    for &v in &[0.1, 0.2, 0.3, 0.6, 1.2] {
        let r = impact_response(&m, &s, v, 1.0).unwrap();
        let e = r.restitution(v).unwrap();
        assert!(e < last, "v={v}: e={e} not below {last}");
        last = e;
        if v == 0.3 {
            // Near the free-impact value: the net drive (0.14 N against a
            // ~6 N peak) takes a little off the rebound.
            assert!(e < 0.85 && e > 0.83, "{e}");
        }
    }
}

#[test]
fn rigid_zeno_sequence_ends_at_its_accumulation_point() {
    // A nearly ballistic relay (spring force 1e-5 of the drive): the
    // bouncing ball under constant acceleration A = f/m, whose impacts
    // accumulate at t1 + 2 e v1 / (A (1 − e)).
    let (mass, f, g) = (1e-3, 1e-2, 1e-4);
    for &e in &[0.3, 0.6, 0.85] {
        let m = Mechanics {
            mass,
            stiffness: 1e-3,
            damping: 0.0,
            force: f,
            gap: g,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        };
        let s = Surface::Rigid { restitution: e };
        let settings = Settings {
            t_end: 10.0,
            min_open_time: 1e-9,
            min_gap: 0.0,
        };
        let c = simulate(&m, &s, &settings).unwrap();
        assert_eq!(c.outcome, Outcome::Resolved);
        let a = f / mass;
        let t1 = (2.0 * g / a).sqrt();
        let v1 = a * t1;
        let t_acc = t1 + 2.0 * e * v1 / (a * (1.0 - e));
        let acc = c.accumulation_time.unwrap();
        assert!(rel(acc, t_acc) < 1e-4, "e={e}: {acc} vs {t_acc}");
        assert!(c.settle_time.unwrap() <= acc);
        // Collapsed, not iterated to exhaustion: a few dozen bounces.
        assert!(
            c.bounce_count > 5 && c.bounce_count < 100,
            "{}",
            c.bounce_count
        );
        // The retained bounces already form the geometric series.
        let n = c.impacts.len();
        let ratio = c.impacts[n - 1].impact_velocity / c.impacts[n - 2].impact_velocity;
        assert!(rel(ratio, e) < 1e-3, "{ratio}");
    }
}

#[test]
fn rigid_zeno_accumulation_does_not_depend_on_where_the_tail_is_cut() {
    let m = Mechanics {
        mass: 2e-4,
        stiffness: 800.0,
        damping: 0.04,
        force: 0.5,
        gap: 4.5e-4,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.0,
    };
    let s = Surface::Rigid { restitution: 0.7 };
    let run = |min_open_time: f64| {
        let settings = Settings {
            t_end: 0.1,
            min_open_time,
            min_gap: 0.0,
        };
        simulate(&m, &s, &settings).unwrap()
    };
    let coarse = run(1e-7);
    let fine = run(1e-11);
    assert_eq!(coarse.outcome, Outcome::Resolved);
    assert!(fine.bounce_count > coarse.bounce_count);
    let (a, b) = (
        coarse.accumulation_time.unwrap(),
        fine.accumulation_time.unwrap(),
    );
    // The first skipped flight is 1e-7 s: the tail estimate is good to a
    // small fraction of it.
    assert!((a - b).abs() < 1e-8, "{a} vs {b}");
}

#[test]
fn si_relay_is_the_dimensionless_one_with_time_scaled_by_one_over_omega_n() {
    let (md, sd) = kv(0.05, 0.9, 101.0, 0.5192 - 0.05);
    let cd = simulate(&md, &sd, &long()).unwrap();
    // The same groups in SI: m = 2e-4 kg, s = 800 N/m → ωn = 2000 rad/s.
    let (mass, stiff, f): (f64, f64, f64) = (2e-4, 800.0, 0.5);
    let crit = 2.0 * (mass * stiff).sqrt();
    let fstat = f / stiff;
    let ms = Mechanics {
        mass,
        stiffness: stiff,
        damping: 0.05 * crit,
        force: f,
        gap: 0.9 * fstat,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.0,
    };
    let ss = Surface::KelvinVoigt {
        stiffness: 100.0 * stiff,
        damping: (0.5192 - 0.05) * crit,
    };
    let settings = Settings {
        t_end: 1e3 / 2000.0,
        ..Settings::default()
    };
    let cs = simulate(&ms, &ss, &settings).unwrap();
    let wn = 2000.0;
    assert_eq!(cs.outcome, cd.outcome);
    assert_eq!(cs.impacts.len(), cd.impacts.len());
    for (a, b) in cs.impacts.iter().zip(&cd.impacts) {
        assert!(rel(a.impact_time * wn, b.impact_time) < 1e-9);
        assert!(rel(a.impact_velocity / (wn * fstat), b.impact_velocity) < 1e-9);
        if let (Some(x), Some(y)) = (a.contact_time, b.contact_time) {
            assert!(rel(x * wn, y) < 1e-9);
        }
        if let (Some(x), Some(y)) = (a.peak_force, b.peak_force) {
            // Forces scale by s·F.
            assert!(rel(x / (stiff * fstat), y) < 1e-9);
        }
    }
}
