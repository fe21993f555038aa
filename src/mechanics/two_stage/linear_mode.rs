//! One linear mode of the two-stage relay and its exact solution: the
//! mode's scaled matrix, equilibrium, Taylor series and step propagator
//! ([`LinearMode`]), and linear functions of the state along the motion
//! ([`Series`]) as scalar polynomials in τ ([`Poly`]) whose roots and
//! extrema locate events.

use crate::mechanics::linalg::{Matrix4, Vector4};

use super::model::Y;

/// The scaled deviation from a mode's equilibrium.
pub(crate) type W = Vector4<f64>;

/// One linear mode: its scaled matrix, equilibrium and step propagator.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LinearMode {
    pub(super) a: Matrix4<f64>,
    /// `(u_a, v_a, u_b, v_b)` at equilibrium.
    pub(super) eq: Vector4<f64>,
    /// The scales of `(u_a, v_a, u_b, v_b)`: `y − eq = D w`, `D = diag(d)`.
    pub(super) d: [f64; 4],
    /// `exp(a h)`.
    pub(super) phi: Matrix4<f64>,
    /// `a^k / k!`, the Taylor series' matrices.
    pub(super) powers: Box<[Matrix4<f64>; TERMS]>,
    /// s
    pub(super) h: f64,
}

impl LinearMode {
    /// The mode of scaled matrix `a`, equilibrium `eq`, scales `d` and
    /// step `h` (`‖a h‖∞ ≤` [`STEP_NORM`]).
    #[inline(always)]
    pub(super) fn new(a: Matrix4<f64>, eq: Vector4<f64>, d: [f64; 4], h: f64) -> LinearMode {
        let mut powers = Box::new([Matrix4::identity(); TERMS]);
        for k in 1..TERMS {
            powers[k] = a * powers[k - 1] * RECIPROCALS[k];
        }
        let mut mode = LinearMode {
            a,
            eq,
            d,
            phi: Matrix4::identity(),
            powers,
            h,
        };
        mode.phi = mode.propagator(h);
        mode
    }

    /// `exp(a τ)` for τ within a step, by Horner's rule on the series.
    #[inline(always)]
    fn propagator(&self, tau: f64) -> Matrix4<f64> {
        let mut m = self.powers[TERMS - 1];
        for power in self.powers[..TERMS - 1].iter().rev() {
            m.scale_add(tau, power);
        }
        m
    }

    /// `w(τ)` from `w0` (τ within a step), by the Taylor series.
    #[inline(always)]
    pub(crate) fn at(&self, w0: &W, tau: f64) -> W {
        self.propagator(tau) * w0
    }

    /// The state of `w`.
    #[inline(always)]
    pub(crate) fn y_of(&self, w: &W) -> Y {
        let d = &self.d;
        Y::new(
            self.eq[0] + d[0] * w[0],
            self.eq[1] + d[1] * w[1],
            self.eq[2] + d[2] * w[2],
            self.eq[3] + d[3] * w[3],
            0.0,
        )
    }

    /// The scaled deviation of state `y`.
    #[inline(always)]
    pub(crate) fn w_of(&self, y: &Y) -> W {
        let d = &self.d;
        W::new(
            (y[0] - self.eq[0]) / d[0],
            (y[1] - self.eq[1]) / d[1],
            (y[2] - self.eq[2]) / d[2],
            (y[3] - self.eq[3]) / d[3],
        )
    }
}

/// The step's size in the mode's own time: `‖a h‖∞`. Under π, so that a
/// step is under half the fastest period (the spectral radius is at most
/// the norm), and at most 3, where the series' [`TERMS`] leave out less
/// than the arithmetic's rounding.
pub(super) const STEP_NORM: f64 = 3.0;

/// Terms of the Taylor series kept per step (a multiple of 4, for
/// [`evaluate`]): with `‖a h‖ ≤ 3` the first one left out is below 1e-16
/// of the first (3²⁸/28! ≈ 7.5e-17; 4.6e-19 at 2.5).
pub(super) const TERMS: usize = 28;

/// A linear function of the state, `c·y + d`, along the motion of one
/// mode: with `w = D⁻¹ (y − eq)` it is `k + q·w`, and from `w0` it is the
/// polynomial `k + Σ (r_k·w0) τ^k` with `r_k = (aᵀ)^k q / k!`. Built once
/// per form and mode, it gives a step's polynomial for 28 dot products,
/// and the form's value and rate at any state as `k + r_0·w` and `r_1·w`.
#[derive(Debug, Clone)]
pub(super) struct Series {
    c: [f64; 4],
    d: f64,
    pub(super) k: f64,
    pub(super) r: [W; TERMS],
    /// The same rows kept by column, so that a step's polynomial,
    /// `r_k·w0` for every k, is had four terms at a time, each dot
    /// product in [`W::dot`]'s order.
    r_columns: [[f64; TERMS]; 4],
    /// `Σ_{k≥1} ‖r_k‖₁ h^k` over the mode's step: the form moves less
    /// than this times `‖w0‖∞` within a step from `w0`.
    pub(super) spread: f64,
    /// `Σ_{k≥LOW_TERMS} ‖r_k‖₁ h^k`: the series past its first
    /// [`LOW_TERMS`] terms is smaller than this times `‖w0‖∞` over a step.
    pub(super) tail: f64,
    /// `Σ_{k≥LOW_TERMS} k ‖r_k‖₁ h^k`: the same for its rate in the step's
    /// own time `s = τ/h`.
    rate_tail: f64,
    /// The Bernstein coefficients (degree `LOW_TERMS − 1`, over the mode's
    /// full step) of the series' first [`LOW_TERMS`] terms, as rows to dot
    /// with `w0`: `b_j = k + Σ_i bern[i][j] w0_i`. Kept by column, so that
    /// the thirteen coefficients of a step are had in four vector
    /// products, and padded to a multiple of four with the last one repeated
    /// (the test is of every coefficient, so a repeated one changes
    /// nothing), so that they go four at a time.
    pub(super) bern: [[f64; LOW_PADDED]; 4],
    /// `max_j ‖bern_j‖₁`, for the rounding of `bern_j·w0`.
    pub(super) bern_norm: f64,
    /// The same for `(f(s) − f(0))/s`, the sign of a form that starts a
    /// step on its zero (the event that began the mode): the Bernstein
    /// coefficients of its first `LOW_TERMS − 1` terms.
    pub(super) bern_after_zero: [W; LOW_TERMS - 1],
    /// The Bernstein coefficients of the whole series (degree
    /// `TERMS − 1`, over the mode's full step) as rows to dot with `w0`,
    /// kept by column as [`Series::bern`] is: `b_j = k + full_j·w0`, the
    /// same polynomial the locator converts.
    full: Box<[[f64; TERMS]; 4]>,
    /// `Σ_k ‖r_k‖₁ h^k`, the full rows' magnitude before their terms
    /// cancel, for the rounding of `full_j·w0`.
    magnitude: f64,
    /// The rate's Bernstein rows (degree `TERMS − 2`, in the step's own
    /// time), `n (full_{j+1} − full_j)`, kept by column as [`Series::bern`]
    /// is.
    rate_rows: Box<[[f64; TERMS - 1]; 4]>,
}

/// A form over a whole step of its mode from one state: the Bernstein
/// coefficients of its series' first [`LOW_TERMS`] terms, and bounds on
/// what they leave out, of the form and of its rate. Over the mode's full
/// step, so what they show holds for a shorter last step too. Its tests
/// are of every coefficient, without a branch per coefficient, so that
/// they go four at a time.
#[derive(Debug, Clone, Copy)]
pub(super) struct StepBernstein {
    /// Padded to [`LOW_PADDED`] with the last one repeated.
    b: [f64; LOW_PADDED],
    /// The form is within this of the coefficients' polynomial.
    margin: f64,
    /// Its rate in the step's own time is within this of theirs.
    rate_margin: f64,
}

impl StepBernstein {
    /// Whether the form, negated when `negated`, is positive over the
    /// step: every coefficient exceeds the margin (a NaN does not).
    #[inline(always)]
    fn positive(&self, negated: bool) -> bool {
        if negated {
            self.every(|b| -b > self.margin)
        } else {
            self.every(|b| b > self.margin)
        }
    }

    /// Whether `ok` holds of every coefficient (padding included).
    #[inline(always)]
    fn every(&self, ok: impl Fn(f64) -> bool) -> bool {
        let mut clear = true;
        for b in self.b {
            clear &= ok(b);
        }
        clear
    }

    /// Whether `ok` holds of the least value the form can take over the
    /// step (its least coefficient less the margin): `ok` must be
    /// monotone, so that it is asked of every coefficient less the margin
    /// instead, which rounds the same way.
    #[inline(always)]
    pub(super) fn least_is(&self, ok: impl Fn(f64) -> bool) -> bool {
        self.every(|b| ok(b - self.margin))
    }

    /// The same of the largest value (its largest coefficient plus the
    /// margin).
    #[inline(always)]
    pub(super) fn largest_is(&self, ok: impl Fn(f64) -> bool) -> bool {
        self.every(|b| ok(b + self.margin))
    }

    /// Whether the form is shown monotone over the step: every
    /// coefficient of its rate, `n (b_{j+1} − b_j)`, clear of the rate's
    /// margin and of one sign.
    #[inline(always)]
    pub(super) fn monotone(&self) -> bool {
        let n = (LOW_TERMS - 1) as f64;
        let (ahead, behind) = (&self.b[1..LOW_TERMS], &self.b[..LOW_TERMS - 1]);
        let (mut rising, mut falling) = (true, true);
        for (next, b) in ahead.iter().zip(behind) {
            let d = n * (next - b);
            rising &= d > self.rate_margin;
            falling &= d < -self.rate_margin;
        }
        rising || falling
    }
}

/// A form's rate over a whole step of its mode, exactly: Bernstein
/// coefficients of degree `TERMS − 2` in the step's own time, and their
/// rounding.
#[derive(Debug, Clone, Copy)]
pub(super) struct RateBernstein {
    d: [f64; TERMS - 1],
    noise: f64,
}

impl RateBernstein {
    /// The sign changes of the coefficients when every one is clear of
    /// its rounding: the rate's zeros over the step, or more by an even
    /// number (Descartes' rule of signs). `None` when one is not clear.
    #[inline(always)]
    pub(super) fn turns(&self) -> Option<usize> {
        // Every coefficient asked, without a branch per coefficient, so
        // that they go four at a time.
        let mut unclear = false;
        let mut count = 0;
        for j in 0..TERMS - 2 {
            // Within the rounding, or a NaN: not clear.
            let clear = self.d[j].abs() > self.noise;
            unclear |= !clear;
            count += usize::from((self.d[j] > 0.0) != (self.d[j + 1] > 0.0));
        }
        let clear = self.d[TERMS - 2].abs() > self.noise;
        unclear |= !clear;
        (!unclear).then_some(count)
    }

    /// Intervals of the full step (in its own time, `[0, 1]`) outside
    /// which the rate keeps one sign: each holds one zero (its
    /// coefficients there change sign once, its ends clear and of
    /// opposite signs) or is no wider than 1/1024 of the step. The
    /// coefficients are split in halves (de Casteljau) until they tell
    /// ([`crate::mechanics::locate::sign_changes_of_coefficients`]).
    /// At most `N`, the earliest; `None` when there were more.
    pub(super) fn zeros<const N: usize>(&self) -> Option<([(f64, f64); N], usize)> {
        // A rate on its zero at an end of the step (from rest, or a turn
        // that ends the step): that end's value is taken in already, and
        // the rate's other zeros are those of the rate divided by `s` (or
        // by `1 − s`), as often as it vanishes there. Their coefficients
        // are the rest scaled, `d_{j+1} n/(j + 1)` (or `d_j n/(n − j)`),
        // n the degree: searched instead, so that the search does not
        // split down to the end's zero.
        let mut d = [0.0; TERMS];
        d[..TERMS - 1].copy_from_slice(&self.d);
        let mut m = TERMS - 1;
        let noise = self.noise;
        while m > 1 && d[0].abs() <= noise {
            let n = (m - 1) as f64;
            for j in 0..m - 1 {
                d[j] = d[j + 1] * n / (j + 1) as f64;
            }
            m -= 1;
        }
        while m > 1 && d[m - 1].abs() <= noise {
            let n = (m - 1) as f64;
            for (j, c) in d.iter_mut().enumerate().take(m - 1) {
                *c *= n / (n - j as f64);
            }
            m -= 1;
        }
        // A rate within its rounding everywhere: the form is constant
        // over the step, its ends taken in already.
        if m == 1 && d[0].abs() <= noise {
            return Some(([(0.0, 0.0); N], 0));
        }
        crate::mechanics::locate::sign_changes_of_coefficients(&d[..m], noise, 1.0 / 1024.0)
    }
}

/// Terms of a form's series in its cheap sign test: the polynomial of
/// this many terms in Bernstein form, plus a bound on the rest (about
/// 3e-4 of the form's swing over a step at `‖a h‖ = 3`, 3e-5 at 2.5:
/// fewer terms cost more in false alarms than they save, 11 by 7 % and 9
/// by 54 % on the bench relay).
pub(super) const LOW_TERMS: usize = 13;

/// [`LOW_TERMS`] rounded up to an even number.
const LOW_PADDED: usize = LOW_TERMS.next_multiple_of(4);

impl Series {
    /// The form `c·y + d` along mode `mode`, with every row its steps
    /// read (built with the mode, once a run: always inlined, so that it
    /// takes the instruction set of the steps that build it).
    #[inline(always)]
    pub(super) fn new(mode: &LinearMode, c: [f64; 4], d: f64) -> Series {
        let eq = &mode.eq;
        let k = c[0] * eq[0] + c[1] * eq[1] + c[2] * eq[2] + c[3] * eq[3] + d;
        let q = W::from_fn(|i, _| c[i] * mode.d[i]);
        let r: [W; TERMS] = std::array::from_fn(|k| mode.powers[k].tr_mul(&q));
        // The terms over the mode's full step, `r_k h^k`.
        let mut scaled = [W::zeros(); TERMS];
        let mut hk = 1.0;
        for (k, (s, rk)) in scaled.iter_mut().zip(&r).enumerate() {
            if k > 0 {
                hk *= mode.h;
            }
            *s = rk * hk;
        }
        let norms = scaled.map(|s| s.abs().sum());
        let spread: f64 = norms[1..].iter().sum();
        let tail: f64 = norms[LOW_TERMS..].iter().sum();
        let rate_tail: f64 = (LOW_TERMS..TERMS).map(|k| k as f64 * norms[k]).sum();
        let rows = bernstein_rows(&scaled[..LOW_TERMS], &LOW_WEIGHTS);
        let bern_norm = rows.iter().map(|b| b.abs().sum()).fold(0.0, f64::max);
        let bern = std::array::from_fn(|i| std::array::from_fn(|j| rows[j.min(LOW_TERMS - 1)][i]));
        // (f − f(0))/s = Σ_{k≥1} a_k s^{k−1}: degree LOW_TERMS − 2.
        let bern_after_zero = bernstein_rows(&scaled[1..LOW_TERMS], &AFTER_ZERO_WEIGHTS);
        // The whole series' rows, `b_j = Σ_{k ≤ j} C(j, k)/C(n, k) r_k h^k`
        // (n = `TERMS − 1`), and its rate's, `n (b_{j+1} − b_j)`.
        let mut magnitude = 0.0;
        for norm in norms {
            magnitude += norm;
        }
        let rows = bernstein_rows(&scaled, &FULL_WEIGHTS);
        let full: Box<[[f64; TERMS]; 4]> =
            Box::new(std::array::from_fn(|i| std::array::from_fn(|j| rows[j][i])));
        let n = (TERMS - 1) as f64;
        let rate_rows = Box::new(std::array::from_fn(|i| {
            std::array::from_fn(|j| n * (full[i][j + 1] - full[i][j]))
        }));
        let r_columns = std::array::from_fn(|i| std::array::from_fn(|k| r[k][i]));
        Series {
            c,
            d,
            k,
            r,
            r_columns,
            spread,
            tail,
            rate_tail,
            bern,
            bern_norm,
            bern_after_zero,
            full,
            magnitude,
            rate_rows,
        }
    }

    /// The rate (in the step's own time `s = τ/h`) of the form over a
    /// whole step of the mode from `w0`, exactly: the differences of the
    /// whole series' Bernstein coefficients, `n (b_{j+1} − b_j)`.
    #[inline(always)]
    pub(super) fn rate_bernstein(&self, w0: &W) -> RateBernstein {
        RateBernstein {
            d: rows_at(0.0, &self.rate_rows, w0),
            noise: 2.0 * (TERMS - 1) as f64 * 256.0 * f64::EPSILON * self.magnitude * w0.amax(),
        }
    }

    /// Whether the form, negated when `negated`, has exactly one zero over
    /// a whole step of the mode from `w0`, with nothing before it to find:
    /// its Bernstein coefficients, every one clear of its rounding, are
    /// positive at the start, negative at the end and change sign once
    /// (Descartes' rule of signs in that basis). This is the locator's
    /// first test on a step ([`crate::mechanics::locate::first_zero`]
    /// returns the whole step then), for 28 dot products instead of a
    /// conversion to the Bernstein form; anything less clear goes to the
    /// locator.
    #[inline(always)]
    pub(super) fn isolated_over_step(&self, w0: &W, negated: bool) -> bool {
        let sign = if negated { -1.0 } else { 1.0 };
        let noise = 256.0 * f64::EPSILON * (self.k.abs() + self.magnitude * w0.amax());
        // Every coefficient asked, without a branch per coefficient, so
        // that they go four at a time.
        let b = rows_at(self.k, &self.full, w0).map(|b| sign * b);
        let mut unclear = false;
        // The count starts from a positive value before the first.
        let first_positive = b[0] > 0.0;
        let mut changes = usize::from(!first_positive);
        unclear |= b[0].abs() <= noise;
        for j in 1..TERMS {
            unclear |= b[j].abs() <= noise;
            changes += usize::from((b[j] > 0.0) != (b[j - 1] > 0.0));
        }
        !unclear && changes == 1 && b[TERMS - 1] < 0.0
    }

    /// Whether the form, negated when `negated`, is shown positive over a
    /// step of the mode from `w0`, where its value (negated likewise) is
    /// `value`, with no polynomial built: far from its zero by its spread
    /// alone; starting on its zero, within the rounding the locator
    /// allows, by [`Series::positive_after_zero`]; else by
    /// [`Series::positive_over_step`].
    /// The coefficients, once computed for the step, are kept in `kept`.
    #[inline(always)]
    pub(super) fn shown_positive(
        &self,
        value: f64,
        w0: &W,
        negated: bool,
        kept: &mut Option<StepBernstein>,
    ) -> bool {
        let scale = w0.amax();
        if value > self.spread * scale * (1.0 + 1e-12) + 1e-300 {
            return true;
        }
        let rounding = self.rounding(scale);
        if value.abs() <= rounding {
            self.positive_after_zero(w0, scale, negated)
        } else {
            // Not `get_or_insert_with`: its closure would be compiled
            // apart, outside the wide steps.
            if kept.is_none() {
                *kept = Some(self.bernstein_at(w0, scale, rounding));
            }
            kept.as_ref().is_some_and(|b| b.positive(negated))
        }
    }

    /// The rounding of a Bernstein coefficient `k + bern_j·w0`
    /// (`‖w0‖∞ = scale`).
    #[inline(always)]
    fn rounding(&self, scale: f64) -> f64 {
        64.0 * f64::EPSILON * (self.k.abs() + self.bern_norm * scale)
    }

    /// The form's Bernstein coefficients over a whole step of the mode
    /// from `w0`, with the bounds on what they leave out.
    #[inline(always)]
    pub(super) fn step_bernstein(&self, w0: &W) -> StepBernstein {
        let scale = w0.amax();
        self.bernstein_at(w0, scale, self.rounding(scale))
    }

    /// [`Series::step_bernstein`] with `‖w0‖∞` and the coefficients'
    /// rounding known.
    #[inline(always)]
    fn bernstein_at(&self, w0: &W, scale: f64, rounding: f64) -> StepBernstein {
        StepBernstein {
            b: rows_at(self.k, &self.bern, w0),
            margin: self.tail * scale * (1.0 + 1e-9) + rounding,
            rate_margin: self.rate_tail * scale * (1.0 + 1e-9)
                + 2.0 * (LOW_TERMS - 1) as f64 * rounding,
        }
    }

    /// Whether the form, negated when `negated`, starts on its zero and
    /// is positive over the rest of a step from `w0` (`‖w0‖∞ = scale`):
    /// `(f(s) − f(0))/s` shown positive as [`Series::positive_over_step`]
    /// shows `f`.
    #[inline(always)]
    fn positive_after_zero(&self, w0: &W, scale: f64, negated: bool) -> bool {
        let sign = if negated { -1.0 } else { 1.0 };
        let margin =
            self.tail * scale * (1.0 + 1e-9) + 64.0 * f64::EPSILON * self.bern_norm * scale;
        self.bern_after_zero
            .iter()
            .all(|b| sign * b.dot(w0) > margin)
    }

    /// The form along the motion from `w0` (the state `y0`), as a
    /// polynomial in τ. Its value at τ = 0 is taken from `y0` itself, so
    /// that a state set exactly on a surface starts exactly on its zero,
    /// whatever the rounding of the scaled deviation.
    #[inline(always)]
    pub(super) fn poly(&self, w0: &W, y0: &Y) -> Poly {
        // `r_k·w0` as `W::dot` sums it, `(a₀b₀ + a₂b₂) + (a₁b₁ + a₃b₃)`.
        let [c0, c1, c2, c3] = &self.r_columns;
        let (w0, w1, w2, w3) = (w0[0], w0[1], w0[2], w0[3]);
        let mut p = [0.0; TERMS];
        for k in 0..TERMS {
            p[k] = (c0[k] * w0 + c2[k] * w2) + (c1[k] * w1 + c3[k] * w3);
        }
        let c = &self.c;
        p[0] = c[0] * y0[0] + c[1] * y0[1] + c[2] * y0[2] + c[3] * y0[3] + self.d;
        Poly { p }
    }
}

/// `C(j, k)/C(n, k)` at `[j][k]` (`k ≤ j ≤ n = N − 1`, else 0): the
/// weight of a polynomial's coefficient `k` (in the power basis on
/// `[0, 1]`) in its Bernstein coefficient `j` of degree `n`. A table, so
/// that a form's rows cost multiplications only.
const fn bernstein_weights<const N: usize>() -> [[f64; N]; N] {
    // C(i, k) for i ≤ n, exact in f64 for n < 60.
    let mut binomial = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        binomial[i][0] = 1.0;
        let mut k = 1;
        while k <= i {
            binomial[i][k] = binomial[i - 1][k - 1] + binomial[i - 1][k];
            k += 1;
        }
        i += 1;
    }
    let mut w = [[0.0; N]; N];
    let mut j = 0;
    while j < N {
        let mut k = 0;
        while k <= j {
            w[j][k] = binomial[j][k] / binomial[N - 1][k];
            k += 1;
        }
        j += 1;
    }
    w
}

const LOW_WEIGHTS: [[f64; LOW_TERMS]; LOW_TERMS] = bernstein_weights();
const AFTER_ZERO_WEIGHTS: [[f64; LOW_TERMS - 1]; LOW_TERMS - 1] = bernstein_weights();
const FULL_WEIGHTS: [[f64; TERMS]; TERMS] = bernstein_weights();

/// The Bernstein rows of degree `N − 1` of the terms `scaled` (each the
/// row of a power-basis coefficient on `[0, 1]`, dotted with `w0`):
/// `b_j = Σ_{k ≤ j} C(j, k)/C(n, k) scaled_k`.
#[inline(always)]
fn bernstein_rows<const N: usize>(scaled: &[W], weights: &[[f64; N]; N]) -> [W; N] {
    std::array::from_fn(|j| {
        let mut b = W::zeros();
        for (s, &w) in scaled[..=j].iter().zip(&weights[j][..=j]) {
            b += s * w;
        }
        b
    })
}

/// The coefficients `k + Σ_i rows[i][j] w0_i` of Bernstein rows kept by
/// column.
#[inline(always)]
fn rows_at<const N: usize>(k: f64, rows: &[[f64; N]; 4], w0: &W) -> [f64; N] {
    let [c0, c1, c2, c3] = rows;
    let (w0, w1, w2, w3) = (w0[0], w0[1], w0[2], w0[3]);
    let mut b = [0.0; N];
    for j in 0..N {
        b[j] = k + (((c0[j] * w0 + c1[j] * w1) + c2[j] * w2) + c3[j] * w3);
    }
    b
}

/// `1/k` for the series' terms.
const RECIPROCALS: [f64; TERMS] = {
    let mut r = [0.0; TERMS];
    let mut k = 1;
    while k < TERMS {
        r[k] = 1.0 / k as f64;
        k += 1;
    }
    r
};

/// The last Newton step of a root, relative to the bracket's end: the
/// error left after it is of the order of its square (to rounding).
const ROOT_TOLERANCE: f64 = 1e-9;

/// The last Newton step of an extremum, relative to the step: the error
/// left is of the order of 1e-12 of the step.
const EXTREMUM_TOLERANCE: f64 = 1e-6;

/// A scalar polynomial in τ.
#[derive(Clone, Copy)]
pub(super) struct Poly {
    pub(super) p: [f64; TERMS],
}

/// `Σ p_k τ^k` by Horner's rule in τ⁴ on the four residues of `k` mod 4,
/// four chains at once (their latency, not their arithmetic, bounds it).
#[inline(always)]
fn evaluate(p: &[f64; TERMS], tau: f64) -> f64 {
    if tau == 0.0 {
        return p[0];
    }
    let t2 = tau * tau;
    let t4 = t2 * t2;
    let mut c = [p[TERMS - 4], p[TERMS - 3], p[TERMS - 2], p[TERMS - 1]];
    for k in (0..TERMS / 4 - 1).rev() {
        for (j, c) in c.iter_mut().enumerate() {
            *c = *c * t4 + p[4 * k + j];
        }
    }
    (c[0] + tau * c[1]) + t2 * (c[2] + tau * c[3])
}

/// `p` at `s` and `q` at `t`, as [`evaluate`] does each, in one pass of
/// eight chains.
#[inline(always)]
fn evaluate_pair(p: &[f64; TERMS], s: f64, q: &[f64; TERMS], t: f64) -> (f64, f64) {
    let (s2, t2) = (s * s, t * t);
    let (s4, t4) = (s2 * s2, t2 * t2);
    let top = TERMS - 4;
    let mut a = [p[top], p[top + 1], p[top + 2], p[top + 3]];
    let mut b = [q[top], q[top + 1], q[top + 2], q[top + 3]];
    for k in (0..TERMS / 4 - 1).rev() {
        for j in 0..4 {
            a[j] = a[j] * s4 + p[4 * k + j];
            b[j] = b[j] * t4 + q[4 * k + j];
        }
    }
    (
        (a[0] + s * a[1]) + s2 * (a[2] + s * a[3]),
        (b[0] + t * b[1]) + t2 * (b[2] + t * b[3]),
    )
}

impl Poly {
    #[inline(always)]
    pub(super) fn value(&self, tau: f64) -> f64 {
        evaluate(&self.p, tau)
    }

    /// [`Poly::value`] at `t > 0`, and a bound on the rounding of a value
    /// over `|τ| ≤ t` (the noise): a few units in the last place of the
    /// sum of the terms' magnitudes. Below it a value is zero as far as
    /// the arithmetic can tell. Both in one pass.
    #[inline(always)]
    pub(super) fn value_and_noise(&self, t: f64) -> (f64, f64) {
        let (v, magnitude) = evaluate_pair(&self.p, t, &self.p.map(f64::abs), t);
        (v, 8.0 * f64::EPSILON * magnitude)
    }

    #[inline(always)]
    pub(super) fn derivative(&self) -> Poly {
        let mut p = [0.0; TERMS];
        for k in 1..TERMS {
            p[k - 1] = self.p[k] * k as f64;
        }
        Poly { p }
    }

    /// τ in `[lo, hi]` where the polynomial is zero, given a sign change
    /// between the ends: Newton's method from the secant's zero, kept
    /// inside the bracket, bisection where it would leave it, to where
    /// the value is lost in its rounding (`floor`, the noise of
    /// [`Poly::value_and_noise`] at the
    /// bracket's farther end) or the bracket is two floats wide. The
    /// values at the ends are given (as [`Poly::value`] has them).
    #[inline(always)]
    pub(super) fn root_within(&self, bracket: (f64, f64), values: (f64, f64), floor: f64) -> f64 {
        self.root_between(bracket, values, floor, ROOT_TOLERANCE)
    }

    /// [`Poly::root`] with the values at the ends known, to where the
    /// value is below `floor` or the step or the bracket below `rel` of
    /// the bracket's end.
    #[inline(always)]
    fn root_between(
        &self,
        (mut lo, mut hi): (f64, f64),
        (v_lo, v_hi): (f64, f64),
        floor: f64,
        rel: f64,
    ) -> f64 {
        let rate = self.derivative();
        let positive_lo = v_lo > 0.0;
        let secant = lo + (hi - lo) * v_lo / (v_lo - v_hi);
        let mut tau = if secant > lo && secant < hi {
            secant
        } else {
            0.5 * (lo + hi)
        };
        for _ in 0..200 {
            let (v, slope) = evaluate_pair(&self.p, tau, &rate.p, tau);
            if v.abs() <= floor {
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
            if (next - tau).abs() <= rel * hi || hi - lo <= rel * hi {
                return next;
            }
            tau = next;
        }
        tau
    }

    /// Every extremum inside `(0, h)` of a step of the mode's full step
    /// `full`, the rate's exact Bernstein coefficients over that full step
    /// being `rate` ([`Series::rate_bernstein`]): the rate's zeros are
    /// isolated on them ([`RateBernstein::zeros`]) and each is polished on
    /// this polynomial to [`EXTREMUM_TOLERANCE`], or, where the rate keeps
    /// its sign at both ends of an interval too narrow to tell (a zero
    /// touched, two a thousandth of the step apart), the form is taken at
    /// its middle. Each value goes to `take`.
    pub(super) fn every_extremum(
        &self,
        rate_form: &RateBernstein,
        (h, full): (f64, f64),
        mut take: impl FnMut(f64),
    ) {
        let rate = self.derivative();
        let Some((brackets, n)) = rate_form.zeros::<8>() else {
            for k in 1..64 {
                take(self.value(h * k as f64 / 64.0));
            }
            return;
        };
        let (_, noise) = rate.value_and_noise(h);
        for &(lo, hi) in &brackets[..n] {
            let (lo, hi) = (lo * full, (hi * full).min(h));
            if lo >= hi {
                break;
            }
            let t = match rate.sign_change(lo, hi) {
                Some((bracket, values)) => {
                    rate.root_between(bracket, values, noise, EXTREMUM_TOLERANCE)
                }
                None => 0.5 * (lo + hi),
            };
            take(self.value(t));
        }
    }

    /// A sub-interval of `[lo, hi]` over which the polynomial changes
    /// sign, and its values at the ends: the whole interval when its ends
    /// differ, else the first of 16 equal parts whose ends do (an end on
    /// a zero the search divided out, a zero touched). `None` when none
    /// does.
    fn sign_change(&self, lo: f64, hi: f64) -> Option<((f64, f64), (f64, f64))> {
        let opposite = |a: f64, b: f64| a != 0.0 && b != 0.0 && (a > 0.0) != (b > 0.0);
        let (v_lo, v_hi) = (self.value(lo), self.value(hi));
        if opposite(v_lo, v_hi) {
            return Some(((lo, hi), (v_lo, v_hi)));
        }
        let mut previous = (lo, v_lo);
        for k in 1..=16 {
            let t = if k == 16 {
                hi
            } else {
                lo + (hi - lo) * k as f64 / 16.0
            };
            let v = if k == 16 { v_hi } else { self.value(t) };
            if opposite(previous.1, v) {
                return Some(((previous.0, t), (previous.1, v)));
            }
            if v != 0.0 {
                previous = (t, v);
            }
        }
        None
    }

    /// The extremum inside `(0, h)`, where the rate changes sign, to
    /// [`EXTREMUM_TOLERANCE`]: a value there is off by a part in 1e24 of
    /// the step's swing (the rate is zero there), and its sign, the one
    /// other use, holds.
    #[inline(always)]
    pub(super) fn extremum(&self, h: f64) -> Option<f64> {
        let rate = self.derivative();
        let (r1, noise) = rate.value_and_noise(h);
        let r0 = rate.p[0];
        if r0 == 0.0 || r1 == 0.0 || (r0 > 0.0) == (r1 > 0.0) {
            return None;
        }
        Some(rate.root_between((0.0, h), (r0, r1), noise, EXTREMUM_TOLERANCE))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Undamped oscillators of ω = 1 (`w₀, w₁`) and ω = 10 (`w₂, w₃`)
    /// side by side, at rest about 0, unscaled, stepped by `h`.
    fn two_oscillators(h: f64) -> LinearMode {
        let mut a = Matrix4::zeros();
        a[(0, 1)] = 1.0;
        a[(1, 0)] = -1.0;
        a[(2, 3)] = 10.0;
        a[(3, 2)] = -10.0;
        LinearMode::new(a, Vector4::zeros(), [1.0; 4], h)
    }

    /// A slow and a fast oscillator side by side (ω = 1 and 10, `h` =
    /// 0.3), and the form `x₁ + x₂` along a step in which the fast one's
    /// rate twice outweighs the slow one's: the rate is positive at both
    /// ends of the step and turns twice inside it. Every extremum is
    /// found, and the largest value over the step is the closed form's.
    #[test]
    fn two_turns_in_one_step_are_both_found() {
        let h = 0.3;
        let mode = two_oscillators(h);
        // x₁ = cos(τ + φ₁), x₂ = B cos(10τ + φ₂); the slow rate is 0.3 at
        // mid-step, the fast one's −sin peaks there at 10 B = 1.
        let (phi1, b, phi2) = (
            -(0.3f64).asin() - 0.15,
            0.1,
            std::f64::consts::FRAC_PI_2 - 1.5,
        );
        let f = |t: f64| (t + phi1).cos() + b * (10.0 * t + phi2).cos();
        let rate = |t: f64| -(t + phi1).sin() - 10.0 * b * (10.0 * t + phi2).sin();
        assert!(
            rate(0.0) > 0.0 && rate(h) > 0.0,
            "{} {}",
            rate(0.0),
            rate(h)
        );
        let w0 = W::new(phi1.cos(), -phi1.sin(), b * phi2.cos(), -b * phi2.sin());
        let y0 = Y::new(w0[0], w0[1], w0[2], w0[3], 0.0);
        let series = Series::new(&mode, [1.0, 0.0, 1.0, 0.0], 0.0);
        let poly = series.poly(&w0, &y0);
        let rate_form = series.rate_bernstein(&w0);
        assert_eq!(rate_form.turns(), Some(2));
        let mut found = Vec::new();
        poly.every_extremum(&rate_form, (h, h), |v| found.push(v));
        assert_eq!(found.len(), 2, "{found:?}");
        let sampled = (0..=100_000)
            .map(|k| f(h * k as f64 / 100_000.0))
            .fold(f64::NEG_INFINITY, f64::max);
        let largest = found.iter().copied().fold(f(0.0).max(f(h)), f64::max);
        assert!(
            (largest - sampled).abs() < 1e-9,
            "{largest} against {sampled}"
        );
        // The interior maximum is what the ends alone would miss.
        assert!(sampled > f(0.0).max(f(h)) + 1e-4);
    }

    /// From rest (the rate zero at the step's start) the form
    /// `cos τ − 0.1 cos 10τ` turns once more inside the step, at π/11:
    /// found without splitting down to the start's zero, and not taken
    /// in a last step cut short of it.
    #[test]
    fn a_turn_after_a_start_at_rest_is_found_and_none_past_a_short_step() {
        let full = 0.3;
        let mode = two_oscillators(full);
        let w0 = W::new(1.0, 0.0, -0.1, 0.0);
        let y0 = Y::new(1.0, 0.0, -0.1, 0.0, 0.0);
        let series = Series::new(&mode, [1.0, 0.0, 1.0, 0.0], 0.0);
        let poly = series.poly(&w0, &y0);
        let rate = series.rate_bernstein(&w0);
        assert_eq!(rate.turns(), None, "the rate starts on its zero");
        let turn = std::f64::consts::PI / 11.0;
        let expected = turn.cos() - 0.1 * (10.0 * turn).cos();
        let mut found = Vec::new();
        poly.every_extremum(&rate, (full, full), |v| found.push(v));
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(
            (found[0] - expected).abs() < 1e-12,
            "{} against {expected}",
            found[0]
        );
        // A last step cut short of the turn: whatever is taken is a value
        // of the form inside it, never the turn's.
        found.clear();
        poly.every_extremum(&rate, (0.2, full), |v| found.push(v));
        let f = |t: f64| t.cos() - 0.1 * (10.0 * t).cos();
        let top = (0..=1000)
            .map(|k| f(0.2 * k as f64 / 1000.0))
            .fold(f64::MIN, f64::max);
        assert!(found.iter().all(|&v| v <= top + 1e-12), "{found:?}");
    }

    /// `Σ_j b_j C(n, j) s^j (1 − s)^(n − j)`, the Bernstein form at `s`.
    fn bernstein_at(b: &[f64], s: f64) -> f64 {
        let n = b.len() - 1;
        let mut binomial = 1.0;
        let mut sum = 0.0;
        for (j, bj) in b.iter().enumerate() {
            if j > 0 {
                binomial *= (n - j + 1) as f64 / j as f64;
            }
            sum += bj * binomial * s.powi(j as i32) * (1.0 - s).powi((n - j) as i32);
        }
        sum
    }

    /// The weights' rows turn a polynomial's power coefficients into
    /// Bernstein coefficients of the same polynomial, for each degree the
    /// engine uses: both forms agree along [0, 1].
    #[test]
    fn bernstein_rows_are_the_same_polynomial() {
        fn check<const N: usize>(weights: &[[f64; N]; N]) {
            let a: [f64; N] = std::array::from_fn(|k| ((k * 7 + 3) % 11) as f64 - 5.0);
            let terms: [W; N] = std::array::from_fn(|k| W::new(a[k], -a[k], 0.5 * a[k], 0.0));
            let rows = bernstein_rows(&terms, weights);
            let b0: Vec<f64> = rows.iter().map(|r| r[0]).collect();
            let b1: Vec<f64> = rows.iter().map(|r| r[1]).collect();
            for i in 0..=20 {
                let s = i as f64 / 20.0;
                let power: f64 = a.iter().rev().fold(0.0, |acc, c| acc * s + c);
                let scale: f64 = a.iter().map(|c| c.abs()).sum();
                assert!(
                    (bernstein_at(&b0, s) - power).abs() <= 1e-12 * scale,
                    "N = {N}, s = {s}"
                );
                assert!(
                    (bernstein_at(&b1, s) + power).abs() <= 1e-12 * scale,
                    "N = {N}, s = {s}"
                );
            }
            // The end coefficients are the polynomial's ends.
            assert_eq!(b0[0], a[0]);
            let sum: f64 = a.iter().sum();
            assert!((b0[N - 1] - sum).abs() <= 1e-12 * sum.abs().max(1.0));
        }
        check(&LOW_WEIGHTS);
        check(&AFTER_ZERO_WEIGHTS);
        check(&FULL_WEIGHTS);
    }
}
