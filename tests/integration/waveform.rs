//! The waveform stage on real engine output and on seeded random state
//! sequences: edge counts, levels inside each interval, and strictly
//! increasing times whatever the input.

use chatterspice::scenario::Scenario;
use chatterspice::waveform::{ContactModel, Waveform};
use chatterspice::{Chatter, ContactState, Interval, Surface, simulate};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn default_chatter(surface: Option<Surface>) -> (Chatter, ContactModel) {
    let scenario = Scenario::builtin_default();
    let surface = surface.unwrap_or_else(|| scenario.surface());
    let chatter = simulate(
        &scenario.mechanics().unwrap(),
        &surface,
        &scenario.settings(),
    )
    .unwrap();
    (chatter, ContactModel::from(&scenario.contact))
}

fn assert_increasing(w: &Waveform) {
    for p in w.points().windows(2) {
        assert!(p[1].time > p[0].time, "{:?} then {:?}", p[0], p[1]);
    }
}

#[test]
fn default_relay_edges_and_levels() {
    let (chatter, model) = default_chatter(None);
    assert!(chatter.bounce_count > 0, "the default relay bounces");
    let w = Waveform::from_chatter(&chatter, &model).unwrap();
    assert_eq!(w.merged_openings(), 0);
    assert_eq!(w.widened_closures(), 0);
    assert_eq!(w.edge_count(), 1 + 2 * chatter.bounce_count);
    assert_increasing(&w);

    let e = model.edge_time;
    for iv in &chatter.intervals {
        // Away from the edges: after the entering edge, before the leaving one.
        let (lo, hi) = (iv.start + e, iv.end);
        assert!(hi - lo > e, "{iv:?} is long enough to probe");
        let expected = match iv.state {
            ContactState::Open => model.g_open(),
            ContactState::Closed => model.g_closed(),
        };
        for k in 1..10 {
            let t = lo + (hi - lo) * f64::from(k) / 10.0;
            assert_eq!(w.conductance_at(t), expected, "at {t:e} s in {iv:?}");
        }
    }
    assert_eq!(w.resistance_at(chatter.t_end), model.r_closed);
}

#[test]
fn rigid_surface_zero_length_closures() {
    let (chatter, model) = default_chatter(Some(Surface::Rigid { restitution: 0.6 }));
    let zero = chatter
        .intervals
        .iter()
        .filter(|iv| iv.state == ContactState::Closed && iv.start == iv.end)
        .count();
    assert!(zero > 0, "a rigid surface gives instant touches");
    let w = Waveform::from_chatter(&chatter, &model).unwrap();
    assert_increasing(&w);
    // Every instant touch is shown as a pulse unless an opening next to it
    // was too short and it joined a neighbour.
    assert!(w.widened_closures() > 0);
    assert!(w.widened_closures() + w.merged_openings() >= zero);
    // Each pulse reaches the closed level one edge after its impact.
    let first = chatter.first_impact.unwrap();
    assert_eq!(w.conductance_at(first + model.edge_time), model.g_closed());
    assert_eq!(w.resistance_at(chatter.t_end), model.r_closed);
}

/// A random sequence tiling [0, t_end], with durations spread over many
/// decades around the edge time, including zero-length intervals.
fn random_intervals(rng: &mut ChaCha8Rng, edge: f64) -> Vec<Interval> {
    let n = 1 + (rng.random::<f64>() * 60.0) as usize;
    let mut state = if rng.random::<f64>() < 0.7 {
        ContactState::Open
    } else {
        ContactState::Closed
    };
    let mut t = 0.0;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let d = if rng.random::<f64>() < 0.15 {
            0.0
        } else {
            edge * 10f64.powf(-3.0 + 6.0 * rng.random::<f64>())
        };
        out.push(Interval {
            state,
            start: t,
            end: t + d,
        });
        t += d;
        state = match state {
            ContactState::Open => ContactState::Closed,
            ContactState::Closed => ContactState::Open,
        };
    }
    out
}

#[test]
fn random_sequences_never_give_non_increasing_times() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x3a7e_f0a1);
    let (mut merged, mut widened) = (0, 0);
    for case in 0..3000 {
        let edge = 10f64.powf(-10.0 + 5.0 * rng.random::<f64>());
        let model = ContactModel {
            r_closed: 0.05,
            r_open: 1e9,
            edge_time: edge,
        };
        let ivs = random_intervals(&mut rng, edge);
        let w =
            Waveform::from_intervals(&ivs, &model).unwrap_or_else(|e| panic!("case {case}: {e}"));
        assert!(!w.points().is_empty());
        merged += w.merged_openings();
        widened += w.widened_closures();
        for p in w.points().windows(2) {
            assert!(
                p[1].time > p[0].time,
                "case {case}: {:?} then {:?} from {ivs:?}",
                p[0],
                p[1]
            );
        }
        for p in w.points() {
            assert!(p.conductance == model.g_open() || p.conductance == model.g_closed());
        }
        // The formatted times are as distinct as the times.
        let body = w.pwl_body();
        let times: Vec<&str> = body.split(' ').step_by(2).collect();
        for pair in times.windows(2) {
            assert_ne!(pair[0], pair[1], "case {case}");
        }
    }
    // The sweep exercises both adjustments, not only easy sequences.
    assert!(
        merged > 1000 && widened > 1000,
        "{merged} merged, {widened} widened"
    );
}
