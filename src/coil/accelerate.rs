//! A better next path for the coupling: the circuit's last run taken as
//! a voltage source, the coil and the mechanics settled against it with
//! no ngspice run.
//!
//! The plain relaxation hands the mechanics' path straight back to
//! ngspice, so every pass settles the two-way coupling between the
//! armature and the coil's flux (the back-EMF `i L'(x) ẋ`, the current
//! that a smaller gap draws at the same flux) only a little further. But
//! that coupling lives in the coil, whose equation is known here:
//!
//! ```text
//! dψ/dt = v(t) − R ψ (a − x(t)) / k
//! ```
//!
//! What ngspice adds is only the driver, i.e. how the coil's terminal
//! voltage `v(t)` answers the coil current; a transistor in saturation or
//! a conducting flyback diode or zener hold it almost fixed. So, given
//! ngspice's run `k` along the path `x_k` (its flux `ψ_k`, its terminal
//! voltage `v_k`), the pull along another path `x` is estimated as
//!
//! ```text
//! ψ(x) ≈ ψ_k + Φ(v_k, x) − Φ(v_k, x_k)
//! ```
//!
//! with `Φ(v, x)` the coil equation integrated under the fixed voltage
//! `v_k`. The correction vanishes at `x = x_k`, so a path that agrees with
//! its own ngspice run is a fixed point here too: the accelerated loop
//! converges to the same answer as the plain one, only with fewer
//! ngspice runs (the estimate is a defect correction, exact up to how far
//! the driver's voltage moves with the current). That movement is taken
//! into account to first order: where the run shows the terminal voltage
//! following the current (a conducting flyback diode or zener), the slope
//! dv/di read along the run makes the estimate's driver a source with
//! that resistance (`Driver`); on the diode example this saves one
//! of five ngspice passes. The path for the next
//! ngspice run is the fixed point of this cheap map, found by relaxation
//! among the mechanics runs alone.

use super::magnet::{Coil, CoilError};
use crate::mechanics::cycle::Stops;
use crate::mechanics::two_stage::{TwoStage, driven_run};
use crate::mechanics::{Mechanics, Settings, Trajectory};

/// One ngspice run of the coil: its time points, the voltage across the
/// coil and its flux linkage there, and the armature path it followed.
pub struct CircuitRun<'a> {
    /// s, the run's time points.
    pub time: &'a [f64],
    /// V, the voltage across the coil at each time point.
    pub volts: &'a [f64],
    /// Wb (V·s), the coil's flux linkage ψ at each time point.
    pub flux: &'a [f64],
    /// (s, m): the path given to ngspice.
    pub path: &'a [(f64, f64)],
}

/// The coupling's tolerances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CouplingTolerances {
    /// s, on the event times.
    pub events: f64,
    /// m, to which paths are thinned before they go to ngspice.
    pub path: f64,
}

/// The old name of [`CouplingTolerances`].
#[deprecated(note = "renamed to `CouplingTolerances`")]
pub type Tolerances = CouplingTolerances;

/// How many mechanics runs the inner relaxation may take per ngspice run:
/// each costs a few milliseconds, and the inner map contracts as fast as
/// the plain coupling did (some ten passes to 0.1 µs on the slow diode
/// release); beyond this the next ngspice run starts from the best path
/// found so far, which is still a valid start.
const MAX_INNER: usize = 40;

/// The inner relaxation settles to this fraction of the coupling's
/// tolerance, so that the next ngspice run's change is its own defect,
/// not the inner loop's leftover.
const INNER_FRACTION: f64 = 0.1;

/// The armature's cycle at the fixed point of the estimated pull (see the
/// module notes), starting from `start`, the mechanics under the run's own
/// flux. Returns the cycle and the number of mechanics runs it took.
#[allow(clippy::too_many_arguments)] // the relay, its stops and the run's tolerances, as the pass has them
pub fn settle(
    coil: &Coil,
    run: &CircuitRun,
    start: Trajectory,
    mechanics: &Mechanics,
    build: &TwoStage,
    stops: &Stops,
    settings: &Settings,
    tolerances: CouplingTolerances,
) -> Result<(Trajectory, usize), CoilError> {
    let driver = Driver::of(coil, run);
    let base = flux_under(coil, run, &driver, run.path);
    let mut current = start;
    for inner in 1..=MAX_INNER {
        // The path as ngspice would be given it (thinned like `run.path`):
        // at the fixed point the correction must vanish exactly, or its
        // leftover would bias the next run's events.
        let phi = flux_under(
            coil,
            run,
            &driver,
            &super::samples::thin(&current.path(), tolerances.path),
        );
        let estimate: Vec<(f64, f64)> = (0..run.time.len())
            .map(|j| (run.time[j], run.flux[j] + phi[j] - base[j]))
            .collect();
        let flux_at = super::samples::Interpolator::new(&estimate);
        let pull = |t: f64, _x: f64| coil.force_from_flux(flux_at.at(t));
        let next = driven_run(mechanics, build, stops, settings, &pull)?;
        let moved = super::samples::event_change(current.chatter(), next.chatter()).max(
            super::samples::event_change(
                super::samples::back_of(&current),
                super::samples::back_of(&next),
            ),
        );
        current = next;
        if moved <= INNER_FRACTION * tolerances.events {
            return Ok((current, inner));
        }
    }
    Ok((current, MAX_INNER))
}

/// Wb, the coil's flux linkage at each of the run's time points under
/// its terminal voltage, with the armature following `path`: the
/// trapezoidal rule, which for this linear equation in ψ is solved for
/// the new value in closed form, from ngspice's own first value.
pub fn flux_along(coil: &Coil, run: &CircuitRun, path: &[(f64, f64)]) -> Vec<f64> {
    flux_under(coil, run, &Driver::of(coil, run), path)
}

/// [`flux_along`] with the run's driver already read (it depends on the
/// run only, not on the path being tried).
fn flux_under(coil: &Coil, run: &CircuitRun, driver: &Driver, path: &[(f64, f64)]) -> Vec<f64> {
    let n = run.time.len();
    let mut out = Vec::with_capacity(n);
    let Some(&first) = run.flux.first() else {
        return out;
    };
    let k = coil.permeance_length();
    let a = coil.air_gap + coil.iron_gap;
    // dψ/dt = u − c ψ with c = (R − s)(a − x)/k (see [`Driver`]).
    let x = super::samples::Interpolator::new(path);
    let rate = |j: usize| (coil.resistance - driver.slope[j]) * (a - x.at(run.time[j])) / k;
    let mut psi = first;
    let mut c0 = rate(0);
    out.push(psi);
    for j in 1..n {
        let h = run.time[j] - run.time[j - 1];
        let c1 = rate(j);
        let rhs = psi + 0.5 * h * (driver.source[j - 1] - c0 * psi + driver.source[j]);
        psi = rhs / (1.0 + 0.5 * h * c1);
        out.push(psi);
        c0 = c1;
    }
    out
}

/// The coil's terminal as the run shows it: `v = v_k + s (i − i_k)`, the
/// run's voltage plus the driver's answer to a change of current, at each
/// of the run's time points. The coil equation then reads
/// `dψ/dt = u − (R − s)(a − x)/k · ψ` with `u = v_k − s i_k`.
struct Driver {
    /// Ω, dv/di of the driver.
    slope: Vec<f64>,
    /// V, `u = v_k − s i_k`.
    source: Vec<f64>,
}

impl Driver {
    /// dv/di is read along the run itself: where the coil's terminal
    /// voltage is a static function of its current (a conducting flyback
    /// diode or zener, a saturated transistor), the ratio of their changes
    /// between neighbouring points is its slope. A driver only ever lowers
    /// the voltage as it gives more current, so the slope is kept within
    /// [−SLOPE_LIMIT·R, 0]; where the current barely moves (a switching
    /// edge) it is taken as 0.
    fn of(coil: &Coil, run: &CircuitRun) -> Driver {
        let n = run.time.len();
        let k = coil.permeance_length();
        let a = coil.air_gap + coil.iron_gap;
        let x = super::samples::Interpolator::new(run.path);
        let current: Vec<f64> = (0..n)
            .map(|j| run.flux[j] * (a - x.at(run.time[j])) / k)
            .collect();
        let scale = current.iter().fold(0.0f64, |m, i| m.max(i.abs()));
        let slope: Vec<f64> = (0..n)
            .map(|j| {
                let (lo, hi) = (j.saturating_sub(1), (j + 1).min(n.saturating_sub(1)));
                let di = current[hi] - current[lo];
                if hi == lo || di.abs() <= 1e-6 * scale {
                    return 0.0;
                }
                ((run.volts[hi] - run.volts[lo]) / di).clamp(-SLOPE_LIMIT * coil.resistance, 0.0)
            })
            .collect();
        let source = (0..n)
            .map(|j| run.volts[j] - slope[j] * current[j])
            .collect();
        Driver { slope, source }
    }
}

/// The steepest driver slope believed, in coil resistances.
const SLOPE_LIMIT: f64 = 10.0;

#[cfg(test)]
mod tests {
    use super::*;

    fn coil() -> Coil {
        Coil {
            resistance: 70.0,
            turns: 3000.0,
            pole_area: 2e-5,
            air_gap: 6e-4,
            iron_gap: 5e-5,
        }
    }

    #[test]
    fn the_driver_slope_is_read_from_a_static_clamp() {
        // A held coil freewheeling through a clamp v = −(0.7 + 5 i): the
        // current decays, and along the run dv/di is the clamp's −5 Ω;
        // a fixed source has none.
        let coil = coil();
        let l = coil.inductance(0.0);
        let time: Vec<f64> = (0..=2000).map(|j| f64::from(j) * 1e-6).collect();
        let current: Vec<f64> = time.iter().map(|t| 0.07 * (-t * 75.0 / l).exp()).collect();
        let flux: Vec<f64> = current.iter().map(|i| l * i).collect();
        let clamp: Vec<f64> = current.iter().map(|i| -(0.7 + 5.0 * i)).collect();
        let fixed = vec![5.0; time.len()];
        let path = [(0.0, 0.0), (1.0, 0.0)];
        for (volts, want) in [(&clamp, -5.0), (&fixed, 0.0)] {
            let run = CircuitRun {
                time: &time,
                volts,
                flux: &flux,
                path: &path,
            };
            for s in Driver::of(&coil, &run).slope {
                assert!((s - want).abs() < 1e-6, "{s} vs {want}");
            }
        }
        // A voltage step with no change of current is not believed.
        let step: Vec<f64> = (0..time.len())
            .map(|j| if j < 1000 { 5.0 } else { -0.7 })
            .collect();
        let held = vec![0.07 * l; time.len()];
        let run = CircuitRun {
            time: &time,
            volts: &step,
            flux: &held,
            path: &path,
        };
        assert!(Driver::of(&coil, &run).slope.iter().all(|&s| s == 0.0));
    }

    #[test]
    fn the_held_coil_charges_as_an_rl_circuit() {
        // A held armature under a 5 V step: ψ = L V/R (1 − e^(−t R/L)).
        let coil = coil();
        let time: Vec<f64> = (0..=20_000).map(|j| f64::from(j) * 1e-6).collect();
        let volts = vec![5.0; time.len()];
        let flux = vec![0.0; time.len()];
        let path = [(0.0, 0.0), (1.0, 0.0)];
        let run = CircuitRun {
            time: &time,
            volts: &volts,
            flux: &flux,
            path: &path,
        };
        let psi = flux_along(&coil, &run, &path);
        let l = coil.inductance(0.0);
        let tau = l / coil.resistance;
        for (j, &t) in time.iter().enumerate().step_by(997) {
            let exact = l * 5.0 / coil.resistance * (1.0 - (-t / tau).exp());
            assert!(
                (psi[j] - exact).abs() <= 1e-6 * l * 5.0 / 70.0,
                "{t}: {} {exact}",
                psi[j]
            );
        }
    }

    #[test]
    fn a_closed_armature_charges_with_the_closed_gaps_inductance() {
        // Held closed at x: the flux heads for L(x) V/R, three times the open
        // coil's.
        let coil = coil();
        let x = 4.5e-4;
        let time: Vec<f64> = (0..=200_000).map(|j| f64::from(j) * 1e-6).collect();
        let volts = vec![5.0; time.len()];
        let flux = vec![0.0; time.len()];
        let path = [(0.0, x), (1.0, x)];
        let run = CircuitRun {
            time: &time,
            volts: &volts,
            flux: &flux,
            path: &path,
        };
        let psi = flux_along(&coil, &run, &path);
        // The RL charge with the closed gap's inductance, 12 of its time
        // constants along.
        let l = coil.inductance(x);
        let steady = l * 5.0 / coil.resistance;
        let t = *time.last().unwrap();
        let exact = steady * (1.0 - (-t * coil.resistance / l).exp());
        assert!((psi.last().unwrap() / exact - 1.0).abs() < 1e-9);
        assert!(*psi.last().unwrap() > 2.0 * coil.inductance(0.0) * 5.0 / coil.resistance);
    }
}
