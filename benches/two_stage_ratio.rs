//! The two-stage engine's cost against the one-mass engine's on the same
//! sequence, timed in turn in one process: `cargo bench --bench
//! two_stage_ratio [-- ROUNDS]` (300 rounds by default).
//!
//! Criterion times its benches one after the other, so on a shared
//! machine the ratio of `two_stage_18_contacts` to
//! `kelvin_voigt_reference_18_contacts` (benches/mechanics.rs) carries
//! whatever the load did between them. Here each round times 200 calls
//! of the one-mass engine and then 20 of the two-stage one on the same
//! relays as those benches, so both see the same load; the least and
//! the median time a call over the rounds, and their ratios, are
//! printed. Target: the two-stage engine within 10× the one-mass one.
//!
//! `two_stage_ratio calls ENGINE N` (ENGINE `one-mass` or `two-stage`)
//! runs N calls of one engine, untimed, for an instruction counter: the
//! difference between N = 100 and N = 0 under `valgrind --tool=cachegrind
//! --cache-sim=no`, divided by 100, is the instructions a call
//! (docs/model.md, "Speed").

use std::hint::black_box;
use std::time::Instant;

use chatterspice::mechanics::Drive;
use chatterspice::mechanics::cycle::Stops;
use chatterspice::mechanics::two_stage::{Horizon, simulate_two_stage};
use chatterspice::simulate;

mod common;
use common::{on_a_blade, reference};

fn main() {
    // The two sequences benches/mechanics.rs times.
    let (m, surface, settings) = reference();
    let stops = Stops {
        make: surface,
        back: None,
    };
    let relay = on_a_blade();
    let one_mass = || simulate(black_box(&m), &surface, &settings).expect("the reference runs");
    let two_stage = || {
        simulate_two_stage(
            black_box(&m),
            &relay,
            &stops,
            &settings,
            Drive::Step,
            Horizon::Closing,
        )
        .expect("the two-stage relay runs")
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let Some(at) = args.iter().position(|a| a == "calls") {
        let (engine, n) = (args.get(at + 1), args.get(at + 2));
        let n: usize = n.and_then(|n| n.parse().ok()).expect("calls ENGINE N");
        for _ in 0..n {
            match engine.map(String::as_str) {
                Some("one-mass") => drop(black_box(one_mass())),
                Some("two-stage") => drop(black_box(two_stage())),
                _ => panic!("calls ENGINE N: ENGINE is one-mass or two-stage"),
            }
        }
        return;
    }
    // `cargo bench` passes `--bench`; a number among the arguments is
    // the rounds.
    let rounds = args
        .iter()
        .find_map(|a| a.parse::<usize>().ok())
        .unwrap_or(300)
        .max(1);
    assert_eq!(one_mass().impacts.len(), 18);
    assert_eq!(two_stage().contact.impacts.len(), 18);
    let (mut one, mut two) = (Vec::with_capacity(rounds), Vec::with_capacity(rounds));
    for _ in 0..rounds {
        let start = Instant::now();
        for _ in 0..200 {
            black_box(one_mass());
        }
        one.push(start.elapsed().as_secs_f64() / 200.0);
        let start = Instant::now();
        for _ in 0..20 {
            black_box(two_stage());
        }
        two.push(start.elapsed().as_secs_f64() / 20.0);
    }
    one.sort_by(f64::total_cmp);
    two.sort_by(f64::total_cmp);
    for (what, k) in [("least", 0), ("median", rounds / 2)] {
        let (a, b) = (one[k] * 1e6, two[k] * 1e6);
        println!(
            "{what:>6}: one-mass {a:.2} µs, two-stage {b:.1} µs a call: {:.2}×",
            b / a
        );
    }
}
