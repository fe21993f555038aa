//! Unit tests of waveform.rs.
use super::*;

const MODEL: ContactModel = ContactModel {
    r_closed: 0.05,
    r_open: 1e9,
    edge_time: 1e-8,
};

fn iv(state: ContactState, start: f64, end: f64) -> Interval {
    Interval { state, start, end }
}

/// Intervals from alternating boundaries, starting in `first`.
fn tiling(first: ContactState, bounds: &[f64]) -> Vec<Interval> {
    let mut state = first;
    bounds
        .windows(2)
        .map(|w| {
            let out = iv(state, w[0], w[1]);
            state = match state {
                ContactState::Open => ContactState::Closed,
                ContactState::Closed => ContactState::Open,
            };
            out
        })
        .collect()
}

fn assert_increasing(w: &Waveform) {
    for p in w.points().windows(2) {
        assert!(p[1].time > p[0].time, "{:?} then {:?}", p[0], p[1]);
    }
}

#[test]
fn one_bounce_gives_three_edges_at_the_events() {
    use ContactState::Open;
    let ivs = tiling(Open, &[0.0, 1e-3, 1.2e-3, 1.5e-3, 2e-3]);
    let w = Waveform::from_intervals(&ivs, &MODEL).unwrap();
    assert_eq!((w.make_edges(), w.break_edges()), (2, 1));
    assert_eq!((w.merged_openings(), w.widened_closures()), (0, 0));
    assert_increasing(&w);
    let (go, gc, e) = (MODEL.g_open(), MODEL.g_closed(), MODEL.edge_time);
    let expect = [
        (0.0, go),
        (1e-3, go),
        (1e-3 + e, gc),
        (1.2e-3, gc),
        (1.2e-3 + e, go),
        (1.5e-3, go),
        (1.5e-3 + e, gc),
        (2e-3, gc),
    ];
    let got: Vec<(f64, f64)> = w.points().iter().map(|p| (p.time, p.conductance)).collect();
    assert_eq!(got, expect);
    // Halfway along the make edge, linear in G.
    let mid = w.conductance_at(1e-3 + e / 2.0);
    assert!((mid - (go + gc) / 2.0).abs() < 1e-9 * gc);
    assert_eq!(w.resistance_at(1.1e-3), 0.05);
    assert!((w.resistance_at(-1.0) / 1e9 - 1.0).abs() < 1e-12);
    assert_eq!(w.conductance_at(5.0), gc);
}

#[test]
fn a_1ns_opening_with_10ns_edges_is_merged() {
    use ContactState::Open;
    let ivs = tiling(Open, &[0.0, 1e-6, 2e-6, 2.001e-6, 3e-6, 4e-6]);
    // Open, closed 1–2 µs, open 1 ns, closed 2.001–3 µs, open.
    let w = Waveform::from_intervals(&ivs, &MODEL).unwrap();
    assert_eq!(w.merged_openings(), 1);
    assert_eq!(w.widened_closures(), 0);
    // One closure 1–3 µs, then open to the end.
    assert_eq!((w.make_edges(), w.break_edges()), (1, 1));
    assert_eq!(w.conductance_at(2.5e-6), MODEL.g_closed());
    assert_eq!(w.conductance_at(3.5e-6), MODEL.g_open());
    assert_eq!(w.conductance_at(2.0005e-6), MODEL.g_closed());
    assert_increasing(&w);
}

#[test]
fn zero_length_closures_become_one_edge_pulses() {
    use ContactState::{Closed, Open};
    let ivs = vec![
        iv(Open, 0.0, 1e-6),
        iv(Closed, 1e-6, 1e-6),
        iv(Open, 1e-6, 2e-6),
        iv(Closed, 2e-6, 3e-6),
    ];
    let w = Waveform::from_intervals(&ivs, &MODEL).unwrap();
    assert_eq!(w.widened_closures(), 1);
    assert_eq!(w.merged_openings(), 0);
    assert_eq!(w.edge_count(), 3);
    let e = MODEL.edge_time;
    assert_eq!(w.conductance_at(1e-6 + e), MODEL.g_closed());
    assert_eq!(w.conductance_at(1e-6 + 2.0 * e), MODEL.g_open());
    assert_increasing(&w);
}

#[test]
fn leading_and_trailing_states_are_kept() {
    use ContactState::{Closed, Open};
    // Starts closed (no make edge), ends open with a short opening.
    let ivs = tiling(Closed, &[0.0, 1e-6, 1e-6 + 1e-9]);
    let w = Waveform::from_intervals(&ivs, &MODEL).unwrap();
    assert_eq!((w.make_edges(), w.break_edges()), (0, 1));
    assert_eq!(w.points()[0].conductance, MODEL.g_closed());
    assert_eq!(w.points().last().unwrap().time, 1e-6 + MODEL.edge_time);
    // Never closes: a flat line.
    let w = Waveform::from_intervals(&[iv(Open, 0.0, 1e-3)], &MODEL).unwrap();
    assert_eq!(w.points().len(), 2);
    assert_eq!(w.edge_count(), 0);
    // Closed from an instant touch at the very end.
    let ivs = vec![iv(Open, 0.0, 1e-3), iv(Closed, 1e-3, 1e-3)];
    let w = Waveform::from_intervals(&ivs, &MODEL).unwrap();
    assert_eq!((w.make_edges(), w.break_edges()), (1, 0));
    assert_increasing(&w);
}

#[test]
fn bad_models_name_their_key() {
    let key = |m: ContactModel| match m.validate() {
        Err(WaveformError::InvalidContact { key, .. }) => key,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        key(ContactModel {
            r_closed: 0.0,
            ..MODEL
        }),
        "contact.r_closed"
    );
    assert_eq!(
        key(ContactModel {
            r_open: 0.01,
            ..MODEL
        }),
        "contact.r_open"
    );
    assert_eq!(
        key(ContactModel {
            r_open: f64::INFINITY,
            ..MODEL
        }),
        "contact.r_open"
    );
    assert_eq!(
        key(ContactModel {
            edge_time: f64::NAN,
            ..MODEL
        }),
        "contact.edge_time"
    );
    let msg = ContactModel {
        edge_time: -1.0,
        ..MODEL
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(msg.contains("`contact.edge_time` = -1.0 must be"), "{msg}");
}

#[test]
fn edges_below_float_resolution_are_refused() {
    let m = ContactModel {
        edge_time: 1e-20,
        ..MODEL
    };
    let ivs = [iv(ContactState::Open, 0.0, 1.0)];
    assert!(matches!(
        Waveform::from_intervals(&ivs, &m),
        Err(WaveformError::EdgeBelowResolution { .. })
    ));
}

#[test]
fn intervals_must_tile() {
    use ContactState::{Closed, Open};
    assert_eq!(
        Waveform::from_intervals(&[], &MODEL),
        Err(WaveformError::NoIntervals)
    );
    let gap = [iv(Open, 0.0, 1.0), iv(Closed, 1.5, 2.0)];
    assert!(matches!(
        Waveform::from_intervals(&gap, &MODEL),
        Err(WaveformError::BadInterval { index: 1, .. })
    ));
    let backwards = [iv(Open, 1.0, 0.5)];
    assert!(matches!(
        Waveform::from_intervals(&backwards, &MODEL),
        Err(WaveformError::BadInterval { index: 0, .. })
    ));
}

#[test]
fn format_time_round_trips_and_separates_neighbours() {
    let t: f64 = 1.0e-3;
    let next = f64::from_bits(t.to_bits() + 1);
    assert_ne!(format_time(t), format_time(next));
    for x in [0.0, 1e-8, 1.5e-3, next, 0.1 + 0.2] {
        assert_eq!(format_time(x).parse::<f64>().unwrap(), x);
    }
    assert_eq!(format_time(0.0), "0e0");
    assert_eq!(format_time(1.5e-3), "1.5e-3");
}

#[test]
fn pwl_body_is_pairs() {
    let w = Waveform::from_intervals(&[iv(ContactState::Closed, 0.0, 1e-3)], &MODEL).unwrap();
    assert_eq!(w.pwl_body(), "0e0 2e1 1e-3 2e1");
}

fn csv(text: &str) -> Result<Vec<Interval>, WaveformError> {
    read_state_csv(text, Path::new("scope.csv"))
}

fn row_problem(text: &str) -> (usize, CsvProblem) {
    match csv(text) {
        Err(WaveformError::CsvRow { line, problem, .. }) => (line, problem),
        other => panic!("{other:?}"),
    }
}

#[test]
fn csv_happy_path() {
    use ContactState::{Closed, Open};
    let text = "Time, State\r\n0,open\n1e-3,1\n\n1.2e-3,OPEN\n1.5e-3,closed\n2e-3,closed\n";
    assert_eq!(
        csv(text).unwrap(),
        vec![
            iv(Open, 0.0, 1e-3),
            iv(Closed, 1e-3, 1.2e-3),
            iv(Open, 1.2e-3, 1.5e-3),
            iv(Closed, 1.5e-3, 2e-3),
        ]
    );
    let w = Waveform::from_state_changes(text, Path::new("scope.csv"), &MODEL).unwrap();
    assert_eq!(w.edge_count(), 3);
}

#[test]
fn csv_errors_name_the_line() {
    assert!(matches!(
        csv("t,s\n0,open\n"),
        Err(WaveformError::CsvHeader { line: 1, .. })
    ));
    assert!(matches!(csv("\n  \n"), Err(WaveformError::CsvEmpty { .. })));
    assert!(matches!(
        csv("time,state\n"),
        Err(WaveformError::CsvEmpty { .. })
    ));
    assert_eq!(
        row_problem("time,state\n0,open\n1e-3,closed\n1e-3,open\n"),
        (
            4,
            CsvProblem::NonIncreasingTime {
                time: 1e-3,
                previous: 1e-3
            }
        )
    );
    assert_eq!(
        row_problem("time,state\n0,open\n\n1e-3,shut\n"),
        (
            4,
            CsvProblem::UnknownState {
                text: "shut".into()
            }
        )
    );
    assert_eq!(
        row_problem("time,state\nNaN,open\n"),
        (2, CsvProblem::NonFiniteTime { text: "NaN".into() })
    );
    assert_eq!(
        row_problem("time,state\n1 ms,open\n").1,
        CsvProblem::BadTime {
            text: "1 ms".into()
        }
    );
    assert_eq!(
        row_problem("time,state\n-1e-6,open\n").1,
        CsvProblem::NegativeTime { time: -1e-6 }
    );
    assert_eq!(
        row_problem("time,state\n0,open,x\n").1,
        CsvProblem::FieldCount { found: 3 }
    );
    let msg = csv("time,state\n0,open\nx,open\n").unwrap_err().to_string();
    assert!(msg.starts_with("scope.csv: line 3: time `x`"), "{msg}");
}

const HOLM: Holm = Holm {
    r_film: 0.01,
    r_ref: 0.04,
    f_ref: 1.0,
    exponent: 0.5,
};

#[test]
fn holm_resistance_follows_the_force_and_is_clamped_to_open() {
    let r = |f| HOLM.resistance(f, MODEL.r_open);
    assert_eq!(r(1.0), 0.05);
    assert_eq!(r(4.0), 0.01 + 0.04 / 2.0);
    assert_eq!(r(0.0), MODEL.r_open);
    assert_eq!(r(-0.3), MODEL.r_open);
    assert_eq!(r(1e-40), MODEL.r_open);
    assert!(r(0.25) > r(1.0) && r(1.0) > r(100.0));
}

#[test]
fn holm_parameters_are_checked_by_key() {
    for (bad, key) in [
        (
            Holm {
                r_film: -1.0,
                ..HOLM
            },
            "contact.holm.r_film",
        ),
        (Holm { r_ref: 0.0, ..HOLM }, "contact.holm.r_ref"),
        (
            Holm {
                f_ref: f64::NAN,
                ..HOLM
            },
            "contact.holm.f_ref",
        ),
        (
            Holm {
                exponent: 1.5,
                ..HOLM
            },
            "contact.holm.exponent",
        ),
    ] {
        let err = bad.validate().unwrap_err();
        assert!(err.to_string().contains(key), "{err}");
    }
}

/// A sequence with 3 bounce closures of different lengths, then closed.
fn bouncing() -> Chatter {
    let mut c = crate::chatter::fixtures::stuck();
    c.intervals = tiling(
        ContactState::Open,
        &[
            0.0, 1.0e-3, 1.05e-3, 1.3e-3, 1.33e-3, 1.5e-3, 1.52e-3, 1.6e-3, 5e-3,
        ],
    );
    c
}

/// A force that rises and falls within each closure, and settles.
fn ringing_force(t: f64) -> f64 {
    0.5 + 0.4 * (2e4 * t).sin()
}

#[test]
fn a_holm_contact_follows_the_force_at_every_sample() {
    let c = bouncing();
    let mut asked = Vec::new();
    let w = Waveform::from_chatter_holm(&c, &MODEL, &HOLM, |ts| {
        asked.extend_from_slice(ts);
        ts.iter().map(|&t| ringing_force(t)).collect()
    })
    .unwrap();
    assert_increasing(&w);
    let plain = Waveform::from_chatter(&c, &MODEL).unwrap();
    assert_eq!(w.make_edges(), plain.make_edges());
    assert_eq!(w.break_edges(), plain.break_edges());
    assert!(
        asked.windows(2).all(|p| p[1] > p[0]),
        "times asked in order"
    );
    // Every time asked for is a corner with the Holm conductance.
    for t in &asked {
        let expected = 1.0 / HOLM.resistance(ringing_force(*t), MODEL.r_open);
        // Read back through the interpolation: exact up to its last
        // bit (which an optimised build may round otherwise).
        let got = w.conductance_at(*t);
        assert!(
            (got / expected - 1.0).abs() < 1e-14,
            "at {t}: {got} {expected}"
        );
    }
    // The shortest closure (20 µs) gets its 16 samples and more: its
    // plateau has at least 16 corners.
    let in_shortest = asked.iter().filter(|&&t| t > 1.5e-3 && t < 1.52e-3).count();
    assert!(in_shortest >= HOLM_SAMPLES_PER_CLOSURE, "{in_shortest}");
    // The final closure is capped, and ends at the end of the record.
    let in_final = asked.iter().filter(|&&t| t > 1.6e-3).count();
    assert!(in_final <= HOLM_MAX_SAMPLES, "{in_final}");
    assert_eq!(*asked.last().unwrap(), 5e-3);
    // Open stays open.
    assert_eq!(w.conductance_at(1.2e-3), MODEL.g_open());
}

#[test]
fn a_constant_force_gives_the_constant_contact_of_its_resistance() {
    let c = bouncing();
    let w = Waveform::from_chatter_holm(&c, &MODEL, &HOLM, |ts| vec![4.0; ts.len()]).unwrap();
    let equivalent = ContactModel {
        r_closed: HOLM.resistance(4.0, MODEL.r_open),
        ..MODEL
    };
    let plain = Waveform::from_chatter(&c, &equivalent).unwrap();
    for k in 0..5000 {
        let t = k as f64 * 1e-6;
        let (a, b) = (w.conductance_at(t), plain.conductance_at(t));
        assert!((a - b).abs() <= 1e-12 * b.abs(), "at {t}: {a} vs {b}");
    }
}

#[test]
fn a_pulling_force_opens_the_contact_electrically() {
    let c = bouncing();
    let w = Waveform::from_chatter_holm(&c, &MODEL, &HOLM, |ts| {
        ts.iter()
            .map(|&t| if t < 1.02e-3 { 1.0 } else { -0.1 })
            .collect()
    })
    .unwrap();
    assert_eq!(w.conductance_at(1.01e-3), 1.0 / 0.05);
    assert_eq!(w.conductance_at(1.04e-3), MODEL.g_open());
}
