//! Closed-form motion under a constant force.
//!
//! Free flight (`m ẍ + r ẋ + s x = f − p`) and contact with a Kelvin–Voigt
//! surface (`m ẍ + (r + r0) ẋ + (s + s0) x = f − p + s0 g`) are both
//! `m ẍ + c ẋ + k x = F` with constant coefficients. With y = x − F/k,
//! a = c/(2m), ωn² = k/m and q = ωn² − a²:
//!
//! ```text
//! y(t) = y0·E(t) + (v0 + a·y0)·G(t)
//! ẏ(t) = v0·E(t) − (a·v0 + ωn²·y0)·G(t)
//! E(t) = e^(−at)·C(t),  G(t) = e^(−at)·S(t)
//! q > 0: C = cos wt, S = sin(wt)/w        (w = √q, under-damped)
//! q = 0: C = 1,      S = t                (critically damped)
//! q < 0: C = cosh wt, S = sinh(wt)/w      (w = √−q, over-damped)
//! ```
//!
//! One formula covers every regime and is continuous across ζ = 1, so
//! ζ ≈ 1 needs no special case. Any quantity `P·E + Q·G` (position,
//! velocity, a Kelvin–Voigt force or its rate) has its zeros in closed
//! form: evenly spaced by π/w when under-damped, at most one otherwise.
//! That is what lets events be bracketed exactly: between two consecutive
//! velocity zeros the position is monotonic, so a level is crossed at most
//! once there.

use super::root;

/// The motion `m ẍ + c ẋ + k x = F` from a given state at local time 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearPiece {
    /// m, position at local time 0.
    pub x0: f64,
    /// m/s, velocity at local time 0.
    pub v0: f64,
    /// m, the equilibrium F/k.
    pub x_eq: f64,
    /// 1/s, decay rate a = c/(2m).
    pub a: f64,
    /// 1/s², ωn² = k/m.
    pub omega2: f64,
    /// 1/s², q = ωn² − a² (> 0 oscillatory).
    pub q: f64,
}

/// A combination `P·E(t) + Q·G(t)` of the two basis functions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Combo {
    pub p: f64,
    pub q: f64,
}

impl LinearPiece {
    /// `mass` kg, `damping` c N·s/m, `stiffness` k N/m (> 0), `force` F N.
    pub fn new(mass: f64, damping: f64, stiffness: f64, force: f64, x0: f64, v0: f64) -> Self {
        let a = damping / (2.0 * mass);
        let omega2 = stiffness / mass;
        LinearPiece {
            x0,
            v0,
            x_eq: force / stiffness,
            a,
            omega2,
            q: omega2 - a * a,
        }
    }

    /// (E(t), G(t)), the damped basis, evaluated without overflow.
    pub fn basis(&self, t: f64) -> (f64, f64) {
        let a = self.a;
        if self.q > 0.0 {
            let w = self.q.sqrt();
            let d = (-a * t).exp();
            let (s, c) = (w * t).sin_cos();
            (d * c, d * s / w)
        } else if self.q < 0.0 {
            let w = (-self.q).sqrt();
            let wt = w * t;
            if wt < 1.0 {
                let d = (-a * t).exp();
                (d * wt.cosh(), d * wt.sinh() / w)
            } else {
                // w < a, so both exponents are ≤ 0: no overflow.
                let up = ((w - a) * t).exp();
                let down = (-(w + a) * t).exp();
                (0.5 * (up + down), 0.5 * (up - down) / w)
            }
        } else {
            let d = (-a * t).exp();
            (d, t * d)
        }
    }

    /// y = x − x_eq as a combination.
    pub fn y_combo(&self) -> Combo {
        let y0 = self.x0 - self.x_eq;
        Combo {
            p: y0,
            q: self.v0 + self.a * y0,
        }
    }

    /// ẏ = ẋ as a combination.
    pub fn v_combo(&self) -> Combo {
        let y0 = self.x0 - self.x_eq;
        Combo {
            p: self.v0,
            q: -(self.a * self.v0 + self.omega2 * y0),
        }
    }

    /// α·y + β·ẏ as a combination.
    pub fn combo(&self, alpha: f64, beta: f64) -> Combo {
        let y = self.y_combo();
        let v = self.v_combo();
        Combo {
            p: alpha * y.p + beta * v.p,
            q: alpha * y.q + beta * v.q,
        }
    }

    /// Evaluate a combination at local time `t`.
    pub fn eval(&self, c: Combo, t: f64) -> f64 {
        let (e, g) = self.basis(t);
        c.p * e + c.q * g
    }

    /// (x, ẋ) at local time `t`.
    pub fn state(&self, t: f64) -> (f64, f64) {
        let (e, g) = self.basis(t);
        let y = self.y_combo();
        let v = self.v_combo();
        (self.x_eq + y.p * e + y.q * g, v.p * e + v.q * g)
    }

    /// The first zero of a combination strictly after local time `after`
    /// (≥ 0), or `None` if it has no later zero. Zeros of `P·C + Q·S` are
    /// known in closed form (see the module docs).
    pub fn next_zero(&self, c: Combo, after: f64) -> Option<f64> {
        if c.p == 0.0 && c.q == 0.0 {
            return None;
        }
        if self.q > 0.0 {
            let w = self.q.sqrt();
            // P cos wt + (Q/w) sin wt = R cos(wt − φ): zeros at
            // wt = φ + π/2 + jπ.
            let phi = (c.q / w).atan2(c.p);
            let period = std::f64::consts::PI / w;
            let first = (phi + std::f64::consts::FRAC_PI_2) / w;
            // Smallest first + j·period past `after`. A zero within a
            // hair of `after` is the one `after` already is (rounding), so
            // the search starts a billionth of a period later.
            let after = after + 1e-9 * period;
            let j = ((after - first) / period).floor() + 1.0;
            let mut t = first + j * period;
            while t <= after {
                t += period;
            }
            while t - period > after {
                t -= period;
            }
            Some(t)
        } else {
            let t = if self.q < 0.0 {
                let w = (-self.q).sqrt();
                if c.q == 0.0 {
                    return None;
                }
                let r = -c.p * w / c.q;
                if !(r > 0.0 && r < 1.0) {
                    return None;
                }
                r.atanh() / w
            } else {
                if c.q == 0.0 {
                    return None;
                }
                -c.p / c.q
            };
            // As above: a zero at `after` itself (up to rounding) is not
            // a later one.
            (t > after + 1e-9 * self.time_scale()).then_some(t)
        }
    }

    /// The first time in (0, ∞) at which x crosses `level` moving in the
    /// direction `upward` (true: x increasing through `level`).
    ///
    /// Position is monotonic between consecutive velocity zeros, so each
    /// such segment holds at most one crossing. The first extremum in the
    /// wanted direction is the farthest the motion will ever reach (the
    /// envelope decays, or is constant when undamped), so at most the first
    /// two segments with the right slope need looking at: the answer is
    /// exact, not a scan.
    pub fn crossing(&self, level: f64, upward: bool) -> Option<f64> {
        let v = self.v_combo();
        let mut t0 = 0.0;
        let mut x_start = self.x0;
        for _ in 0..3 {
            let t1 = self.next_zero(v, t0);
            let slope_at = |t: f64| self.state(t).1;
            // Direction of this segment: velocity at its middle, or just
            // after its start when it is unbounded.
            let probe = match t1 {
                Some(t1) => 0.5 * (t0 + t1),
                None => t0 + self.time_scale(),
            };
            let rising = slope_at(probe) > 0.0;
            if rising == upward {
                let crosses = |x: f64| if upward { x > level } else { x < level };
                let starts_before = if upward {
                    x_start < level || (x_start == level && t0 > 0.0)
                } else {
                    x_start > level || (x_start == level && t0 > 0.0)
                };
                if starts_before {
                    let end = match t1 {
                        Some(t1) => Some(t1),
                        None => self.unbounded_bracket(t0, level, upward),
                    };
                    if let Some(t_end) = end {
                        let x_end = self.state(t_end).0;
                        // Strictly past the level: touching it with zero
                        // speed at an extremum is a graze, not an impact.
                        if crosses(x_end) {
                            return Some(self.polish(t0, t_end, level));
                        }
                    }
                }
                // The first extremum in the wanted direction fell short:
                // no later one reaches farther.
                if t0 > 0.0 || starts_before {
                    return None;
                }
            }
            match t1 {
                Some(t1) => {
                    t0 = t1;
                    x_start = self.state(t1).0;
                }
                None => return None,
            }
        }
        None
    }

    /// The value of x at the first extremum strictly after local time 0
    /// that is a maximum (`upward`) or a minimum, and its time; `None` if
    /// the motion has no such extremum.
    pub fn first_extremum(&self, maximum: bool) -> Option<(f64, f64)> {
        let v = self.v_combo();
        let mut t0 = 0.0;
        for _ in 0..2 {
            let t1 = self.next_zero(v, t0)?;
            let mid = 0.5 * (t0 + t1);
            let rising = self.state(mid).1 > 0.0;
            if rising == maximum {
                return Some((t1, self.state(t1).0));
            }
            t0 = t1;
        }
        None
    }

    /// A natural time scale of the motion (s): 1/ωn.
    pub fn time_scale(&self) -> f64 {
        1.0 / self.omega2.sqrt()
    }

    /// For the last, unbounded monotone segment: a time by which x has
    /// passed `level`, found by doubling, or `None` if it never does
    /// (x approaches x_eq without reaching `level`).
    fn unbounded_bracket(&self, t0: f64, level: f64, upward: bool) -> Option<f64> {
        let reaches = if upward {
            self.x_eq > level
        } else {
            self.x_eq < level
        };
        if !reaches {
            return None;
        }
        let mut dt = self.time_scale();
        for _ in 0..200 {
            let t = t0 + dt;
            let x = self.state(t).0;
            if (upward && x >= level) || (!upward && x <= level) {
                return Some(t);
            }
            dt *= 2.0;
        }
        None
    }

    /// The crossing of `level` in the monotone segment [lo, hi], polished
    /// by safeguarded Newton iteration (the derivative is the exact
    /// velocity).
    fn polish(&self, lo: f64, hi: f64, level: f64) -> f64 {
        root::newton_bracketed(
            |t| {
                let (x, v) = self.state(t);
                (x - level, v)
            },
            lo,
            hi,
        )
    }
}
