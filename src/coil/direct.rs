//! The direct solver: a coil switched onto an ideal voltage source at
//! t = 0, with no circuit simulator (the cross-check of the
//! coupled ngspice runs).
//!
//! One ODE in the flux linkage ψ, the position x and the velocity ẋ
//! (docs/model.md §7), with `R` the coil resistance plus any series resistance
//! and `a = g_a + l_eq`, `k = μ0 N² A`:
//!
//! ```text
//! dψ/dt = V − R i,           i = ψ (a − x) / k
//! m ẍ + r ẋ + s x + p + Fc = F_m = ψ² / (2k)
//! ```
//!
//! which is `V = R i + L(x) di/dt + i L'(x) ẋ` written in the flux. The
//! armature sits on its rest stop until `F_m > p`, flies, and chatters on
//! the fixed contact by the surface law, as in the step-force engine; the
//! events and endings are those of one closing of the mechanics' cycle
//! engine, whose sticking test freezes the coil current at the smaller of
//! its present value and `V/R`.
//!
//! The result adds to the [`Chatter`] the coil current over time, the
//! named events of a closing (lift-off, first make, the pull-in dip of the
//! current) and an energy balance, which the integration must close:
//! `∫V i dt = ∫R i² dt + Δ(½ L i²) + ∫F_m ẋ dt`, and the mechanical work
//! goes into the armature's energy and its losses.

use super::magnet::{Coil, CoilError};
use crate::chatter::Chatter;
use crate::mechanics::cycle::{self, ClosingRun};
use crate::mechanics::driven::{self, DriveModel, Piece, State, StepKind};
use crate::mechanics::segment::Segment;
use crate::mechanics::{self, Mechanics, Settings, Surface};

/// The ideal voltage source the coil is switched onto at t = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Source {
    /// V, the step voltage.
    pub voltage: f64,
    /// Ω, any resistance in series with the coil (0 for an ideal source).
    pub series_resistance: f64,
}

/// The state of the coil and armature at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoilState {
    /// s
    pub time: f64,
    /// A, the coil current.
    pub current: f64,
    /// Wb, the flux linkage ψ = L(x) i.
    pub flux: f64,
    /// m, the armature position x.
    pub position: f64,
    /// m/s, the armature velocity.
    pub velocity: f64,
}

/// The local minimum of the coil current while the armature pulls in: the
/// back-EMF of the moving armature beats the source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PullInDip {
    /// s
    pub time: f64,
    /// A
    pub current: f64,
}

/// The named events of one closing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoilEvents {
    /// s, when the pull first exceeds the preload (`None`: it never does).
    pub lift_off: Option<f64>,
    /// s, the first touch of the contacts.
    pub first_make: Option<f64>,
    /// m/s, the impact speed of the first touch.
    pub make_velocity: Option<f64>,
    /// A, the coil current at the first touch.
    pub current_at_make: Option<f64>,
    /// A, what the current would be at the first touch had the armature
    /// been held: the plain RL step `V/R (1 − e^(−t R/L(0)))`.
    pub held_current_at_make: Option<f64>,
    /// The first local minimum of the current after lift-off. With a
    /// rigid surface it is the touch itself (the armature stops at once);
    /// with a compliant one it falls just after the touch, when the
    /// armature stops inside the surface.
    pub pull_in_dip: Option<PullInDip>,
    /// s, closed for good from here (the chatter's settle time).
    pub settle_time: Option<f64>,
}

/// Where the energy from the source went, from t = 0 to the end of the
/// run (J).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyBalance {
    /// `∫ V i dt`, delivered by the source.
    pub source: f64,
    /// `∫ R i² dt`, lost in the coil and series resistance.
    pub resistive: f64,
    /// `½ L i²` at the end less at the start: stored in the field.
    pub magnetic: f64,
    /// `∫ F_m ẋ dt`, the work of the pull on the armature.
    pub mechanical_work: f64,
    /// The armature's kinetic, spring, preload and surface energy at the
    /// end less at the start.
    pub mechanical: f64,
    /// Lost in the structural and surface damping and in rigid impacts.
    pub dissipated: f64,
}

impl EnergyBalance {
    /// J, what the electrical side leaves unaccounted for:
    /// `source − resistive − magnetic − mechanical_work`.
    pub fn electrical_residual(&self) -> f64 {
        self.source - self.resistive - self.magnetic - self.mechanical_work
    }

    /// J, what the mechanical side leaves unaccounted for:
    /// `mechanical_work − mechanical − dissipated`.
    pub fn mechanical_residual(&self) -> f64 {
        self.mechanical_work - self.mechanical - self.dissipated
    }
}

/// The result of [`simulate_direct`].
#[derive(Debug, Clone)]
pub struct CoilRun {
    /// The contact's chatter sequence.
    pub chatter: Chatter,
    /// The named events of the closing.
    pub events: CoilEvents,
    /// (s, A): the coil current at every accepted integration step, from
    /// t = 0 to the end of the run (the sticking decision, or `t_end`).
    pub current: Vec<(f64, f64)>,
    /// J, where the source's energy went, from t = 0 to the end of the run.
    pub energy: EnergyBalance,
    coil: Coil,
    gap: f64,
    /// The integrator's steps, each a [`Piece`].
    steps: Vec<Segment>,
}

/// The integrator's steps of a closing, in time order.
fn pieces(steps: &[Segment]) -> impl DoubleEndedIterator<Item = Piece<'_>> {
    steps.iter().filter_map(Segment::piece)
}

impl CoilRun {
    /// The state at `t` (s), from the integrator's dense output; `None`
    /// outside the run.
    pub fn state_at(&self, t: f64) -> Option<CoilState> {
        let (t0, _) = self.steps.first()?.span();
        let (_, t1) = self.steps.last()?.span();
        if !(t >= t0 && t <= t1) {
            return None;
        }
        let j = self.steps.partition_point(|s| s.span().1 < t);
        let piece = self.steps.get(j)?.piece()?;
        Some(self.state(t, &piece.at(t)))
    }

    /// The end of the run: s.
    pub fn end_time(&self) -> f64 {
        self.steps.last().map_or(0.0, |s| s.span().1)
    }

    fn state(&self, t: f64, y: &State) -> CoilState {
        let x = self.gap + y[0];
        CoilState {
            time: t,
            current: self.coil.current(y[2], x),
            flux: y[2],
            position: x,
            velocity: y[1],
        }
    }
}

/// Switch `coil` onto `source` at t = 0 with the armature of `mechanics`
/// (whose `force` is ignored: the coil makes it) at rest on its stop, and
/// simulate the closing to an ending of docs/model.md §4.
pub fn simulate_direct(
    coil: &Coil,
    source: &Source,
    mechanics: &Mechanics,
    surface: &Surface,
    settings: &Settings,
) -> Result<CoilRun, CoilError> {
    let m = Mechanics {
        force: 0.0,
        initial_position: 0.0,
        initial_velocity: 0.0,
        ..*mechanics
    };
    mechanics::validate(&m, surface, settings)?;
    coil.validate(m.gap)?;
    if !source.voltage.is_finite() {
        return Err(CoilError::InvalidParameter {
            name: "source.voltage",
            value: source.voltage,
            requirement: "a finite step voltage in V",
        });
    }
    if !(source.series_resistance >= 0.0 && source.series_resistance.is_finite()) {
        return Err(CoilError::InvalidParameter {
            name: "source.series_resistance",
            value: source.series_resistance,
            requirement: "a resistance in Ω in series with the coil, ≥ 0",
        });
    }
    let drive = CoilDrive::new(coil, source, m.gap);
    let run = cycle::run_closing(&m, surface, settings, &drive, 0.0)?;
    let events = drive.events(&run, &m);
    let energy = drive.energy(&run, &m, surface);
    let current = current_trace(&drive, &run.steps, m.gap);
    Ok(CoilRun {
        chatter: run.chatter,
        events,
        current,
        energy,
        coil: *coil,
        gap: m.gap,
        steps: run.steps,
    })
}

/// The closing of the relay as built (`build`: blade, pole face,
/// release rules) when `coil` is switched onto `source` at t = 0, as
/// [`simulate_direct`] does for the one-mass model (and for it, exactly
/// that): the contact's chatter, with the two-stage record when there is
/// one.
pub fn direct_closing(
    coil: &Coil,
    source: &Source,
    mechanics: &Mechanics,
    build: &crate::mechanics::two_stage::TwoStage,
    surface: &Surface,
    settings: &Settings,
) -> Result<(Chatter, Option<crate::mechanics::two_stage::TwoStageRun>), CoilError> {
    use crate::mechanics::two_stage::engine::run_relay;
    use crate::mechanics::two_stage::model::RelayModel;
    if build.is_one_mass() {
        return Ok((
            simulate_direct(coil, source, mechanics, surface, settings)?.chatter,
            None,
        ));
    }
    let m = Mechanics {
        force: 0.0,
        initial_position: 0.0,
        initial_velocity: 0.0,
        ..*mechanics
    };
    crate::mechanics::two_stage::validate_all(&m, build, surface, settings)?;
    coil.validate(m.gap)?;
    if !source.voltage.is_finite() {
        return Err(CoilError::InvalidParameter {
            name: "source.voltage",
            value: source.voltage,
            requirement: "a finite step voltage in V",
        });
    }
    let drive = CoilDrive::new(coil, source, m.gap);
    let model = RelayModel {
        m: &m,
        build,
        contact: *surface,
        back: None,
        rest: true,
        drive: &drive,
    };
    let out = run_relay(
        &model,
        settings,
        0.0,
        crate::mechanics::two_stage::Horizon::Closing,
    )?;
    Ok((out.contact.clone(), Some(out)))
}

/// The coil on its ideal source, in the flux.
struct CoilDrive {
    coil: Coil,
    /// V
    voltage: f64,
    /// Ω, coil plus series resistance.
    resistance: f64,
    /// H·m, μ0 N² A.
    k: f64,
    /// m, g_a + l_eq.
    a: f64,
    /// m, the contact travel.
    gap: f64,
}

impl CoilDrive {
    fn new(coil: &Coil, source: &Source, gap: f64) -> Self {
        CoilDrive {
            coil: *coil,
            voltage: source.voltage,
            resistance: coil.resistance + source.series_resistance,
            k: coil.permeance_length(),
            a: coil.air_gap + coil.iron_gap,
            gap,
        }
    }

    /// A, the current at flux `psi` and position `x`.
    fn current(&self, psi: f64, x: f64) -> f64 {
        psi * (self.a - x) / self.k
    }

    /// A/s along the motion: `d/dt [ψ (a − x)/k]`.
    fn current_rate(&self, y: &State) -> f64 {
        let x = self.gap + y[0];
        (self.rate(0.0, x, y[2]) * (self.a - x) - y[2] * y[1]) / self.k
    }

    fn events(&self, run: &ClosingRun, m: &Mechanics) -> CoilEvents {
        let first = run.chatter.impacts.first();
        let first_make = first.map(|i| i.impact_time);
        let tau0 = self.coil.inductance(0.0) / self.resistance;
        CoilEvents {
            lift_off: run.lift_off,
            first_make,
            make_velocity: first.map(|i| i.impact_velocity),
            current_at_make: first_make.map(|t| {
                // The last piece of the first flight ends at the touch.
                let piece = pieces(&run.steps)
                    .rev()
                    .find(|p| p.phase == StepKind::Flight && p.t1 <= t)
                    .expect("a flight reached the first touch");
                self.current(piece.y1[2], m.gap + piece.y1[0])
            }),
            held_current_at_make: first_make
                .map(|t| self.voltage / self.resistance * -(-t / tau0).exp_m1()),
            pull_in_dip: run.lift_off.and_then(|t| self.pull_in_dip(&run.steps, t)),
            settle_time: run.chatter.settle_time,
        }
    }

    /// The first local minimum of the current after `lift_off`: a sign
    /// change of di/dt from − to +, inside a step (located by bisection on
    /// its interpolant) or across an event (a rigid impact reverses the
    /// back-EMF at once).
    fn pull_in_dip(&self, steps: &[Segment], lift_off: f64) -> Option<PullInDip> {
        let at = |t: f64, y: &State| PullInDip {
            time: t,
            current: self.current(y[2], self.gap + y[0]),
        };
        let mut falling = false;
        for piece in pieces(steps).filter(|p| p.phase != StepKind::Held && p.t1 > lift_off) {
            let (y0, y1) = (piece.y0(), piece.y1);
            let (d0, d1) = (self.current_rate(&y0), self.current_rate(&y1));
            if falling && d0 >= 0.0 {
                return Some(at(piece.t0(), &y0));
            }
            if d0 < 0.0 && d1 >= 0.0 {
                let t = driven::first_true(
                    |t| self.current_rate(&piece.at(t)) >= 0.0,
                    piece.t0(),
                    piece.t1,
                );
                return Some(at(t, &piece.at(t)));
            }
            falling = d1 < 0.0;
        }
        None
    }

    /// The energy balance, each integral by 5-point Gauss–Legendre on each
    /// step's interpolant (which is smooth inside a step: events end
    /// steps).
    fn energy(&self, run: &ClosingRun, m: &Mechanics, surface: &Surface) -> EnergyBalance {
        const GL5: [(f64, f64); 5] = [
            (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
            (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
            (0.0, 0.568_888_888_888_888_9),
            (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
            (0.906_179_845_938_664, 0.236_926_885_056_189_1),
        ];
        let (mut source, mut resistive, mut work, mut lost) = (0.0, 0.0, 0.0, 0.0);
        for piece in pieces(&run.steps) {
            let phase = &piece.phase;
            let (mid, half) = (0.5 * (piece.t0() + piece.t1), 0.5 * (piece.t1 - piece.t0()));
            for &(z, w) in &GL5 {
                let y = piece.at(mid + half * z);
                let i = self.current(y[2], self.gap + y[0]);
                let wh = w * half;
                source += wh * self.voltage * i;
                resistive += wh * self.resistance * i * i;
                if *phase != StepKind::Held {
                    work += wh * self.coil.force_from_flux(y[2]) * y[1];
                    lost += wh * m.damping * y[1] * y[1];
                }
                if *phase == StepKind::Contact {
                    lost += wh * crate::mechanics::surface::surface_loss(surface, y[0], y[1]);
                }
            }
        }
        let (_, y_end) = run.end;
        let magnetic = |y: &State| {
            let x = self.gap + y[0];
            0.5 * y[2] * y[2] / self.coil.inductance(x)
        };
        let mechanical = |y: &State| {
            let x = self.gap + y[0];
            0.5 * m.mass * y[1] * y[1]
                + 0.5 * m.stiffness * x * x
                + m.preload * x
                + crate::mechanics::surface::surface_energy(surface, y[0])
        };
        let y_start = State::new(-self.gap, 0.0, 0.0);
        EnergyBalance {
            source,
            resistive,
            magnetic: magnetic(&y_end) - magnetic(&y_start),
            mechanical_work: work,
            mechanical: mechanical(&y_end) - mechanical(&y_start),
            dissipated: lost + run.jump_loss,
        }
    }
}

impl DriveModel for CoilDrive {
    fn force(&self, _t: f64, _x: f64, psi: f64) -> f64 {
        0.5 * psi * psi / self.k
    }

    fn rate(&self, _t: f64, x: f64, psi: f64) -> f64 {
        self.voltage - self.resistance * self.current(psi, x)
    }

    fn frozen_work(&self, _t: f64, psi: f64, from: f64, to: f64) -> f64 {
        // At constant current c the pull ½c²L'(x) integrates to
        // ½c²(L(to) − L(from)); the current is frozen at the smaller of
        // its present and final values (the closing's sticking test).
        let c = self
            .current(psi, to)
            .abs()
            .min((self.voltage / self.resistance).abs());
        0.5 * c * c * (self.coil.inductance(to) - self.coil.inductance(from))
    }

    fn held_work(&self, _t: f64, psi: f64, from: f64, to: f64) -> f64 {
        // At constant flux the pull ψ²/(2k) does not depend on position.
        0.5 * psi * psi / self.k * (to - from)
    }

    fn e_scale(&self) -> f64 {
        // The final flux with the contacts closed.
        (self.coil.inductance(self.gap) * self.voltage / self.resistance)
            .abs()
            .max(f64::MIN_POSITIVE)
    }

    fn time_scale(&self) -> f64 {
        self.coil.inductance(0.0) / self.resistance
    }

    fn pole(&self) -> f64 {
        self.coil.air_gap
    }
}

/// (s, A) at t = 0 and at the end of every step.
fn current_trace(drive: &CoilDrive, steps: &[Segment], gap: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(steps.len() + 1);
    if let Some(p) = pieces(steps).next() {
        let y = p.y0();
        out.push((p.t0(), drive.current(y[2], gap + y[0])));
    }
    out.extend(pieces(steps).map(|p| (p.t1, drive.current(p.y1[2], gap + p.y1[0]))));
    out
}
