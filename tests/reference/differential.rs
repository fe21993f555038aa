//! The two-stage engine against a brute-force reference over many seeded
//! random relays.
//!
//! The reference is written here from the equations alone (docs/model.md,
//! the two-stage relay) and shares no code with the engine: classical
//! Runge–Kutta 4 at a fixed step of 1 ns, the event functions checked
//! after every step and each event bisected by re-integrating its step to
//! the bisection point (60 halvings). Families: a blade with and without
//! a pole face, a contact released by position and by force,
//! Kelvin–Voigt and Hunt–Crossley contact surfaces (n = 1 and 3/2), light
//! and heavy armatures.
//!
//! Every relay must give the same sequence of contact and pole-face
//! events, with every impact and release time within 1e-6 relative, the
//! same peak and least force of every contact and widest opening after
//! every release (within 1e-6 of the run's largest), and the same ending
//! and settle time when `t_end` is doubled.
//!
//! The pole face's events are compared over the same horizon as the
//! contact's, past the contact's ending: its record runs to `t_end`. A
//! third of the relays run to a short `t_end` (1.5–10 ms), often inside
//! the sequence; a family driven short of the contact ends open. An
//! opening below resolution (1 ns, 1 nm) is merged by both.
//!
//! `CHATTERSPICE_DIFFERENTIAL=N` sets the number of relays (64 by
//! default, for CI); `CHATTERSPICE_DIFFERENTIAL_SEED=S` the first seed.
//! `scripts/differential` runs 10⁵ of them, optimised, for a release.

use chatterspice::mechanics::Drive;
use chatterspice::mechanics::cycle::Stops;
use chatterspice::mechanics::two_stage::{
    Blade, Horizon, PoleFace, Release, TwoStage, TwoStageRun, simulate_two_stage,
};
use chatterspice::{Mechanics, Outcome, Settings, Surface};

/// The reference's step, s.
const STEP: f64 = 1e-9;

/// s and m: an opening shorter or shallower than these (the defaults of
/// `simulation.min_open_time` and `simulation.min_gap`) is below
/// resolution and merged into the contact it interrupts.
const MIN_OPEN: f64 = 1e-9;
const MIN_GAP: f64 = 1e-9;

/// A contact or pole-face law of the reference.
#[derive(Debug, Clone, Copy)]
enum Law {
    /// F = s0 δ + r0 δ̇
    Kv { s0: f64, r0: f64 },
    /// F = max(0, k δⁿ (1 + χ δ̇))
    Hc { k: f64, n: f64, chi: f64 },
}

impl Law {
    fn force(&self, delta: f64, rate: f64) -> f64 {
        match *self {
            Law::Kv { s0, r0 } => s0 * delta + r0 * rate,
            Law::Hc { k, n, chi } => (k * delta.max(0.0).powf(n) * (1.0 + chi * rate)).max(0.0),
        }
    }

    /// Positive while the law pushes (the force rule's release).
    fn pushing(&self, delta: f64, rate: f64) -> f64 {
        match *self {
            Law::Kv { s0, r0 } => s0 * delta + r0 * rate,
            Law::Hc { chi, .. } => 1.0 + chi * rate,
        }
    }

    fn surface(&self) -> Surface {
        match *self {
            Law::Kv { s0, r0 } => Surface::KelvinVoigt {
                stiffness: s0,
                damping: r0,
            },
            Law::Hc { k, n, chi } => Surface::HuntCrossley {
                stiffness: k,
                exponent: n,
                chi,
            },
        }
    }
}

/// One random relay.
#[derive(Debug, Clone, Copy)]
pub struct Relay {
    m: f64,
    s: f64,
    r: f64,
    f: f64,
    g: f64,
    mb: f64,
    sb: f64,
    rb: f64,
    contact: Law,
    contact_by_force: bool,
    /// (overtravel, law, released by force)
    pole: Option<(f64, Law, bool)>,
}

/// What happened, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
}

/// One contact of the reference: its largest and least force (N, over
/// every step and the states at its touch and release) and the widest
/// opening after its release (m, until the next touch or the horizon).
#[derive(Debug, Clone, Copy)]
struct Extremes {
    peak: f64,
    min: f64,
    gap: Option<f64>,
}

type S = [f64; 4];

/// `(M, k)`: the step `y ↦ M y + k`.
type Affine = ([[f64; 4]; 4], S);

impl Relay {
    /// (ẋ_a, ẍ_a, ẋ_b, ẍ_b) in absolute positions from rest.
    fn rate(&self, y: &S, contact: bool, pole: bool) -> S {
        let fb = self.sb * (y[0] - y[2]) + self.rb * (y[1] - y[3]);
        let fp = match (self.pole, pole) {
            (Some((o, law, _)), true) => law.force(y[0] - self.g - o, y[1]),
            _ => 0.0,
        };
        let fc = if contact {
            self.contact.force(y[2] - self.g, y[3])
        } else {
            0.0
        };
        [
            y[1],
            (self.f - self.s * y[0] - self.r * y[1] - fb - fp) / self.m,
            y[3],
            (fb - fc) / self.mb,
        ]
    }

    fn rk4(&self, y: &S, h: f64, c: bool, p: bool) -> S {
        let add = |a: &S, k: &S, f: f64| {
            [
                a[0] + f * k[0],
                a[1] + f * k[1],
                a[2] + f * k[2],
                a[3] + f * k[3],
            ]
        };
        let k1 = self.rate(y, c, p);
        let k2 = self.rate(&add(y, &k1, 0.5 * h), c, p);
        let k3 = self.rate(&add(y, &k2, 0.5 * h), c, p);
        let k4 = self.rate(&add(y, &k3, h), c, p);
        let w = h / 6.0;
        [0, 1, 2, 3].map(|i| y[i] + w * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }

    /// The event functions of the contact and the pole face, each
    /// positive while its mode lasts.
    fn guards(&self, y: &S, c: bool, p: bool) -> [f64; 2] {
        let rule = |engaged: bool, by_force: bool, law: &Law, delta: f64, rate: f64| {
            let push = law.pushing(delta, rate);
            match (engaged, by_force) {
                (false, false) => -delta,
                (false, true) => (-delta).max(-push),
                (true, false) => delta,
                (true, true) => delta.min(push),
            }
        };
        let contact = rule(c, self.contact_by_force, &self.contact, y[2] - self.g, y[3]);
        let pole = match self.pole {
            None => 1.0,
            Some((o, law, by_force)) => rule(p, by_force, &law, y[0] - self.g - o, y[1]),
        };
        [contact, pole]
    }

    /// One RK4 step of [`STEP`] in modes `(c, p)` as `y ↦ M y + k`, when
    /// the equations are linear there.
    fn affine(&self, c: bool, p: bool, step: f64) -> Option<Affine> {
        if c && matches!(self.contact, Law::Hc { .. }) {
            return None;
        }
        let k = self.rk4(&[0.0; 4], step, c, p);
        let mut m = [[0.0; 4]; 4];
        for j in 0..4 {
            let mut e = [0.0; 4];
            e[j] = 1.0;
            let col = self.rk4(&e, step, c, p);
            for i in 0..4 {
                m[i][j] = col[i] - k[i];
            }
        }
        Some((m, k))
    }

    /// Every event up to `t_end`.
    fn reference(&self, t_end: f64) -> Vec<Ev> {
        self.reference_at(t_end, STEP).0
    }

    /// The contact's force as the engine reports it: the law's, and not
    /// below zero for a contact released by force.
    fn contact_force(&self, y: &S) -> f64 {
        let f = self.contact.force(y[2] - self.g, y[3]);
        if self.contact_by_force { f.max(0.0) } else { f }
    }

    /// Every event up to `t_end`, and each contact's extremes.
    fn reference_at(&self, t_end: f64, step: f64) -> (Vec<Ev>, Vec<Extremes>) {
        let (events, extremes, _) = self.reference_with_reach(t_end, step);
        (events, extremes)
    }

    /// [`Relay::reference_at`], with the blade's farthest reach before its
    /// first touch (m, from rest).
    fn reference_with_reach(&self, t_end: f64, step: f64) -> (Vec<Ev>, Vec<Extremes>, f64) {
        let mut y: S = [0.0; 4];
        let (mut c, mut p) = (false, false);
        let mut t = 0.0;
        let mut out = Vec::new();
        let mut contacts: Vec<Extremes> = Vec::new();
        // Take in a state of the contact closed: its force.
        let observe = |contacts: &mut Vec<Extremes>, y: &S| {
            let f = self.contact_force(y);
            if let Some(last) = contacts.last_mut() {
                (last.peak, last.min) = (last.peak.max(f), last.min.min(f));
            }
        };
        // The last release and the deepest the contact point went behind
        // the surface since: an opening shorter than `MIN_OPEN` or
        // shallower than `MIN_GAP` is merged into the contact.
        let (mut released, mut deepest) = (f64::NAN, 0.0f64);
        let mut reach = y[2];
        // Where the equations are linear (every mode but a Hunt–Crossley
        // contact engaged), one RK4 step is an affine map of the state:
        // found once per mode from the step itself, applied as a product.
        let mut maps: [Option<Option<Affine>>; 4] = [None; 4];
        let full = step;
        while t < t_end {
            let key = usize::from(c) + 2 * usize::from(p);
            let map = *maps[key].get_or_insert_with(|| self.affine(c, p, full));
            // The last step ends at `t_end`, not past it: an opening still
            // growing there is read where the run ends.
            let step = full.min(t_end - t);
            let next = match map {
                Some((m, k)) if step == full => std::array::from_fn(|i| {
                    m[i][0] * y[0] + m[i][1] * y[1] + m[i][2] * y[2] + m[i][3] * y[3] + k[i]
                }),
                _ => self.rk4(&y, step, c, p),
            };
            let gs = self.guards(&next, c, p);
            if gs[0] >= 0.0 && gs[1] >= 0.0 {
                y = next;
                t += step;
                if c {
                    observe(&mut contacts, &y);
                } else {
                    deepest = deepest.max(self.g - y[2]);
                    if contacts.is_empty() {
                        reach = reach.max(y[2]);
                    }
                }
                continue;
            }
            let (mut lo, mut hi) = (0.0, step);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                let g = self.guards(&self.rk4(&y, mid, c, p), c, p);
                if g[0] < 0.0 || g[1] < 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            y = self.rk4(&y, hi, c, p);
            t += hi;
            let g = self.guards(&y, c, p);
            if c {
                observe(&mut contacts, &y);
            } else {
                deepest = deepest.max(self.g - y[2]);
            }
            if g[0] < 0.0 {
                let short = t - released < MIN_OPEN || deepest < MIN_GAP;
                if !c && short {
                    // The opening's release goes (pole-face events may
                    // have come since) and this touch with it.
                    let k = out.iter().rposition(|e: &Ev| e.kind == Kind::Release);
                    out.remove(k.expect("an opening follows a release"));
                    if let Some(last) = contacts.last_mut() {
                        last.gap = None;
                    }
                } else {
                    out.push(Ev {
                        t,
                        kind: if c { Kind::Release } else { Kind::Touch },
                    });
                    if !c {
                        if let Some(last) = contacts.last_mut() {
                            last.gap = Some(deepest.max(0.0));
                        }
                        let f = self.contact_force(&y);
                        contacts.push(Extremes {
                            peak: f,
                            min: f,
                            gap: None,
                        });
                    }
                }
                if c {
                    (released, deepest) = (t, 0.0);
                } else {
                    observe(&mut contacts, &y);
                }
                c = !c;
            }
            if g[1] < 0.0 {
                out.push(Ev {
                    t,
                    kind: if p {
                        Kind::PoleRelease
                    } else {
                        Kind::PoleTouch
                    },
                });
                p = !p;
            }
        }
        // An opening the horizon cuts short: its widest so far.
        if let Some(last) = contacts.last_mut().filter(|_| !c) {
            last.gap = Some(deepest.max(0.0));
        }
        if contacts.is_empty() && !c {
            reach = reach.max(y[2]);
        }
        (out, contacts, reach)
    }

    fn mechanics(&self) -> Mechanics {
        Mechanics {
            mass: self.m,
            stiffness: self.s,
            damping: self.r,
            force: self.f,
            gap: self.g,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        }
    }

    fn build(&self) -> TwoStage {
        let release = |force: bool| {
            if force {
                Release::Force
            } else {
                Release::Position
            }
        };
        TwoStage {
            blade: Some(Blade {
                mass: self.mb,
                stiffness: self.sb,
                damping: self.rb,
            }),
            pole_face: self.pole.map(|(o, law, by_force)| PoleFace {
                overtravel: o,
                surface: law.surface(),
                release: release(by_force),
            }),
            release: release(self.contact_by_force),
        }
    }

    fn engine(&self, t_end: f64) -> Result<TwoStageRun, chatterspice::mechanics::DriveError> {
        let stops = Stops {
            make: self.contact.surface(),
            back: None,
        };
        let settings = Settings {
            t_end,
            ..Settings::default()
        };
        simulate_two_stage(
            &self.mechanics(),
            &self.build(),
            &stops,
            &settings,
            Drive::Step,
            Horizon::Closing,
        )
    }
}

/// A small, seeded generator (xorshift64*), so that a failure names the
/// seed that reproduces it.
struct Draw(u64);

impl Draw {
    fn new(seed: u64) -> Draw {
        Draw(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    fn log(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }
}

/// The relay of `seed`: its family from the seed's low bits (pole face or
/// not, release rule, surface law, light or heavy armature), the numbers
/// from ranges around small signal and power relays.
pub fn relay(seed: u64) -> Relay {
    let mut d = Draw::new(seed);
    let pole = seed & 1 == 1;
    let by_force = seed & 2 == 2;
    let hunt_crossley = seed & 4 == 4;
    let heavy = seed & 8 == 8;
    let m = if heavy {
        d.log(3e-4, 1e-3)
    } else {
        d.log(3e-5, 1.5e-4)
    };
    let omega = d.uniform(3000.0, 9000.0);
    let s = m * omega * omega;
    let r = 2.0 * d.uniform(0.01, 0.1) * (m * s).sqrt();
    let g = d.uniform(1e-4, 5e-4);
    let mb = d.log(1e-5, 5e-5);
    let sb = d.uniform(1000.0, 4000.0);
    let rb = d.uniform(0.0, 0.01);
    let contact = if hunt_crossley {
        let n = if d.unit() < 0.5 { 1.0 } else { 1.5 };
        // The stiffness at a 1 µm penetration between 2e5 and 2e6 N/m.
        let k = d.log(2e5, 2e6) * 1e-6f64.powf(1.0 - n);
        Law::Hc {
            k,
            n,
            chi: d.uniform(0.05, 0.5),
        }
    } else {
        Law::Kv {
            s0: d.log(2e5, 2e6),
            r0: d.uniform(0.5, 3.0),
        }
    };
    let o = d.uniform(1e-4, 3e-4);
    let pole_law = Law::Kv {
        s0: d.log(1e6, 5e6),
        r0: d.uniform(1.0, 5.0),
    };
    let load = if pole { s * (g + o) + sb * o } else { s * g };
    let mut f = load * d.uniform(1.3, 2.5);
    if !pole && seed & 16 == 16 {
        // Short of the contact at rest: only the overshoot reaches it,
        // and the contact ends open (or is never touched).
        f = load * (0.55 + 0.4 * Draw::new(seed ^ 0xF0CE).unit());
    }
    Relay {
        m,
        s,
        r,
        f,
        g,
        mb,
        sb,
        rb,
        contact,
        contact_by_force: by_force,
        pole: pole.then_some((o, pole_law, d.unit() < 0.3)),
    }
}

/// The engine's events of `run` up to `horizon`, in time order.
fn engine_events(run: &TwoStageRun, horizon: f64) -> Vec<Ev> {
    let mut out = Vec::new();
    let mut add = |impacts: &[chatterspice::Impact], touch: Kind, release: Kind| {
        for i in impacts {
            out.push(Ev {
                t: i.impact_time,
                kind: touch,
            });
            if let Some(t) = i.release_time {
                out.push(Ev { t, kind: release });
            }
        }
    };
    add(&run.contact.impacts, Kind::Touch, Kind::Release);
    add(&run.pole_face, Kind::PoleTouch, Kind::PoleRelease);
    out.retain(|e| e.t <= horizon);
    out.sort_by(|a, b| a.t.total_cmp(&b.t));
    out
}

/// The horizon of the relay of `seed`: a third of the relays run to a
/// short one (1.5–10 ms), often inside the sequence or the pole face's
/// burst, the rest to 20 ms.
fn t_end_of(seed: u64) -> f64 {
    if seed % 3 == 0 {
        1.5e-3 + 8.5e-3 * Draw::new(seed ^ 0x7E7D).unit()
    } else {
        0.02
    }
}

/// Compare the engine with the reference on the relay of `seed`: `Ok` with
/// the number of contact events and the ending, or what differed.
pub fn compare(seed: u64) -> Result<(usize, Outcome), String> {
    let relay = relay(seed);
    let t_end = t_end_of(seed);
    let run = relay
        .engine(t_end)
        .map_err(|e| format!("seed {seed}: the engine failed: {e}\n{relay:?}"))?;
    let contact = |e: &&Ev| matches!(e.kind, Kind::Touch | Kind::Release);
    let events = engine_events(&run, f64::INFINITY);
    let last = events.iter().rfind(contact).map_or(0.0, |e| e.t);
    let settle = run.contact.settle_time.unwrap_or(last).max(last);
    // The reference goes on past the contact's last event: a contact
    // event there would be one the engine's ending said could not happen.
    // The pole face's record runs to `t_end` whatever the contact does:
    // every pole-face event up to the horizon is compared too.
    // A contact that ends open is followed to `t_end`: its last opening's
    // widest is over the whole run, however early the energy proved the
    // ending.
    let horizon = if run.contact.outcome == Outcome::EndsOpen {
        t_end
    } else {
        (settle * 1.1 + 3e-4).min(t_end)
    };
    let (reference, extremes) = relay.reference_at(horizon, STEP);
    let engine = engine_events(&run, horizon);
    let kinds = |v: &[Ev]| v.iter().map(|e| e.kind).collect::<Vec<_>>();
    let describe = || {
        let list = |v: &[Ev]| {
            v.iter()
                .map(|e| format!("{:?}@{:.9e}", e.kind, e.t))
                .collect::<Vec<_>>()
                .join(" ")
        };
        format!(
            "seed {seed}: {relay:?}\n  ending {:?}, settle {:?}\n  engine    {}\n  reference {}",
            run.contact.outcome,
            run.contact.settle_time,
            list(&engine),
            list(&reference)
        )
    };
    if kinds(&engine) != kinds(&reference) {
        return Err(format!("the sequences differ\n{}", describe()));
    }
    // Where a time differs by more than 1e-6, the reference is run again
    // at a quarter of its step: in a long chaotic sequence (a hundred
    // impacts of a light armature on a Hertz contact) the 1 ns reference
    // itself can be off by more than that. The engine must then agree with
    // the finer reference to 1e-6 plus the coarse one's own error.
    let mut finer: Option<Vec<Ev>> = None;
    for (k, (a, b)) in engine.iter().zip(&reference).enumerate() {
        let off = (a.t - b.t).abs();
        let within = off <= 1e-6 * b.t.abs() || {
            let fine = finer.get_or_insert_with(|| relay.reference_at(horizon, STEP / 4.0).0);
            fine.get(k).is_some_and(|f| {
                f.kind == a.kind && (a.t - f.t).abs() <= 1e-6 * f.t.abs() + 2.0 * (b.t - f.t).abs()
            })
        };
        if !within {
            return Err(format!(
                "{:?} at {:e} against {:e} ({:.1e} relative)\n{}",
                a.kind,
                a.t,
                b.t,
                (a.t - b.t).abs() / b.t,
                describe()
            ));
        }
    }
    extremes_agree(&run, &extremes, horizon).map_err(|e| format!("{e}\n{}", describe()))?;
    // A contact never reached: the shortfall is the least distance over
    // the whole run, however early the energy proved it.
    if run.contact.outcome == Outcome::NeverCloses {
        let (_, _, reach) = relay.reference_with_reach(t_end, STEP);
        let shortfall = run.contact.shortfall.unwrap_or(f64::NAN);
        if (shortfall - (relay.g - reach)).abs() > 1e-6 * relay.g {
            return Err(format!(
                "shortfall {shortfall:e} m against {:e} m\n{}",
                relay.g - reach,
                describe()
            ));
        }
    }
    // A contact that ends open: the widest of its last opening, against
    // the reference's over the whole run to `t_end`.
    if run.contact.outcome == Outcome::EndsOpen {
        let engine_gap = run.contact.impacts.last().and_then(|i| i.max_gap_after);
        let reference_gap = extremes.last().and_then(|e| e.gap);
        if let (Some(a), Some(b)) = (engine_gap, reference_gap) {
            if (a - b).abs() > 1e-6 * relay.g {
                return Err(format!(
                    "last opening {a:e} m against {b:e} m\n{}",
                    describe()
                ));
            }
        }
    }
    // The contact's last closure, stuck or resolved: the engine follows
    // it past the proof until its force can reach no further than its
    // record, so its record holds every force the reference saw to the
    // horizon (and more, where the engine followed it beyond).
    if matches!(run.contact.outcome, Outcome::Stuck | Outcome::Resolved)
        && run.contact.impacts.len() == extremes.len()
    {
        let scale = extremes
            .iter()
            .map(|e| e.peak.abs().max(e.min.abs()))
            .fold(0.0, f64::max);
        if let (Some(i), Some(r)) = (run.contact.impacts.last(), extremes.last()) {
            let tolerance = 1e-6 * scale;
            let holds = i.peak_force.is_some_and(|p| p >= r.peak - tolerance)
                && i.min_force.is_some_and(|m| m <= r.min + tolerance);
            if !holds {
                return Err(format!(
                    "last closure: force from {:?} to {:?} N, the reference's from {:e} to {:e} N\n{}",
                    i.min_force,
                    i.peak_force,
                    r.min,
                    r.peak,
                    describe()
                ));
            }
        }
    }
    // The ending does not depend on how long the run was allowed: the
    // same with `t_end` doubled, unless the longer run's contact was still
    // moving at the first one's end.
    let longer = relay
        .engine(2.0 * t_end)
        .map_err(|e| format!("seed {seed}, t_end doubled: {e}"))?;
    let moving_at_end = longer
        .contact
        .impacts
        .iter()
        .any(|i| i.impact_time > t_end || i.release_time.is_some_and(|r| r > t_end));
    // The same settle time to rounding: the longer run's last step before
    // the shorter one's `t_end` is a whole step, not one cut at it, and the
    // steps after differ, so an impact found on them can differ in its
    // last bits (1–2 units in the last place on 2 of 1 000 relays).
    let settle_same = match (longer.contact.settle_time, run.contact.settle_time) {
        (Some(a), Some(b)) => (a - b).abs() <= 1e-12 * a.abs(),
        (a, b) => a == b,
    };
    let same = longer.contact.outcome == run.contact.outcome && settle_same;
    let honest = moving_at_end && run.contact.outcome == Outcome::EndOfTime;
    if !same && !honest {
        return Err(format!(
            "doubling t_end changed the ending: {:?} {:?} against {:?} {:?}\n{}",
            longer.contact.outcome,
            longer.contact.settle_time,
            run.contact.outcome,
            run.contact.settle_time,
            describe()
        ));
    }
    Ok((run.contact.impacts.len(), run.contact.outcome))
}

/// The engine's peak and least contact force of every contact that
/// released before `horizon`, and the widest opening of every opening
/// closed again before it, against the reference's: within 1e-6 of the
/// run's largest force (or opening), the reference's own error being
/// that of a value read every 1 ns (at most ½|f''|·(0.5 ns)² off a peak
/// between two steps). The engine's linear modes find them where their
/// rates vanish on the exact solution, its general integrator on each
/// step's interpolant.
fn extremes_agree(run: &TwoStageRun, reference: &[Extremes], horizon: f64) -> Result<(), String> {
    let tolerance = 1e-6;
    let impacts = &run.contact.impacts;
    let force_scale = reference
        .iter()
        .map(|e| e.peak.abs().max(e.min.abs()))
        .fold(0.0, f64::max);
    let gap_scale = reference.iter().filter_map(|e| e.gap).fold(0.0, f64::max);
    for (k, (i, r)) in impacts.iter().zip(reference).enumerate() {
        if i.release_time.is_none_or(|t| t > horizon) {
            break;
        }
        let close = |a: Option<f64>, b: f64, scale: f64| {
            a.is_some_and(|a| (a - b).abs() <= tolerance * scale)
        };
        if !close(i.peak_force, r.peak, force_scale) || !close(i.min_force, r.min, force_scale) {
            return Err(format!(
                "contact {k}: force from {:?} to {:?} N against {:e} to {:e} N",
                i.min_force, i.peak_force, r.min, r.peak
            ));
        }
        let reopened = impacts.get(k + 1).is_some_and(|n| n.impact_time <= horizon);
        if let (true, Some(gap)) = (reopened, r.gap) {
            if !close(i.max_gap_after, gap, gap_scale) {
                return Err(format!(
                    "opening {k}: widest {:?} m against {gap:e} m",
                    i.max_gap_after
                ));
            }
        }
    }
    Ok(())
}

/// Relays per run: 64 in the test suite (four of each of the sixteen
/// families the seed's low bits choose: 5 s on two cores, 9 CPU-seconds),
/// as many as `scripts/differential` asks for before a release.
fn count() -> u64 {
    std::env::var("CHATTERSPICE_DIFFERENTIAL")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64)
}

fn first_seed() -> u64 {
    std::env::var("CHATTERSPICE_DIFFERENTIAL_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1)
}

#[test]
fn the_engine_agrees_with_a_brute_force_reference_on_random_relays() {
    let (n, first) = (count(), first_seed());
    let threads = std::thread::available_parallelism()
        .map_or(2, |n| n.get())
        .min(8) as u64;
    let failures: Vec<String> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|w| {
                scope.spawn(move || {
                    let mut bad = Vec::new();
                    let mut contacts = 0;
                    let mut endings = Vec::new();
                    for seed in (first + w..first + n).step_by(threads as usize) {
                        match compare(seed) {
                            Ok((c, ending)) => {
                                contacts += c;
                                endings.push(ending);
                            }
                            Err(e) => bad.push(e),
                        }
                    }
                    (bad, contacts, endings)
                })
            })
            .collect();
        let mut all = Vec::new();
        let mut contacts = 0;
        let mut endings = Vec::new();
        for w in workers {
            let (bad, c, e) = w.join().expect("a worker panicked");
            all.extend(bad);
            contacts += c;
            endings.extend(e);
        }
        // Most relays bounce: the comparison is not of empty sequences.
        assert!(
            contacts as u64 > 2 * n,
            "{contacts} contacts over {n} relays"
        );
        // Every ending the engine proves is among them.
        if n >= 200 {
            for ending in [Outcome::Stuck, Outcome::Resolved, Outcome::EndsOpen] {
                assert!(endings.contains(&ending), "no {ending:?} in {n} relays");
            }
        }
        all
    });
    assert!(
        failures.is_empty(),
        "{} of {n} relays disagree:\n{}\n\nthe first in full:\n{}",
        failures.len(),
        failures
            .iter()
            .map(|f| f.lines().take(2).collect::<Vec<_>>().join(" | "))
            .collect::<Vec<_>>()
            .join("\n"),
        failures[0]
    );
}

/// The engine's linear steps are compiled twice, for the baseline
/// processor and with AVX2 where the processor has it (chosen at run
/// time). Both must give the same runs to the last bit: every relay of
/// the Kelvin–Voigt families (the linear ones) is run both ways at both
/// horizons and its whole record compared as its `Debug` text, each
/// number printed to its shortest exact form. On a processor without
/// AVX2 both ways are the baseline and this shows nothing; optimised
/// (`scripts/differential`), it checks the vectorised code.
#[test]
fn the_wide_and_the_baseline_steps_agree_to_the_bit() {
    use chatterspice::mechanics::two_stage::with_baseline_steps;
    let (n, first) = (count(), first_seed());
    let mut compared = 0;
    for seed in (first..first + n).filter(|seed| seed & 4 == 0) {
        let relay = relay(seed);
        let t_end = t_end_of(seed);
        for horizon in [t_end, 2.0 * t_end] {
            let wide = format!("{:?}", relay.engine(horizon));
            let baseline = format!("{:?}", with_baseline_steps(|| relay.engine(horizon)));
            assert!(wide.contains("impact_time"), "seed {seed}: {wide}");
            assert_eq!(wide, baseline, "seed {seed}, t_end {horizon:e}");
            compared += 1;
        }
    }
    assert!(compared >= n / 2, "{compared} runs compared");
}

/// The bundled two-stage example released by position with a 3 200 N/m
/// blade: the case that once stepped over a 4 µs re-closure.
#[test]
fn the_bundled_example_released_by_position_agrees_with_the_reference() {
    let relay = Relay {
        m: 1.0e-4,
        s: 5000.0,
        r: 0.07,
        f: 1.0,
        g: 1.4e-4,
        mb: 2.0e-5,
        sb: 3200.0,
        rb: 0.005,
        contact: Law::Kv { s0: 5.0e5, r0: 0.3 },
        contact_by_force: false,
        pole: Some((1.0e-4, Law::Kv { s0: 2.0e6, r0: 2.0 }, false)),
    };
    let run = relay.engine(0.02).unwrap();
    let settle = run.contact.settle_time.expect("it settles");
    let reference = relay.reference(settle + 3e-4);
    let touches: Vec<&Ev> = reference.iter().filter(|e| e.kind == Kind::Touch).collect();
    assert_eq!(run.contact.impacts.len(), touches.len(), "contacts");
    let releases: Vec<&Ev> = reference
        .iter()
        .filter(|e| e.kind == Kind::Release)
        .collect();
    for (k, (i, r)) in run.contact.impacts.iter().zip(&touches).enumerate() {
        assert!(
            i.impact_velocity > 0.0,
            "an impact at {} approaches backwards",
            i.impact_time
        );
        assert!(
            (i.impact_time - r.t).abs() <= 1e-6 * r.t,
            "{} against {}",
            i.impact_time,
            r.t
        );
        // Every contact but the last releases, at the reference's time.
        match (i.release_time, releases.get(k)) {
            (Some(t), Some(r)) => assert!((t - r.t).abs() <= 1e-6 * r.t, "{t} against {}", r.t),
            (None, None) => {}
            other => panic!("release {k}: {other:?}"),
        }
    }
    assert_eq!(run.contact.bounce_count, releases.len());
}

/// The one-mass engines (Kelvin–Voigt in closed form, Hunt–Crossley by
/// DOP853) and the driven one: the ending and settle time of a closing do
/// not change when `t_end` is doubled, unless the longer run saw the
/// contact move after the first one's end. Short horizons (2–6 ms) put
/// `t_end` inside the last contact of many of these relays.
#[test]
fn one_mass_endings_do_not_depend_on_the_horizon() {
    use chatterspice::mechanics::simulate;
    let mut closed_at_end = 0;
    for seed in 1..=300u64 {
        let r = relay(seed);
        let hunt_crossley = matches!(r.contact, Law::Hc { .. });
        let m = Mechanics {
            mass: r.m + r.mb,
            ..r.mechanics()
        };
        let t_end = 2e-3 + 4e-3 * Draw::new(seed ^ 0xABCD).unit();
        let at = |t_end: f64| {
            simulate(
                &m,
                &r.contact.surface(),
                &Settings {
                    t_end,
                    ..Settings::default()
                },
            )
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"))
        };
        let (short, long) = (at(t_end), at(2.0 * t_end));
        let moved_after = long
            .impacts
            .iter()
            .any(|i| i.impact_time > t_end || i.release_time.is_some_and(|x| x > t_end));
        if moved_after {
            assert_eq!(short.outcome, Outcome::EndOfTime, "seed {seed}");
            continue;
        }
        if short
            .intervals
            .last()
            .is_some_and(|i| i.state == chatterspice::ContactState::Closed)
            && long.settle_time.is_some_and(|s| s < t_end)
        {
            closed_at_end += 1;
        }
        assert_eq!(
            (short.outcome, short.settle_time),
            (long.outcome, long.settle_time),
            "seed {seed} ({}): t_end {t_end:e} against twice that",
            if hunt_crossley {
                "Hunt–Crossley"
            } else {
                "Kelvin–Voigt"
            }
        );
    }
    // The horizons do cut into closed contacts: the test is not vacuous.
    assert!(closed_at_end > 10, "{closed_at_end} relays closed at t_end");
}

/// The pole face's record does not stop where the contact's ending is
/// proven: over relays with a pole face at a short `t_end`, every
/// pole-face impact and release up to `t_end` is the reference's, the
/// bounces after the contact's final closure included.
#[test]
fn the_pole_face_record_runs_to_t_end() {
    let t_end = 1.5e-3;
    let mut after_settling = 0;
    for seed in (1..=40u64).map(|k| 2 * k + 1) {
        let relay = relay(seed);
        let run = relay
            .engine(t_end)
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let Some(settle) = run.contact.settle_time else {
            continue;
        };
        let engine = engine_events(&run, t_end);
        let reference = relay.reference(t_end);
        let kinds = |v: &[Ev]| v.iter().map(|e| e.kind).collect::<Vec<_>>();
        assert_eq!(kinds(&engine), kinds(&reference), "seed {seed}");
        for (a, b) in engine.iter().zip(&reference) {
            assert!((a.t - b.t).abs() <= 1e-6 * b.t, "seed {seed}: {a:?} {b:?}");
        }
        // A pole-face impact left without its release is one the
        // armature does not leave before t_end.
        for (k, i) in run.pole_face.iter().enumerate() {
            if i.release_time.is_none() {
                assert_eq!(k + 1, run.pole_face.len(), "seed {seed}");
            }
        }
        after_settling += run
            .pole_face
            .iter()
            .filter(|i| i.impact_time > settle)
            .count();
    }
    assert!(
        after_settling > 10,
        "{after_settling} pole-face impacts after settling"
    );
}

/// Every ending is proven as soon as the energy proves it, whatever
/// `t_end`: a contact closed for good is `stuck` (or `resolved`) at the
/// same settle time from just past its last impact on, and a contact that
/// only the overshoot reaches `ends_open` once it has opened.
#[test]
fn endings_are_proven_whatever_t_end() {
    let mut proven = 0;
    for seed in 1..=64u64 {
        let relay = relay(seed);
        let long = relay
            .engine(0.02)
            .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let c = &long.contact;
        let last = c.intervals.last().expect("a state").start;
        if !matches!(
            c.outcome,
            Outcome::Stuck | Outcome::Resolved | Outcome::EndsOpen
        ) || last > 5e-3
        {
            continue;
        }
        for factor in [1.02, 1.3, 2.0] {
            let short = relay
                .engine(last * factor)
                .unwrap_or_else(|e| panic!("seed {seed}: {e}"));
            // The same settle time, to the rounding of a step cut at t_end.
            let same_settle = match (short.contact.settle_time, c.settle_time) {
                (Some(a), Some(b)) => (a - b).abs() <= 1e-9 * b,
                (a, b) => a == b,
            };
            assert!(
                short.contact.outcome == c.outcome && same_settle,
                "seed {seed}, t_end {:e}: {:?} {:?} against {:?} {:?}",
                last * factor,
                short.contact.outcome,
                short.contact.settle_time,
                c.outcome,
                c.settle_time
            );
            proven += 1;
        }
    }
    assert!(proven > 60, "{proven} endings checked");
}

/// The engine's time on each relay of the random families (both horizons
/// the comparison runs), the slowest printed: a survey, not a check (speed
/// is held by `cargo bench --bench mechanics`). Run it optimised:
/// `CHATTERSPICE_DIFFERENTIAL=3000 cargo test --release --test reference
/// slowest_relays -- --ignored --nocapture`.
#[test]
#[ignore = "a timing survey; run it by name, optimised"]
fn slowest_relays() {
    let (n, first) = (count(), first_seed());
    let mut times: Vec<(f64, u64, usize, Outcome)> = Vec::new();
    for seed in first..first + n {
        let relay = relay(seed);
        let t_end = t_end_of(seed);
        for horizon in [t_end, 2.0 * t_end] {
            let start = std::time::Instant::now();
            let run = relay.engine(horizon);
            let took = start.elapsed().as_secs_f64();
            let (impacts, ending) = run.map_or((0, Outcome::EndOfTime), |r| {
                (r.contact.impacts.len(), r.contact.outcome)
            });
            times.push((took, seed, impacts, ending));
        }
    }
    times.sort_by(|a, b| b.0.total_cmp(&a.0));
    let total: f64 = times.iter().map(|t| t.0).sum();
    println!(
        "{} runs of {n} relays from seed {first}: {total:.3} s",
        times.len()
    );
    for (took, seed, impacts, ending) in times.iter().take(10) {
        println!(
            "{took:.4} s  seed {seed}  {:?}  {impacts} impacts  {ending:?}",
            relay(*seed).contact
        );
    }
    assert!(total > 0.0);
}

/// The engine's whole records (every impact's times, velocities, forces
/// and openings, the pole face's, the ending) on the random relays at
/// both horizons, written to the file `CHATTERSPICE_DUMP` names: a change
/// that should not move a result is checked by dumping before and after
/// and comparing the numbers. A tool, not a check. Run it optimised:
/// `CHATTERSPICE_DUMP=/tmp/a CHATTERSPICE_DIFFERENTIAL=400 cargo test
/// --release --test reference record_dump -- --ignored`.
#[test]
#[ignore = "a tool for comparing the engine's records before and after a change"]
fn record_dump() {
    use std::fmt::Write as _;
    let Ok(path) = std::env::var("CHATTERSPICE_DUMP") else {
        return;
    };
    let (n, first) = (count(), first_seed());
    let mut out = String::new();
    for seed in first..first + n {
        let relay = relay(seed);
        let t_end = t_end_of(seed);
        for horizon in [t_end, 2.0 * t_end] {
            match relay.engine(horizon) {
                Ok(run) => writeln!(
                    out,
                    "seed {seed} t_end {horizon:e}: {:?} settle {:?} impacts {:?} pole {:?}",
                    run.contact.outcome,
                    run.contact.settle_time,
                    run.contact.impacts,
                    run.pole_face
                ),
                Err(e) => writeln!(out, "seed {seed} t_end {horizon:e}: error {e}"),
            }
            .expect("a string takes it");
        }
    }
    // The speed bench's relay (benches/mechanics.rs): the paper's
    // reference sequence carried on a blade.
    let m = Mechanics {
        mass: 1.0,
        stiffness: 1.0,
        damping: 0.1,
        force: 1.0,
        gap: 0.9,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.0,
    };
    let stops = Stops {
        make: Surface::KelvinVoigt {
            stiffness: 100.0,
            damping: 2.0 * 0.4692,
        },
        back: None,
    };
    let build = TwoStage {
        blade: Some(Blade {
            mass: 0.2,
            stiffness: 100.0,
            damping: 1.0,
        }),
        pole_face: None,
        release: Release::Position,
    };
    let settings = Settings {
        t_end: 100.0,
        ..Settings::default()
    };
    let run = simulate_two_stage(&m, &build, &stops, &settings, Drive::Step, Horizon::Closing)
        .expect("the bench relay runs");
    writeln!(
        out,
        "bench: {:?} settle {:?} impacts {:?} steps {}",
        run.contact.outcome, run.contact.settle_time, run.contact.impacts, run.steps
    )
    .expect("a string takes it");
    std::fs::write(&path, out).expect("the dump is written");
}
