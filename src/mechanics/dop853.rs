//! Dormand–Prince 8(5,3): an explicit Runge–Kutta method of order 8 with
//! a 7th-order continuous extension, for tight tolerances.
//!
//! At the tolerances the engine needs (rtol 1e-9) an 8th-order method
//! takes several times fewer steps than [`super::integrate::Dopri5`], and
//! with 12 stages a step against 6 it is the cheaper of the two. The
//! coefficients are those published by Hairer, Nørsett & Wanner, *Solving
//! ODEs I* (2nd ed., 1993), §II.10 (the code DOP853): the 12-stage 8th-order
//! formula, a 5th- and a 3rd-order error estimate combined as in that code,
//! and three extra stages for the 7th-order dense output. They are kept as
//! published (30 digits) so they can be checked against the source; the
//! tests check the order conditions they must satisfy.
//!
//! Like [`super::integrate::Dopri5`], the caller owns the loop:
//! [`Dop853::step`] returns one accepted [`Dop853Step`]. Its continuous
//! extension costs three more evaluations of the right-hand side, so
//! [`Dop853::dense`] builds it only when asked, for the step just taken
//! (the solver keeps that step's stages; nothing large is copied per
//! step).

#![allow(clippy::excessive_precision)]

use crate::mechanics::linalg::SVector;

use super::error::MechanicsError;
use super::step_control::{StepTolerance, trial_step};

const C2: f64 = 0.526001519587677318785587544488e-01;
const C3: f64 = 0.789002279381515978178381316732e-01;
const C4: f64 = 0.118350341907227396726757197510e+00;
const C5: f64 = 0.281649658092772603273242802490e+00;
const C6: f64 = 0.333333333333333333333333333333e+00;
const C7: f64 = 0.25e+00;
const C8: f64 = 0.307692307692307692307692307692e+00;
const C9: f64 = 0.651282051282051282051282051282e+00;
const C10: f64 = 0.6e+00;
const C11: f64 = 0.857142857142857142857142857142e+00;
const C14: f64 = 0.1e+00;
const C15: f64 = 0.2e+00;
const C16: f64 = 0.777777777777777777777777777778e+00;

const A21: f64 = 5.26001519587677318785587544488e-2;
const A31: f64 = 1.97250569845378994544595329183e-2;
const A32: f64 = 5.91751709536136983633785987549e-2;
const A41: f64 = 2.95875854768068491816892993775e-2;
const A43: f64 = 8.87627564304205475450678981324e-2;
const A51: f64 = 2.41365134159266685502369798665e-1;
const A53: f64 = -8.84549479328286085344864962717e-1;
const A54: f64 = 9.24834003261792003115737966543e-1;
const A61: f64 = 3.7037037037037037037037037037e-2;
const A64: f64 = 1.70828608729473871279604482173e-1;
const A65: f64 = 1.25467687566822425016691814123e-1;
const A71: f64 = 3.7109375e-2;
const A74: f64 = 1.70252211019544039314978060272e-1;
const A75: f64 = 6.02165389804559606850219397283e-2;
const A76: f64 = -1.7578125e-2;
const A81: f64 = 3.70920001185047927108779319836e-2;
const A84: f64 = 1.70383925712239993810214054705e-1;
const A85: f64 = 1.07262030446373284651809199168e-1;
const A86: f64 = -1.53194377486244017527936158236e-2;
const A87: f64 = 8.27378916381402288758473766002e-3;
const A91: f64 = 6.24110958716075717114429577812e-1;
const A94: f64 = -3.36089262944694129406857109825e0;
const A95: f64 = -8.68219346841726006818189891453e-1;
const A96: f64 = 2.75920996994467083049415600797e1;
const A97: f64 = 2.01540675504778934086186788979e1;
const A98: f64 = -4.34898841810699588477366255144e1;
const A101: f64 = 4.77662536438264365890433908527e-1;
const A104: f64 = -2.48811461997166764192642586468e0;
const A105: f64 = -5.90290826836842996371446475743e-1;
const A106: f64 = 2.12300514481811942347288949897e1;
const A107: f64 = 1.52792336328824235832596922938e1;
const A108: f64 = -3.32882109689848629194453265587e1;
const A109: f64 = -2.03312017085086261358222928593e-2;
const A111: f64 = -9.3714243008598732571704021658e-1;
const A114: f64 = 5.18637242884406370830023853209e0;
const A115: f64 = 1.09143734899672957818500254654e0;
const A116: f64 = -8.14978701074692612513997267357e0;
const A117: f64 = -1.85200656599969598641566180701e1;
const A118: f64 = 2.27394870993505042818970056734e1;
const A119: f64 = 2.49360555267965238987089396762e0;
const A1110: f64 = -3.0467644718982195003823669022e0;
const A121: f64 = 2.27331014751653820792359768449e0;
const A124: f64 = -1.05344954667372501984066689879e1;
const A125: f64 = -2.00087205822486249909675718444e0;
const A126: f64 = -1.79589318631187989172765950534e1;
const A127: f64 = 2.79488845294199600508499808837e1;
const A128: f64 = -2.85899827713502369474065508674e0;
const A129: f64 = -8.87285693353062954433549289258e0;
const A1210: f64 = 1.23605671757943030647266201528e1;
const A1211: f64 = 6.43392746015763530355970484046e-1;

// The 8th-order weights (b2–b5 are zero); stage 12 is at c = 1 and
// stage 13, f(t + h, y1), is the next step's first (first same as last).
const B1: f64 = 5.42937341165687622380535766363e-2;
const B6: f64 = 4.45031289275240888144113950566e0;
const B7: f64 = 1.89151789931450038304281599044e0;
const B8: f64 = -5.8012039600105847814672114227e0;
const B9: f64 = 3.1116436695781989440891606237e-1;
const B10: f64 = -1.52160949662516078556178806805e-1;
const B11: f64 = 2.01365400804030348374776537501e-1;
const B12: f64 = 4.47106157277725905176885569043e-2;

// The 3rd-order error estimate is (b − b̂3)·k with b̂3 on stages 1, 9, 12.
const BHH1: f64 = 0.244094488188976377952755905512e+00;
const BHH2: f64 = 0.733846688281611857341361741547e+00;
const BHH3: f64 = 0.220588235294117647058823529412e-01;

// The 5th-order error estimate: (b − b̂5)·k.
const ER1: f64 = 0.1312004499419488073250102996e-01;
const ER6: f64 = -0.1225156446376204440720569753e+01;
const ER7: f64 = -0.4957589496572501915214079952e+00;
const ER8: f64 = 0.1664377182454986536961530415e+01;
const ER9: f64 = -0.3503288487499736816886487290e+00;
const ER10: f64 = 0.3341791187130174790297318841e+00;
const ER11: f64 = 0.8192320648511571246570742613e-01;
const ER12: f64 = -0.2235530786388629525884427845e-01;

// The three extra stages of the dense output.
const A141: f64 = 5.61675022830479523392909219681e-2;
const A147: f64 = 2.53500210216624811088794765333e-1;
const A148: f64 = -2.46239037470802489917441475441e-1;
const A149: f64 = -1.24191423263816360469010140626e-1;
const A1410: f64 = 1.5329179827876569731206322685e-1;
const A1411: f64 = 8.20105229563468988491666602057e-3;
const A1412: f64 = 7.56789766054569976138603589584e-3;
const A1413: f64 = -8.298e-3;
const A151: f64 = 3.18346481635021405060768473261e-2;
const A156: f64 = 2.83009096723667755288322961402e-2;
const A157: f64 = 5.35419883074385676223797384372e-2;
const A158: f64 = -5.49237485713909884646569340306e-2;
const A1511: f64 = -1.08347328697249322858509316994e-4;
const A1512: f64 = 3.82571090835658412954920192323e-4;
const A1513: f64 = -3.40465008687404560802977114492e-4;
const A1514: f64 = 1.41312443674632500278074618366e-1;
const A161: f64 = -4.28896301583791923408573538692e-1;
const A166: f64 = -4.69762141536116384314449447206e0;
const A167: f64 = 7.68342119606259904184240953878e0;
const A168: f64 = 4.06898981839711007970213554331e0;
const A169: f64 = 3.56727187455281109270669543021e-1;
const A1613: f64 = -1.39902416515901462129418009734e-3;
const A1614: f64 = 2.9475147891527723389556272149e0;
const A1615: f64 = -9.15095847217987001081870187138e0;

/// Dense-output coefficients: row r gives the weights of stages 1, 6–16
/// in the r-th correction term of the interpolant (see [`Dense::at`]).
const D: [[f64; 12]; 4] = [
    [
        -0.84289382761090128651353491142e+01,
        0.56671495351937776962531783590e+00,
        -0.30689499459498916912797304727e+01,
        0.23846676565120698287728149680e+01,
        0.21170345824450282767155149946e+01,
        -0.87139158377797299206789907490e+00,
        0.22404374302607882758541771650e+01,
        0.63157877876946881815570249290e+00,
        -0.88990336451333310820698117400e-01,
        0.18148505520854727256656404962e+02,
        -0.91946323924783554000451984436e+01,
        -0.44360363875948939664310572000e+01,
    ],
    [
        0.10427508642579134603413151009e+02,
        0.24228349177525818288430175319e+03,
        0.16520045171727028198505394887e+03,
        -0.37454675472269020279518312152e+03,
        -0.22113666853125306036270938578e+02,
        0.77334326684722638389603898808e+01,
        -0.30674084731089398182061213626e+02,
        -0.93321305264302278729567221706e+01,
        0.15697238121770843886131091075e+02,
        -0.31139403219565177677282850411e+02,
        -0.93529243588444783865713862664e+01,
        0.35816841486394083752465898540e+02,
    ],
    [
        0.19985053242002433820987653617e+02,
        -0.38703730874935176555105901742e+03,
        -0.18917813819516756882830838328e+03,
        0.52780815920542364900561016686e+03,
        -0.11573902539959630126141871134e+02,
        0.68812326946963000169666922661e+01,
        -0.10006050966910838403183860980e+01,
        0.77771377980534432092869265740e+00,
        -0.27782057523535084065932004339e+01,
        -0.60196695231264120758267380846e+02,
        0.84320405506677161018159903784e+02,
        0.11992291136182789328035130030e+02,
    ],
    [
        -0.25693933462703749003312586129e+02,
        -0.15418974869023643374053993627e+03,
        -0.23152937917604549567536039109e+03,
        0.35763911791061412378285349910e+03,
        0.93405324183624310003907691704e+02,
        -0.37458323136451633156875139351e+02,
        0.10409964950896230045147246184e+03,
        0.29840293426660503123344363579e+02,
        -0.43533456590011143754432175058e+02,
        0.96324553959188282948394950600e+02,
        -0.39177261675615439165231486172e+02,
        -0.14972683625798562581422125276e+03,
    ],
];

/// One accepted step from `t0` to `t1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dop853Step<const N: usize> {
    /// The independent variable at the start of the step.
    pub t0: f64,
    /// The independent variable at the end of the step.
    pub t1: f64,
    /// The state at `t0`.
    pub y0: SVector<f64, N>,
    /// The state at `t1`.
    pub y1: SVector<f64, N>,
}

/// The 7th-order continuous extension of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dense<const N: usize> {
    /// The independent variable at the start of the step.
    pub t0: f64,
    /// The independent variable at the end of the step.
    pub t1: f64,
    /// y0, then the seven correction terms of the nested form.
    c: [SVector<f64, N>; 8],
}

impl<const N: usize> Dense<N> {
    /// A state held constant at `y` over [t0, t1].
    pub(crate) fn constant(t0: f64, t1: f64, y: SVector<f64, N>) -> Self {
        let zero = SVector::<f64, N>::zeros();
        Dense {
            t0,
            t1,
            c: [y, zero, zero, zero, zero, zero, zero, zero],
        }
    }

    /// The interpolated state at `t` ∈ [t0, t1].
    #[inline]
    pub fn at(&self, t: f64) -> SVector<f64, N> {
        let h = self.t1 - self.t0;
        let th = if h > 0.0 { (t - self.t0) / h } else { 0.0 };
        let th1 = 1.0 - th;
        let [c0, c1, c2, c3, c4, c5, c6, c7] = &self.c;
        // Hairer's nested form: corrections alternate factors θ and 1 − θ,
        // so each vanishes at both ends except the first.
        let tail = c5 + (c6 + c7 * th) * th1;
        let tail = c3 + (c4 + tail * th) * th1;
        c0 + (c1 + (c2 + tail * th) * th1) * th
    }
}

impl<const N: usize> Dense<N> {
    /// The interpolant as a polynomial in `θ = (t − t0)/(t1 − t0)`: its
    /// coefficients of `θ⁰ … θ⁷`, expanded from the nested form.
    pub(crate) fn monomial(&self) -> [SVector<f64, N>; 8] {
        let zero = SVector::<f64, N>::zeros();
        // p·θ and p·(1 − θ) on coefficient arrays.
        let times_theta = |p: &[SVector<f64, N>; 8]| {
            let mut q = [zero; 8];
            q[1..].copy_from_slice(&p[..7]);
            q
        };
        let times_one_minus = |p: &[SVector<f64, N>; 8]| {
            let shifted = times_theta(p);
            std::array::from_fn(|k| p[k] - shifted[k])
        };
        let plus = |c: &SVector<f64, N>, mut p: [SVector<f64, N>; 8]| {
            p[0] += c;
            p
        };
        let [c0, c1, c2, c3, c4, c5, c6, c7] = &self.c;
        let mut u = [zero; 8];
        u[0] = *c6;
        u[1] = *c7;
        let u = plus(c5, times_one_minus(&u));
        let t = plus(c4, times_theta(&u));
        let t = plus(c3, times_one_minus(&t));
        let p = plus(c2, times_theta(&t));
        let p = plus(c1, times_one_minus(&p));
        plus(c0, times_theta(&p))
    }
}

/// DOP853 stepper for `ẏ = f(t, y)`.
///
/// The error of the first `M` components (all, by default) sets the step
/// size. Any further ones must be quadratures that the right-hand side
/// does not read, such as the physical time in a system integrated in a
/// fictitious time: they are integrated by the same formula, to the same
/// order, and their error follows that of the components they integrate,
/// so controlling them too only costs work.
pub struct Dop853<const N: usize, F, const M: usize = N>
where
    F: Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
{
    f: F,
    tol: StepTolerance<N>,
    t: f64,
    y: SVector<f64, N>,
    /// f(t, y), reused as the first stage (first same as last).
    k1: SVector<f64, N>,
    h: f64,
    /// The last accepted step, and f at its stages 1, 6–13 (stages 2–5
    /// carry no weight in the interpolant; stage 13 is f(t1, y1)): what
    /// [`Dop853::dense`] is built from.
    last: Dop853Step<N>,
    stages: [SVector<f64, N>; 9],
    /// Whether the last trial step was rejected (then the next accepted
    /// step must not grow).
    rejected: bool,
    /// Number of right-hand-side evaluations so far.
    pub evaluations: usize,
}

impl<const N: usize, F> Dop853<N, F>
where
    F: Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
{
    /// Start at (`t0`, `y0`) with a first trial step `h0` (> 0), every
    /// component controlled.
    pub fn new(f: F, t0: f64, y0: SVector<f64, N>, h0: f64, tol: StepTolerance<N>) -> Self {
        let k1 = f(t0, &y0);
        Dop853 {
            f,
            tol,
            t: t0,
            y: y0,
            k1,
            h: h0,
            last: Dop853Step {
                t0,
                t1: t0,
                y0,
                y1: y0,
            },
            stages: [k1; 9],
            rejected: false,
            evaluations: 1,
        }
    }

    /// The same solver with only the first `K` components controlled (the
    /// rest quadratures, see [`Dop853`]).
    pub fn controlling_first<const K: usize>(self) -> Dop853<N, F, K> {
        let Dop853 {
            f,
            tol,
            t,
            y,
            k1,
            h,
            last,
            stages,
            rejected,
            evaluations,
        } = self;
        Dop853 {
            f,
            tol,
            t,
            y,
            k1,
            h,
            last,
            stages,
            rejected,
            evaluations,
        }
    }
}

impl<const N: usize, F, const M: usize> Dop853<N, F, M>
where
    F: Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
{
    /// The current time.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// The current state.
    pub fn y(&self) -> SVector<f64, N> {
        self.y
    }

    /// The step size the controller would try next.
    pub fn next_step(&self) -> f64 {
        self.h
    }

    /// Advance one accepted step, never past `t_stop`.
    ///
    /// Always inlined: a caller has one call site per right-hand side, in
    /// its loop, and inlined there the step's state stays in registers
    /// from one step to the next (10 % on the Hunt–Crossley benchmark,
    /// where the compiler otherwise declines once there are several
    /// right-hand sides).
    #[inline(always)]
    pub fn step(&mut self, t_stop: f64) -> Result<Dop853Step<N>, MechanicsError> {
        let f = &self.f;
        let (t, y, k1) = (self.t, self.y, self.k1);
        loop {
            let (h, last) = trial_step(self.h, t, t_stop)?;
            // Each stage's input is y + h·Σ a_ij k_j. The newest stage is
            // added last, on its own: the rest is ready earlier, so the
            // chain of dependent operations from one stage to the next is
            // just a multiply and an add (the steps are latency-bound).
            let k2 = f(t + C2 * h, &(y + k1 * (A21 * h)));
            let k3 = f(t + C3 * h, &(y + k1 * (A31 * h) + k2 * (A32 * h)));
            let k4 = f(t + C4 * h, &(y + k1 * (A41 * h) + k3 * (A43 * h)));
            let k5 = f(
                t + C5 * h,
                &(y + (k1 * A51 + k3 * A53) * h + k4 * (A54 * h)),
            );
            let k6 = f(
                t + C6 * h,
                &(y + (k1 * A61 + k4 * A64) * h + k5 * (A65 * h)),
            );
            let k7 = f(
                t + C7 * h,
                &(y + (k1 * A71 + k4 * A74 + k5 * A75) * h + k6 * (A76 * h)),
            );
            let k8 = f(
                t + C8 * h,
                &(y + (k1 * A81 + k4 * A84 + k5 * A85 + k6 * A86) * h + k7 * (A87 * h)),
            );
            let k9 = f(
                t + C9 * h,
                &(y + (k1 * A91 + k4 * A94 + k5 * A95 + k6 * A96 + k7 * A97) * h + k8 * (A98 * h)),
            );
            let k10 = f(
                t + C10 * h,
                &(y + (k1 * A101 + k4 * A104 + k5 * A105 + k6 * A106 + k7 * A107 + k8 * A108) * h
                    + k9 * (A109 * h)),
            );
            let k11 = f(
                t + C11 * h,
                &(y + (k1 * A111
                    + k4 * A114
                    + k5 * A115
                    + k6 * A116
                    + k7 * A117
                    + k8 * A118
                    + k9 * A119)
                    * h
                    + k10 * (A1110 * h)),
            );
            let t1 = if last { t_stop } else { t + h };
            let k12 = f(
                t1,
                &(y + (k1 * A121
                    + k4 * A124
                    + k5 * A125
                    + k6 * A126
                    + k7 * A127
                    + k8 * A128
                    + k9 * A129
                    + k10 * A1210)
                    * h
                    + k11 * (A1211 * h)),
            );
            let slope =
                k1 * B1 + k6 * B6 + k7 * B7 + k8 * B8 + k9 * B9 + k10 * B10 + k11 * B11 + k12 * B12;
            let y1 = y + slope * h;
            self.evaluations += 11;
            let err3 = slope - k1 * BHH1 - k9 * BHH2 - k12 * BHH3;
            let err5 = k1 * ER1
                + k6 * ER6
                + k7 * ER7
                + k8 * ER8
                + k9 * ER9
                + k10 * ER10
                + k11 * ER11
                + k12 * ER12;
            let (mut sum3, mut sum5) = (0.0, 0.0);
            for i in 0..M {
                let scale = self.tol.atol[i] + self.tol.rtol * y[i].abs().max(y1[i].abs());
                // One division per component, not two.
                let inv = 1.0 / scale;
                let (r3, r5) = (err3[i] * inv, err5[i] * inv);
                sum3 += r3 * r3;
                sum5 += r5 * r5;
            }
            // Hairer's combination: the 5th-order estimate, damped by the
            // 3rd-order one where that is the more pessimistic (large h).
            let deno = if sum5 + 0.01 * sum3 > 0.0 {
                sum5 + 0.01 * sum3
            } else {
                1.0
            };
            // The squared error, err² = (h·sum5)² / (N·deno): no square root
            // on the way from the stages to the next step size.
            let hs = h * sum5;
            let err2 = hs * hs / (M as f64 * deno);
            if !err2.is_finite() {
                self.h = 0.1 * h;
                self.rejected = true;
                continue;
            }
            // Controller: growth within [0.333, 6]; the safety factor 0.87
            // with the root's overestimate (≤ 6.6 %) is Hairer's 0.9 ± 3 %.
            let factor = if err2 == 0.0 {
                6.0
            } else {
                (0.87 * inverse_16th_root(err2)).clamp(0.333, 6.0)
            };
            if err2 <= 1.0 {
                let k13 = f(t1, &y1);
                self.evaluations += 1;
                let step = Dop853Step {
                    t0: t,
                    t1,
                    y0: y,
                    y1,
                };
                self.last = step;
                self.stages = [k1, k6, k7, k8, k9, k10, k11, k12, k13];
                self.t = t1;
                self.y = y1;
                self.k1 = k13;
                if !last {
                    self.h = h * if self.rejected {
                        factor.min(1.0)
                    } else {
                        factor
                    };
                }
                self.rejected = false;
                return Ok(step);
            }
            self.h = h * factor.min(1.0);
            self.rejected = true;
        }
    }

    /// The continuous extension of the step [`Dop853::step`] returned
    /// last (three more evaluations).
    pub fn dense(&mut self) -> Dense<N> {
        let f = &self.f;
        let step = self.last;
        let (t, y) = (step.t0, step.y0);
        let h = step.t1 - step.t0;
        let [k1, k6, k7, k8, k9, k10, k11, k12, k13] = self.stages;
        let k14 = f(
            t + C14 * h,
            &(y + (k1 * A141
                + k7 * A147
                + k8 * A148
                + k9 * A149
                + k10 * A1410
                + k11 * A1411
                + k12 * A1412
                + k13 * A1413)
                * h),
        );
        let k15 = f(
            t + C15 * h,
            &(y + (k1 * A151
                + k6 * A156
                + k7 * A157
                + k8 * A158
                + k11 * A1511
                + k12 * A1512
                + k13 * A1513
                + k14 * A1514)
                * h),
        );
        let k16 = f(
            t + C16 * h,
            &(y + (k1 * A161
                + k6 * A166
                + k7 * A167
                + k8 * A168
                + k9 * A169
                + k13 * A1613
                + k14 * A1614
                + k15 * A1615)
                * h),
        );
        self.evaluations += 3;
        let stages = [k1, k6, k7, k8, k9, k10, k11, k12, k13, k14, k15, k16];
        let dy = step.y1 - y;
        let bspl = k1 * h - dy;
        let mut c = [y, dy, bspl, dy - k13 * h - bspl, y, y, y, y];
        for (r, row) in D.iter().enumerate() {
            let mut sum = SVector::<f64, N>::zeros();
            for (k, d) in stages.iter().zip(row) {
                sum += k * *d;
            }
            c[4 + r] = sum * h;
        }
        Dense {
            t0: step.t0,
            t1: step.t1,
            c,
        }
    }
}

/// x^(−1/16) for normal x > 0, high by 0 to 6.6 %: the controller's
/// factor err^(−1/8) from err².
///
/// The controller needs only a rough factor (it multiplies it by a safety
/// factor anyway), but it sits on the chain of dependent operations of
/// every step, where `powf` or four square roots cost 60–100 cycles. The
/// bits of a positive f64 read as an integer are 2⁵²·(e + m + 1023) for
/// x = 2ᵉ(1 + m), and e + m is log2 x to within 0.086, so multiplying the
/// logarithm by −1/16 is an integer division and a subtraction (the idea
/// of the well-known fast inverse square root). Exact at x = 1.
fn inverse_16th_root(x: f64) -> f64 {
    const ONE: u64 = 1.0f64.to_bits();
    f64::from_bits(ONE + ONE / 16 - x.to_bits() / 16)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::linalg::Vector2;

    #[test]
    fn inverse_16th_root_is_within_its_bound() {
        assert_eq!(inverse_16th_root(1.0), 1.0);
        for k in -2000..2000 {
            let x = 10f64.powf(k as f64 * 0.15);
            let rel = inverse_16th_root(x) / x.powf(-1.0 / 16.0) - 1.0;
            assert!((0.0..0.067).contains(&rel), "{x}: {rel}");
        }
    }

    /// Every stage's weights sum to its node (the method is consistent).
    #[test]
    fn rows_sum_to_their_nodes() {
        let rows: [(f64, &[f64]); 14] = [
            (C2, &[A21]),
            (C3, &[A31, A32]),
            (C4, &[A41, A43]),
            (C5, &[A51, A53, A54]),
            (C6, &[A61, A64, A65]),
            (C7, &[A71, A74, A75, A76]),
            (C8, &[A81, A84, A85, A86, A87]),
            (C9, &[A91, A94, A95, A96, A97, A98]),
            (C10, &[A101, A104, A105, A106, A107, A108, A109]),
            (C11, &[A111, A114, A115, A116, A117, A118, A119, A1110]),
            (
                1.0,
                &[A121, A124, A125, A126, A127, A128, A129, A1210, A1211],
            ),
            (C14, &[A141, A147, A148, A149, A1410, A1411, A1412, A1413]),
            (C15, &[A151, A156, A157, A158, A1511, A1512, A1513, A1514]),
            (C16, &[A161, A166, A167, A168, A169, A1613, A1614, A1615]),
        ];
        for (c, row) in rows {
            let sum: f64 = row.iter().sum();
            assert!((sum - c).abs() < 1e-14, "{c}: {sum}");
        }
    }

    /// The quadrature conditions Σ bᵢ cᵢᵏ = 1/(k + 1) up to order 8, and
    /// those of the two embedded error estimates (which vanish for the
    /// orders they are exact to).
    #[test]
    fn weights_integrate_polynomials_to_order_eight() {
        let c = [1.0, C6, C7, C8, C9, C10, C11, 1.0];
        let b = [B1, B6, B7, B8, B9, B10, B11, B12];
        let er = [ER1, ER6, ER7, ER8, ER9, ER10, ER11, ER12];
        for k in 0..8 {
            let ck = |i: usize| if i == 0 { 0f64.powi(k) } else { c[i].powi(k) };
            let sum: f64 = (0..8).map(|i| b[i] * ck(i)).sum();
            assert!((sum - 1.0 / (k as f64 + 1.0)).abs() < 1e-14, "b, k={k}");
            // The 5th-order estimate integrates x⁰ … x⁴ exactly.
            if k < 5 {
                let e: f64 = (0..8).map(|i| er[i] * ck(i)).sum();
                assert!(e.abs() < 1e-13, "er, k={k}: {e}");
            }
        }
        // The 3rd-order weights sit on stages 1, 9 and 12 and integrate
        // x⁰ … x² exactly.
        for k in 0..3 {
            let sum = BHH1 * 0f64.powi(k) + BHH2 * C9.powi(k) + BHH3;
            assert!((sum - 1.0 / (k as f64 + 1.0)).abs() < 1e-14, "bhh, k={k}");
        }
    }

    /// Fixed steps of `h` over [0, 2] on a forced, damped Duffing
    /// oscillator (nonlinear, non-autonomous: it exercises the order
    /// conditions that scalar or linear problems do not). Returns the state
    /// at every multiple of `h / 2`: step ends, and dense output between.
    fn duffing_fixed(h: f64) -> Vec<Vector2<f64>> {
        let loose = StepTolerance {
            rtol: 1e10,
            atol: Vector2::new(1e10, 1e10),
        };
        let mut s = Dop853::new(
            |t: f64, y: &Vector2<f64>| Vector2::new(y[1], -y[0].powi(3) - 0.1 * y[1] + t.cos()),
            0.0,
            Vector2::new(1.0, 0.0),
            h,
            loose,
        );
        let n = (2.0 / h).round() as usize;
        let mut out = vec![s.y()];
        for j in 1..=n {
            let st = s.step(j as f64 * h).unwrap();
            let dense = s.dense();
            out.push(dense.at(0.5 * (st.t0 + st.t1)));
            out.push(st.y1);
        }
        out
    }

    #[test]
    fn fixed_steps_converge_at_order_eight_and_dense_output_at_seven() {
        let reference = duffing_fixed(0.2 / 32.0);
        let error = |h: f64| {
            let run = duffing_fixed(h);
            let stride = (reference.len() - 1) / (run.len() - 1);
            let (mut ends, mut mids): (f64, f64) = (0.0, 0.0);
            for (i, y) in run.iter().enumerate() {
                let e = (y - reference[i * stride]).norm();
                if i % 2 == 0 {
                    ends = ends.max(e);
                } else {
                    mids = mids.max(e);
                }
            }
            (ends, mids)
        };
        let (ends1, mids1) = error(0.2);
        let (ends2, mids2) = error(0.1);
        // Halving h divides the error by 2⁸ = 256 at step ends and by
        // 2⁷ = 128 in between (a wrong coefficient drops the order).
        assert!(ends1 / ends2 > 150.0, "{ends1} / {ends2}");
        assert!(mids1 / mids2 > 80.0, "{mids1} / {mids2}");
    }

    #[test]
    fn a_quadrature_left_out_of_the_control_stays_accurate() {
        // ẍ = −x from (1, 0) with q' = x: q = sin t. Only (x, ẋ) set the
        // steps (M = 2).
        let tol = StepTolerance {
            rtol: 1e-9,
            atol: crate::mechanics::linalg::Vector3::new(1e-9, 1e-9, f64::NAN),
        };
        let mut s = Dop853::new(
            |_t, y: &crate::mechanics::linalg::Vector3<f64>| {
                crate::mechanics::linalg::Vector3::new(y[1], -y[0], y[0])
            },
            0.0,
            crate::mechanics::linalg::Vector3::new(1.0, 0.0, 0.0),
            1e-2,
            tol,
        )
        .controlling_first::<2>();
        while s.t() < 20.0 {
            let st = s.step(20.0).unwrap();
            assert!((st.y1[2] - st.t1.sin()).abs() < 1e-8, "{}", st.t1);
        }
    }

    fn oscillator(rtol: f64) -> (f64, f64, usize) {
        // ẍ = −x, x(0) = 1: x = cos t.
        let tol = StepTolerance {
            rtol,
            atol: Vector2::new(rtol, rtol),
        };
        let mut s = Dop853::new(
            |_t, y: &Vector2<f64>| Vector2::new(y[1], -y[0]),
            0.0,
            Vector2::new(1.0, 0.0),
            1e-3,
            tol,
        );
        let (mut worst_end, mut worst_dense): (f64, f64) = (0.0, 0.0);
        let mut steps = 0;
        while s.t() < 10.0 {
            let st = s.step(10.0).unwrap();
            steps += 1;
            let t = st.t1;
            worst_end = worst_end.max((st.y1[0] - t.cos()).abs());
            let dense = s.dense();
            assert_eq!(dense.at(st.t0), st.y0);
            assert!((dense.at(st.t1) - st.y1).norm() < 1e-15);
            for k in 0..=8 {
                let t = st.t0 + (st.t1 - st.t0) * k as f64 / 8.0;
                let y = dense.at(t);
                worst_dense = worst_dense
                    .max((y[0] - t.cos()).abs())
                    .max((y[1] + t.sin()).abs());
            }
        }
        assert_eq!(s.t(), 10.0);
        (worst_end, worst_dense, steps)
    }

    #[test]
    fn steps_and_dense_output_track_the_exact_solution() {
        let (end6, dense6, steps6) = oscillator(1e-6);
        let (end10, dense10, steps10) = oscillator(1e-10);
        assert!(end6 < 1e-5 && dense6 < 1e-5, "{end6} {dense6}");
        assert!(end10 < 1e-9 && dense10 < 1e-9, "{end10} {dense10}");
        // 8th order: 10⁴ in tolerance costs about 10^(4/8) ≈ 3 times the
        // steps (a 5th-order method would need 6).
        let ratio = steps10 as f64 / steps6 as f64;
        assert!(ratio > 2.0 && ratio < 4.5, "{steps6} → {steps10}");
    }
}
