//! The event-driven chatter engine.
//!
//! A closing alternates two phases until one of the endings of docs/model.md §4:
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

use super::error::{MAX_EVENTS, MechanicsError};
use super::hunt_crossley::{HcContact, HcEnd};
use super::linear::{LinearPiece, Mode, Shift, Zeros};
pub use super::parameters::validate;
use super::parameters::{Mechanics, PROOF_SPAN, Settings};
use super::surface::Surface;
use crate::chatter::{Chatter, ContactState, Impact, Interval, Outcome, bounces};

/// Simulate one closing: the chatter sequence from t = 0 to an ending of
/// docs/model.md §4. Parameters are validated first; an invalid one is an
/// error naming its scenario key.
pub fn simulate(
    mechanics: &Mechanics,
    surface: &Surface,
    settings: &Settings,
) -> Result<Chatter, MechanicsError> {
    validate(mechanics, surface, settings)?;
    Engine::new(mechanics, surface, settings).run()
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
    /// Free flight's equation, and the surface's response to an impact.
    flight: Mode,
    law: Law,
    impacts: Vec<Impact>,
    intervals: Vec<Interval>,
}

/// Room for a typical sequence (a few dozen contacts) without regrowing.
const TYPICAL_CONTACTS: usize = 32;

impl<'a> Engine<'a> {
    fn new(m: &'a Mechanics, surface: &'a Surface, settings: &'a Settings) -> Self {
        let f_net = m.force - m.preload;
        Engine {
            m,
            surface,
            settings,
            f_net,
            flight: free_flight(m),
            law: Law::new(m, surface),
            impacts: Vec::with_capacity(TYPICAL_CONTACTS),
            intervals: Vec::with_capacity(2 * TYPICAL_CONTACTS + 1),
        }
    }

    fn flight(&self, x0: f64, v0: f64) -> LinearPiece {
        LinearPiece::start(&self.flight, x0, v0)
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
            if self.impacts.len() >= MAX_EVENTS {
                return Ok(self.finish_open(Outcome::EventLimit, open_since, None));
            }
            // Flight from (t, x, v).
            let piece = self.flight(x, v);
            let hit = piece.crossing(g, true);
            let Some(hit) = hit.filter(|c| t + c.time > t) else {
                return Ok(if self.impacts.is_empty() {
                    let reach = piece
                        .first_extremum(true)
                        .map_or(piece.x_eq.max(x), |(_, xm)| xm.max(x));
                    self.finish_open(Outcome::NeverCloses, open_since, Some(g - reach))
                } else {
                    self.finish_open(Outcome::EndsOpen, open_since, None)
                });
            };
            let dt = hit.time;
            // The largest opening of this flight (after a release): the
            // minimum the flight turned at, found on the way to the impact.
            if let Some(last) = self.impacts.last_mut() {
                let lowest = match hit.turned_at {
                    Some((_, x_turn)) => x_turn,
                    None => piece.first_extremum(false).map_or(x, |(_, xm)| xm),
                };
                let gap_opened = g - lowest;
                last.max_gap_after = Some(gap_opened);
                // Never resolve finer than f64 can: positions carry
                // rounding of ~ε·|x_eq|, times of ~ε·t.
                let min_gap = self
                    .settings
                    .min_gap
                    .max(1e3 * f64::EPSILON * piece.x_eq.abs().max(g));
                let min_open = self
                    .settings
                    .min_open_time
                    .max(1e3 * f64::EPSILON * (t + dt));
                if dt < min_open || gap_opened < min_gap {
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
            let v_hit = hit.velocity;
            self.intervals.push(Interval {
                state: ContactState::Open,
                start: open_since,
                end: t_hit,
            });
            self.impacts.push(Impact::touch(t_hit, v_hit));

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
        let budget = self.settings.t_end - t_hit;
        let r = self.law.respond(self.m, v_hit, budget)?;
        let last = self.impacts.last_mut().expect("the impact was pushed");
        last.peak_force = r.peak_force;
        last.min_force = r.min_force;
        Ok(match r.end {
            ResponseEnd::Released {
                contact_time,
                velocity,
            } => ContactEnd::Released {
                time: t_hit + contact_time,
                velocity,
            },
            ResponseEnd::Stuck => ContactEnd::Stuck,
            // Closed at t_end: the same contact followed on (the response
            // is a function of the impact alone) up to PROOF_SPAN × t_end;
            // stuck only if proven so before it releases.
            ResponseEnd::Horizon => {
                let longer = PROOF_SPAN * self.settings.t_end - t_hit;
                match self.law.respond(self.m, v_hit, longer) {
                    Ok(r) if matches!(r.end, ResponseEnd::Stuck) => ContactEnd::Stuck,
                    _ => ContactEnd::Horizon,
                }
            }
        })
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
            settle_time: (outcome != Outcome::EndOfTime && outcome != Outcome::EventLimit)
                .then_some(since),
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

/// How a single contact ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ResponseEnd {
    /// Released after `contact_time` s with `velocity` m/s (≤ 0).
    Released {
        /// s, from touch to release.
        contact_time: f64,
        /// m/s, the velocity at release (≤ 0: away from the contact).
        velocity: f64,
    },
    /// Never releases.
    Stuck,
    /// Still in contact when the time budget ran out.
    Horizon,
}

/// One contact, from touch to release: what the surface does to an impact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactResponse {
    /// Whether and how the contact released.
    pub end: ResponseEnd,
    /// N, largest contact force (`None` for a rigid impulse).
    pub peak_force: Option<f64>,
    /// N, smallest contact force (`None` for a rigid impulse).
    pub min_force: Option<f64>,
}

impl ImpactResponse {
    /// −release velocity / impact velocity, if it released.
    pub fn restitution(&self, v_hit: f64) -> Option<f64> {
        match self.end {
            ResponseEnd::Released { velocity, .. } => Some(-velocity / v_hit),
            _ => None,
        }
    }

    /// s, the contact time, if it released.
    pub fn contact_time(&self) -> Option<f64> {
        match self.end {
            ResponseEnd::Released { contact_time, .. } => Some(contact_time),
            _ => None,
        }
    }
}

/// The response of the surface to one impact at speed `v_hit` (m/s, > 0)
/// with the relay's suspension and drive acting throughout, followed for
/// at most `budget` seconds. This is the contact phase of the engine on
/// its own: it gives the restitution and contact time as functions of
/// impact speed (the paper's Figs. 5–8).
pub fn impact_response(
    m: &Mechanics,
    surface: &Surface,
    v_hit: f64,
    budget: f64,
) -> Result<ImpactResponse, MechanicsError> {
    Law::new(m, surface).respond(m, v_hit, budget)
}

/// A surface law with what depends only on the relay worked out once, so
/// that a sequence of contacts does not redo it.
enum Law {
    Rigid {
        restitution: f64,
    },
    KelvinVoigt {
        /// The in-contact equation.
        contact: Mode,
        /// N/m and N·s/m, the surface's s0 and r0.
        stiffness: f64,
        damping: f64,
        /// The varying part of the force, s0·y + r0·ẏ, as shifted
        /// position (under-damped contact only).
        force_shift: Option<Shift>,
    },
    HuntCrossley(HcContact),
}

impl Law {
    fn new(m: &Mechanics, surface: &Surface) -> Law {
        match *surface {
            Surface::Rigid { restitution } => Law::Rigid { restitution },
            Surface::KelvinVoigt { stiffness, damping } => {
                let contact = kelvin_voigt_contact(m, stiffness, damping);
                Law::KelvinVoigt {
                    contact,
                    stiffness,
                    damping,
                    force_shift: contact.combination_shift(stiffness, damping),
                }
            }
            Surface::HuntCrossley {
                stiffness,
                exponent,
                chi,
            } => Law::HuntCrossley(HcContact::new(m, stiffness, exponent, chi)),
        }
    }

    /// See [`impact_response`].
    fn respond(
        &self,
        m: &Mechanics,
        v_hit: f64,
        budget: f64,
    ) -> Result<ImpactResponse, MechanicsError> {
        let g = m.gap;
        match *self {
            Law::Rigid { restitution } => {
                let v_out = -restitution * v_hit;
                let x_eq = (m.force - m.preload) / m.stiffness;
                if v_out == 0.0 && x_eq >= g {
                    // Held against the surface by the static overtravel force.
                    let static_force = m.stiffness * (x_eq - g);
                    return Ok(ImpactResponse {
                        end: ResponseEnd::Stuck,
                        peak_force: Some(static_force),
                        min_force: Some(static_force),
                    });
                }
                Ok(ImpactResponse {
                    end: ResponseEnd::Released {
                        contact_time: 0.0,
                        velocity: v_out,
                    },
                    peak_force: None,
                    min_force: None,
                })
            }
            Law::KelvinVoigt {
                ref contact,
                stiffness,
                damping,
                force_shift,
            } => {
                let piece = LinearPiece::start(contact, g, v_hit);
                let release = piece.crossing(g, false);
                let budget = budget.max(0.0);
                // Where the force is last looked at: (time, x, ẋ).
                let until = match release {
                    Some(c) if c.time <= budget => Some((c.time, g, c.velocity)),
                    _ if budget.is_finite() => {
                        let (x, v) = piece.state(budget);
                        Some((budget, x, v))
                    }
                    _ => None,
                };
                // The force's extrema: from the deepest point, where the
                // release crossing turned, when the force is shifted
                // position; else from the closed-form zeros of its rate.
                let turn = release.and_then(|c| c.turned_at);
                let extrema = match (force_shift, turn) {
                    (Some(shift), Some((t, x))) => {
                        piece.combination_extrema(shift, (t, x - piece.x_eq))
                    }
                    _ => {
                        let rate = piece
                            .combo(-damping * piece.omega2, stiffness - 2.0 * piece.a * damping);
                        piece.zeros(rate, piece.combo(stiffness, damping))
                    }
                };
                let (peak, min) =
                    kv_force_extremes(&piece, g, (stiffness, damping), extrema, until);
                Ok(ImpactResponse {
                    end: match release {
                        None => ResponseEnd::Stuck,
                        Some(c) if c.time > budget => ResponseEnd::Horizon,
                        Some(c) => ResponseEnd::Released {
                            contact_time: c.time,
                            velocity: c.velocity,
                        },
                    },
                    peak_force: Some(peak),
                    min_force: Some(min),
                })
            }
            Law::HuntCrossley(ref hc) => {
                let out = hc.run(v_hit, budget)?;
                Ok(ImpactResponse {
                    end: match out.end {
                        HcEnd::Released { after, velocity } => ResponseEnd::Released {
                            contact_time: after,
                            velocity,
                        },
                        HcEnd::Stuck { .. } => ResponseEnd::Stuck,
                        HcEnd::Horizon => ResponseEnd::Horizon,
                    },
                    peak_force: Some(out.peak_force),
                    min_force: Some(out.min_force),
                })
            }
        }
    }
}

/// The critical (sticking) impact speed v_c (m/s): impacts slower than
/// this never release (docs/model.md §3, paper §3.5). Zero when the contact
/// always releases (k0 ≥ 1, or a rigid surface with e > 0); infinite for a
/// rigid surface with e = 0 and overtravel. Found by bisection on "does
/// this impact release", to `rel_tol` relative.
pub fn critical_impact_speed(
    m: &Mechanics,
    surface: &Surface,
    rel_tol: f64,
) -> Result<f64, MechanicsError> {
    let law = Law::new(m, surface);
    let releases = |v: f64| -> Result<bool, MechanicsError> {
        let r = law.respond(m, v, f64::INFINITY)?;
        Ok(matches!(r.end, ResponseEnd::Released { .. }))
    };
    let x_eq = (m.force - m.preload) / m.stiffness;
    if x_eq <= m.gap {
        return Ok(0.0);
    }
    if let Surface::Rigid { restitution } = *surface {
        return Ok(if restitution > 0.0 {
            0.0
        } else {
            f64::INFINITY
        });
    }
    // A speed scale: the overtravel crossed at the suspension's natural
    // frequency. Grow until it releases, then bisect.
    let mut hi = (x_eq - m.gap) * (m.stiffness / m.mass).sqrt();
    let mut lo = 0.0;
    let mut tries = 0;
    while !releases(hi)? {
        lo = hi;
        hi *= 2.0;
        tries += 1;
        if tries > 200 {
            return Ok(f64::INFINITY);
        }
    }
    while hi - lo > rel_tol * hi {
        let mid = 0.5 * (lo + hi);
        if releases(mid)? {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok(0.5 * (lo + hi))
}

/// Largest and smallest Kelvin–Voigt force `s0 (x − g) + r0 ẋ` over a
/// contact piece from local time 0 to `until` = (time, x, ẋ), the end
/// state the caller already has (`None` for a contact that sticks: the
/// force tends to its static value). The force is a constant plus a
/// combination of y and ẏ; `extrema` are that combination's extrema
/// (local time, value) in order, from its closed-form rate zeros or as
/// shifted position ([`Mode::combination_shift`]).
fn kv_force_extremes(
    piece: &LinearPiece,
    g: f64,
    (s0, r0): (f64, f64),
    extrema: Zeros,
    until: Option<(f64, f64, f64)>,
) -> (f64, f64) {
    let force = |x: f64, v: f64| s0 * (x - g) + r0 * v;
    let mut peak = force(piece.x0, piece.v0);
    let mut min = peak;
    let mut consider = |f: f64| {
        peak = peak.max(f);
        min = min.min(f);
    };
    let at_rest = s0 * (piece.x_eq - g);
    let t_until = match until {
        Some((t, x, v)) => {
            consider(force(x, v));
            t
        }
        None => {
            consider(at_rest);
            f64::INFINITY
        }
    };
    // The force's own extrema decay like the motion: the first two (one
    // maximum, one minimum) bound every later one.
    for (_, varying) in extrema.take(2).take_while(|&(z, _)| z < t_until) {
        consider(at_rest + varying);
    }
    (peak, min)
}

/// The free flight of the step-force relay `m`: `m ẍ + r ẋ + s x = f − p`.
pub(crate) fn free_flight(m: &Mechanics) -> Mode {
    Mode::new(m.mass, m.damping, m.stiffness, m.force - m.preload)
}

/// The step-force relay `m` in contact with a Kelvin–Voigt surface of
/// `stiffness` and `damping`: the surface's spring and damper add to the
/// suspension's, and its spring pushes back from the contact at `g`.
pub(crate) fn kelvin_voigt_contact(m: &Mechanics, stiffness: f64, damping: f64) -> Mode {
    Mode::new(
        m.mass,
        m.damping + damping,
        m.stiffness + stiffness,
        m.force - m.preload + stiffness * m.gap,
    )
}
