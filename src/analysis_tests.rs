//! The probe analysis against hand-built plots and records.

use super::*;

fn probe(signal: &str, low: f64, high: f64) -> Probe {
    Probe::new(signal, low, high)
}

/// `n` points evenly spaced over [0, t_end].
fn grid(n: usize, t_end: f64) -> Vec<f64> {
    (0..n).map(|k| t_end * k as f64 / (n - 1) as f64).collect()
}

/// A deterministic uniform sequence in [-1, 1) (64-bit LCG, Knuth's
/// constants), so the noise test needs no crate and never changes.
fn noise(seed: u64, n: usize) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}

#[test]
fn square_wave_with_n_pulses_gives_two_n_edges() {
    // 0 V, then N pulses of 3.3 V: samples every 1 µs, high from
    // sample 100 + 100p to 139 + 100p. The steps fall between samples,
    // so the interpolated crossing of 2.31 V (rising) or 0.99 V
    // (falling) is 2.31/3.3 of the way from the sample before it.
    const N: usize = 7;
    let t = grid(1001, 1e-3);
    let v: Vec<f64> = (0..t.len())
        .map(|k| {
            let high = (100..100 + 100 * N).contains(&k) && (k % 100) < 40;
            if high { 3.3 } else { 0.0 }
        })
        .collect();
    let a = analyze_samples(&probe("v(in)", 0.99, 2.31), ProbeKind::Voltage, &t, &v, &[]).unwrap();
    assert_eq!(a.edges, 2 * N);
    assert_eq!(a.glitches, 2 * N - 1);
    assert_eq!((a.initial_state, a.final_state), (Level::Low, Level::Low));
    assert_eq!((a.min, a.max), (0.0, 3.3));
    let fraction = 2.31 / 3.3;
    for (k, e) in a.transitions.iter().enumerate() {
        let (before, direction) = if k % 2 == 0 {
            (99 + 50 * k, Direction::Rising)
        } else {
            (139 + 50 * (k - 1), Direction::Falling)
        };
        let expected = (before as f64 + fraction) * 1e-6;
        assert_eq!(e.direction, direction, "edge {k}");
        assert!((e.time - expected).abs() < 1e-15, "edge {k} at {}", e.time);
    }
    // Widths alternate 40 µs high and 60 µs low.
    let widths: Vec<f64> = a.transitions.iter().filter_map(|e| e.width).collect();
    assert_eq!(widths.len(), 2 * N - 1);
    for (k, w) in widths.iter().enumerate() {
        let expected = if k % 2 == 0 { 40e-6 } else { 60e-6 };
        assert!((w - expected).abs() < 1e-15, "width {k}: {w}");
    }
    assert!((a.shortest_pulse.unwrap() - 40e-6).abs() < 1e-15);
    assert_eq!(a.first_edge, Some(a.transitions[0].time));
    assert_eq!(a.last_edge, Some(a.transitions[2 * N - 1].time));
}

#[test]
fn ringing_between_the_thresholds_gives_no_edge() {
    // From 0 V to 1.65 V with a ±0.6 V decaying ring: it stays within
    // [1.05, 2.25] V, between low = 0.99 V and high = 2.31 V.
    let t = grid(20_001, 2e-3);
    let v: Vec<f64> = t
        .iter()
        .map(|&t| {
            if t < 1e-4 {
                0.0
            } else {
                let s = t - 1e-4;
                1.65 + 0.6 * (-s / 5e-4).exp() * (2.0 * std::f64::consts::PI * 1e4 * s).sin()
            }
        })
        .collect();
    assert!(v.iter().all(|&x| x < 2.31));
    assert!(v.iter().skip_while(|&&x| x == 0.0).all(|&x| x > 0.99));
    let a = analyze_samples(&probe("v(x)", 0.99, 2.31), ProbeKind::Voltage, &t, &v, &[]).unwrap();
    assert_eq!((a.edges, a.glitches), (0, 0));
    assert_eq!(
        (a.first_edge, a.last_edge, a.shortest_pulse),
        (None, None, None)
    );
    assert_eq!(a.final_state, Level::Low);
}

#[test]
fn noise_around_one_threshold_gives_one_edge() {
    // A ramp to 2.31 V, then ±0.3 V of noise around 2.31 V for 10^4
    // samples: it crosses `high` thousands of times but never reaches
    // `low`, so the hysteresis keeps a single rising edge.
    let n = 11_000;
    let t = grid(n, 1.1e-2);
    let jitter = noise(42, n);
    let v: Vec<f64> = (0..n)
        .map(|k| {
            if k < 1000 {
                2.31 * k as f64 / 1000.0
            } else {
                2.31 + 0.3 * jitter[k]
            }
        })
        .collect();
    let crossings = v
        .windows(2)
        .filter(|w| (w[0] < 2.31) != (w[1] < 2.31))
        .count();
    assert!(crossings > 1000, "{crossings}");
    let s = schmitt("v(in)", &t, &v, 0.99, 2.31).unwrap();
    assert_eq!(s.edges.len(), 1);
    assert_eq!(s.edges[0].direction, Direction::Rising);
    assert_eq!(s.edges[0].width, None);
}

#[test]
fn crossing_of_a_sampled_exponential_is_within_the_interpolation_error() {
    // v = 1 − e^(−t/τ) crosses 0.5 at τ·ln 2. Linear interpolation of
    // a concave curve crosses late, by at most Δt²·max|v''|/(8·min v')
    // over the bracketing interval = Δt²/(8τ)·e^(Δt/τ).
    let tau = 1e-3;
    for dt in [1e-4, 3e-5, 1e-6] {
        let n = (5.0 * tau / dt) as usize + 1;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let v: Vec<f64> = t.iter().map(|&t| 1.0 - (-t / tau).exp()).collect();
        let s = schmitt("v(out)", &t, &v, 0.2, 0.5).unwrap();
        assert_eq!(s.edges.len(), 1);
        let exact = tau * std::f64::consts::LN_2;
        let bound = dt * dt / (8.0 * tau) * (dt / tau).exp();
        let error = s.edges[0].time - exact;
        assert!(
            (-1e-15..=bound + 1e-15).contains(&error),
            "Δt = {dt}: error {error:e}, bound {bound:e}"
        );
    }
}

#[test]
fn an_undetermined_start_becomes_a_level_without_an_edge() {
    let t = [0.0, 1.0, 2.0, 3.0, 4.0];
    // Starts at 1.5 V (between), reaches high: defined, not an edge;
    // then falls through low: one falling edge at 3.5 s.
    let v = [1.5, 2.0, 3.0, 3.0, 0.0];
    let s = schmitt("v(a)", &t, &v, 1.0, 2.5).unwrap();
    assert_eq!(s.initial_state, Level::Undetermined);
    assert_eq!(s.final_state, Level::Low);
    assert_eq!(s.edges.len(), 1);
    assert_eq!(s.edges[0].direction, Direction::Falling);
    assert!((s.edges[0].time - (3.0 + 2.0 / 3.0)).abs() < 1e-12);
    // Never reaching a threshold leaves it undetermined.
    let s = schmitt("v(a)", &t, &[1.5; 5], 1.0, 2.5).unwrap();
    assert_eq!(s.final_state, Level::Undetermined);
    assert!(s.edges.is_empty());
}

#[test]
fn a_start_on_a_threshold_is_that_level() {
    let t = [0.0, 1.0, 2.0];
    let s = schmitt("v(a)", &t, &[2.5, 1.0, 1.0], 1.0, 2.5).unwrap();
    assert_eq!(s.initial_state, Level::High);
    assert_eq!(s.edges.len(), 1);
    assert_eq!(s.edges[0].time, 1.0);
    // A step stored as two samples at one instant is an edge at it.
    let s = schmitt(
        "v(a)",
        &[0.0, 1.0, 1.0, 2.0],
        &[0.0, 0.0, 3.0, 3.0],
        1.0,
        2.5,
    )
    .unwrap();
    assert_eq!(s.edges.len(), 1);
    assert_eq!(s.edges[0].time, 1.0);
}

#[test]
fn charge_per_closure_of_exponential_pulses() {
    // Two closures, each a current pulse i = I0·e^(−(t−ts)/τ) while
    // closed and 0 when open: charge I0·τ·(1 − e^(−T/τ)) each, with T
    // the closure's length. Sampled every 0.1 µs; the trapezoid's error
    // is at most Δt²/12·T·max|i''| = Δt²·T·I0/(12τ²), plus the open
    // edges, which are steps inside one sample interval (≤ I0·Δt/2).
    let (i0, tau, dt) = (0.5, 2e-5, 1e-7);
    let n = 5001;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    // On samples, so that each pulse's first value is I0 exactly.
    let closures = [(t[1000], t[1800]), (t[3000], t[3200])];
    let i: Vec<f64> = t
        .iter()
        .map(|&t| {
            closures
                .iter()
                .find(|&&(a, b)| t >= a && t <= b)
                .map_or(0.0, |&(a, _)| i0 * (-(t - a) / tau).exp())
        })
        .collect();
    let c = current("i(v1)", &t, &i, &closures).unwrap();
    assert_eq!(c.per_closure.len(), 2);
    let mut total = 0.0;
    for (w, &(a, b)) in c.per_closure.iter().zip(&closures) {
        let length = b - a;
        let exact = i0 * tau * (1.0 - (-length / tau).exp());
        let bound = dt * dt * length * i0 / (12.0 * tau * tau) + i0 * dt;
        assert!(
            (w.charge - exact).abs() <= bound,
            "{} vs {exact}, bound {bound:e}",
            w.charge
        );
        assert!((w.peak - i0).abs() < 1e-12, "{}", w.peak);
        assert!((w.peak_time - a).abs() <= dt, "{}", w.peak_time);
        assert_eq!((w.start, w.end), (a, b));
        total += exact;
    }
    assert!((c.closed_charge - total).abs() < 2.0 * i0 * dt);
    // Zero current outside the closures: the record's charge is theirs.
    assert!((c.charge - total).abs() < 2.0 * i0 * dt);
    assert!((c.peak - i0).abs() < 1e-12);
}

#[test]
fn window_interpolates_its_ends() {
    // A ramp i = t: ∫ from 0.25 to 2.5 of t dt = (2.5² − 0.25²)/2.
    let t = [0.0, 1.0, 2.0, 3.0];
    let c = current("i(x)", &t, &t, &[(0.25, 2.5), (1.5, 1.5), (2.5, 9.0)]).unwrap();
    let q = c.per_closure[0];
    assert!((q.charge - (2.5f64.powi(2) - 0.0625) / 2.0).abs() < 1e-12);
    assert_eq!((q.peak, q.peak_time), (2.5, 2.5));
    // A zero-length closure (rigid surface): no charge, the value then.
    let q = c.per_closure[1];
    assert_eq!((q.charge, q.peak), (0.0, 1.5));
    // Clipped to the record's end.
    let q = c.per_closure[2];
    assert_eq!((q.start, q.end), (2.5, 3.0));
    assert!((q.charge - (9.0 - 6.25) / 2.0).abs() < 1e-12);
    assert_eq!(c.charge, 4.5);
}

#[test]
fn a_voltage_has_no_current_analysis_and_a_current_has_one() {
    let t = [0.0, 1.0];
    let p = probe("i(v1)", -1.0, 1.0);
    let a = analyze_samples(&p, ProbeKind::Current, &t, &[0.0, -2.0], &[(0.0, 1.0)]).unwrap();
    let c = a.current.unwrap();
    assert_eq!((c.peak, c.peak_time, c.charge), (2.0, 1.0, -1.0));
    let a = analyze_samples(&p, ProbeKind::Voltage, &t, &[0.0, -2.0], &[]).unwrap();
    assert_eq!(a.current, None);
}

#[test]
fn comparison_is_bounced_minus_ideal() {
    let t = grid(1001, 1e-3);
    let p = probe("i(v1)", 0.1, 0.2);
    // Ideal: one make at 100 µs to 0.3 A. Bounced: two short closures
    // to 0.4 A first, final make at 300 µs.
    let ideal: Vec<f64> = t
        .iter()
        .map(|&t| if t >= 1e-4 { 0.3 } else { 0.0 })
        .collect();
    let bounced: Vec<f64> = t
        .iter()
        .map(|&t| match t {
            t if (1e-4..1.2e-4).contains(&t) || (2e-4..2.1e-4).contains(&t) => 0.4,
            t if t >= 3e-4 => 0.3,
            _ => 0.0,
        })
        .collect();
    let kind = ProbeKind::Current;
    let i = analyze_samples(&p, kind, &t, &ideal, &[(1e-4, 1e-3)]).unwrap();
    let b = analyze_samples(&p, kind, &t, &bounced, &[(1e-4, 1e-3)]).unwrap();
    assert_eq!((i.edges, b.edges), (1, 5));
    let c = compare(&b, &i).unwrap();
    // Current glitches are pulses after the first: 3 pulses against 1.
    assert_eq!((b.pulses, i.pulses), (Some(3), Some(1)));
    assert_eq!((c.extra_edges, c.extra_glitches), (4, 2));
    assert!(c.same_final_state);
    let delay = c.settle_delay.unwrap();
    assert!((delay - 2e-4).abs() < 1e-6 + 1e-12, "{delay}");
    assert!((c.max_difference - 0.1).abs() < 1e-12);
    assert_eq!(c.min_difference, 0.0);
    assert!((c.peak_difference.unwrap() - 0.1).abs() < 1e-12);
    // Less charge: 200 µs late at 0.3 A, partly made up by 30 µs at 0.4 A.
    let expected = -2e-4 * 0.3 + 3e-5 * 0.4;
    assert!((c.charge_difference.unwrap() - expected).abs() < 3e-6 * 0.4);
    // And the other way round, the signs flip.
    let r = compare(&i, &b).unwrap();
    assert_eq!(r.extra_edges, -4);
    let other = analyze_samples(&probe("v(x)", 0.1, 0.2), kind, &t, &ideal, &[]).unwrap();
    assert!(matches!(
        compare(&b, &other),
        Err(AnalysisError::NotComparable { .. })
    ));
}

#[test]
fn classify_by_name_then_raw_type() {
    use ProbeKind::*;
    assert_eq!(ProbeKind::classify("v(in)", None), Voltage);
    assert_eq!(ProbeKind::classify("V(a,b)", Some("current")), Voltage);
    assert_eq!(ProbeKind::classify("i(v1)", None), Current);
    assert_eq!(ProbeKind::classify("@r1[i]", None), Current);
    assert_eq!(ProbeKind::classify("v1#branch", Some("current")), Current);
    assert_eq!(ProbeKind::classify("out", Some("voltage")), Voltage);
    assert_eq!(ProbeKind::classify("@m1[gm]", Some("notype")), Other);
    assert_eq!(ProbeKind::classify("x", None), Other);
    assert_eq!(
        (Voltage.unit(), Current.unit(), Other.unit()),
        ("V", "A", "")
    );
}

#[test]
fn bad_input_is_named() {
    let t = [0.0, 1e-3, 2e-3];
    let err = schmitt("v(in)", &t, &[0.0, f64::NAN, 1.0], 1.0, 2.0).unwrap_err();
    assert!(
        matches!(err, AnalysisError::NotFinite { index: 1, time, value, .. }
            if time == 1e-3 && value.is_nan()),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("v(in)") && msg.contains("NaN") && msg.contains("1e-3"),
        "{msg}"
    );
    let err = schmitt("v(in)", &[0.0, f64::NAN], &[0.0, 1.0], 1.0, 2.0).unwrap_err();
    assert!(matches!(err, AnalysisError::NotFinite { ref signal, .. } if signal == "time"));
    for (low, high) in [
        (2.0, 1.0),
        (1.0, 1.0),
        (f64::NAN, 1.0),
        (0.0, f64::INFINITY),
    ] {
        let err = schmitt("v(q)", &t, &[0.0; 3], low, high).unwrap_err();
        assert!(matches!(err, AnalysisError::Thresholds { .. }), "{err}");
        assert!(err.to_string().contains("v(q)"), "{err}");
    }
    let err = schmitt("v(in)", &[], &[], 1.0, 2.0).unwrap_err();
    assert!(matches!(err, AnalysisError::Empty { .. }), "{err}");
    let err = schmitt("v(in)", &t, &[0.0; 2], 1.0, 2.0).unwrap_err();
    assert!(matches!(
        err,
        AnalysisError::LengthMismatch {
            time: 3,
            values: 2,
            ..
        }
    ));
    let err = schmitt("v(in)", &[0.0, 2.0, 1.0], &[0.0; 3], 1.0, 2.0).unwrap_err();
    assert!(
        matches!(err, AnalysisError::TimeGoesBack { index: 2, .. }),
        "{err}"
    );
    for bad in [(2e-3, 1e-3), (f64::NAN, 1e-3)] {
        let err = current("i(v1)", &t, &[0.0; 3], &[bad]).unwrap_err();
        assert!(
            matches!(err, AnalysisError::BadClosure { index: 0, .. }),
            "{err}"
        );
    }
    let err = current("i(v1)", &t, &[0.0; 3], &[(0.0, 1e-3), (3e-3, 4e-3)]).unwrap_err();
    assert!(
        matches!(err, AnalysisError::ClosureOutsideRecord { index: 1, .. }),
        "{err}"
    );
}

#[test]
fn json_starts_with_the_contract_fields() {
    let a = analyze_samples(
        &probe("v(in)", 1.0, 2.0),
        ProbeKind::Voltage,
        &[0.0, 1.0, 2.0],
        &[3.0, 0.0, 3.0],
        &[],
    )
    .unwrap();
    let json = serde_json::to_string(&a).unwrap();
    assert!(
        json.starts_with(r#"{"signal":"v(in)","edges":2,"glitches":1,"first_edge":"#),
        "{json}"
    );
    let at = |key: &str| json.find(&format!("\"{key}\":")).unwrap();
    let order = ["first_edge", "last_edge", "min", "max", "kind"].map(at);
    assert!(order.windows(2).all(|w| w[0] < w[1]), "{json}");
    assert!(json.contains(r#""current":null"#), "{json}");
    assert!(json.contains(r#""direction":"falling""#), "{json}");
}

#[test]
fn closures_are_the_closed_intervals() {
    let chatter = crate::report::fixtures::stuck();
    assert_eq!(
        closures(&chatter),
        vec![(0.0012, 0.00121), (0.0014, 0.001405), (0.0016, 0.02)]
    );
}

/// An MCU input the contact shorts: 3.3 V through 10 kΩ onto 1 nF, the
/// contact across the capacitor ramping from 1 nS to 20 S over 10 ns from
/// `make`. Integrated on ngspice's kind of time grid (100 ns steps, then
/// the `inner` steps from the edge on, then steps growing 1.5× back to
/// 100 ns) by the trapezoidal rule and by backward Euler, whose solution
/// of this linear circuit never overshoots. Returns (time, trapezoidal,
/// backward Euler).
fn make_onto_a_capacitor(make: f64, inner: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (vdd, r, c) = (3.3, 1e4, 1e-9);
    let g = |t: f64| {
        if t < make {
            1e-9
        } else if t < make + 1e-8 {
            1e-9 + (20.0 - 1e-9) * (t - make) / 1e-8
        } else {
            20.0
        }
    };
    let mut time = vec![0.0];
    while time.last().unwrap() + 100e-9 < make {
        time.push(time.last().unwrap() + 100e-9);
    }
    time.push(make);
    for h in inner {
        time.push(time.last().unwrap() + h);
    }
    let mut h = *inner.last().unwrap();
    while *time.last().unwrap() < make + 50e-6 {
        h = (h * 1.5).min(100e-9);
        time.push(time.last().unwrap() + h);
    }
    let a = |t: f64| -(1.0 / r + g(t)) / c;
    let b = vdd / (r * c);
    let (mut trap, mut euler) = (vec![vdd], vec![vdd]);
    for k in 1..time.len() {
        let (t0, t1) = (time[k - 1], time[k]);
        let h = t1 - t0;
        let v = trap[k - 1];
        trap.push((v * (1.0 + h * a(t0) / 2.0) + h * b) / (1.0 - h * a(t1) / 2.0));
        euler.push((euler[k - 1] + h * b) / (1.0 - h * a(t1)));
    }
    (time, trap, euler)
}

fn range(values: &[f64]) -> (f64, f64) {
    values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

#[test]
fn integration_ringing_after_a_make_is_reported_beside_the_range() {
    let make = 100e-6;
    let closures = [(make, 200e-6)];
    // Steps like ngspice's around a make: the trapezoidal rule rings up
    // and down from one time point to the next.
    let steps: Vec<f64> = [1e-9, 2e-9, 1.16e-9, 0.65e-9, 0.34e-9]
        .into_iter()
        .chain([0.1e-9; 40])
        .collect();
    let (time, trap, euler) = make_onto_a_capacitor(make, &steps);
    let (raw_min, raw_max) = range(&trap);
    assert!(
        raw_min < -0.01,
        "the trapezoidal rule overshoots: {raw_min}"
    );
    let (true_min, _) = range(&euler);
    assert!(true_min > 0.0, "{true_min}");
    let a = analyze_samples(
        &probe("v(in)", 0.99, 2.31),
        ProbeKind::Voltage,
        &time,
        &trap,
        &closures,
    )
    .unwrap();
    // The range is every sample's; without the ringing it is the
    // circuit's, whose lowest value is where it settles,
    // VDD·(1/20 S)/(10 kΩ), as backward Euler has it.
    assert_eq!((a.min, a.max), (raw_min, raw_max));
    let without = a.min_without_ringing.unwrap();
    assert!((without - true_min).abs() < 1e-6, "{without} vs {true_min}");
    assert_eq!(a.max_without_ringing, None);
    assert_eq!(a.range_for_limits(false), (raw_min, raw_max));
    assert_eq!(a.range_for_limits(true), (without, raw_max));
    assert_eq!(a.ringing.len(), 1, "{:?}", a.ringing);
    let r = &a.ringing[0];
    assert_eq!(r.edge, make);
    assert_eq!(r.min, raw_min);
    assert!(r.start > make && r.start < make + 1e-8, "{r:?}");
    // Said, with both ranges, and the edges are the raw samples'.
    let warning = a.threshold_warning().unwrap();
    let shown = |v: f64| crate::report::units::engineering(v, "V");
    assert!(
        warning.starts_with("v(in): ") && warning.contains(&shown(raw_min)),
        "{warning}"
    );
    assert!(warning.contains(&shown(without)), "{warning}");
    assert!(warning.contains("ignore_ringing"), "{warning}");
    assert_eq!(a.edges, 1);
    // Without the contact's edges nothing is taken for ringing.
    let blind = analyze_samples(
        &probe("v(in)", 0.99, 2.31),
        ProbeKind::Voltage,
        &time,
        &trap,
        &[],
    )
    .unwrap();
    assert_eq!((blind.min, blind.ringing.len()), (raw_min, 0));
    assert_eq!(blind.min_without_ringing, None);
    assert_eq!(blind.threshold_warning(), None);
}

#[test]
fn a_single_overshoot_that_creeps_back_is_not_ringing() {
    // The trapezoidal rule overshooting once and creeping back: not an
    // alternation about a smooth curve, so nothing is set aside.
    let make = 100e-6;
    let steps: Vec<f64> = [0.65e-9, 1.3e-9, 0.78e-9]
        .into_iter()
        .chain([0.1e-9; 40])
        .collect();
    let (time, trap, _) = make_onto_a_capacitor(make, &steps);
    let a = analyze_samples(
        &probe("v(in)", 0.99, 2.31),
        ProbeKind::Voltage,
        &time,
        &trap,
        &[(make, 200e-6)],
    )
    .unwrap();
    assert_eq!((a.min, a.max), range(&trap));
    assert!(a.ringing.is_empty(), "{:?}", a.ringing);
    assert_eq!((a.min_without_ringing, a.max_without_ringing), (None, None));
}

#[test]
fn a_smooth_inrush_peak_right_after_a_make_is_kept() {
    // 12 V through 0.2 Ω (plus the contact's 50 mΩ) into 4.7 µF: the
    // current jumps to 47.7 A in one step at the make and falls smoothly
    // with τ = 0.25 Ω · 4.7 µF = 1.2 µs, sampled as ngspice does after an
    // edge (steps growing from 0.1 µs). Its peak is the circuit's.
    let make = 1e-3;
    let tau = 0.25 * 4.7e-6;
    let mut time: Vec<f64> = (0..10).map(|k| k as f64 * 1e-4).collect();
    let mut values = vec![0.0; time.len()];
    let (mut t, mut h) = (make, 2e-9);
    while t < make + 20e-6 {
        time.push(t);
        values.push(47.7 * (-(t - make) / tau).exp());
        t += h;
        h = (h * 1.8).min(0.5e-6);
    }
    let a = analyze_samples(
        &probe("i(vs)", 1.0, 5.0),
        ProbeKind::Current,
        &time,
        &values,
        &[(make, 2e-3)],
    )
    .unwrap();
    assert!(a.ringing.is_empty(), "{:?}", a.ringing);
    assert_eq!(a.max, 47.7);
    assert_eq!(a.max_without_ringing, None);
    // So a 46 A limit on the peak fails, with or without ignore_ringing.
    for ignore in [false, true] {
        let (lo, hi) = a.range_for_limits(ignore);
        assert!(hi.abs().max(lo.abs()) > 46.0);
    }
}

#[test]
fn a_resolved_oscillation_after_an_edge_is_the_signal() {
    // A break that rings physically: 1 − e^(−t/τ)·cos(ωt) from the edge,
    // sampled as ngspice resolves it (steps from T/1000 doubling to T/40),
    // undershooting and overshooting 1 by a lot. Nothing is left out.
    let (edge, period, tau) = (1e-3, 1e-6, 3e-6);
    let omega = 2.0 * std::f64::consts::PI / period;
    let mut time: Vec<f64> = (0..10).map(|k| k as f64 * 1e-4).collect();
    let mut h = period / 1000.0;
    let mut t = edge;
    while t < edge + 10.0 * period {
        time.push(t);
        t += h;
        h = (2.0 * h).min(period / 40.0);
    }
    let values: Vec<f64> = time
        .iter()
        .map(|&t| {
            if t < edge {
                0.0
            } else {
                1.0 - (-(t - edge) / tau).exp() * (omega * (t - edge)).cos()
            }
        })
        .collect();
    let a = analyze_samples(
        &probe("v(out)", 0.3, 0.7),
        ProbeKind::Voltage,
        &time,
        &values,
        &[(0.5e-3, edge)],
    )
    .unwrap();
    assert!(a.ringing.is_empty(), "{:?}", a.ringing);
    assert_eq!((a.min, a.max), range(&values));
    assert!(a.max > 1.5, "it rings: {}", a.max);
}
