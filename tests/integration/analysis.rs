//! The analysis against raw files written by real ngspice 39
//! (`tests/data/raw/*.raw`, decks next to them; see `tests/rawfile.rs`),
//! checked against the circuits' closed forms.

use std::path::PathBuf;

use chatterspice::analysis::{
    AnalysisError, Direction, Level, ProbeKind, analyze, compare, schmitt, signal_values,
};
use chatterspice::rawfile::{Plot, RawFile};
use chatterspice::scenario::Probe;

fn read(name: &str) -> RawFile {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/raw")
        .join(name);
    RawFile::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn transient(raw: &RawFile) -> &Plot {
    raw.plot_named("transient analysis").expect("a .tran plot")
}

fn probe(signal: &str, low: f64, high: f64) -> Probe {
    Probe::new(signal, low, high)
}

const R: f64 = 1e3; // Ω
const C: f64 = 1e-6; // F
const TAU: f64 = R * C; // s

/// ngspice's default RELTOL: the transient is within about 1e-3 V of the
/// exact solution on a 1 V signal (tests/rawfile.rs checks it point by
/// point), so a crossing is within 1e-3 V / |dv/dt| of the exact instant.
const TRAN_TOL: f64 = 1e-3;

#[test]
fn rc_step_crosses_half_at_tau_ln_2() {
    // v(out) = 1 − e^(−t/τ) (after a 1 ns ramp): 50 % at τ·ln 2 + ~0.5 ns.
    // Error budget: the simulator's 1e-3 V over the slope 0.5 V/τ, plus
    // linear interpolation over the 50 µs TMAX, Δt²/(8τ)·e^(Δt/τ).
    for file in ["rc_tran.raw", "rc_tran_ascii.raw", "rc_tran_ngspice44.raw"] {
        let raw = read(file);
        let plot = transient(&raw);
        let a = analyze(plot, &probe("v(out)", 0.1, 0.5), &[]).unwrap();
        assert_eq!(a.kind, ProbeKind::Voltage);
        assert_eq!((a.edges, a.glitches), (1, 0), "{file}");
        assert_eq!((a.initial_state, a.final_state), (Level::Low, Level::High));
        assert_eq!(a.transitions[0].direction, Direction::Rising);
        let exact = TAU * std::f64::consts::LN_2 + 0.5e-9;
        let dt = 50e-6;
        let tolerance = TRAN_TOL / (0.5 / TAU) + dt * dt / (8.0 * TAU) * (dt / TAU).exp();
        let t = a.first_edge.unwrap();
        assert!(
            (t - exact).abs() < tolerance,
            "{file}: {t:e} vs {exact:e} (±{tolerance:e})"
        );
        assert_eq!(a.last_edge, Some(t));
        assert_eq!(a.min, 0.0);
        assert!(a.max < 1.0 && a.max > 1.0 - (-2.0f64).exp(), "{}", a.max);
    }
}

#[test]
fn rc_source_current_peak_and_charge() {
    // i(v1) = −(v(in) − v(out))/R: −1 mA at the end of the ramp, decaying
    // with τ. ngspice integrates the capacitor with the trapezoid rule, so
    // the trapezoid ∫ i dt is −C·Δv(out) up to the tolerance of v(out).
    let raw = read("rc_tran.raw");
    let plot = transient(&raw);
    let vout = plot.real("v(out)").unwrap();
    let time = plot.real("time").unwrap();
    let window = (1e-3, 2e-3);
    let a = analyze(plot, &probe("i(v1)", -0.6e-3, -0.4e-3), &[window]).unwrap();
    assert_eq!(a.kind, ProbeKind::Current);
    let c = a.current.as_ref().expect("a current analysis");
    assert!((c.peak - 1e-3).abs() < 1e-3 * TRAN_TOL, "{}", c.peak);
    assert!(c.peak_time <= 2e-9, "{}", c.peak_time);
    let end = *vout.last().unwrap();
    assert!(
        (c.charge + C * end).abs() < C * TRAN_TOL,
        "{} vs {}",
        c.charge,
        -C * end
    );
    let exact = -C * ((-1.0f64).exp() - (-2.0f64).exp());
    let q = c.per_closure[0];
    assert_eq!((q.start, q.end), window);
    assert!(
        (q.charge - exact).abs() < 2.0 * C * TRAN_TOL,
        "{} vs {exact}",
        q.charge
    );
    assert_eq!(c.closed_charge, q.charge);
    assert!((q.peak - (-1.0f64).exp() * 1e-3).abs() < 1e-3 * TRAN_TOL);
    assert!((q.peak_time - 1e-3).abs() < 1e-12);
    // The current starts at 0, above `high` = −0.4 mA: level high. It
    // falls through `low` = −0.6 mA on the 1 ns ramp, then decays back up
    // through `high` at τ·ln(1/0.4).
    assert_eq!(a.initial_state, Level::High);
    assert_eq!(a.edges, 2);
    assert!(a.transitions[0].time <= 1e-9, "{}", a.transitions[0].time);
    let rise = TAU * (1.0f64 / 0.4).ln();
    let rising = a.transitions[1];
    assert_eq!(rising.direction, Direction::Rising);
    assert!(
        (rising.time - rise).abs() < 1e-3 * TRAN_TOL / (0.4e-3 / TAU) + 1e-6,
        "{} vs {rise}",
        rising.time
    );
    assert_eq!(time.len(), plot.points());
}

#[test]
fn divider_pulse_edges_are_exact_on_ngspice_breakpoints() {
    // v(in) = PULSE(0 4 100u 1u 1u 300u 1m): ngspice puts time points on
    // the pulse's corners and keeps a resistive divider linear between
    // them, so the interpolated crossings are exact: 3 V rising at
    // 100.75 µs, 1 V falling at 401.75 µs.
    let raw = read("divider_op_tran.raw");
    let plot = transient(&raw);
    let a = analyze(plot, &probe("v(in)", 1.0, 3.0), &[]).unwrap();
    assert_eq!((a.edges, a.glitches), (2, 1));
    let (rise, fall) = (a.transitions[0], a.transitions[1]);
    assert_eq!(rise.direction, Direction::Rising);
    assert!((rise.time - 100.75e-6).abs() < 1e-12, "{}", rise.time);
    assert!((fall.time - 401.75e-6).abs() < 1e-12, "{}", fall.time);
    assert!((rise.width.unwrap() - 301e-6).abs() < 1e-12);
    assert_eq!(fall.width, None);
    assert_eq!(a.shortest_pulse, rise.width);
    assert_eq!((a.min, a.max), (0.0, 4.0));
    // The divider's middle is a quarter of it: same instants at 1/4 the
    // thresholds.
    let m = analyze(plot, &probe("V(MID)", 0.25, 0.75), &[]).unwrap();
    assert_eq!(m.signal, "V(MID)");
    let r = compare(&a, &a).unwrap();
    assert_eq!((r.extra_edges, r.settle_delay), (0, Some(0.0)));
    for (x, y) in m.transitions.iter().zip(&a.transitions) {
        assert!((x.time - y.time).abs() < 1e-12);
    }
}

#[test]
fn a_missing_signal_lists_the_vectors_there_are() {
    let raw = read("rc_tran.raw");
    let err = analyze(transient(&raw), &probe("v(nope)", 1.0, 2.0), &[]).unwrap_err();
    match &err {
        AnalysisError::MissingSignal {
            signal, available, ..
        } => {
            assert_eq!(signal, "v(nope)");
            assert_eq!(available, &["i(v1)", "time", "v(in)", "v(out)"]);
        }
        other => panic!("{other:?}"),
    }
    let msg = err.to_string();
    assert!(
        msg.contains("v(nope)") && msg.contains("i(v1), time, v(in), v(out)"),
        "{msg}"
    );
}

#[test]
fn an_ac_plot_is_refused() {
    let raw = read("rc_ac.raw");
    let err = analyze(&raw.plots[0], &probe("v(out)", 0.1, 0.5), &[]).unwrap_err();
    assert!(
        matches!(err, AnalysisError::NotTransient { ref scale, .. } if scale.as_deref() == Some("frequency")),
        "{err:?}"
    );
    assert!(err.to_string().contains(".tran"), "{err}");
}

#[test]
fn a_killed_run_analyses_what_was_written() {
    // The cut file holds whole points only (the reader drops the partial
    // one), so the analysis runs on them without complaint.
    let raw = read("killed_binary.raw");
    let plot = transient(&raw);
    let time = plot.real("time").unwrap();
    let out = plot.real("v(out)").unwrap();
    let a = analyze(plot, &probe("v(out)", 0.2, 0.8), &[]).unwrap();
    assert_eq!(a.final_value, *out.last().unwrap());
    let direct = schmitt("v(out)", time, out, 0.2, 0.8).unwrap();
    assert_eq!(direct.edges, a.transitions);
}

#[test]
fn a_differential_voltage_is_the_difference_of_its_nodes() {
    let raw = read("rc_tran.raw");
    let plot = transient(&raw);
    let v_in = plot.real("v(in)").unwrap();
    let v_out = plot.real("v(out)").unwrap();
    // Across the resistor: the same as the capacitor's current times R.
    let (across, kind) = signal_values(plot, "v(in, out)").unwrap();
    assert_eq!(kind.as_deref(), Some("voltage"));
    assert_eq!(across.len(), v_in.len());
    for ((d, a), b) in across.iter().zip(v_in).zip(v_out) {
        assert_eq!(*d, a - b);
    }
    let (to_ground, _) = signal_values(plot, "V(out,0)").unwrap();
    assert_eq!(&*to_ground, v_out);
    let (reversed, _) = signal_values(plot, "v(0,out)").unwrap();
    assert!(reversed.iter().zip(v_out).all(|(r, v)| *r == -v));

    let peak = analyze(plot, &probe("v(in,out)", 0.2, 0.8), &[]).unwrap();
    assert!(
        (peak.max
            - v_in
                .iter()
                .zip(v_out)
                .map(|(a, b)| a - b)
                .fold(f64::MIN, f64::max))
        .abs()
            < 1e-15
    );
    assert!(matches!(
        signal_values(plot, "v(in,nowhere)"),
        Err(AnalysisError::MissingSignal { .. })
    ));
}
