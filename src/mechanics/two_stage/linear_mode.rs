//! One linear mode of the two-stage relay and its exact solution: the
//! mode's scaled matrix, equilibrium and step propagator
//! ([`LinearMode`]), a step's motion as a Taylor series in τ
//! ([`Taylor`]), and linear functions of the state ([`Form`]) as scalar
//! polynomials ([`Poly`]) whose roots and extrema locate events.

use nalgebra::{Matrix4, Vector4};

use super::model::Y;

/// The scaled deviation from a mode's equilibrium.
pub(crate) type W = Vector4<f64>;

/// One linear mode: its scaled matrix, equilibrium and step propagator.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LinearMode {
    pub(super) a: Matrix4<f64>,
    /// `(u_a, v_a, u_b, v_b)` at equilibrium.
    pub(super) eq: Vector4<f64>,
    /// rad/s, the velocity scale.
    pub(super) omega: f64,
    /// `exp(a h)`.
    pub(super) phi: Matrix4<f64>,
    /// s
    pub(super) h: f64,
}

impl LinearMode {
    /// `w(τ)` from `w0` (τ within a step), by the step's Taylor series.
    pub(crate) fn at(&self, w0: &W, tau: f64) -> W {
        Taylor::new(self, w0).at(tau)
    }

    /// The state of `w`.
    pub(crate) fn y_of(&self, w: &W) -> Y {
        Y::new(
            self.eq[0] + w[0],
            self.eq[1] + self.omega * w[1],
            self.eq[2] + w[2],
            self.eq[3] + self.omega * w[3],
            0.0,
        )
    }

    /// The scaled deviation of state `y`.
    pub(crate) fn w_of(&self, y: &Y) -> W {
        W::new(
            y[0] - self.eq[0],
            (y[1] - self.eq[1]) / self.omega,
            y[2] - self.eq[2],
            (y[3] - self.eq[3]) / self.omega,
        )
    }

    /// The linear form `c·y + d` as `k + q·w`.
    pub(super) fn form(&self, c: [f64; 4], d: f64) -> Form {
        let scale = [1.0, self.omega, 1.0, self.omega];
        Form {
            k: c[0] * self.eq[0] + c[1] * self.eq[1] + c[2] * self.eq[2] + c[3] * self.eq[3] + d,
            q: W::new(
                c[0] * scale[0],
                c[1] * scale[1],
                c[2] * scale[2],
                c[3] * scale[3],
            ),
        }
    }
}

/// `k + q·w`: a linear function of the state.
#[derive(Debug, Clone, Copy)]
pub(super) struct Form {
    pub(super) k: f64,
    pub(super) q: W,
}

impl Form {
    pub(super) fn value(&self, w: &W) -> f64 {
        self.k + self.q.dot(w)
    }

    pub(super) fn negated(self) -> Form {
        Form {
            k: -self.k,
            q: -self.q,
        }
    }
}

/// Terms of the Taylor series kept per step: with `‖a h‖ ≤ 2.5` the
/// first one left out is below 5e-18 of the first.
pub(super) const TERMS: usize = 28;

/// One step's motion as a power series in τ: `w(τ) = Σ c_k τ^k`,
/// `c_k = a^k w0 / k!`. Built only for steps where something must be
/// located; any linear form of it is then a scalar polynomial.
pub(super) struct Taylor {
    pub(super) c: [W; TERMS],
}

impl Taylor {
    pub(super) fn new(mode: &LinearMode, w0: &W) -> Taylor {
        let mut c = [W::zeros(); TERMS];
        c[0] = *w0;
        for k in 1..TERMS {
            c[k] = mode.a * c[k - 1] / k as f64;
        }
        Taylor { c }
    }

    pub(super) fn at(&self, tau: f64) -> W {
        let mut w = self.c[TERMS - 1];
        for k in (0..TERMS - 1).rev() {
            w = w * tau + self.c[k];
        }
        w
    }

    pub(super) fn poly(&self, form: &Form) -> Poly {
        let mut p = [0.0; TERMS];
        for (k, c) in self.c.iter().enumerate() {
            p[k] = form.q.dot(c);
        }
        p[0] += form.k;
        Poly { p }
    }
}

/// A scalar polynomial in τ.
#[derive(Clone, Copy)]
pub(super) struct Poly {
    pub(super) p: [f64; TERMS],
}

impl Poly {
    pub(super) fn value(&self, tau: f64) -> f64 {
        self.p.iter().rev().fold(0.0, |acc, &c| acc * tau + c)
    }

    /// (value, rate) at τ.
    pub(super) fn jet(&self, tau: f64) -> (f64, f64) {
        let (mut v, mut d) = (self.p[TERMS - 1], 0.0);
        for k in (0..TERMS - 1).rev() {
            d = d * tau + v;
            v = v * tau + self.p[k];
        }
        (v, d)
    }

    pub(super) fn derivative(&self) -> Poly {
        let mut p = [0.0; TERMS];
        for k in 1..TERMS {
            p[k - 1] = self.p[k] * k as f64;
        }
        Poly { p }
    }

    /// τ in `[lo, hi]` where the polynomial is zero, given a sign change
    /// between the ends: Newton's method kept inside the bracket,
    /// bisection where it would leave it.
    pub(super) fn root(&self, mut lo: f64, mut hi: f64) -> f64 {
        let positive_lo = self.value(lo) > 0.0;
        let mut tau = 0.5 * (lo + hi);
        for _ in 0..200 {
            let (v, slope) = self.jet(tau);
            if v == 0.0 {
                return tau;
            }
            if (v > 0.0) == positive_lo {
                lo = tau;
            } else {
                hi = tau;
            }
            let newton = tau - v / slope;
            let next = if slope != 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - tau).abs() <= 2.0 * f64::EPSILON * hi || hi - lo <= 2.0 * f64::EPSILON * hi {
                return next;
            }
            tau = next;
        }
        tau
    }

    /// The extremum inside `(0, h)`, where the rate changes sign.
    pub(super) fn extremum(&self, h: f64) -> Option<f64> {
        let rate = self.derivative();
        let (r0, r1) = (rate.value(0.0), rate.value(h));
        if r0 == 0.0 || r1 == 0.0 || (r0 > 0.0) == (r1 > 0.0) {
            return None;
        }
        Some(rate.root(0.0, h))
    }
}
