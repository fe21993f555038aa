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

/// The zeros of a [`Combo`], in increasing order, each with the value a
/// second combination takes there (see [`LinearPiece::zeros`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Zeros {
    next: f64,
    period: f64,
    value: f64,
    /// What the value is multiplied by from one zero to the next.
    factor: f64,
}

impl Zeros {
    const NONE: Zeros = Zeros {
        next: f64::INFINITY,
        period: f64::INFINITY,
        value: 0.0,
        factor: 0.0,
    };
}

impl Iterator for Zeros {
    /// (local time s, value of the second combination there).
    type Item = (f64, f64);

    fn next(&mut self) -> Option<(f64, f64)> {
        if !self.next.is_finite() {
            return None;
        }
        let out = (self.next, self.value);
        self.next += self.period;
        self.value *= self.factor;
        Some(out)
    }
}

/// The constants of one equation `m ẍ + c ẋ + k x = F`, shared by every
/// piece of motion under it: the engine works them out once per
/// simulation (free flight and, for Kelvin–Voigt, contact) rather than
/// once per piece.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// m, the equilibrium F/k.
    pub x_eq: f64,
    /// 1/s, decay rate a = c/(2m).
    pub a: f64,
    /// 1/s², ωn² = k/m.
    pub omega2: f64,
    /// 1/s², q = ωn² − a² (> 0 oscillatory).
    pub q: f64,
    /// 1/s, w = √|q|, and 1/w.
    w: f64,
    inv_w: f64,
    /// s, π/w: the spacing of the zeros of any combination when
    /// under-damped (∞ otherwise).
    period: f64,
    /// e^(−aπ/w) over half a period (1 unless under-damped).
    half_period_decay: f64,
    /// s, 1/ωn.
    time_scale: f64,
}

impl Mode {
    /// `mass` kg, `damping` c N·s/m, `stiffness` k N/m (> 0), `force` F N.
    pub fn new(mass: f64, damping: f64, stiffness: f64, force: f64) -> Self {
        let a = damping / (2.0 * mass);
        let omega2 = stiffness / mass;
        let q = omega2 - a * a;
        let w = q.abs().sqrt();
        let under_damped = q > 0.0;
        let period = if under_damped {
            std::f64::consts::PI / w
        } else {
            f64::INFINITY
        };
        Mode {
            x_eq: force / stiffness,
            a,
            omega2,
            q,
            w,
            inv_w: 1.0 / w,
            period,
            half_period_decay: if under_damped {
                (-a * period).exp()
            } else {
                1.0
            },
            time_scale: 1.0 / omega2.sqrt(),
        }
    }
}

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
    mode: Mode,
    /// The y and ẏ combinations: every evaluation needs them.
    y: Combo,
    v: Combo,
}

/// A level crossing found by [`LinearPiece::crossing`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// s, local time of the crossing.
    pub time: f64,
    /// m/s, the velocity at `time`.
    pub velocity: f64,
    /// (s, m): the extremum (local time, position) at which the motion
    /// turned toward the level, or `None` if it crossed in the first
    /// monotone segment without turning.
    pub turned_at: Option<(f64, f64)>,
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
        LinearPiece::start(&Mode::new(mass, damping, stiffness, force), x0, v0)
    }

    /// The motion under `mode` from (`x0` m, `v0` m/s).
    pub fn start(mode: &Mode, x0: f64, v0: f64) -> Self {
        let (a, omega2) = (mode.a, mode.omega2);
        let y0 = x0 - mode.x_eq;
        LinearPiece {
            x0,
            v0,
            x_eq: mode.x_eq,
            a,
            omega2,
            q: mode.q,
            mode: *mode,
            y: Combo {
                p: y0,
                q: v0 + a * y0,
            },
            v: Combo {
                p: v0,
                q: -(a * v0 + omega2 * y0),
            },
        }
    }

    /// (E(t), G(t)), the damped basis, evaluated without overflow.
    pub fn basis(&self, t: f64) -> (f64, f64) {
        let (a, w) = (self.a, self.mode.w);
        if self.q > 0.0 {
            let d = (-a * t).exp();
            let (s, c) = (w * t).sin_cos();
            (d * c, d * s * self.mode.inv_w)
        } else if self.q < 0.0 {
            let wt = w * t;
            if wt < 1.0 {
                let d = (-a * t).exp();
                (d * wt.cosh(), d * wt.sinh() * self.mode.inv_w)
            } else {
                // w < a, so both exponents are ≤ 0: no overflow.
                let up = ((w - a) * t).exp();
                let down = (-(w + a) * t).exp();
                (0.5 * (up + down), 0.5 * (up - down) * self.mode.inv_w)
            }
        } else {
            let d = (-a * t).exp();
            (d, t * d)
        }
    }

    /// y = x − x_eq as a combination.
    pub fn y_combo(&self) -> Combo {
        self.y
    }

    /// ẏ = ẋ as a combination.
    pub fn v_combo(&self) -> Combo {
        self.v
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
        let (y, v) = self.y_and_v(t);
        (self.x_eq + y, v)
    }

    /// (y, ẏ) at local time `t`, from one evaluation of the basis.
    fn y_and_v(&self, t: f64) -> (f64, f64) {
        let (e, g) = self.basis(t);
        let (y, v) = (self.y, self.v);
        (y.p * e + y.q * g, v.p * e + v.q * g)
    }

    /// ÿ = ẍ, from the equation of motion (no evaluation needed).
    fn acceleration(&self, y: f64, v: f64) -> f64 {
        -2.0 * self.a * v - self.omega2 * y
    }

    /// The zeros of a combination `c` in (0, ∞), in increasing order,
    /// each with the value of the combination `d` there. Zeros of
    /// `P·C + Q·S` are known in closed form (see the module docs): evenly
    /// spaced by π/w when under-damped, at most one otherwise.
    ///
    /// When under-damped, `P cos wt + (Q/w) sin wt = R cos(wt − φ)` and
    /// the zeros are at wt = φ + π/2 + jπ, where (cos wt, sin wt) =
    /// (−1)ʲ (−Q/(wR), P/R): so `d` there is
    /// (−1)ʲ e^(−at) (P·Q_d − Q·P_d)/(wR), one `exp` for the first zero and
    /// a factor −e^(−aπ/w) from each to the next, with no trigonometry.
    ///
    /// A zero at t = 0 itself (up to the rounding of the phase, 64 ulps of
    /// the period) is not reported: it is where the piece starts.
    pub fn zeros(&self, c: Combo, d: Combo) -> Zeros {
        if c.p == 0.0 && c.q == 0.0 {
            return Zeros::NONE;
        }
        if self.q > 0.0 {
            let (w, inv_w, period) = (self.mode.w, self.mode.inv_w, self.mode.period);
            let qw = c.q * inv_w;
            let phi = qw.atan2(c.p);
            let floor = 64.0 * f64::EPSILON * period;
            let mut t = (phi + std::f64::consts::FRAC_PI_2) * inv_w;
            // (−1)ʲ for the zero finally chosen.
            let mut sign = 1.0;
            while t <= floor {
                t += period;
                sign = -sign;
            }
            while t - period > floor {
                t -= period;
                sign = -sign;
            }
            let r2 = c.p * c.p + qw * qw;
            let r = if r2.is_normal() {
                r2.sqrt()
            } else {
                c.p.hypot(qw)
            };
            let value = sign * (-self.a * t).exp() * (c.p * d.q - c.q * d.p) / (w * r);
            Zeros {
                next: t,
                period,
                value,
                factor: -self.mode.half_period_decay,
            }
        } else {
            let t = if self.q < 0.0 {
                let w = self.mode.w;
                let r = -c.p * w / c.q;
                if !(r > 0.0 && r < 1.0) {
                    return Zeros::NONE;
                }
                r.atanh() * self.mode.inv_w
            } else {
                -c.p / c.q
            };
            if t > 64.0 * f64::EPSILON * self.time_scale() {
                Zeros {
                    next: t,
                    period: f64::INFINITY,
                    value: self.eval(d, t),
                    factor: 1.0,
                }
            } else {
                Zeros::NONE
            }
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
    pub fn crossing(&self, level: f64, upward: bool) -> Option<Crossing> {
        let mut extrema = self.zeros(self.v, self.y);
        let mut t0 = 0.0;
        let mut x_start = self.x0;
        // Velocity zeros are simple, so segments alternate direction. The
        // first one's comes from the start state, never from sampling the
        // velocity (which may underflow to 0 far into a decay).
        let mut rising = self.initially_rising();
        for _ in 0..3 {
            let t1 = extrema.next();
            if rising == upward {
                let crosses = |x: f64| if upward { x > level } else { x < level };
                let starts_before = if upward {
                    x_start < level || (x_start == level && t0 > 0.0)
                } else {
                    x_start > level || (x_start == level && t0 > 0.0)
                };
                if starts_before {
                    let end = match t1 {
                        Some((t1, y1)) => Some((t1, self.x_eq + y1)),
                        None => self.unbounded_bracket(t0, level, upward),
                    };
                    if let Some((t_end, x_end)) = end {
                        // Strictly past the level: touching it with zero
                        // speed at an extremum is a graze, not an impact.
                        if crosses(x_end) {
                            let between_extrema = t1.is_some() && (t0 > 0.0 || self.v0 == 0.0);
                            let (time, velocity) =
                                self.polish((t0, x_start), (t_end, x_end), level, between_extrema);
                            return Some(Crossing {
                                time,
                                velocity,
                                turned_at: (t0 > 0.0).then_some((t0, x_start)),
                            });
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
                Some((t1, y1)) => {
                    t0 = t1;
                    x_start = self.x_eq + y1;
                    rising = !rising;
                }
                None => return None,
            }
        }
        None
    }

    /// Whether x increases just after local time 0: the sign of the
    /// velocity, or of the acceleration when starting at rest.
    fn initially_rising(&self) -> bool {
        if self.v0 != 0.0 {
            self.v0 > 0.0
        } else {
            self.x0 < self.x_eq
        }
    }

    /// The value of x at the first extremum strictly after local time 0
    /// that is a maximum (`upward`) or a minimum, and its time; `None` if
    /// the motion has no such extremum.
    pub fn first_extremum(&self, maximum: bool) -> Option<(f64, f64)> {
        let mut extrema = self.zeros(self.v, self.y);
        let mut rising = self.initially_rising();
        for _ in 0..2 {
            let (t1, y1) = extrema.next()?;
            // A segment rising to t1 ends at a maximum.
            if rising == maximum {
                return Some((t1, self.x_eq + y1));
            }
            rising = !rising;
        }
        None
    }

    /// A natural time scale of the motion (s): 1/ωn.
    pub fn time_scale(&self) -> f64 {
        self.mode.time_scale
    }

    /// For the last, unbounded monotone segment: a time by which x has
    /// passed `level` and x there, found by doubling, or `None` if it
    /// never does (x approaches x_eq without reaching `level`).
    fn unbounded_bracket(&self, t0: f64, level: f64, upward: bool) -> Option<(f64, f64)> {
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
                return Some((t, x));
            }
            dt *= 2.0;
        }
        None
    }

    /// The crossing of `level` in the monotone segment between `lo` and
    /// `hi` (local time, position), and the velocity there, by safeguarded
    /// Halley iteration: the exact velocity and acceleration are the
    /// derivatives.
    ///
    /// Between two extrema x runs like half a cosine, so inverting that
    /// (an `acos`) starts Halley within a few per cent of the root;
    /// elsewhere the start is the secant point.
    fn polish(
        &self,
        (t_lo, x_lo): (f64, f64),
        (t_hi, x_hi): (f64, f64),
        level: f64,
        between_extrema: bool,
    ) -> (f64, f64) {
        let frac = (level - x_lo) / (x_hi - x_lo);
        let start = if between_extrema {
            t_lo + (t_hi - t_lo) * (1.0 - 2.0 * frac).acos() / std::f64::consts::PI
        } else {
            t_lo + (t_hi - t_lo) * frac
        };
        // x − level = y − (level − x_eq), with y kept apart from x_eq so
        // that a small y keeps its relative precision.
        let offset = level - self.x_eq;
        let root = root::halley_bracketed(
            |t| {
                let (y, v) = self.y_and_v(t);
                (y - offset, v, self.acceleration(y, v))
            },
            (t_lo, x_lo - level),
            (t_hi, x_hi - level),
            start,
        );
        match root.last {
            // Converged steps are tiny, so a Taylor step from the last
            // evaluation (ẏ' = ÿ, ÿ' = −2a ÿ − ωn² ẏ) is exact to rounding.
            Some(j) if (root.t - j.t).abs() <= 1e-6 * self.time_scale() => {
                let h = root.t - j.t;
                let jerk = -2.0 * self.a * j.d2 - self.omega2 * j.d1;
                (root.t, j.d1 + h * (j.d2 + 0.5 * h * jerk))
            }
            _ => (root.t, self.state(root.t).1),
        }
    }
}
