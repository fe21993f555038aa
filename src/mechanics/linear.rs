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
//!
//! Speed (a whole sequence takes microseconds): the constants of each
//! equation are worked out once ([`Mode`]); a crossing between extrema of
//! an under-damped piece is solved in the phase from the first extremum,
//! where the motion is one exact formula and Halley's iterates advance by
//! addition theorems rather than fresh `exp`/`sin_cos` calls
//! ([`LinearPiece::crossing`]); a piece that returns to the level it
//! started at (every impact and release) starts that iteration from the
//! mirror image of its way out, whose phase the turn already gives, so a
//! crossing costs one `atan2` and one `exp`; any combination of y and ẏ (a
//! Kelvin–Voigt force) is y itself shifted in time and scaled
//! ([`Mode::combination_shift`]), so its extrema need no trigonometry.

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
    /// e^(−aπ/w) over half a period (1 unless under-damped), and
    /// 1/(1 + e^(−aπ/w)).
    half_period_decay: f64,
    inv_swing: f64,
    /// κ = a/w, the decay per radian of phase (under-damped).
    kappa: f64,
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
        let half_period_decay = if under_damped {
            (-a * period).exp()
        } else {
            1.0
        };
        Mode {
            x_eq: force / stiffness,
            a,
            omega2,
            q,
            w,
            inv_w: 1.0 / w,
            period,
            half_period_decay,
            inv_swing: 1.0 / (1.0 + half_period_decay),
            kappa: a / w,
            time_scale: 1.0 / omega2.sqrt(),
        }
    }
}

impl Mode {
    /// Under-damped only: a combination α·y + β·ẏ of any piece under this
    /// mode is that piece's y itself, advanced and scaled:
    /// `α y(t) + β ẏ(t) = gain · y(t + lead)`. With y = Re(A e^(λt)),
    /// λ = −a + iw, the combination is Re(μ A e^(λt)) with μ = α + βλ, and
    /// multiplying by |μ|·e^(iψ) is the same as advancing by ψ/w and
    /// scaling by |μ|·e^(aψ/w). So the combination's extrema are those of
    /// y, `lead` earlier and `gain` times larger, with no trigonometry
    /// per piece ([`LinearPiece::combination_extrema`]).
    pub fn combination_shift(&self, alpha: f64, beta: f64) -> Option<Shift> {
        if self.q <= 0.0 {
            return None;
        }
        let (re, im) = (alpha - beta * self.a, beta * self.w);
        let lead = im.atan2(re) * self.inv_w;
        Some(Shift {
            lead,
            gain: re.hypot(im) * (self.a * lead).exp(),
        })
    }
}

/// See [`Mode::combination_shift`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shift {
    /// s, how far the combination runs ahead of y.
    pub lead: f64,
    /// Its size relative to y.
    pub gain: f64,
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
    /// The coefficient P of E(t).
    pub p: f64,
    /// The coefficient Q of G(t).
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
        self.zeros_and_phase(c, d).0
    }

    /// [`LinearPiece::zeros`], and when under-damped the basis phase at the
    /// first zero: e^(−at), cos wt and sin wt there, which the closed form
    /// gives for free (see above).
    #[inline(always)]
    fn zeros_and_phase(&self, c: Combo, d: Combo) -> (Zeros, Option<SwingPhase>) {
        if c.p == 0.0 && c.q == 0.0 {
            return (Zeros::NONE, None);
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
            // The amplitude part is ready long before the exponential.
            let amplitude = (c.p * d.q - c.q * d.p) / (w * r);
            let decay = (-self.a * t).exp();
            let value = sign * decay * amplitude;
            let zeros = Zeros {
                next: t,
                period,
                value,
                factor: -self.mode.half_period_decay,
            };
            let phase = SwingPhase {
                decay,
                cos: -sign * qw / r,
                sin: sign * c.p / r,
            };
            (zeros, Some(phase))
        } else {
            let t = if self.q < 0.0 {
                let w = self.mode.w;
                let r = -c.p * w / c.q;
                if !(r > 0.0 && r < 1.0) {
                    return (Zeros::NONE, None);
                }
                r.atanh() * self.mode.inv_w
            } else {
                -c.p / c.q
            };
            let zeros = if t > 64.0 * f64::EPSILON * self.time_scale() {
                Zeros {
                    next: t,
                    period: f64::INFINITY,
                    value: self.eval(d, t),
                    factor: 1.0,
                }
            } else {
                Zeros::NONE
            };
            (zeros, None)
        }
    }

    /// The extrema of the combination described by `shift` (from
    /// [`Mode::combination_shift`] of this piece's mode), in increasing
    /// local time, each with the combination's value there, given the
    /// first extremum of y after local time 0, `(time, y)`. Under-damped
    /// pieces only (`shift` exists for no other).
    pub fn combination_extrema(&self, shift: Shift, (t_turn, y_turn): (f64, f64)) -> Zeros {
        let period = self.mode.period;
        let factor = -self.mode.half_period_decay;
        // y's extrema are t_turn + jπ/w (j ≥ 0) and none before t_turn
        // in (0, ∞); the combination's come `lead` ∈ (−π/w, π/w) earlier,
        // so at most one of them, before t_turn, may also lie in (0, ∞).
        let (mut next, mut value) = (t_turn - shift.lead, shift.gain * y_turn);
        if next - period > 64.0 * f64::EPSILON * period {
            next -= period;
            value /= factor;
        }
        while next <= 64.0 * f64::EPSILON * period {
            next += period;
            value *= factor;
        }
        Zeros {
            next,
            period,
            value,
            factor,
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
        let (mut extrema, first_phase) = self.zeros_and_phase(self.v, self.y);
        // Positions are tracked as y = x − x_eq (so that small swings about
        // a distant equilibrium keep their relative precision).
        let offset = level - self.x_eq;
        let mut t0 = 0.0;
        let mut y_start = self.y.p;
        // Back through the start level after the first turn (every
        // crossing of the engine: it starts each piece at the gap), the
        // way out mirrors the way back: see `polish_half_swing`.
        let returns = offset == self.y.p;
        let mut mirror = None;
        // Velocity zeros are simple, so segments alternate direction. The
        // first one's comes from the start state, never from sampling the
        // velocity (which may underflow to 0 far into a decay).
        let mut rising = self.initially_rising();
        for _ in 0..3 {
            let t1 = extrema.next();
            if rising == upward {
                let crosses = |y: f64| if upward { y > offset } else { y < offset };
                let starts_before = if upward {
                    y_start < offset || (y_start == offset && t0 > 0.0)
                } else {
                    y_start > offset || (y_start == offset && t0 > 0.0)
                };
                if starts_before {
                    let end = match t1 {
                        Some(end) => Some(end),
                        None => self
                            .unbounded_bracket(t0, level, upward)
                            .map(|(t, x)| (t, x - self.x_eq)),
                    };
                    if let Some((t_end, y_end)) = end {
                        // Strictly past the level: touching it with zero
                        // speed at an extremum is a graze, not an impact.
                        if crosses(y_end) {
                            let between_extrema = t1.is_some() && (t0 > 0.0 || self.v0 == 0.0);
                            let (time, velocity) = self.polish(
                                (t0, y_start),
                                (t_end, y_end),
                                offset,
                                between_extrema,
                                mirror,
                            );
                            return Some(Crossing {
                                time,
                                velocity,
                                turned_at: (t0 > 0.0).then_some((t0, self.x_eq + y_start)),
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
                    // The phase known at the first extremum only.
                    mirror = (t0 == 0.0 && returns).then_some(first_phase).flatten();
                    t0 = t1;
                    y_start = y1;
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

    /// The crossing of y = `offset` in the monotone segment between `lo`
    /// and `hi` (local time, y), and the velocity there.
    ///
    /// Between two extrema of an under-damped piece the exact phase form
    /// ([`LinearPiece::polish_half_swing`]) is used. Otherwise, safeguarded
    /// Halley iteration on the closed form (the exact velocity and
    /// acceleration are the derivatives), from the `acos` start between
    /// extrema (x runs like half a cosine there) or the secant point.
    fn polish(
        &self,
        (t_lo, y_lo): (f64, f64),
        (t_hi, y_hi): (f64, f64),
        offset: f64,
        between_extrema: bool,
        mirror: Option<SwingPhase>,
    ) -> (f64, f64) {
        // Up to κ = 1 (a half swing decays by e^(−π) or less) the undamped
        // start is close; beyond, the generic iteration serves.
        if between_extrema && self.q > 0.0 && self.mode.kappa <= 1.0 {
            return self.polish_half_swing(t_lo, y_lo, offset, mirror);
        }
        let frac = (offset - y_lo) / (y_hi - y_lo);
        let start = if between_extrema {
            t_lo + (t_hi - t_lo) * (1.0 - 2.0 * frac).acos() / std::f64::consts::PI
        } else {
            t_lo + (t_hi - t_lo) * frac
        };
        let root = root::halley_bracketed(
            |t| {
                let (y, v) = self.y_and_v(t);
                (y - offset, v, self.acceleration(y, v))
            },
            (t_lo, y_lo - offset),
            (t_hi, y_hi - offset),
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

    /// The crossing of y = `offset` in the half swing from the extremum
    /// (`t_lo`, `y_lo`) of an under-damped piece to the next, and the
    /// velocity there.
    ///
    /// From an extremum the motion is exactly
    /// `y = y_lo·e^(−κθ)(cos θ + κ sin θ)` in the phase θ = w(t − t_lo) ∈
    /// [0, π], κ = a/w, so the crossing solves `H(θ) = offset/y_lo` for a
    /// decreasing H whose derivatives follow from the same three numbers
    /// e^(−κθ), cos θ and sin θ. At the undamped start (an `acos`) cos θ
    /// and sin θ are known exactly. Halley's method converges from there in
    /// two steps (for the engine's relays about 3e-2 and 4e-6 rad), so
    /// each step *advances* the three numbers by the step (addition
    /// theorems, [`SwingPhase::advance`]) instead of calling `exp` and
    /// `sin_cos` anew: per crossing, one `acos` and one `exp`. Bisection
    /// takes over if Halley leaves the bracket or stalls.
    ///
    /// Back through the level the piece started at, u = w·t_lo after it,
    /// `mirror` is the phase of that start seen from the turn, e^(−κu),
    /// cos u and sin u (known from [`LinearPiece::zeros`] at no cost). The
    /// start is then θ = −u, so the crossing solves H(θ) = H(−u): undamped,
    /// the way back takes as long as the way out, θ = u. To second order
    /// in κ (expand H in κ and θ about u) the root is
    /// `θ ≈ u + δ·(1 + κu − δ·cos u/(2 sin u))`, δ = 2κ(1 − u·cot u). Where
    /// that step from u is within [`SMALL_STEP`] it is as close as the
    /// `acos` start or closer (within 3e-2 rad for κ ≤ 1; about 1e-3 for
    /// the engine's relays), and its phase follows from the turn's by
    /// [`SwingPhase::advance`]: no `acos` and no second `exp`. Beyond (a slow
    /// start near the bottom of the swing, or heavy damping), the `acos`
    /// start serves.
    fn polish_half_swing(
        &self,
        t_lo: f64,
        y_lo: f64,
        offset: f64,
        mirror: Option<SwingPhase>,
    ) -> (f64, f64) {
        use std::f64::consts::PI;
        let Mode {
            w,
            inv_w,
            kappa,
            inv_swing,
            ..
        } = self.mode;
        let k2 = 1.0 + kappa * kappa;
        let mirrored = mirror.and_then(|turn| {
            let u = w * t_lo;
            let cot = turn.cos / turn.sin;
            let delta = 2.0 * kappa * (1.0 - u * cot);
            let step = delta * (1.0 + kappa * u - 0.5 * delta * cot);
            let theta = u + step;
            // Also refuses a NaN (sin u = 0: the start was at rest).
            (step.abs() <= SMALL_STEP && theta > 0.0 && theta < PI)
                .then(|| (theta, turn.advance(step, kappa, theta)))
        });
        let (mut theta, mut p) = mirrored.unwrap_or_else(|| {
            // The undamped start: a half cosine between the two extreme
            // values H(0) = 1 and H(π) = −e^(−κπ), where cos and sin are
            // known exactly.
            let frac = ((1.0 - offset / y_lo) * inv_swing).clamp(0.0, 1.0);
            let theta = (1.0 - 2.0 * frac).acos();
            let p = SwingPhase {
                cos: 1.0 - 2.0 * frac,
                sin: 2.0 * (frac * (1.0 - frac)).sqrt(),
                decay: (-kappa * theta).exp(),
            };
            (theta, p)
        });
        let (mut lo, mut hi) = (0.0, PI);
        // The phase w·t at the root is ~w·t_lo + θ: its ulps set the tolerance.
        let phase_ulps = |theta: f64| 4.0 * f64::EPSILON * (w * t_lo + theta);
        // The last Halley step (for the convergence rate), and the last
        // move of any kind (Halley must beat bisection, or bisect).
        let mut step_before = f64::NAN;
        let mut moved = std::f64::consts::PI;
        // The residual is y_lo·H(θ) − offset, positions rather than their
        // ratio: no division before the first step, and the same steps.
        let falling = y_lo > 0.0;
        for _ in 0..100 {
            let scale = y_lo * p.decay;
            let f = scale * (p.cos + kappa * p.sin) - offset;
            if f == 0.0 {
                break;
            }
            // H decreases: a residual of the sign of y_lo means the root
            // is ahead.
            if (f > 0.0) == falling {
                lo = theta;
            } else {
                hi = theta;
            }
            let d1 = -k2 * scale * p.sin;
            let d2 = -k2 * scale * (p.cos - kappa * p.sin);
            let step = -2.0 * f * d1 / (2.0 * d1 * d1 - f * d2);
            let next = theta + step;
            if !(next > lo && next < hi && 2.0 * step.abs() <= moved) {
                // Halley left the bracket or stalled (a root near an
                // extremum): bisect.
                moved = 0.5 * (hi - lo);
                theta = lo + moved;
                let (sin, cos) = theta.sin_cos();
                p = SwingPhase {
                    cos,
                    sin,
                    decay: (-kappa * theta).exp(),
                };
                step_before = f64::NAN;
                if hi - lo <= phase_ulps(theta) {
                    break;
                }
                continue;
            }
            // Done at a step within a few ulps, or once cubic convergence
            // predicts the next one would be: |step·(step/step_before)³|
            // within them (written without a division).
            let tol = phase_ulps(next);
            let converged = step.abs() <= tol
                || (step * step) * (step * step)
                    <= tol * (step_before * step_before * step_before).abs();
            if converged && step.abs() <= TAYLOR_STEP {
                // The velocity at θ + step from the derivatives at θ, to
                // second order: the error, O(step³), is below rounding.
                let d3 = -k2 * scale * ((kappa * kappa - 1.0) * p.sin - 2.0 * kappa * p.cos);
                let velocity = w * (d1 + step * (d2 + 0.5 * step * d3));
                return (t_lo + next * inv_w, velocity);
            }
            p = p.advance(step, kappa, next);
            theta = next;
            if converged {
                break;
            }
            moved = step.abs();
            step_before = step;
        }
        let velocity = y_lo * w * (-k2 * p.decay * p.sin);
        (t_lo + theta * inv_w, velocity)
    }
}

/// e^(−κθ), cos θ and sin θ at one phase θ of a half swing.
#[derive(Debug, Clone, Copy)]
struct SwingPhase {
    decay: f64,
    cos: f64,
    sin: f64,
}

impl SwingPhase {
    /// The same at θ + `step` (= `theta_new`), by addition theorems with
    /// short series where the step is small enough for them to be exact
    /// to rounding (the first omitted terms are below 1e-17 relative):
    /// far cheaper than `sin_cos` and `exp`, which serve larger steps.
    #[inline(always)]
    fn advance(self, step: f64, kappa: f64, theta_new: f64) -> SwingPhase {
        let x = -kappa * step;
        if step.abs() <= TINY_STEP && x.abs() <= TINY_STEP {
            // A converging Halley step: to δ⁵, δ⁴ and x⁵ (the first
            // omitted terms are below 5e-18).
            let d2 = step * step;
            let sin = step + (step * d2) * (-1.0 / 6.0 + d2 * (1.0 / 120.0));
            let cos_m1 = d2 * (-0.5 + d2 * (1.0 / 24.0));
            let x2 = x * x;
            let exp_m1 =
                x * ((1.0 + 0.5 * x) + x2 * ((1.0 / 6.0 + x * (1.0 / 24.0)) + x2 * (1.0 / 120.0)));
            return SwingPhase {
                decay: self.decay + self.decay * exp_m1,
                cos: self.cos + (self.cos * cos_m1 - self.sin * sin),
                sin: self.sin + (self.sin * cos_m1 + self.cos * sin),
            };
        }
        let decay = if x.abs() <= SMALL_DECAY {
            // eˣ − 1 to x⁷, grouped (Estrin) to shorten the dependency
            // chain.
            let x2 = x * x;
            let high = (1.0 / 6.0 + x * (1.0 / 24.0))
                + x2 * ((1.0 / 120.0 + x * (1.0 / 720.0)) + x2 * (1.0 / 5040.0));
            let exp_m1 = x * ((1.0 + 0.5 * x) + x2 * high);
            self.decay + self.decay * exp_m1
        } else {
            (-kappa * theta_new).exp()
        };
        if step.abs() > SMALL_STEP {
            let (sin, cos) = theta_new.sin_cos();
            return SwingPhase { decay, cos, sin };
        }
        // sin δ and cos δ − 1 to δ¹¹ and δ¹² as polynomials in δ², grouped
        // (Estrin) to shorten the dependency chain; the reciprocal
        // factorials are constants, so no divisions.
        let d2 = step * step;
        let d4 = d2 * d2;
        let sin_high = (-1.0 / 6.0 + d2 * (1.0 / 120.0))
            + d4 * ((-1.0 / 5040.0 + d2 * (1.0 / 362880.0)) + d4 * (-1.0 / 39916800.0));
        let sin = step + (step * d2) * sin_high;
        let cos_m1 = d2
            * ((-0.5 + d2 * (1.0 / 24.0))
                + d4 * ((-1.0 / 720.0 + d2 * (1.0 / 40320.0))
                    + d4 * (-1.0 / 3628800.0 + d2 * (1.0 / 479001600.0))));
        SwingPhase {
            decay,
            cos: self.cos + (self.cos * cos_m1 - self.sin * sin),
            sin: self.sin + (self.sin * cos_m1 + self.cos * sin),
        }
    }
}

/// The largest final step (radians) from whose start the velocity is
/// extrapolated (to second order: 2⁻¹⁷ cubed is 5e-16).
const TAYLOR_STEP: f64 = 1.0 / 131072.0;

/// The largest step (radians) and change of the decay exponent that
/// [`SwingPhase::advance`] takes by series: Halley's steps, and the step from a
/// turn to the mirrored start ([`LinearPiece::polish_half_swing`]).
const SMALL_STEP: f64 = 1.0 / 4.0;
const TINY_STEP: f64 = 1.0 / 256.0;
const SMALL_DECAY: f64 = 1.0 / 64.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// Under-damped modes (w = 1, x_eq = 0 so that x is y with no
    /// rounding from an offset) from undamped to strongly decaying per
    /// radian: κ = a/w = 0 … 3.5 (the phase form serves κ ≤ 1).
    fn modes() -> Vec<Mode> {
        [0.0, 0.01, 0.1, 0.5, 1.0, 2.0, 3.5]
            .iter()
            .map(|&kappa| Mode::new(1.0, 2.0 * kappa, 1.0 + kappa * kappa, 0.0))
            .collect()
    }

    #[test]
    fn half_swing_crossings_match_bisection_on_the_closed_form() {
        for mode in modes() {
            // Each starts rising, so the downward crossing is in the swing
            // from the first maximum to the next minimum.
            for &(x0, v0) in &[(-1.0, 0.0), (0.5, 0.5), (-0.5, 0.01), (-0.2, 3.0)] {
                let piece = LinearPiece::start(&mode, x0, v0);
                let Some((t_max, x_max)) = piece.first_extremum(true) else {
                    continue;
                };
                let Some((t_min, x_min)) = piece
                    .zeros(piece.v_combo(), piece.y_combo())
                    .find(|&(t, _)| t > t_max)
                    .map(|(t, y)| (t, mode.x_eq + y))
                else {
                    continue;
                };
                for k in 1..20 {
                    let level = x_max + (x_min - x_max) * k as f64 / 20.0;
                    let c = piece.crossing(level, false).expect("crosses");
                    // Independent: bisection on x(t) − level in the swing.
                    let (mut lo, mut hi) = (t_max, t_min);
                    for _ in 0..200 {
                        let mid = 0.5 * (lo + hi);
                        if piece.state(mid).0 > level {
                            lo = mid
                        } else {
                            hi = mid
                        }
                    }
                    let ctx = format!("{mode:?} x0={x0} v0={v0} k={k}");
                    assert!(
                        (c.time - lo).abs() <= 1e-13 * lo,
                        "{ctx}: {} vs {lo}",
                        c.time
                    );
                    let v = piece.state(c.time).1;
                    assert!((c.velocity - v).abs() <= 1e-12 * v.abs(), "{ctx}");
                }
            }
        }
    }

    #[test]
    fn phase_advance_by_series_is_exact_to_rounding() {
        for kappa in [0.0f64, 0.05, 1.0, 3.0] {
            let theta: f64 = 0.7;
            let (sin, cos) = theta.sin_cos();
            let p = SwingPhase {
                decay: (-kappa * theta).exp(),
                cos,
                sin,
            };
            for step in [1e-7, -3e-4, 0.01, -0.03, 0.0625] {
                let q = p.advance(step, kappa, theta + step);
                let (sin, cos) = (theta + step).sin_cos();
                let decay = (-kappa * (theta + step)).exp();
                assert!((q.sin - sin).abs() < 4e-16, "{kappa} {step}");
                assert!((q.cos - cos).abs() < 4e-16, "{kappa} {step}");
                assert!((q.decay - decay).abs() < 4e-16 * decay, "{kappa} {step}");
            }
        }
    }

    #[test]
    fn phase_advance_by_long_series_is_exact_to_rounding() {
        // The mirrored start's step, up to SMALL_STEP, and decay changes up
        // to SMALL_DECAY.
        for kappa in [0.0f64, 0.01, 1.0 / 16.0] {
            for theta in [0.1f64, 1.3, 2.9] {
                let (sin, cos) = theta.sin_cos();
                let p = SwingPhase {
                    decay: (-kappa * theta).exp(),
                    cos,
                    sin,
                };
                for step in [0.07, -0.1, 0.18, 0.25, -0.25] {
                    let q = p.advance(step, kappa, theta + step);
                    let (sin, cos) = (theta + step).sin_cos();
                    let decay = (-kappa * (theta + step)).exp();
                    let ctx = format!("κ={kappa} θ={theta} step={step}");
                    assert!((q.sin - sin).abs() < 4e-16, "{ctx}");
                    assert!((q.cos - cos).abs() < 4e-16, "{ctx}");
                    assert!((q.decay - decay).abs() < 4e-16 * decay, "{ctx}");
                }
            }
        }
    }

    #[test]
    fn crossings_back_through_the_start_level_match_bisection() {
        // The engine's case: each piece starts at the level it next
        // crosses, so the mirrored start serves (or, far from the turn,
        // the `acos` one).
        let mut modes = modes();
        modes.extend(
            [1e-3, 0.03, 0.0517, 0.2]
                .iter()
                .map(|&kappa| Mode::new(1.0, 2.0 * kappa, 1.0 + kappa * kappa, 0.0)),
        );
        for mode in modes {
            for &(x0, v0) in &[
                (-0.1, 0.8),
                (-0.1, -0.8),
                (-0.9, 0.05),
                (-0.5, 1e-3),
                (0.3, -2.0),
                (0.3, 0.01),
                (-1e-3, 1.0),
            ] {
                let piece = LinearPiece::start(&mode, x0, v0);
                let upward = v0 < 0.0;
                let mut turns = piece.zeros(piece.v_combo(), piece.y_combo());
                let (Some((t1, y1)), Some((t2, _))) = (turns.next(), turns.next()) else {
                    continue;
                };
                let ctx = format!("{mode:?} x0={x0} v0={v0}");
                let Some(c) = piece.crossing(x0, upward) else {
                    // No return: the second turn falls short of x0.
                    let x2 = piece.state(t2).0;
                    assert!(if upward { x2 <= x0 } else { x2 >= x0 }, "{ctx}");
                    continue;
                };
                // Independent: bisection on x(t) − x0 between the turns.
                let (mut lo, mut hi) = (t1, t2);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if (piece.state(mid).0 < x0) == upward {
                        lo = mid
                    } else {
                        hi = mid
                    }
                }
                // A slow crossing is ill-conditioned: positions carry
                // rounding of a few ulps of the swing, so the time does so
                // divided by the speed.
                let v = piece.state(c.time).1;
                let conditioning = 8.0 * f64::EPSILON * y1.abs().max(x0.abs()) / v.abs();
                assert!(
                    (c.time - lo).abs() <= 1e-13 * lo + conditioning,
                    "{ctx}: {} vs {lo}",
                    c.time
                );
                assert!((c.velocity - v).abs() <= 1e-12 * v.abs(), "{ctx}");
            }
        }
    }

    #[test]
    fn combination_extrema_are_the_zeros_of_its_rate() {
        for mode in modes() {
            let piece = LinearPiece::start(&mode, 0.9, 0.8);
            let turn = piece
                .zeros(piece.v_combo(), piece.y_combo())
                .next()
                .unwrap();
            for (alpha, beta) in [(1.0, 0.0), (100.0, 0.9), (3.0, -2.0), (0.0, 1.0)] {
                let shift = mode.combination_shift(alpha, beta).unwrap();
                // The rate of α·y + β·ẏ is α·ẏ + β·ÿ = −β ωn² y + (α − 2aβ) ẏ.
                let rate = piece.combo(-beta * mode.omega2, alpha - 2.0 * mode.a * beta);
                let expected = piece.zeros(rate, piece.combo(alpha, beta));
                let got = piece.combination_extrema(shift, turn);
                for ((t1, f1), (t2, f2)) in got.zip(expected).take(4) {
                    let ctx = format!("{mode:?} α={alpha} β={beta}");
                    assert!(
                        (t1 - t2).abs() <= 1e-13 * t2.max(1.0),
                        "{ctx}: {t1} vs {t2}"
                    );
                    assert!((f1 - f2).abs() <= 1e-12 * f2.abs(), "{ctx}: {f1} vs {f2}");
                }
            }
        }
    }
}
