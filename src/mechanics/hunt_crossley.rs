//! One contact with a Hunt–Crossley surface, integrated numerically.
//!
//! In contact the motion is `m ẍ + c ẋ + k x = F − Fc`, with
//! `Fc = ks δⁿ (1 + χ δ̇)` clamped at 0 and δ = x − g. There is no closed
//! form, so the contact is integrated by [`Dopri5`] in the state (δ, δ̇)
//! (δ rather than x, so the tiny penetration keeps its relative precision).
//!
//! Two events end a contact:
//! - release: δ returns to 0 moving out, located on the step's dense
//!   output by bisection;
//! - sticking: mechanical energy `E = ½mv² + ½kx² − Fx + ks δⁿ⁺¹/(n+1)`
//!   never increases (both the viscous term and the clamp only remove
//!   energy), and reaching δ = 0 needs `E ≥ U(g) = ½kg² − Fg`. Once
//!   `E < U(g)` the contact can never release: it has stuck. This is exact
//!   and happens in finite time whenever the in-contact equilibrium lies
//!   past the surface (k0 < 1).

use nalgebra::Vector2;

use super::MechanicsError;
use super::integrate::{Dopri5, Step, Tolerance};
use super::root;

/// Everything the contact integration needs (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HcContact {
    pub mass: f64,
    /// N·s/m, structural damping c.
    pub damping: f64,
    /// N/m, suspension stiffness k (may be 0 for a free impact).
    pub stiffness: f64,
    /// N, constant drive F (net of preload).
    pub force: f64,
    /// m, surface position g.
    pub gap: f64,
    /// N/mⁿ
    pub surface_stiffness: f64,
    pub exponent: f64,
    /// s/m
    pub chi: f64,
}

/// How a Hunt–Crossley contact ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HcEnd {
    /// Released `after` seconds with velocity `velocity` (< 0).
    Released { after: f64, velocity: f64 },
    /// Energy fell below the release threshold `after` seconds in.
    Stuck { after: f64 },
    /// Still in contact at the time budget.
    Horizon,
}

/// The result of one contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HcOutcome {
    pub end: HcEnd,
    /// N, largest contact force seen.
    pub peak_force: f64,
    /// N, smallest contact force seen (0 at touch and release).
    pub min_force: f64,
}

impl HcContact {
    /// Contact force at penetration δ and rate δ̇.
    pub fn force_at(&self, delta: f64, delta_dot: f64) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        (self.surface_stiffness * self.power(delta) * (1.0 + self.chi * delta_dot)).max(0.0)
    }

    /// δⁿ for δ > 0. Hertz (n = 1.5) and the linear spring (n = 1) are
    /// what scenarios use, and `powf` would be most of the cost of a step.
    fn power(&self, delta: f64) -> f64 {
        let n = self.exponent;
        if n == 1.5 {
            delta * delta.sqrt()
        } else if n == 1.0 {
            delta
        } else {
            delta.powf(n)
        }
    }

    fn energy_margin(&self, y: &Vector2<f64>) -> f64 {
        // E − U(g), with x = g + δ: the spring and drive terms expand to
        // (k g − F) δ + ½ k δ², avoiding cancellation of large ½kx² terms.
        let (d, v) = (y[0], y[1]);
        let n = self.exponent;
        let surface = if d > 0.0 {
            self.surface_stiffness * d * self.power(d) / (n + 1.0)
        } else {
            0.0
        };
        0.5 * self.mass * v * v
            + (self.stiffness * self.gap - self.force) * d
            + 0.5 * self.stiffness * d * d
            + surface
    }

    /// Integrate one contact that starts at δ = 0 with impact speed
    /// `v_hit` (> 0), for at most `budget` seconds.
    pub fn run(&self, v_hit: f64, budget: f64) -> Result<HcOutcome, MechanicsError> {
        let m = *self;
        let rhs = move |_t: f64, y: &Vector2<f64>| {
            let (d, v) = (y[0], y[1]);
            let fc = m.force_at(d, v);
            let a = (m.force - m.damping * v - m.stiffness * (m.gap + d) - fc) / m.mass;
            Vector2::new(v, a)
        };
        // Scales: the depth at which the surface alone would stop the
        // impact (energy balance), and the time to get there.
        let n = self.exponent;
        let depth = ((n + 1.0) * self.mass * v_hit * v_hit / (2.0 * self.surface_stiffness))
            .powf(1.0 / (n + 1.0));
        let t_scale = depth / v_hit;
        let rtol = 1e-9;
        let tol = Tolerance {
            rtol,
            atol: Vector2::new(rtol * depth, rtol * v_hit),
        };
        let mut solver = Dopri5::new(rhs, 0.0, Vector2::new(0.0, v_hit), 1e-2 * t_scale, tol);
        let mut peak = Peak::default();
        let sticks_possible = self.stiffness * self.gap < self.force;
        // Sticking is tested with a small margin so that rounding can never
        // call a contact stuck that will still release.
        let stick_margin = 1e-9 * 0.5 * self.mass * v_hit * v_hit;
        // The force is clamped at 0, which it is at touch: nothing smaller
        // is ever seen.
        let min_force = 0.0;
        loop {
            let step = solver.step(budget)?;
            peak.track(step, self.force_at(step.y1[0], step.y1[1]));
            if step.y1[0] < 0.0 {
                // Released inside this step: δ(t0) ≥ 0 > δ(t1).
                let t_rel =
                    root::bisect(|t| step.at(t)[0], step.t0, step.t1, 1e-15).unwrap_or(step.t1);
                let y = step.at(t_rel);
                return Ok(HcOutcome {
                    end: HcEnd::Released {
                        after: t_rel,
                        velocity: y[1],
                    },
                    peak_force: self.refine_peak(&peak),
                    min_force,
                });
            }
            // Stuck is declared only once moving out again (past the
            // deepest penetration, so the force peak has been seen): the
            // reported peak force then does not depend on step sizes.
            let moving_out = step.y1[1] < 0.0;
            if sticks_possible && moving_out && self.energy_margin(&step.y1) < -stick_margin {
                return Ok(HcOutcome {
                    end: HcEnd::Stuck { after: step.t1 },
                    peak_force: self.refine_peak(&peak),
                    min_force,
                });
            }
            if step.t1 >= budget {
                return Ok(HcOutcome {
                    end: HcEnd::Horizon,
                    peak_force: self.refine_peak(&peak),
                    min_force,
                });
            }
        }
    }

    /// Golden-section search for the force maximum on the dense output
    /// around the largest step-end force.
    fn refine_peak(&self, peak: &Peak) -> f64 {
        let Some(step) = peak.step else {
            return peak.force;
        };
        let next = peak.next.unwrap_or(step);
        let fc = |t: f64| {
            let y = if t <= step.t1 { step.at(t) } else { next.at(t) };
            self.force_at(y[0], y[1])
        };
        let (mut a, mut b) = (step.t0, next.t1);
        let r = 0.5 * (5f64.sqrt() - 1.0);
        let mut c = b - r * (b - a);
        let mut d = a + r * (b - a);
        let (mut fc_c, mut fc_d) = (fc(c), fc(d));
        // 0.618⁴⁰ ≈ 4e-9 of the bracket: the force is flat to ~1e-17 there.
        for _ in 0..40 {
            if fc_c > fc_d {
                b = d;
                d = c;
                fc_d = fc_c;
                c = b - r * (b - a);
                fc_c = fc(c);
            } else {
                a = c;
                c = d;
                fc_c = fc_d;
                d = a + r * (b - a);
                fc_d = fc(d);
            }
        }
        peak.force.max(fc_c).max(fc_d)
    }
}

/// The largest contact force at a step end, the step that ended there and
/// the step after it. The force rises and falls once, so its maximum lies
/// between the start of the first and the end of the second.
#[derive(Default)]
struct Peak {
    force: f64,
    step: Option<Step<2>>,
    next: Option<Step<2>>,
}

impl Peak {
    fn track(&mut self, step: Step<2>, force_at_end: f64) {
        if force_at_end > self.force {
            *self = Peak {
                force: force_at_end,
                step: Some(step),
                next: None,
            };
        } else if self.step.is_some() && self.next.is_none() {
            self.next = Some(step);
        }
    }
}
