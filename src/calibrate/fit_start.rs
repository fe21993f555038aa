//! The fit's first start: the preload and the spring stiffness solved
//! from the pick-up and drop-out voltages over the armature's load line
//! ([`crate::coil::pick_up`]), so that the rest of the fit (the times)
//! starts from a point that already meets them.

use super::Problem;
use super::coil_tolerance_corner;
use crate::coil::Coil;
use crate::coil::pick_up::{LoadLine, drop_out, pick_up};
use crate::scenario::{DatasheetSection, PrintedFigure};

/// The prior, with the preload and the spring stiffness (those of them
/// that are free) solved from the pick-up and drop-out voltages; a key
/// keeps its prior when the voltages give it no positive value.
pub(super) fn closed_form_start(problem: &Problem, u_prior: &[f64]) -> Vec<f64> {
    let mut u = u_prior.to_vec();
    let (Some(d), Some(s)) = (&problem.datasheet, problem.scenario_at(u_prior)) else {
        return u;
    };
    let Some(c) = &s.coil else {
        return u;
    };
    let coil = Coil::from(c);
    let key = |name: &str| problem.keys.iter().position(|k| k == name);
    let (kp, ks) = (key("mechanics.preload"), key("mechanics.stiffness"));
    let line = LoadLine::of_relay(&s.armature(), &s.two_stage());
    let solved = solve_spring(
        &coil,
        &line,
        Currents {
            pick_up: start_voltage(
                d,
                "pick_up_voltage",
                d.pick_up_voltage,
                pick_up(&coil, &line).voltage,
            )
            .map(|v| v / coil.resistance),
            drop_out: start_voltage(
                d,
                "drop_out_voltage",
                d.drop_out_voltage,
                drop_out(&coil, &line).voltage,
            )
            .map(|v| v / coil.resistance),
        },
        kp.is_some(),
        ks.is_some(),
    );
    if let Some(solved) = solved {
        for (k, value) in [(kp, solved.preload), (ks, solved.stiffness)] {
            if let Some(k) = k
                && value > 0.0
                && value.is_finite()
            {
                u[k] = value.ln();
            }
        }
    }
    problem.clamp(&mut u);
    u
}

/// V, the voltage to solve the spring for: a typical figure's value; a
/// bound's only when the prior's `model` voltage crosses it (a prior
/// inside the bound needs no moving); `None` otherwise.
fn start_voltage(
    d: &DatasheetSection,
    name: &str,
    figure: Option<PrintedFigure>,
    model: f64,
) -> Option<f64> {
    let figure = figure?;
    if let Some(t) = figure.typ {
        return Some(t);
    }
    // The bound as the nominal relay must meet it (see
    // `coil_tolerance_corner`): the corner's voltage over the nominal's.
    let scale = coil_tolerance_corner(d, name, &figure, 1.0);
    let (lo, hi) = figure.band();
    let corner = model * scale;
    if corner > hi {
        Some(hi / scale)
    } else if corner < lo {
        Some(lo / scale)
    } else {
        None
    }
}

/// A, the coil currents of the datasheet's pick-up and drop-out voltages.
#[derive(Debug, Clone, Copy)]
pub(super) struct Currents {
    pub pick_up: Option<f64>,
    pub drop_out: Option<f64>,
}

/// The load line with its preload and/or stiffness (as `free_preload`,
/// `free_stiffness` allow) moved so that `coil` picks up and drops out at
/// the given currents; `None` when nothing can be solved (no figure for a
/// free key, or no root with a preload ≥ 0 and a stiffness ≥ 0).
///
/// - Both free, both figures: the drop-out fixes the load at the closed
///   position, `p + s·x_c (+ the blade's) = ½ i_do² L'(x_c)`. Along that
///   line a stiffer spring means a smaller preload and so a smaller load
///   everywhere before `x_c`: the pick-up current falls as `s` grows,
///   from the spring-less `s = 0` to the preload-less end, and the one
///   `s` that meets the pick-up is found by bisection between them.
/// - Only the preload free: from the pick-up if given (the pick-up current
///   grows with `p`), else from the drop-out.
/// - Only the stiffness free: from the drop-out if given, else from the
///   pick-up (which grows with `s`).
pub(super) fn solve_spring(
    coil: &Coil,
    line: &LoadLine,
    currents: Currents,
    free_preload: bool,
    free_stiffness: bool,
) -> Option<LoadLine> {
    let x_c = line.closed_position();
    let with = |preload: f64, stiffness: f64| LoadLine {
        preload,
        stiffness,
        ..*line
    };
    // N, the load at the closed position that the drop-out current only
    // just holds, and the blade's share of it (none without a blade).
    let hold = currents
        .drop_out
        .map(|i| 0.5 * i * i * coil.d_inductance(x_c));
    let blade = with(0.0, 0.0).load(x_c);
    let misses = |l: &LoadLine, i: f64| pick_up(coil, l).current - i;
    let (p, s) = (line.preload, line.stiffness);
    let solved = match (free_preload, free_stiffness, currents.pick_up, hold) {
        (true, true, Some(i), Some(h)) => {
            let preload = |s: f64| h - blade - s * x_c;
            let s_max = (h - blade) / x_c;
            let s = bisect(|s| misses(&with(preload(s), s), i), 0.0, s_max)?;
            with(preload(s), s)
        }
        (true, _, Some(i), _) => {
            // At this preload the rest position alone needs `i`.
            let p_high = 0.5 * i * i * coil.d_inductance(0.0);
            with(bisect(|p| misses(&with(p, s), i), 0.0, p_high)?, s)
        }
        (true, _, None, Some(h)) => with(h - blade - s * x_c, s),
        (false, true, _, Some(h)) => with(p, (h - blade - p) / x_c),
        (false, true, Some(i), None) => {
            let mut high = s.max(1.0);
            for _ in 0..64 {
                if misses(&with(p, high), i) >= 0.0 {
                    break;
                }
                high *= 2.0;
            }
            with(p, bisect(|s| misses(&with(p, s), i), 0.0, high)?)
        }
        _ => return None,
    };
    (solved.preload >= 0.0 && solved.stiffness >= 0.0).then_some(solved)
}

/// A root of `f` in `[low, high]` by bisection; `None` unless `f` changes
/// sign there (or is zero at an end).
pub(super) fn bisect(f: impl Fn(f64) -> f64, mut low: f64, mut high: f64) -> Option<f64> {
    let (mut f_low, f_high) = (f(low), f(high));
    if !(f_low.is_finite() && f_high.is_finite() && low <= high) {
        return None;
    }
    if f_low == 0.0 {
        return Some(low);
    }
    if f_high == 0.0 {
        return Some(high);
    }
    if f_low.signum() == f_high.signum() {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (low + high);
        if mid <= low || mid >= high {
            break;
        }
        let f_mid = f(mid);
        if f_mid == 0.0 {
            return Some(mid);
        }
        if f_mid.signum() == f_low.signum() {
            (low, f_low) = (mid, f_mid);
        } else {
            high = mid;
        }
    }
    Some(0.5 * (low + high))
}
