//! The two-stage relay (armature, blade, pole face) against an
//! independent integration of its equations, written here from the model
//! alone: classical fixed-step Runge–Kutta 4 at a step far below every
//! period, each event bisected by re-integrating its step to the
//! bisection point. It shares nothing with the engine but the equations.

use chatterspice::mechanics::cycle::Stops;
use chatterspice::mechanics::two_stage::{
    Blade, Horizon, PoleFace, Release, TwoStage, simulate_two_stage,
};
use chatterspice::mechanics::{Drive, simulate};
use chatterspice::{Mechanics, Outcome, Settings, Surface};

/// The armature of the example relay.
fn armature() -> Mechanics {
    Mechanics {
        mass: 1.0e-4,
        stiffness: 5000.0,
        damping: 0.07,
        force: 1.0,
        gap: 1.4e-4,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.0,
    }
}

const BLADE: Blade = Blade {
    mass: 2.0e-5,
    stiffness: 2000.0,
    damping: 0.005,
};

/// (s0, r0) of the contact, and of the pole face.
const CONTACT: (f64, f64) = (5.0e5, 0.3);
const POLE: (f64, f64) = (2.0e6, 2.0);
const OVERTRAVEL: f64 = 1.0e-4;

/// One event of the reference: (time, which, velocity of the body).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Touch,
    Release,
    PoleTouch,
    PoleRelease,
}

#[derive(Debug, Clone, Copy)]
struct Ev {
    t: f64,
    kind: Kind,
    v: f64,
}

/// The reference model: step force, blade, Kelvin–Voigt contact and
/// (optionally) a Kelvin–Voigt pole face released by position.
struct Reference {
    m: Mechanics,
    blade: Blade,
    pole: bool,
    by_force: bool,
}

type S = [f64; 4];

impl Reference {
    fn contact_force(&self, y: &S, engaged: bool) -> f64 {
        let (s0, r0) = CONTACT;
        if engaged {
            s0 * (y[2] - self.m.gap) + r0 * y[3]
        } else {
            0.0
        }
    }

    fn rate(&self, y: &S, contact: bool, pole: bool) -> S {
        let m = &self.m;
        let fb = self.blade.stiffness * (y[0] - y[2]) + self.blade.damping * (y[1] - y[3]);
        let fp = if pole {
            POLE.0 * (y[0] - m.gap - OVERTRAVEL) + POLE.1 * y[1]
        } else {
            0.0
        };
        let aa = (m.force - m.preload - m.stiffness * y[0] - m.damping * y[1] - fb - fp) / m.mass;
        let ab = (fb - self.contact_force(y, contact)) / self.blade.mass;
        [y[1], aa, y[3], ab]
    }

    fn rk4(&self, y: &S, h: f64, c: bool, p: bool) -> S {
        let add = |a: &S, k: &S, f: f64| [0, 1, 2, 3].map(|i| a[i] + f * k[i]);
        let k1 = self.rate(y, c, p);
        let k2 = self.rate(&add(y, &k1, h / 2.0), c, p);
        let k3 = self.rate(&add(y, &k2, h / 2.0), c, p);
        let k4 = self.rate(&add(y, &k3, h), c, p);
        [0, 1, 2, 3].map(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }

    /// Positive while the modes last.
    fn guards(&self, y: &S, c: bool, p: bool) -> [f64; 2] {
        let g = self.m.gap;
        let (s0, r0) = CONTACT;
        let delta = y[2] - g;
        let push = s0 * delta + r0 * y[3];
        let contact = match (c, self.by_force) {
            (false, false) => -delta,
            (false, true) => (-delta).max(-push),
            (true, false) => delta,
            (true, true) => delta.min(push),
        };
        let pole = if !self.pole {
            1.0
        } else if p {
            y[0] - g - OVERTRAVEL
        } else {
            g + OVERTRAVEL - y[0]
        };
        [contact, pole]
    }

    fn run(&self, t_end: f64, h: f64) -> Vec<Ev> {
        let (g, o) = (self.m.gap, OVERTRAVEL);
        let mut y: S = [0.0; 4];
        let (mut c, mut p) = (false, false);
        let mut t = 0.0;
        let mut out = Vec::new();
        while t < t_end {
            let next = self.rk4(&y, h, c, p);
            let gs = self.guards(&next, c, p);
            let Some(which) = (0..2).find(|&k| gs[k] < 0.0) else {
                y = next;
                t += h;
                continue;
            };
            // Bisect the step: the first τ at which a guard turns negative.
            let (mut lo, mut hi) = (0.0, h);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                let ym = self.rk4(&y, mid, c, p);
                if self.guards(&ym, c, p).iter().any(|&v| v < 0.0) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let which = {
                let yh = self.rk4(&y, hi, c, p);
                let gh = self.guards(&yh, c, p);
                if gh[0] < 0.0 { 0 } else { which.max(1) }
            };
            y = self.rk4(&y, hi, c, p);
            t += hi;
            if which == 0 {
                if (y[2] - g).abs() < 1e-12 {
                    y[2] = g;
                }
                out.push(Ev {
                    t,
                    kind: if c { Kind::Release } else { Kind::Touch },
                    v: y[3],
                });
                c = !c;
            } else {
                y[0] = g + o;
                out.push(Ev {
                    t,
                    kind: if p {
                        Kind::PoleRelease
                    } else {
                        Kind::PoleTouch
                    },
                    v: y[1],
                });
                p = !p;
            }
        }
        out
    }
}

fn relay(pole: bool, release: Release) -> TwoStage {
    TwoStage {
        blade: Some(BLADE),
        pole_face: pole.then_some(PoleFace {
            overtravel: OVERTRAVEL,
            surface: Surface::KelvinVoigt {
                stiffness: POLE.0,
                damping: POLE.1,
            },
            release: Release::Position,
        }),
        release,
    }
}

fn contact() -> Stops {
    Stops {
        make: Surface::KelvinVoigt {
            stiffness: CONTACT.0,
            damping: CONTACT.1,
        },
        back: None,
    }
}

fn close(a: f64, b: f64, rel: f64, what: &str) {
    let scale = a.abs().max(b.abs()).max(1e-300);
    assert!(
        (a - b).abs() <= rel * scale,
        "{what}: engine {a:e} against reference {b:e} ({:.2e} relative)",
        (a - b).abs() / scale
    );
}

/// The engine's contact and pole-face events against the reference's,
/// in order, over the reference's horizon.
fn compare(pole: bool, release: Release) -> (usize, usize) {
    let m = armature();
    let settings = Settings {
        t_end: 0.02,
        ..Settings::default()
    };
    let run = simulate_two_stage(
        &m,
        &relay(pole, release),
        &contact(),
        &settings,
        Drive::Step,
        Horizon::Closing,
    )
    .unwrap();
    let horizon = run.contact.settle_time.expect("the contact settles") + 2e-4;
    let reference = Reference {
        m,
        blade: BLADE,
        pole,
        by_force: release == Release::Force,
    }
    .run(horizon, 2e-9);
    let mut engine = Vec::new();
    for i in &run.contact.impacts {
        engine.push(Ev {
            t: i.impact_time,
            kind: Kind::Touch,
            v: i.impact_velocity,
        });
        if let (Some(t), Some(v)) = (i.release_time, i.release_velocity) {
            engine.push(Ev {
                t,
                kind: Kind::Release,
                v,
            });
        }
    }
    for i in run.pole_face.iter().filter(|i| i.impact_time < horizon) {
        engine.push(Ev {
            t: i.impact_time,
            kind: Kind::PoleTouch,
            v: i.impact_velocity,
        });
        if let (Some(t), Some(v)) = (i.release_time, i.release_velocity) {
            engine.push(Ev {
                t,
                kind: Kind::PoleRelease,
                v,
            });
        }
    }
    engine.sort_by(|a, b| a.t.total_cmp(&b.t));
    // The reference follows the pole face after the contact has settled
    // (the engine stops there): compare what both have.
    let reference: Vec<Ev> = reference
        .into_iter()
        .filter(|e| {
            e.t <= run.contact.settle_time.unwrap() + 1e-12
                || engine.iter().any(|x| (x.t - e.t).abs() < 1e-9)
        })
        .collect();
    assert_eq!(
        engine.iter().map(|e| e.kind).collect::<Vec<_>>(),
        reference.iter().map(|e| e.kind).collect::<Vec<_>>(),
        "the sequence of events"
    );
    for (a, b) in engine.iter().zip(&reference) {
        close(a.t, b.t, 1e-6, &format!("{:?} time", a.kind));
        let vscale = 1e-5 * m.force / (m.mass * (m.stiffness / m.mass).sqrt());
        assert!(
            (a.v - b.v).abs() <= 1e-5 * b.v.abs() + vscale,
            "{:?} velocity at {:e}: engine {:e}, reference {:e}",
            a.kind,
            a.t,
            a.v,
            b.v
        );
    }
    (run.contact.impacts.len(), run.pole_face.len())
}

#[test]
fn a_blade_without_a_pole_face_agrees_with_an_independent_integration() {
    let (contacts, poles) = compare(false, Release::Position);
    assert!(contacts > 3, "{contacts} contacts");
    assert_eq!(poles, 0);
}

#[test]
fn a_blade_and_a_pole_face_agree_with_an_independent_integration() {
    let (contacts, poles) = compare(true, Release::Position);
    assert!(
        poles >= 1 && contacts > 3,
        "{contacts} contacts, {poles} pole-face impacts"
    );
}

#[test]
fn a_contact_released_by_force_agrees_with_an_independent_integration() {
    let (contacts, poles) = compare(true, Release::Force);
    assert!(
        poles >= 1 && contacts > 3,
        "{contacts} contacts, {poles} pole-face impacts"
    );
}

#[test]
fn the_pole_face_impact_opens_the_contact_again() {
    let m = armature();
    let run = simulate_two_stage(
        &m,
        &relay(true, Release::Position),
        &contact(),
        &Settings::default(),
        Drive::Step,
        Horizon::Closing,
    )
    .unwrap();
    let first_pole = run.pole_face[0].impact_time;
    // The contact made before the pole face was reached, and opens again
    // after it: a release later than the pole-face impact.
    assert!(run.contact.impacts[0].impact_time < first_pole);
    assert!(
        run.contact
            .impacts
            .iter()
            .any(|i| i.release_time.is_some_and(|r| r > first_pole)),
        "no opening after the pole-face impact at {first_pole:e}"
    );
    // Without the pole face the sequence is another one.
    let free = simulate_two_stage(
        &m,
        &relay(false, Release::Position),
        &contact(),
        &Settings::default(),
        Drive::Step,
        Horizon::Closing,
    )
    .unwrap();
    assert_ne!(free.contact.impacts.len(), run.contact.impacts.len());
}

#[test]
fn a_stiff_light_blade_converges_to_the_one_mass_model() {
    let m = armature();
    let settings = Settings::default();
    let surface = contact().make;
    // A thousandth of the mass, a hundred times the contact's stiffness.
    let light = Blade {
        mass: 1e-3 * m.mass,
        stiffness: 100.0 * CONTACT.0,
        damping: 0.5,
    };
    let one = simulate(
        &Mechanics {
            mass: m.mass + light.mass,
            ..m
        },
        &surface,
        &settings,
    )
    .unwrap();
    let two = simulate_two_stage(
        &m,
        &TwoStage {
            blade: Some(light),
            pole_face: None,
            release: Release::Position,
        },
        &contact(),
        &settings,
        Drive::Step,
        Horizon::Closing,
    )
    .unwrap();
    close(
        two.contact.first_impact.unwrap(),
        one.first_impact.unwrap(),
        1e-3,
        "first impact",
    );
    assert_eq!(two.contact.bounce_count, one.bounce_count);
    assert_eq!(two.contact.outcome, Outcome::Stuck);
}

#[test]
fn the_integrating_and_the_exact_engines_agree() {
    // The same relay under the same constant force, once as the step
    // drive (solved exactly, mode by mode) and once as a force F(t, x)
    // (integrated by DOP853; the rest stop it adds is never reached).
    let m = armature();
    let settings = Settings::default();
    for release in [Release::Position, Release::Force] {
        let relay = relay(true, release);
        let exact = simulate_two_stage(
            &m,
            &relay,
            &contact(),
            &settings,
            Drive::Step,
            Horizon::Closing,
        )
        .unwrap();
        let force = |_t: f64, _x: f64| m.force;
        let integrated = simulate_two_stage(
            &m,
            &relay,
            &contact(),
            &settings,
            Drive::Force(&force),
            Horizon::Closing,
        )
        .unwrap();
        let (a, b) = (&exact.contact, &integrated.contact);
        assert_eq!(a.impacts.len(), b.impacts.len(), "{release:?}");
        assert_eq!(a.outcome, b.outcome);
        for (x, y) in a.impacts.iter().zip(&b.impacts) {
            close(x.impact_time, y.impact_time, 1e-8, "impact time");
            close(
                x.impact_velocity,
                y.impact_velocity,
                1e-6,
                "impact velocity",
            );
        }
        close(
            a.settle_time.unwrap(),
            b.settle_time.unwrap(),
            1e-8,
            "settle time",
        );
        assert_eq!(exact.pole_face.len(), integrated.pole_face.len());
    }
}

#[test]
fn hunt_crossley_and_rigid_surfaces_work_on_both_stops() {
    use chatterspice::mechanics::surface::hunt_crossley_chi;
    let m = armature();
    let hc = Surface::HuntCrossley {
        stiffness: 1e9,
        exponent: 1.5,
        chi: hunt_crossley_chi(0.8, 0.3).unwrap(),
    };
    let rigid = Surface::Rigid { restitution: 0.5 };
    for (contact_law, pole_law) in [(hc, rigid), (rigid, hc)] {
        let relay = TwoStage {
            blade: Some(BLADE),
            pole_face: Some(PoleFace {
                overtravel: OVERTRAVEL,
                surface: pole_law,
                release: Release::Position,
            }),
            release: Release::Position,
        };
        let stops = Stops {
            make: contact_law,
            back: None,
        };
        let run = simulate_two_stage(
            &m,
            &relay,
            &stops,
            &Settings::default(),
            Drive::Step,
            Horizon::Closing,
        )
        .unwrap();
        let c = &run.contact;
        assert!(
            c.outcome.is_closed(),
            "{contact_law:?} / {pole_law:?}: {:?}",
            c.outcome
        );
        assert!(c.impacts.len() > 1 && !run.pole_face.is_empty());
        // Every contact releases before the next touch, in time order.
        for pair in c.impacts.windows(2) {
            let released = pair[0].release_time.expect("an earlier contact released");
            assert!(pair[0].impact_time <= released && released <= pair[1].impact_time);
        }
    }
}

/// The one-mass model with a Kelvin–Voigt contact released by force,
/// integrated as [`Reference`] does.
fn one_mass_released_by_force(m: &Mechanics, t_end: f64, h: f64) -> Vec<(f64, bool)> {
    let (s0, r0) = CONTACT;
    let g = m.gap;
    let rate = |y: [f64; 2], engaged: bool| {
        let fc = if engaged {
            s0 * (y[0] - g) + r0 * y[1]
        } else {
            0.0
        };
        [
            y[1],
            (m.force - m.stiffness * y[0] - m.damping * y[1] - fc) / m.mass,
        ]
    };
    let rk4 = |y: [f64; 2], h: f64, c: bool| {
        let k1 = rate(y, c);
        let k2 = rate([y[0] + h / 2.0 * k1[0], y[1] + h / 2.0 * k1[1]], c);
        let k3 = rate([y[0] + h / 2.0 * k2[0], y[1] + h / 2.0 * k2[1]], c);
        let k4 = rate([y[0] + h * k3[0], y[1] + h * k3[1]], c);
        [
            y[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            y[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
        ]
    };
    let guard = |y: [f64; 2], c: bool| {
        let delta = y[0] - g;
        let push = s0 * delta + r0 * y[1];
        if c {
            delta.min(push)
        } else {
            (-delta).max(-push)
        }
    };
    let (mut y, mut c, mut t) = ([0.0, 0.0], false, 0.0);
    let mut out = Vec::new();
    while t < t_end {
        let next = rk4(y, h, c);
        if guard(next, c) >= 0.0 {
            y = next;
            t += h;
            continue;
        }
        let (mut lo, mut hi) = (0.0, h);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if guard(rk4(y, mid, c), c) < 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        y = rk4(y, hi, c);
        t += hi;
        c = !c;
        out.push((t, c));
    }
    out
}

#[test]
fn a_one_mass_contact_released_by_force_agrees_with_an_independent_integration() {
    let m = armature();
    let relay = TwoStage {
        blade: None,
        pole_face: None,
        release: Release::Force,
    };
    let run = simulate_two_stage(
        &m,
        &relay,
        &contact(),
        &Settings::default(),
        Drive::Step,
        Horizon::Closing,
    )
    .unwrap();
    let horizon = run.contact.settle_time.unwrap() + 1e-4;
    let reference = one_mass_released_by_force(&m, horizon, 2e-9);
    let mut engine = Vec::new();
    for i in &run.contact.impacts {
        engine.push((i.impact_time, true));
        if let Some(r) = i.release_time {
            engine.push((r, false));
        }
    }
    assert_eq!(engine.len(), reference.len(), "{engine:?}\n{reference:?}");
    for (a, b) in engine.iter().zip(&reference) {
        assert_eq!(a.1, b.1);
        close(a.0, b.0, 1e-6, "event time");
    }
    // Released by force, the contact is shorter than by position.
    let by_position = simulate(&m, &contact().make, &Settings::default()).unwrap();
    let (f, p) = (&run.contact.impacts[0], &by_position.impacts[0]);
    assert!(f.contact_time.unwrap() < p.contact_time.unwrap());
    assert!(f.restitution.unwrap() > p.restitution.unwrap());
}
