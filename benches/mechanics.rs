//! The mechanics engine's speed: one whole chatter sequence per iteration.
//!
//! `cargo bench --bench mechanics`. Targets: the docs/model.md
//! reference sequence (Kelvin–Voigt, 18 contacts) ≤ 5 µs median; a
//! Hunt–Crossley sequence ≤ 50 µs; the two-stage engine on the same
//! reference (`two_stage_18_contacts`) ≤ 10 × the one-mass one, and on the
//! slowest random family (`two_stage_hunt_crossley_force_release`)
//! ≤ 0.3 s. Also measured: the same reference as a
//! whole trajectory (`simulate_drive` with the step drive: the sequence
//! and the motion rebuilt between its events), and one closing and the
//! whole cycle of the integrated engine under a drive that varies.

use std::hint::black_box;

use chatterspice::coil::simulate_forced;
use chatterspice::mechanics::cycle::Stops;
use chatterspice::mechanics::surface::hunt_crossley_chi;
use chatterspice::mechanics::two_stage::{Blade, Horizon, Release, TwoStage, simulate_two_stage};
use chatterspice::mechanics::{Drive, simulate_drive};
use chatterspice::{Mechanics, Settings, Surface, simulate};
use criterion::{Criterion, criterion_group, criterion_main};

mod common;
use common::{on_a_blade, reference};

/// A signal relay that chatters and sticks: the default relay's armature
/// (0.2 g, 800 N/m, 0.45 mm travel) driven with 1 N onto a Hertzian
/// Hunt–Crossley contact (n = 1.5, 1e9 N/m^1.5) with e = 0.8 at 0.3 m/s.
/// First impact at 0.45 ms and 1.9 m/s, 11 contacts, stuck at 2.1 ms:
/// the 1–5 ms bounce of a datasheet signal relay (docs/model.md §6).
fn hunt_crossley() -> (Mechanics, Surface, Settings) {
    let (m, _, _) = reference();
    let m = Mechanics {
        mass: 2e-4,
        stiffness: 800.0,
        damping: 0.04,
        force: 1.0,
        gap: 4.5e-4,
        ..m
    };
    let s = Surface::HuntCrossley {
        stiffness: 1e9,
        exponent: 1.5,
        chi: hunt_crossley_chi(0.8, 0.3).expect("valid restitution"),
    };
    (m, s, Settings::default())
}

fn bench(c: &mut Criterion) {
    let (m, s, st) = reference();
    let n = simulate(&m, &s, &st).unwrap().impacts.len();
    assert_eq!(n, 18);
    c.bench_function("kelvin_voigt_reference_18_contacts", |b| {
        b.iter(|| simulate(black_box(&m), black_box(&s), black_box(&st)).unwrap())
    });
    let (m, s, st) = hunt_crossley();
    let r = simulate(&m, &s, &st).unwrap();
    assert_eq!((r.impacts.len(), r.outcome.as_str()), (11, "stuck"));
    c.bench_function("hunt_crossley_sequence", |b| {
        b.iter(|| simulate(black_box(&m), black_box(&s), black_box(&st)).unwrap())
    });

    // The reference armature carrying a blade of a fifth of its mass, as
    // stiff as the contact (s_b = 100 s, r_b = 1): also 18 contacts, by
    // the two-stage engine.
    let (m, s, st) = reference();
    let stops = Stops {
        make: s,
        back: None,
    };
    let relay = on_a_blade();
    let run = simulate_two_stage(&m, &relay, &stops, &st, Drive::Step, Horizon::Closing).unwrap();
    assert_eq!(
        (run.contact.impacts.len(), run.contact.outcome.as_str()),
        (18, "stuck")
    );
    c.bench_function("two_stage_18_contacts", |b| {
        b.iter(|| {
            simulate_two_stage(
                black_box(&m),
                &relay,
                &stops,
                &st,
                Drive::Step,
                Horizon::Closing,
            )
            .unwrap()
        })
    });

    // The slowest family of the random relays the differential test
    // draws: a light armature on a blade, a Hertzian Hunt–Crossley
    // contact (n = 3/2) released by its force, no pole face (the
    // differential test's seed 2854, run to 40 ms): some 370 contacts,
    // integrated by DOP853. Target: ≤ 0.3 s.
    let (m, _, _) = reference();
    let m = Mechanics {
        mass: 3.93929914837911e-05,
        stiffness: 1985.778836845934,
        damping: 0.047661527017649453,
        force: 0.38743002955142436,
        gap: 0.00014961833068559866,
        ..m
    };
    let relay = TwoStage {
        blade: Some(Blade {
            mass: 4.5589204586750366e-05,
            stiffness: 2355.7311259089524,
            damping: 0.0020002396815135513,
        }),
        pole_face: None,
        release: Release::Force,
    };
    let stops = Stops {
        make: Surface::HuntCrossley {
            stiffness: 1944407158.8513405,
            exponent: 1.5,
            chi: 0.1399266282057719,
        },
        back: None,
    };
    let st = Settings {
        t_end: 0.04,
        ..Settings::default()
    };
    let run = simulate_two_stage(&m, &relay, &stops, &st, Drive::Step, Horizon::Closing).unwrap();
    assert!(
        run.contact.impacts.len() > 300,
        "{}",
        run.contact.impacts.len()
    );
    c.bench_function("two_stage_hunt_crossley_force_release", |b| {
        b.iter(|| {
            simulate_two_stage(
                black_box(&m),
                &relay,
                &stops,
                &st,
                Drive::Step,
                Horizon::Closing,
            )
            .unwrap()
        })
    });

    let (m, s, st) = reference();
    let stops = Stops {
        make: s,
        back: None,
    };
    c.bench_function("kelvin_voigt_reference_trajectory", |b| {
        b.iter(|| simulate_drive(black_box(&m), &stops, &st, Drive::Step).unwrap())
    });

    // The signal relay of `hunt_crossley` on a Kelvin–Voigt contact,
    // under a 1 N force that switches on at 0.1 ms and off at 5 ms,
    // against a 0.1 N preload.
    let (m, _, _) = hunt_crossley();
    let m = Mechanics { preload: 0.1, ..m };
    let stops = Stops {
        make: Surface::KelvinVoigt {
            stiffness: 8e4,
            damping: 0.37536,
        },
        back: None,
    };
    let st = Settings {
        t_end: 0.012,
        ..Settings::default()
    };
    let pulse = |t: f64, _x: f64| if (1e-4..5e-3).contains(&t) { 1.0 } else { 0.0 };
    c.bench_function("driven_closing", |b| {
        b.iter(|| simulate_forced(black_box(&m), &stops.make, &st, pulse).unwrap())
    });
    c.bench_function("driven_cycle", |b| {
        b.iter(|| simulate_drive(black_box(&m), &stops, &st, Drive::Force(&pulse)).unwrap())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
