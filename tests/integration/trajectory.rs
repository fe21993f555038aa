//! The one trajectory for every drive: the step force's exact pieces and
//! the integrated cycle under a force F(t, x) describe the same motion,
//! obey the equation of motion between events, and agree with the event
//! records they come with.

use chatterspice::chatter::{ContactState, Outcome};
use chatterspice::mechanics::cycle::Stops;
use chatterspice::mechanics::surface::hunt_crossley_chi;
use chatterspice::mechanics::{
    Drive, Mechanics, Settings, Surface, Trajectory, TrajectoryEventKind, simulate_drive,
};

/// The model's Kelvin–Voigt reference: 18 contacts, stuck.
fn reference() -> (Mechanics, Surface, Settings) {
    (
        Mechanics {
            mass: 1.0,
            stiffness: 1.0,
            damping: 0.1,
            force: 1.0,
            gap: 0.9,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        },
        Surface::KelvinVoigt {
            stiffness: 100.0,
            damping: 2.0 * 0.4692,
        },
        Settings {
            t_end: 100.0,
            ..Settings::default()
        },
    )
}

/// A signal relay on a Hertzian Hunt–Crossley contact: 11 contacts, stuck.
fn hertz() -> (Mechanics, Surface, Settings) {
    (
        Mechanics {
            mass: 2e-4,
            stiffness: 800.0,
            damping: 0.04,
            force: 1.0,
            gap: 4.5e-4,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        },
        Surface::HuntCrossley {
            stiffness: 1e9,
            exponent: 1.5,
            chi: hunt_crossley_chi(0.8, 0.3).unwrap(),
        },
        Settings::default(),
    )
}

fn only(make: Surface) -> Stops {
    Stops { make, back: None }
}

fn step(m: &Mechanics, s: Surface, st: &Settings) -> Trajectory {
    simulate_drive(m, &only(s), st, Drive::Step).unwrap()
}

/// Every contact interval's start and end, with what it starts from.
fn contacts(tr: &Trajectory) -> Vec<(f64, f64)> {
    tr.chatter()
        .intervals
        .iter()
        .filter(|i| i.state == ContactState::Closed && i.end > i.start)
        .map(|i| (i.start, i.end))
        .collect()
}

#[test]
fn the_step_trajectory_meets_the_contact_at_every_event_with_the_event_velocities() {
    let (m, s, st) = reference();
    let tr = step(&m, s, &st);
    let chatter = tr.chatter();
    assert_eq!(chatter.impacts.len(), 18);
    for i in &chatter.impacts {
        let (x, v) = tr.state(i.impact_time);
        assert!((x - m.gap).abs() < 1e-12, "x at touch {x}");
        assert!((v - i.impact_velocity).abs() < 1e-12 * i.impact_velocity.abs().max(1.0));
        if let Some(t) = i.release_time {
            // Just after the release, the flight from (g, v_release).
            let (x, v) = tr.state(t + 1e-9);
            let v_rel = i.release_velocity.unwrap();
            assert!((x - (m.gap + v_rel * 1e-9)).abs() < 1e-15, "{x}");
            assert!((v - v_rel).abs() < 1e-8, "{v} vs {v_rel}");
        }
    }
}

#[test]
fn between_events_the_step_trajectory_obeys_its_equations() {
    // m ẍ + r ẋ + s x = f − p in flight, plus the surface force in
    // contact, by central differences of the velocity in every interval.
    let (m, s, st) = reference();
    let tr = step(&m, s, &st);
    let mut checked = 0;
    for iv in &tr.chatter().intervals {
        if iv.end - iv.start < 1e-3 || iv.end > 50.0 {
            continue;
        }
        for k in 1..8 {
            let t = iv.start + (iv.end - iv.start) * k as f64 / 8.0;
            let h = 1e-5 * (iv.end - iv.start);
            let a = (tr.velocity(t + h) - tr.velocity(t - h)) / (2.0 * h);
            let (x, v) = tr.state(t);
            let contact = tr.contact_force(t);
            if iv.state == ContactState::Open {
                assert_eq!(contact, 0.0);
                assert!(tr.gap(t) > 0.0 && (tr.gap(t) - (m.gap - x)).abs() < 1e-15);
            } else {
                assert_eq!(tr.gap(t), 0.0);
                assert!(contact != 0.0);
            }
            let residual = m.mass * a + m.damping * v + m.stiffness * x + contact - m.force;
            assert!(residual.abs() < 1e-6, "t = {t}: residual {residual}");
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked}");
}

#[test]
fn the_contact_force_peaks_where_the_engine_says() {
    for (m, s, st) in [reference(), hertz()] {
        let tr = step(&m, s, &st);
        for (i, (t0, t1)) in tr
            .chatter()
            .impacts
            .iter()
            .zip(contacts(&tr))
            .filter(|(i, _)| i.release_time.is_some())
        {
            let peak = (0..=2000)
                .map(|k| tr.contact_force(t0 + (t1 - t0) * k as f64 / 2000.0))
                .fold(f64::MIN, f64::max);
            let expected = i.peak_force.unwrap();
            assert!(
                (peak - expected).abs() < 1e-4 * expected,
                "{s:?}: sampled peak {peak}, engine {expected}"
            );
        }
    }
}

#[test]
fn the_hunt_crossley_contacts_are_followed_to_their_release() {
    let (m, s, st) = hertz();
    let tr = step(&m, s, &st);
    let chatter = tr.chatter();
    assert_eq!(
        (chatter.impacts.len(), chatter.outcome),
        (11, Outcome::Stuck)
    );
    for i in &chatter.impacts {
        let Some(t) = i.release_time else { continue };
        // Mid-contact the armature is past the surface; at the release
        // it is back at it with the release velocity.
        let mid = 0.5 * (i.impact_time + t);
        assert!(tr.position(mid) > m.gap, "{}", tr.position(mid));
        let (x, v) = tr.state(t);
        assert!((x - m.gap).abs() < 1e-9 * m.gap, "{x}");
        let v_rel = i.release_velocity.unwrap();
        assert!((v - v_rel).abs() < 1e-6 * v_rel.abs(), "{v} vs {v_rel}");
    }
    // Stuck: pressed into the surface to the end, at the static
    // penetration where spring and surface balance the drive.
    let (x, v) = tr.state(st.t_end);
    let Surface::HuntCrossley {
        stiffness,
        exponent,
        ..
    } = s
    else {
        unreachable!()
    };
    let balance = m.force - m.stiffness * x - stiffness * (x - m.gap).powf(exponent);
    assert!(x > m.gap && v.abs() < 1e-3, "{x} {v}");
    assert!(balance.abs() < 1e-3 * m.force, "{balance}");
}

#[test]
fn a_constant_force_and_the_step_give_the_same_motion() {
    for (m, s, st) in [reference(), hertz()] {
        let exact = step(&m, s, &st);
        let f = m.force;
        let force = move |_t: f64, _x: f64| f;
        let driven = simulate_drive(&m, &only(s), &st, Drive::Force(&force)).unwrap();
        let end = exact.chatter().settle_time.unwrap() * 1.5;
        for k in 0..=500 {
            let t = end * k as f64 / 500.0;
            let (a, b) = (exact.position(t), driven.position(t));
            assert!(
                (a - b).abs() < 1e-6 * m.gap,
                "{s:?}, t = {t}: step {a}, driven {b}"
            );
        }
        let touches = |tr: &Trajectory| {
            tr.events()
                .iter()
                .filter(|e| e.kind == TrajectoryEventKind::Touch)
                .map(|e| e.time)
                .collect::<Vec<_>>()
        };
        let (a, b) = (touches(&exact), touches(&driven));
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-7 * end, "{x} vs {y}");
        }
    }
}

#[test]
fn the_events_are_the_records_in_time_order() {
    let (m, s, st) = reference();
    let tr = step(&m, s, &st);
    let events = tr.events();
    assert!(events.windows(2).all(|w| w[0].time <= w[1].time));
    let count = |k: TrajectoryEventKind| events.iter().filter(|e| e.kind == k).count();
    let chatter = tr.chatter();
    assert_eq!(count(TrajectoryEventKind::LiftOff), 1);
    assert_eq!(count(TrajectoryEventKind::Touch), chatter.impacts.len());
    assert_eq!(
        count(TrajectoryEventKind::Release),
        chatter
            .impacts
            .iter()
            .filter(|i| i.release_time.is_some())
            .count()
    );
    let settled: Vec<_> = events
        .iter()
        .filter(|e| e.kind == TrajectoryEventKind::Settled)
        .collect();
    assert_eq!(settled.len(), 1);
    assert_eq!(Some(settled[0].time), chatter.settle_time);
}

#[test]
fn a_pulse_gives_the_whole_cycle_with_its_forces() {
    // A 1 N pulse from 0.2 ms to 5 ms against a 0.1 N preload: lift-off,
    // chatter on a rigid contact, pressed, the break, the landing on an
    // inelastic rest stop, held there.
    let m = Mechanics {
        mass: 2e-4,
        stiffness: 800.0,
        damping: 0.04,
        force: 0.0,
        gap: 4.5e-4,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.1,
    };
    let stops = Stops {
        make: Surface::Rigid { restitution: 0.5 },
        back: None,
    };
    let st = Settings {
        t_end: 0.012,
        ..Settings::default()
    };
    let pulse = |t: f64, _x: f64| if (2e-4..5e-3).contains(&t) { 1.0 } else { 0.0 };
    let tr = simulate_drive(&m, &stops, &st, Drive::Force(&pulse)).unwrap();
    let kinds: Vec<TrajectoryEventKind> = tr.events().iter().map(|e| e.kind).collect();
    assert_eq!(kinds.first(), Some(&TrajectoryEventKind::LiftOff));
    assert!(kinds.contains(&TrajectoryEventKind::Settled));
    assert_eq!(kinds.last(), Some(&TrajectoryEventKind::Landing));
    let lift = tr.events()[0].time;
    assert!((lift - 2e-4).abs() < 1e-9, "{lift}");
    // Held on the rest stop before: the stop carries the preload.
    assert!((tr.back_force(1e-4) - m.preload).abs() < 1e-12);
    assert_eq!(tr.position(1e-4), 0.0);
    // Pressed on the rigid contact: the drive less preload and spring.
    let pressed = 4.5e-3;
    assert_eq!(tr.gap(pressed), 0.0);
    let expected = 1.0 - m.preload - m.stiffness * m.gap;
    assert!((tr.contact_force(pressed) - expected).abs() < 1e-9);
    assert_eq!(tr.back_force(pressed), 0.0);
    // Back on the stop at the end, the contact open by the whole gap.
    assert_eq!(tr.position(st.t_end), 0.0);
    assert_eq!(tr.gap(st.t_end), m.gap);
    assert_eq!(tr.strokes().len(), 1);
    assert!(tr.back().is_some());
}

#[test]
fn the_path_and_the_gap_samples_follow_the_trajectory() {
    let (m, s, st) = hertz();
    let f = m.force;
    let force = move |_t: f64, _x: f64| f;
    for drive in [Drive::Step, Drive::Force(&force)] {
        let tr = simulate_drive(&m, &only(s), &st, drive).unwrap();
        let path = tr.path();
        assert!(path.windows(2).all(|w| w[0].0 < w[1].0));
        for &(t, x) in &path {
            assert!(
                (tr.position(t) - x).abs() < 1e-9 * m.gap,
                "{drive:?} t = {t}"
            );
        }
        let gaps = tr.gap_samples(24);
        assert!(gaps.windows(2).all(|w| w[0].0 < w[1].0));
        assert!(gaps.iter().all(|&(_, g)| (0.0..=m.gap).contains(&g)));
        // The first opening is sampled densely enough to show the flight.
        let first = tr.chatter().first_impact.unwrap();
        assert!(gaps.iter().filter(|&&(t, _)| t < first).count() >= 20);
    }
}
