//! The event-driven chatter engine.
//!
//! A closing alternates two phases until one of the endings of model.md §4:
//!
//! 1. **flight** (contact open): closed-form [`LinearPiece`]; the next
//!    impact is its first upward crossing of the gap, or there is none;
//! 2. **contact**: by surface law — rigid (instantaneous velocity
//!    reversal), Kelvin–Voigt (closed-form piece; release is the first
//!    downward crossing of the gap, sticking is "no such crossing"), or
//!    Hunt–Crossley (integrated, [`super::hunt_crossley`]).
//!
//! Each phase starts its own local clock at 0 from the exact event state
//! (x = g and the event velocity), so no error accumulates through the
//! phases beyond the rounding of each event time. The state after an
//! impact or release is the state *at* the event time.
//!
//! A sequence whose next opening would be shorter than `min_open_time` or
//! open less than `min_gap` is `resolved`: the contact is taken as closed
//! from the last retained impact. For a rigid surface that tail is a Zeno
//! sequence (infinitely many ever shorter bounces in finite time); as the
//! bounces shrink, the motion between impacts tends to flight under the
//! constant net force at the surface, whose flight times form a geometric
//! series of ratio e, so the tail sums to `T/(1 − e)` from the first
//! skipped flight `T`: that is the reported accumulation time.

use super::hunt_crossley::{HcContact, HcEnd};
use super::linear::LinearPiece;
use super::{Mechanics, MechanicsError, Settings, Surface};
use crate::chatter::{Chatter, ContactState, Impact, Interval, Outcome};

/// Simulate one closing: the chatter sequence from t = 0 to an ending of
/// model.md §4. Parameters are validated first; an invalid one is an
/// error naming its scenario key.
pub fn simulate(
    mechanics: &Mechanics,
    surface: &Surface,
    settings: &Settings,
) -> Result<Chatter, MechanicsError> {
    validate(mechanics, surface, settings)?;
    Engine::new(mechanics, surface, settings).run()
}

/// Check every parameter the engine relies on.
pub fn validate(m: &Mechanics, surface: &Surface, s: &Settings) -> Result<(), MechanicsError> {
    fn check(
        name: &'static str,
        value: f64,
        ok: bool,
        requirement: &'static str,
    ) -> Result<(), MechanicsError> {
        if value.is_finite() && ok {
            Ok(())
        } else {
            Err(MechanicsError::InvalidParameter {
                name,
                value,
                requirement,
            })
        }
    }
    check("mechanics.mass", m.mass, m.mass > 0.0, "a mass in kg, > 0")?;
    check(
        "mechanics.stiffness",
        m.stiffness,
        m.stiffness > 0.0,
        "a suspension stiffness in N/m, > 0",
    )?;
    check(
        "mechanics.damping",
        m.damping,
        m.damping >= 0.0,
        "a damping in N·s/m, ≥ 0",
    )?;
    check("mechanics.force", m.force, true, "a finite force in N")?;
    check("mechanics.gap", m.gap, m.gap > 0.0, "a gap in m, > 0")?;
    check(
        "mechanics.initial_position",
        m.initial_position,
        m.initial_position < m.gap,
        "a position in m below the gap (the contact starts open)",
    )?;
    check(
        "mechanics.initial_velocity",
        m.initial_velocity,
        true,
        "a finite velocity in m/s",
    )?;
    check(
        "mechanics.preload",
        m.preload,
        m.preload >= 0.0,
        "a preload in N, ≥ 0",
    )?;
    match *surface {
        Surface::Rigid { restitution } => check(
            "surface.restitution",
            restitution,
            (0.0..=1.0).contains(&restitution),
            "a coefficient of restitution in [0, 1]",
        )?,
        Surface::KelvinVoigt { stiffness, damping } => {
            check(
                "surface.stiffness",
                stiffness,
                stiffness > 0.0,
                "a surface stiffness in N/m, > 0",
            )?;
            check(
                "surface.damping",
                damping,
                damping >= 0.0,
                "a surface damping in N·s/m, ≥ 0",
            )?;
        }
        Surface::HuntCrossley {
            stiffness,
            exponent,
            chi,
        } => {
            check(
                "surface.stiffness",
                stiffness,
                stiffness > 0.0,
                "a surface stiffness in N/mⁿ, > 0",
            )?;
            check(
                "surface.exponent",
                exponent,
                (1.0..=3.0).contains(&exponent),
                "an exponent n in [1, 3] (1: linear spring, 1.5: Hertz)",
            )?;
            check("surface.chi", chi, chi >= 0.0, "χ = λ/k in s/m, ≥ 0")?;
        }
    }
    check(
        "simulation.t_end",
        s.t_end,
        s.t_end > 0.0,
        "a horizon in s, > 0",
    )?;
    check(
        "simulation.min_open_time",
        s.min_open_time,
        s.min_open_time >= 0.0,
        "a time in s, ≥ 0",
    )?;
    check(
        "simulation.min_gap",
        s.min_gap,
        s.min_gap >= 0.0,
        "a distance in m, ≥ 0",
    )?;
    Ok(())
}

/// How one contact phase ended.
enum ContactEnd {
    Released { time: f64, velocity: f64 },
    Stuck,
    Horizon,
}

struct Engine<'a> {
    m: &'a Mechanics,
    surface: &'a Surface,
    settings: &'a Settings,
    /// N, drive net of preload.
    f_net: f64,
    impacts: Vec<Impact>,
    intervals: Vec<Interval>,
}

impl<'a> Engine<'a> {
    fn new(m: &'a Mechanics, surface: &'a Surface, settings: &'a Settings) -> Self {
        Engine {
            m,
            surface,
            settings,
            f_net: m.force - m.preload,
            impacts: Vec::new(),
            intervals: Vec::new(),
        }
    }

    fn flight(&self, x0: f64, v0: f64) -> LinearPiece {
        let m = self.m;
        LinearPiece::new(m.mass, m.damping, m.stiffness, self.f_net, x0, v0)
    }

    fn run(mut self) -> Result<Chatter, MechanicsError> {
        let m = *self.m;
        let g = m.gap;
        let t_end = self.settings.t_end;

        // The armature rests on its stop until the drive beats the preload.
        if m.initial_position == 0.0 && m.initial_velocity == 0.0 && self.f_net <= 0.0 {
            return Ok(self.finish_open(Outcome::NeverCloses, 0.0, Some(g)));
        }

        let (mut t, mut x, mut v) = (0.0, m.initial_position, m.initial_velocity);
        let mut open_since = 0.0;
        loop {
            // Flight from (t, x, v).
            let piece = self.flight(x, v);
            let hit = piece.crossing(g, true);
            let Some(dt) = hit.filter(|dt| t + dt > t) else {
                return Ok(if self.impacts.is_empty() {
                    let reach = piece
                        .first_extremum(true)
                        .map_or(piece.x_eq.max(x), |(_, xm)| xm.max(x));
                    self.finish_open(Outcome::NeverCloses, open_since, Some(g - reach))
                } else {
                    self.finish_open(Outcome::EndsOpen, open_since, None)
                });
            };
            // The largest opening of this flight (after a release).
            if let Some(last) = self.impacts.last_mut() {
                let lowest = piece.first_extremum(false).map_or(x, |(_, xm)| xm);
                let gap_opened = g - lowest;
                last.max_gap_after = Some(gap_opened);
                if dt < self.settings.min_open_time || gap_opened < self.settings.min_gap {
                    let tail = match *self.surface {
                        Surface::Rigid { restitution } if restitution < 1.0 => {
                            Some(t + dt / (1.0 - restitution))
                        }
                        _ => None,
                    };
                    return Ok(self.finish_resolved(tail));
                }
            }
            let t_hit = t + dt;
            if t_hit > t_end {
                return Ok(self.finish_open(Outcome::EndOfTime, open_since, None));
            }
            let (_, v_hit) = piece.state(dt);
            self.intervals.push(Interval {
                state: ContactState::Open,
                start: open_since,
                end: t_hit,
            });
            self.impacts.push(Impact {
                impact_time: t_hit,
                impact_velocity: v_hit,
                release_time: None,
                release_velocity: None,
                restitution: None,
                contact_time: None,
                peak_force: None,
                min_force: None,
                max_gap_after: None,
            });

            // Contact from (t_hit, g, v_hit).
            match self.contact(t_hit, v_hit)? {
                ContactEnd::Released { time, velocity } => {
                    let last = self.impacts.last_mut().expect("impact pushed above");
                    last.release_time = Some(time);
                    last.release_velocity = Some(velocity);
                    last.restitution = Some(-velocity / v_hit);
                    last.contact_time = Some(time - t_hit);
                    self.intervals.push(Interval {
                        state: ContactState::Closed,
                        start: t_hit,
                        end: time,
                    });
                    (t, x, v) = (time, g, velocity);
                    open_since = time;
                }
                ContactEnd::Stuck => return Ok(self.finish_closed(Outcome::Stuck, t_hit, None)),
                ContactEnd::Horizon => {
                    return Ok(self.finish_closed(Outcome::EndOfTime, t_hit, None));
                }
            }
        }
    }

    /// One contact starting at `t_hit` with speed `v_hit`; fills the force
    /// fields of the last impact.
    fn contact(&mut self, t_hit: f64, v_hit: f64) -> Result<ContactEnd, MechanicsError> {
        let m = *self.m;
        let g = m.gap;
        let t_end = self.settings.t_end;
        let last = self.impacts.len() - 1;
        match *self.surface {
            Surface::Rigid { restitution } => {
                let v_out = -restitution * v_hit;
                let x_eq = self.f_net / m.stiffness;
                if v_out == 0.0 && x_eq >= g {
                    // Held against the surface by the static overtravel force.
                    let static_force = m.stiffness * (x_eq - g);
                    self.impacts[last].peak_force = Some(static_force);
                    self.impacts[last].min_force = Some(static_force);
                    return Ok(ContactEnd::Stuck);
                }
                Ok(ContactEnd::Released {
                    time: t_hit,
                    velocity: v_out,
                })
            }
            Surface::KelvinVoigt { stiffness, damping } => {
                let piece = LinearPiece::new(
                    m.mass,
                    m.damping + damping,
                    m.stiffness + stiffness,
                    self.f_net + stiffness * g,
                    g,
                    v_hit,
                );
                let release = piece.crossing(g, false).filter(|dt| t_hit + dt > t_hit);
                let horizon = release.map_or(f64::INFINITY, |dt| dt);
                let (peak, min) = kv_force_extremes(&piece, g, stiffness, damping, horizon);
                self.impacts[last].peak_force = Some(peak);
                self.impacts[last].min_force = Some(min);
                Ok(match release {
                    None => ContactEnd::Stuck,
                    Some(dt) if t_hit + dt > t_end => ContactEnd::Horizon,
                    Some(dt) => ContactEnd::Released {
                        time: t_hit + dt,
                        velocity: piece.state(dt).1,
                    },
                })
            }
            Surface::HuntCrossley {
                stiffness,
                exponent,
                chi,
            } => {
                let hc = HcContact {
                    mass: m.mass,
                    damping: m.damping,
                    stiffness: m.stiffness,
                    force: self.f_net,
                    gap: g,
                    surface_stiffness: stiffness,
                    exponent,
                    chi,
                };
                let out = hc.run(v_hit, t_end - t_hit)?;
                self.impacts[last].peak_force = Some(out.peak_force);
                self.impacts[last].min_force = Some(out.min_force);
                Ok(match out.end {
                    HcEnd::Released { after, velocity } if t_hit + after > t_hit => {
                        ContactEnd::Released {
                            time: t_hit + after,
                            velocity,
                        }
                    }
                    HcEnd::Released { .. } | HcEnd::Stuck { .. } => ContactEnd::Stuck,
                    HcEnd::Horizon => ContactEnd::Horizon,
                })
            }
        }
    }

    /// The sequence ends with the contact open from `open_since`.
    fn finish_open(self, outcome: Outcome, open_since: f64, shortfall: Option<f64>) -> Chatter {
        let mut intervals = self.intervals;
        let t_end = self.settings.t_end;
        intervals.push(Interval {
            state: ContactState::Open,
            start: open_since.min(t_end),
            end: t_end,
        });
        let bounce_count = bounces(&intervals);
        Chatter {
            outcome,
            first_impact: self.impacts.first().map(|i| i.impact_time),
            settle_time: None,
            bounce_count,
            impacts: self.impacts,
            intervals,
            shortfall,
            accumulation_time: None,
            t_end,
        }
    }

    /// The sequence ends with the contact closed from the last impact on.
    fn finish_closed(self, outcome: Outcome, since: f64, accumulation: Option<f64>) -> Chatter {
        let mut intervals = self.intervals;
        let t_end = self.settings.t_end;
        intervals.push(Interval {
            state: ContactState::Closed,
            start: since,
            end: t_end.max(since),
        });
        let bounce_count = bounces(&intervals);
        Chatter {
            outcome,
            first_impact: self.impacts.first().map(|i| i.impact_time),
            settle_time: (outcome != Outcome::EndOfTime).then_some(since),
            bounce_count,
            impacts: self.impacts,
            intervals,
            shortfall: None,
            accumulation_time: accumulation,
            t_end,
        }
    }

    /// The opening after the last contact is below resolution: drop it
    /// and take the contact as closed from that contact's impact on.
    fn finish_resolved(mut self, accumulation: Option<f64>) -> Chatter {
        // The last pushed interval is that contact's closed span.
        let closed = self
            .intervals
            .pop()
            .expect("a release pushed its closed interval");
        debug_assert_eq!(closed.state, ContactState::Closed);
        self.finish_closed(Outcome::Resolved, closed.start, accumulation)
    }
}

/// Releases after the first impact that opened the contact: every open
/// interval but the one before the first impact.
fn bounces(intervals: &[Interval]) -> usize {
    intervals
        .iter()
        .filter(|i| i.state == ContactState::Open)
        .count()
        .saturating_sub(1)
}

/// Largest and smallest Kelvin–Voigt force `s0 (x − g) + r0 ẋ` over a
/// contact piece on local times [0, `until`] (`until` may be ∞ for a
/// contact that sticks). The force is a constant plus a combination of y
/// and ẏ, so its extrema are the closed-form zeros of its rate
/// `s0 ẏ + r0 ÿ = (s0 − 2a r0) ẏ − r0 ωn² y`.
fn kv_force_extremes(piece: &LinearPiece, g: f64, s0: f64, r0: f64, until: f64) -> (f64, f64) {
    let force = |t: f64| {
        let (x, v) = piece.state(t);
        s0 * (x - g) + r0 * v
    };
    let rate = piece.combo(-r0 * piece.omega2, s0 - 2.0 * piece.a * r0);
    let mut peak = force(0.0);
    let mut min = peak;
    let mut consider = |f: f64| {
        peak = peak.max(f);
        min = min.min(f);
    };
    if until.is_finite() {
        consider(force(until));
    } else {
        consider(s0 * (piece.x_eq - g));
    }
    // The force's own extrema decay like the motion: the first two (one
    // maximum, one minimum) bound every later one.
    let mut t = 0.0;
    for _ in 0..2 {
        match piece.next_zero(rate, t) {
            Some(z) if z < until => {
                consider(force(z));
                t = z;
            }
            _ => break,
        }
    }
    (peak, min)
}
