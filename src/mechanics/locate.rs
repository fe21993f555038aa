//! The one event locator: the first time in a step at which an event
//! function turns negative, with a guarantee that nothing was stepped
//! over.
//!
//! Every event of every engine (an impact, a release, a pole-face touch
//! or release, a landing on the rest stop) is the first zero of a guard:
//! one linear form of the state, or the larger or smaller of two (a
//! surface released by its force). Over one step the state is a
//! polynomial in the step's own time `s ∈ [0, 1]`: the exact linear modes'
//! Taylor series (28 terms, truncated below 1e-20 of the state's
//! swing), or DOP853's dense output (degree 7). So each form is a
//! polynomial `f(s) = Σ a_k s^k`.
//!
//! # The guarantee
//!
//! The locator never asks whether `f` looks positive at a few points; it
//! asks whether `f` can be shown positive on an interval, by the Bernstein
//! form of `f` there: `f` is a convex combination of its Bernstein
//! coefficients, so when every coefficient is positive (beyond a bound on
//! their rounding) so is `f`, everywhere on the interval. The step is
//! searched from its start: an interval shown positive is skipped, any
//! other is halved (de Casteljau) and searched left half first, down to a
//! leaf no wider than a quarter of the resolution (`simulation.min_open_time`
//! of the model's endings), where the guard is evaluated at the leaf's
//! end and middle. Hence:
//!
//! - every interval skipped is one where the guard is provably positive:
//!   no sign change is stepped over there, however many roots the step
//!   holds (two roots a hair apart, a re-closure shorter than a step, a
//!   function that starts on its zero and comes back);
//! - an excursion below zero that lasts at least half the resolution
//!   contains a whole leaf, whose end is then seen negative: it is found;
//! - the search stops early on an interval where the guard is positive at
//!   the start and negative at the end and no form's coefficients change
//!   sign more than once: by Descartes' rule of signs in the Bernstein
//!   basis each form then has at most one zero there, so the guard's first
//!   zero is bracketed with nothing hidden before it (this is what makes
//!   an ordinary event cost a few halvings, not forty);
//! - otherwise the interval returned is the first leaf where the guard was
//!   seen negative, with every point before it shown positive or inside an
//!   excursion shorter than half the resolution, which the model's
//!   endings would merge anyway.
//!
//! A form that starts on its own zero (the event that began the mode set
//! the state exactly on the surface) is divided by `s` first: for `s > 0`
//! it has the sign of `(f(s) − f(0))/s`, whose first zero is the form's
//! return to the surface; so a mode that begins on its zero cannot end on
//! the same zero, and a return within the step is still found.
//!
//! The cost is a Bernstein conversion per form and step (a few hundred
//! multiplications for the 28-term series), skipped when the coefficients
//! alone bound the form away from zero, and halvings only near a zero.

/// Most coefficients a form may have.
pub(crate) const MAX_COEFFS: usize = 32;

/// Deepest halving of a step: a leaf is never narrower than 2⁻⁴⁰ of the
/// step, so a search costs at most 40 halvings per root.
const MAX_DEPTH: u32 = 40;

/// `C(n, k)` for `n, k < MAX_COEFFS`, exact in f64 (all below 2^53).
const BINOMIAL: [[f64; MAX_COEFFS]; MAX_COEFFS] = {
    let mut t = [[0.0; MAX_COEFFS]; MAX_COEFFS];
    let mut n = 0;
    while n < MAX_COEFFS {
        t[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            t[n][k] = t[n - 1][k - 1] + if k < n { t[n - 1][k] } else { 0.0 };
            k += 1;
        }
        n += 1;
    }
    t
};

/// `1/C(n, k)`, for the conversion to the Bernstein form without a
/// division per coefficient.
const INVERSE_BINOMIAL: [[f64; MAX_COEFFS]; MAX_COEFFS] = {
    let mut t = [[0.0; MAX_COEFFS]; MAX_COEFFS];
    let mut n = 0;
    while n < MAX_COEFFS {
        let mut k = 0;
        while k <= n {
            t[n][k] = 1.0 / BINOMIAL[n][k];
            k += 1;
        }
        n += 1;
    }
    t
};

/// A form over one step: `f(s) = Σ a_k s^k`, `s ∈ [0, 1]`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepForm {
    a: [f64; MAX_COEFFS],
    n: usize,
}

impl StepForm {
    /// The form of coefficients `a` (in the step's own time `s`).
    pub(crate) fn new(a: &[f64]) -> StepForm {
        assert!(a.len() <= MAX_COEFFS && !a.is_empty());
        let mut c = [0.0; MAX_COEFFS];
        c[..a.len()].copy_from_slice(a);
        StepForm { a: c, n: a.len() }
    }

    /// The form of the polynomial `Σ p_k τ^k` over `τ ∈ [0, h]`.
    pub(crate) fn scaled(p: &[f64], h: f64) -> StepForm {
        assert!(p.len() <= MAX_COEFFS && !p.is_empty());
        let mut c = [0.0; MAX_COEFFS];
        let mut hk = 1.0;
        for (c, p) in c.iter_mut().zip(p) {
            *c = p * hk;
            hk *= h;
        }
        StepForm { a: c, n: p.len() }
    }

    /// `f(s)`, by Horner's rule.
    fn value(&self, s: f64) -> f64 {
        self.a[..self.n]
            .iter()
            .rev()
            .fold(0.0, |acc, &c| acc * s + c)
    }

    fn magnitude(&self) -> f64 {
        self.a[..self.n].iter().map(|c| c.abs()).sum()
    }

    /// A bound on the rounding of a value or Bernstein coefficient of the
    /// form: a few units in the last place of its terms' magnitudes, for
    /// each of the conversions' roughly `n` operations.
    fn noise(&self) -> f64 {
        (4.0 * self.n as f64 + 16.0) * f64::EPSILON * self.magnitude()
    }

    /// Whether the form starts on its zero: `|f(0)|` within its rounding.
    fn starts_on_zero(&self) -> bool {
        self.a[0].abs() <= self.noise()
    }

    /// `(f(s) − f(0))/s`: the sign of `f` for `s > 0` when `f(0) = 0`.
    fn deflated(&self) -> StepForm {
        let mut c = [0.0; MAX_COEFFS];
        let n = (self.n - 1).max(1);
        c[..self.n - 1].copy_from_slice(&self.a[1..self.n]);
        StepForm { a: c, n }
    }
}

/// How a guard combines its forms: the one form, or the larger or the
/// smaller of two.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Combine {
    One,
    Max,
    Min,
}

/// The sign of a form (or a guard) over an interval, as far as its
/// Bernstein coefficients can show it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sign {
    Positive,
    Negative,
    Unknown,
}

impl Combine {
    fn sign(self, signs: &[Sign]) -> Sign {
        let all = |s: Sign| signs.iter().all(|&x| x == s);
        let any = |s: Sign| signs.contains(&s);
        match self {
            Combine::One => signs[0],
            Combine::Max if any(Sign::Positive) => Sign::Positive,
            Combine::Max if all(Sign::Negative) => Sign::Negative,
            Combine::Min if all(Sign::Positive) => Sign::Positive,
            Combine::Min if any(Sign::Negative) => Sign::Negative,
            _ => Sign::Unknown,
        }
    }

    fn value(self, values: &[f64]) -> f64 {
        match self {
            Combine::One => values[0],
            Combine::Max => values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            Combine::Min => values.iter().copied().fold(f64::INFINITY, f64::min),
        }
    }
}

/// A form in Bernstein form on one interval of the step.
#[derive(Clone, Copy)]
struct Bernstein {
    b: [f64; MAX_COEFFS],
    n: usize,
    noise: f64,
}

impl Bernstein {
    /// The Bernstein form of `f` on `[0, 1]`:
    /// `b_j = Σ_{k ≤ j} C(j, k)/C(d, k) a_k`, `d = n − 1`.
    fn of(f: &StepForm) -> Bernstein {
        let n = f.n;
        let d = n - 1;
        let mut scaled = [0.0; MAX_COEFFS];
        for (k, s) in scaled.iter_mut().enumerate().take(n) {
            *s = f.a[k] * INVERSE_BINOMIAL[d][k];
        }
        // Summed over k in order for each j, as the sum's definition
        // reads, but with j innermost: the n sums are independent chains,
        // not one chain after another.
        let mut b = [0.0; MAX_COEFFS];
        for (k, &s) in scaled.iter().enumerate().take(n) {
            for (j, bj) in b.iter_mut().enumerate().take(n).skip(k) {
                *bj += BINOMIAL[j][k] * s;
            }
        }
        Bernstein {
            b,
            n,
            noise: f.noise(),
        }
    }

    fn sign(&self) -> Sign {
        let b = &self.b[..self.n];
        if b.iter().all(|&c| c > self.noise) {
            Sign::Positive
        } else if b.iter().all(|&c| c < -self.noise) {
            Sign::Negative
        } else {
            Sign::Unknown
        }
    }

    /// Sign changes along the coefficients, those within their rounding
    /// of zero skipped: a bound on the form's zeros in the interval, of the
    /// same parity (Descartes' rule of signs in the Bernstein basis).
    fn variations(&self) -> usize {
        let mut last = 0.0f64;
        let mut count = 0;
        for &c in &self.b[..self.n] {
            if c.abs() <= self.noise {
                continue;
            }
            if last != 0.0 && (c > 0.0) != (last > 0.0) {
                count += 1;
            }
            last = c;
        }
        count
    }

    /// The form's value at the interval's start and end (exact in the
    /// Bernstein form: the end coefficients).
    fn ends(&self) -> (f64, f64) {
        (self.b[0], self.b[self.n - 1])
    }

    /// The two halves (de Casteljau at ½).
    fn split(&self) -> (Bernstein, Bernstein) {
        let n = self.n;
        let mut work = self.b;
        let mut left = *self;
        let mut right = *self;
        left.b[0] = work[0];
        right.b[n - 1] = work[n - 1];
        for r in 1..n {
            for j in 0..n - r {
                work[j] = 0.5 * (work[j] + work[j + 1]);
            }
            left.b[r] = work[0];
            right.b[n - 1 - r] = work[n - 1 - r];
        }
        (left, right)
    }
}

/// The first zero of a guard over one step, as a bracket `[lo, hi]` in
/// the step's own time: the guard is shown positive (or below the
/// resolution) everywhere before `lo` and seen negative at `hi`. `None`:
/// the guard stays positive over the whole step, but for excursions
/// shorter than half of `resolution` (itself in units of the step).
///
/// `forms` are the guard's one or two forms, `combine` how they make it.
pub(crate) fn first_zero(
    forms: &[StepForm],
    combine: Combine,
    resolution: f64,
) -> Option<(f64, f64)> {
    debug_assert!(!forms.is_empty() && forms.len() <= 2);
    if clearly_positive(forms, combine) {
        return None;
    }
    let leaf = (0.25 * resolution).clamp(0.5f64.powi(MAX_DEPTH as i32), 1.0);
    // Forms that start on their zero are searched as (f − f(0))/s. One
    // that then starts falling (a graze) counts from where it has risen
    // (`start`), or not at all when it does not rise in the step.
    let mut used = [forms[0]; 2];
    let mut start = [0.0f64; 2];
    for (i, f) in forms.iter().enumerate() {
        used[i] = *f;
        if f.starts_on_zero() && f.n > 1 {
            let q = f.deflated();
            if q.a[0] <= 0.0 {
                let mut negated = q;
                negated.a.iter_mut().for_each(|c| *c = -*c);
                start[i] = search_one(&negated, leaf).map_or(f64::INFINITY, |(_, hi)| hi);
            }
            used[i] = q;
        }
    }
    let n = forms.len();
    let mut kept = [used[0]; 2];
    let mut count = 0;
    let mut from = 0.0f64;
    for i in 0..n {
        // Both must be negative for a max: a grazing form is not positive
        // before it rises, so the other decides there; alone or in a min,
        // a form counts from where it has risen.
        if combine == Combine::Max || start[i] < 1.0 {
            kept[count] = used[i];
            count += 1;
            if combine != Combine::Max {
                from = from.max(start[i]);
            }
        }
    }
    if count == 0 {
        return None;
    }
    let kept = &kept[..count];
    let combine = if count == 1 { Combine::One } else { combine };
    let mut set = Forms {
        b: [Bernstein::of(&kept[0]); 2],
        n: count,
    };
    if count == 2 {
        set.b[1] = Bernstein::of(&kept[1]);
    }
    let (mut lo, mut hi) = search(&set, combine, (0.0, 1.0), leaf, from)?;
    // A bracket that begins at the step's start, where a form divided by
    // s started on its zero: moved inside, to where the guard is positive,
    // so that the caller's polish on the form itself (zero at the start)
    // cannot fall back onto that start.
    let divided = forms.iter().any(|f| f.starts_on_zero() && f.n > 1);
    if lo == 0.0 && divided {
        let guard = |s: f64| {
            let v = [kept[0].value(s), kept[count - 1].value(s)];
            combine.value(&v[..count])
        };
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if guard(mid) < 0.0 {
                hi = mid;
            } else {
                lo = mid;
                break;
            }
        }
    }
    Some((lo, hi))
}

/// Where a form changes sign over the step, for a search of every zero
/// (not only the first): intervals `[lo, hi]` of the step's own time,
/// each holding one zero (the form's Bernstein coefficients there change
/// sign once and its ends differ), or an interval of `leaf` or less
/// where the coefficients could not decide (a zero touched, two zeros
/// closer than `leaf`). Outside them the form keeps one sign. At most
/// `N` are found (the earliest); `None` when there were more.
pub(crate) fn sign_changes<const N: usize>(
    f: &StepForm,
    leaf: f64,
) -> Option<([(f64, f64); N], usize)> {
    changes_of(&Bernstein::of(f), leaf)
}

/// [`sign_changes`] of a form given by its Bernstein coefficients on
/// `[0, 1]` (at most [`MAX_COEFFS`]) and their rounding.
pub(crate) fn sign_changes_of_coefficients<const N: usize>(
    coefficients: &[f64],
    noise: f64,
    leaf: f64,
) -> Option<([(f64, f64); N], usize)> {
    assert!(!coefficients.is_empty() && coefficients.len() <= MAX_COEFFS);
    let mut b = [0.0; MAX_COEFFS];
    b[..coefficients.len()].copy_from_slice(coefficients);
    let form = Bernstein {
        b,
        n: coefficients.len(),
        noise,
    };
    changes_of(&form, leaf)
}

fn changes_of<const N: usize>(b: &Bernstein, leaf: f64) -> Option<([(f64, f64); N], usize)> {
    let mut out = ([(0.0, 0.0); N], 0);
    let leaf = leaf.max(0.5f64.powi(MAX_DEPTH as i32));
    changes(b, (0.0, 1.0), leaf, &mut out).then_some(out)
}

/// [`sign_changes`] over `[lo, hi]`, its form `b` there, into `out`:
/// `false` when `out` is full.
fn changes<const N: usize>(
    b: &Bernstein,
    (lo, hi): (f64, f64),
    leaf: f64,
    out: &mut ([(f64, f64); N], usize),
) -> bool {
    if b.sign() != Sign::Unknown {
        return true;
    }
    let (start, end) = b.ends();
    let apart = start.abs() > b.noise && end.abs() > b.noise && (start > 0.0) != (end > 0.0);
    if (apart && b.variations() <= 1) || hi - lo <= leaf {
        if out.1 == N {
            return false;
        }
        out.0[out.1] = (lo, hi);
        out.1 += 1;
        return true;
    }
    let mid = 0.5 * (lo + hi);
    let (left, right) = b.split();
    changes(&left, (lo, mid), leaf, out) && changes(&right, (mid, hi), leaf, out)
}

/// Whether the coefficients alone show the guard positive over the whole
/// step (`f(s) ≥ a_0 − Σ_{k≥1} |a_k|`): the common step, far from every
/// stop, costs no Bernstein form.
pub(crate) fn clearly_positive(forms: &[StepForm], combine: Combine) -> bool {
    let mut signs = [Sign::Unknown; 2];
    for (sign, f) in signs.iter_mut().zip(forms) {
        let spread: f64 = f.a[1..f.n].iter().map(|c| c.abs()).sum();
        if f.a[0] - spread > f.noise() {
            *sign = Sign::Positive;
        }
    }
    combine.sign(&signs[..forms.len()]) == Sign::Positive
}

/// [`first_zero`] of one form alone.
fn search_one(f: &StepForm, leaf: f64) -> Option<(f64, f64)> {
    let set = Forms {
        b: [Bernstein::of(f); 2],
        n: 1,
    };
    search(&set, Combine::One, (0.0, 1.0), leaf, 0.0)
}

/// A guard's one or two forms in Bernstein form on one interval.
#[derive(Clone, Copy)]
struct Forms {
    b: [Bernstein; 2],
    n: usize,
}

impl Forms {
    fn sign(&self, combine: Combine) -> Sign {
        let signs = [self.b[0].sign(), self.b[1].sign()];
        combine.sign(&signs[..self.n])
    }

    fn value_at_end(&self, combine: Combine) -> f64 {
        let v = [self.b[0].ends().1, self.b[1].ends().1];
        combine.value(&v[..self.n])
    }

    fn value_at_start(&self, combine: Combine) -> f64 {
        let v = [self.b[0].ends().0, self.b[1].ends().0];
        combine.value(&v[..self.n])
    }

    /// Whether the interval holds the guard's first zero and nothing can
    /// hide before it: the guard is positive at the start and negative at
    /// the end, and no form has more than one zero here (at most one sign
    /// change in its coefficients), so each form crosses at most once and
    /// the guard's first zero is where the last (max) or first (min) of
    /// them crosses.
    fn isolated(&self, combine: Combine) -> bool {
        self.value_at_start(combine) > 0.0
            && self.value_at_end(combine) < 0.0
            && self.b[..self.n].iter().all(|b| b.variations() <= 1)
    }

    fn split(&self) -> (Forms, Forms) {
        let (mut left, mut right) = (*self, *self);
        for i in 0..self.n {
            (left.b[i], right.b[i]) = self.b[i].split();
        }
        (left, right)
    }
}

/// Depth-first, left half first, over `[lo, hi]`, ignoring zeros before
/// `from`.
fn search(
    forms: &Forms,
    combine: Combine,
    (lo, hi): (f64, f64),
    leaf: f64,
    from: f64,
) -> Option<(f64, f64)> {
    if hi <= from || forms.sign(combine) == Sign::Positive {
        return None;
    }
    if lo >= from && forms.isolated(combine) {
        return Some((lo, hi));
    }
    let mid = 0.5 * (lo + hi);
    let (left, right) = forms.split();
    if hi - lo <= leaf {
        if forms.value_at_end(combine) < 0.0 {
            return Some((lo.max(from), hi));
        }
        if mid > from && left.value_at_end(combine) < 0.0 {
            return Some((lo.max(from), mid));
        }
        return None;
    }
    search(&left, combine, (lo, mid), leaf, from)
        .or_else(|| search(&right, combine, (mid, hi), leaf, from))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn product(roots: &[f64], scale: f64) -> StepForm {
        let mut a = vec![scale];
        for &r in roots {
            let mut next = vec![0.0; a.len() + 1];
            for (k, &c) in a.iter().enumerate() {
                next[k + 1] += c;
                next[k] -= r * c;
            }
            a = next;
        }
        StepForm::new(&a)
    }

    /// Every zero is bracketed alone, two a hair apart included, and a
    /// zero the form only touches is left in an interval of the leaf's
    /// width; `None` when the brackets would not fit.
    #[test]
    fn sign_changes_bracket_every_zero() {
        let roots = [0.1, 0.35, 0.3505, 0.8];
        let (brackets, n) = sign_changes::<8>(&product(&roots, 1.0), 1e-6).unwrap();
        assert_eq!(n, 4, "{:?}", &brackets[..n]);
        for (&(lo, hi), &r) in brackets[..n].iter().zip(&roots) {
            assert!(lo <= r && r <= hi, "{r} outside [{lo}, {hi}]");
            let inside = roots.iter().filter(|&&q| lo <= q && q <= hi).count();
            assert_eq!(inside, 1, "[{lo}, {hi}]");
        }
        // (s − 0.2)(s − 0.5)²: one crossing, one touch.
        let (brackets, n) = sign_changes::<8>(&product(&[0.2, 0.5, 0.5], -1.0), 1e-4).unwrap();
        assert!(n >= 2, "{:?}", &brackets[..n]);
        assert!(brackets[0].0 <= 0.2 && 0.2 <= brackets[0].1);
        let touch = brackets[1..n]
            .iter()
            .any(|&(lo, hi)| lo <= 0.5 && 0.5 <= hi && hi - lo <= 1e-4);
        assert!(touch, "{:?}", &brackets[..n]);
        // A positive form has none; nine zeros do not fit in eight.
        assert_eq!(
            sign_changes::<8>(&product(&[-0.5, 1.5], 1.0), 1e-6)
                .unwrap()
                .1,
            0
        );
        let nine: Vec<f64> = (1..=9).map(|k| k as f64 / 10.0).collect();
        assert!(sign_changes::<8>(&product(&nine, 1.0), 1e-6).is_none());
    }

    #[test]
    fn bernstein_form_reproduces_the_polynomial() {
        let f = StepForm::new(&[0.3, -2.0, 5.0, -1.0, 0.25, 3.0]);
        let b = Bernstein::of(&f);
        let d = f.n - 1;
        for &s in &[0.0f64, 0.1, 0.37, 0.5, 0.93, 1.0] {
            let mut v = 0.0;
            let mut binom = 1.0;
            for j in 0..=d {
                if j > 0 {
                    binom *= (d - j + 1) as f64 / j as f64;
                }
                v += b.b[j] * binom * s.powi(j as i32) * (1.0 - s).powi((d - j) as i32);
            }
            assert!(
                (v - f.value(s)).abs() < 1e-13,
                "at {s}: {v} against {}",
                f.value(s)
            );
        }
        let (l, r) = b.split();
        assert!((l.ends().1 - f.value(0.5)).abs() < 1e-13);
        assert!((r.ends().0 - f.value(0.5)).abs() < 1e-13);
    }

    #[test]
    fn two_roots_a_hair_apart_are_found() {
        // Positive at both ends, negative only on (0.4, 0.4 + 1e-5): a
        // sampler at a few fixed points misses it.
        let f = product(&[0.4, 0.4 + 1e-5, -0.5, -1.0], 1.0);
        assert!(f.value(0.0) > 0.0 && f.value(1.0) > 0.0);
        let (lo, hi) = first_zero(&[f], Combine::One, 1e-6).expect("the dip is found");
        // A bracket of the first zero: positive before, negative at its end.
        assert!(lo <= 0.4 && hi > 0.4 && hi < 0.4 + 1e-5, "{lo} {hi}");
        assert!(f.value(lo) >= 0.0 && f.value(hi) < 0.0);
    }

    #[test]
    fn a_form_that_starts_on_its_zero_and_returns_is_found() {
        // f(0) = 0, rising, back through zero at 0.003.
        let f = product(&[0.0, 0.003, 2.0], 1.0);
        let (lo, hi) = first_zero(&[f], Combine::One, 1e-9).expect("the return is found");
        // Not the zero it starts on: the bracket begins inside, positive.
        assert!(lo > 0.0 && lo <= 0.003 && hi >= 0.003, "{lo} {hi}");
        assert!(f.value(lo) > 0.0 && f.value(hi) < 0.0);
        // Without the return it stays open.
        let g = product(&[0.0, 2.0], -1.0);
        assert!(g.value(0.5) > 0.0);
        assert_eq!(first_zero(&[g], Combine::One, 1e-9), None);
    }

    #[test]
    fn a_positive_form_has_no_zero() {
        let f = StepForm::new(&[1e-3, -4e-3, 4e-3 + 1e-6]);
        // min at s = 0.5: 1e-3 − 2e-3 + 1e-3 + 2.5e-7 > 0.
        assert_eq!(first_zero(&[f], Combine::One, 1e-12), None);
    }

    #[test]
    fn max_needs_both_negative_and_min_either() {
        let a = product(&[0.3], -1.0); // positive before 0.3
        let b = product(&[0.6], -1.0); // positive before 0.6
        let (lo, hi) = first_zero(&[a, b], Combine::Max, 1e-9).unwrap();
        assert!(lo <= 0.6 && hi >= 0.6, "{lo} {hi}");
        let (lo, hi) = first_zero(&[a, b], Combine::Min, 1e-9).unwrap();
        assert!(lo <= 0.3 && hi >= 0.3, "{lo} {hi}");
    }

    #[test]
    fn random_polynomials_agree_with_dense_sampling() {
        // Against a sampler fine enough to see every excursion of these
        // low-degree polynomials: the first negative sample is in the
        // bracket, or at most one resolution after it.
        let mut state = 0x9e3779b97f4a7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..400 {
            let roots: Vec<f64> = (0..4).map(|_| next() * 1.4 - 0.2).collect();
            let f = product(&roots, if next() < 0.5 { 1.0 } else { -1.0 });
            if f.value(0.0) <= 0.0 {
                continue;
            }
            let samples = 200_000;
            let first = (1..=samples)
                .map(|i| i as f64 / samples as f64)
                .find(|&s| f.value(s) < 0.0);
            let found = first_zero(&[f], Combine::One, 1e-7);
            match (first, found) {
                (None, None) => {}
                (Some(s), Some((lo, hi))) => {
                    assert!(
                        lo <= s + 1e-12 && hi >= s - 1.0 / samples as f64 - 1e-7,
                        "{s} in {lo}..{hi}"
                    )
                }
                (a, b) => panic!("sampled {a:?}, located {b:?} for roots {roots:?}"),
            }
        }
    }
}
