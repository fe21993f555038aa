//! Adaptive Runge–Kutta integration with dense output, for the pieces of
//! motion that have no closed form (later, a force that varies in time).
//! The Hunt–Crossley contact, which needs tight tolerances, uses the
//! higher-order method of `dop853` instead; [`StepTolerance`] serves both.
//!
//! The method is Dormand–Prince 5(4) with its 4th-order continuous
//! extension (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.5–6). It is
//! written here rather than taken from a crate because the engine needs to
//! drive it one step at a time and locate events on each step's dense
//! output, and because the states are tiny (2–3 components): a
//! stack-allocated `SVector` step is a few dozen flops.
//!
//! The caller owns the loop ([`Dopri5::step`] returns one accepted
//! [`Dopri5Step`]), checks its events on the step, and stops when it likes; so
//! events are bracketed by the step and polished on the interpolant.

use crate::mechanics::linalg::SVector;

use super::error::MechanicsError;
pub use super::step_control::StepTolerance;
use super::step_control::trial_step;

/// One accepted step from `t0` to `t1`, with the coefficients of its
/// continuous extension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dopri5Step<const N: usize> {
    /// The independent variable at the start of the step.
    pub t0: f64,
    /// The independent variable at the end of the step.
    pub t1: f64,
    /// The state at `t0`.
    pub y0: SVector<f64, N>,
    /// The state at `t1`.
    pub y1: SVector<f64, N>,
    cont: [SVector<f64, N>; 4],
}

impl<const N: usize> Dopri5Step<N> {
    /// The dense-output state at `t` ∈ [t0, t1] (4th order accurate).
    pub fn at(&self, t: f64) -> SVector<f64, N> {
        let h = self.t1 - self.t0;
        let th = if h > 0.0 { (t - self.t0) / h } else { 0.0 };
        let th1 = 1.0 - th;
        let [c2, c3, c4, c5] = &self.cont;
        self.y0 + (c2 + (c3 + (c4 + c5 * th1) * th) * th1) * th
    }
}

/// The old name of [`StepTolerance`].
#[deprecated(note = "renamed to `StepTolerance`")]
pub type Tolerance<const N: usize> = StepTolerance<N>;

/// The old name of [`Dopri5Step`].
#[deprecated(note = "renamed to `Dopri5Step`")]
pub type Step<const N: usize> = Dopri5Step<N>;

/// Dormand–Prince 5(4) stepper for `ẏ = f(t, y)`.
pub struct Dopri5<const N: usize, F>
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
    /// Number of right-hand-side evaluations so far.
    pub evaluations: usize,
}

// Butcher tableau of Dormand & Prince (1980).
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// Error coefficients: 5th-order weights minus the embedded 4th-order ones.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Continuous extension.
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

impl<const N: usize, F> Dopri5<N, F>
where
    F: Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
{
    /// Start at (`t0`, `y0`) with a first trial step `h0` (> 0): the
    /// controller corrects a poor guess within a few steps.
    pub fn new(f: F, t0: f64, y0: SVector<f64, N>, h0: f64, tol: StepTolerance<N>) -> Self {
        let k1 = f(t0, &y0);
        Dopri5 {
            f,
            tol,
            t: t0,
            y: y0,
            k1,
            h: h0,
            evaluations: 1,
        }
    }

    /// The current time.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// The current state.
    pub fn y(&self) -> SVector<f64, N> {
        self.y
    }

    /// Advance one accepted step, never past `t_stop`.
    pub fn step(&mut self, t_stop: f64) -> Result<Dopri5Step<N>, MechanicsError> {
        let f = &self.f;
        let (t, y, k1) = (self.t, self.y, self.k1);
        loop {
            let (h, last) = trial_step(self.h, t, t_stop)?;
            let k2 = f(t + C2 * h, &(y + k1 * (A21 * h)));
            let k3 = f(t + C3 * h, &(y + (k1 * A31 + k2 * A32) * h));
            let k4 = f(t + C4 * h, &(y + (k1 * A41 + k2 * A42 + k3 * A43) * h));
            let k5 = f(
                t + C5 * h,
                &(y + (k1 * A51 + k2 * A52 + k3 * A53 + k4 * A54) * h),
            );
            let t1 = if last { t_stop } else { t + h };
            let k6 = f(
                t1,
                &(y + (k1 * A61 + k2 * A62 + k3 * A63 + k4 * A64 + k5 * A65) * h),
            );
            let y1 = y + (k1 * A71 + k3 * A73 + k4 * A74 + k5 * A75 + k6 * A76) * h;
            let k7 = f(t1, &y1);
            self.evaluations += 6;
            let err_vec = (k1 * E1 + k3 * E3 + k4 * E4 + k5 * E5 + k6 * E6 + k7 * E7) * h;
            let mut sum = 0.0;
            for i in 0..N {
                let scale = self.tol.atol[i] + self.tol.rtol * y[i].abs().max(y1[i].abs());
                let r = err_vec[i] / scale;
                sum += r * r;
            }
            let err = (sum / N as f64).sqrt();
            if !err.is_finite() {
                self.h = 0.1 * h;
                continue;
            }
            // Standard controller: safety 0.9, growth within [0.2, 10].
            let factor = if err == 0.0 {
                10.0
            } else {
                (0.9 * err.powf(-0.2)).clamp(0.2, 10.0)
            };
            if err <= 1.0 {
                let dy = y1 - y;
                let bspl = k1 * h - dy;
                let c4 = dy - k7 * h - bspl;
                let c5 = (k1 * D1 + k3 * D3 + k4 * D4 + k5 * D5 + k6 * D6 + k7 * D7) * h;
                let step = Dopri5Step {
                    t0: t,
                    t1,
                    y0: y,
                    y1,
                    cont: [dy, bspl, c4, c5],
                };
                self.t = t1;
                self.y = y1;
                self.k1 = k7;
                if !last {
                    self.h = h * factor;
                }
                return Ok(step);
            }
            self.h = h * factor.min(1.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::linalg::Vector2;

    fn oscillator_error(rtol: f64) -> f64 {
        // ẍ = −x, x(0) = 1: x = cos t.
        let tol = StepTolerance {
            rtol,
            atol: Vector2::new(rtol, rtol),
        };
        let mut s = Dopri5::new(
            |_t, y: &Vector2<f64>| Vector2::new(y[1], -y[0]),
            0.0,
            Vector2::new(1.0, 0.0),
            1e-3,
            tol,
        );
        let mut worst: f64 = 0.0;
        while s.t() < 10.0 {
            let st = s.step(10.0).unwrap();
            for k in 0..=8 {
                let t = st.t0 + (st.t1 - st.t0) * k as f64 / 8.0;
                let y = st.at(t);
                worst = worst
                    .max((y[0] - t.cos()).abs())
                    .max((y[1] + t.sin()).abs());
            }
        }
        assert_eq!(s.t(), 10.0);
        worst
    }

    #[test]
    fn dense_output_tracks_the_exact_solution() {
        let e6 = oscillator_error(1e-6);
        let e10 = oscillator_error(1e-10);
        assert!(e6 < 1e-5, "{e6}");
        assert!(e10 < 1e-9, "{e10}");
        // Tightening the tolerance must buy accuracy (the method works).
        assert!(e10 < e6 / 100.0);
    }

    #[test]
    fn steps_end_exactly_at_the_stop_time() {
        let tol = StepTolerance {
            rtol: 1e-8,
            atol: SVector::<f64, 1>::new(1e-12),
        };
        let mut s = Dopri5::new(
            |_t, y: &SVector<f64, 1>| -y,
            0.0,
            SVector::<f64, 1>::new(1.0),
            0.1,
            tol,
        );
        let st = s.step(0.05).unwrap();
        assert_eq!(st.t1, 0.05);
        assert!((st.y1[0] - (-0.05f64).exp()).abs() < 1e-10);
    }
}
