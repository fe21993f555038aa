//! The solver's stages: a survey of the log-bounds box for starts, the
//! Levenberg–Marquardt refinement from the best of them, one bad edge set
//! aside, and the keys the data cannot see held at their priors.

use super::problem::{Candidate, Held, Point, Problem, halton};
use super::{EXTRA_STARTS, SINGULAR_RATIO, SURVEY_PER_KEY, closed_form_start};

/// The starts of the local solver: the closed-form start, then the best
/// points of a coarse survey of the log-bounds box.
pub(super) fn survey(problem: &Problem, u_prior: &[f64], active: &[usize]) -> Vec<Vec<f64>> {
    // A coarse survey of the log-bounds box (a Halton sequence:
    // deterministic and even) finds the basin: with many bounces the
    // misfit has many local minima where the event count changes, and
    // a local solver started far off lands in one of them.
    const BASES: [usize; 8] = [2, 3, 5, 7, 11, 13, 17, 19];
    let n = problem.keys.len();
    let survey = SURVEY_PER_KEY * n;
    let mut sampled: Vec<(f64, Vec<f64>)> = (1..=survey)
        .map(|i| {
            let u: Vec<f64> = (0..n)
                .map(|k| {
                    let (lo, hi) = (problem.low[k].ln(), problem.high[k].ln());
                    lo + (hi - lo) * halton(i, BASES[k % BASES.len()])
                })
                .collect();
            let cost = problem
                .residuals(&u, active, Candidate::All)
                .map_or(f64::INFINITY, |r| r.iter().map(|x| x * x).sum());
            (cost, u)
        })
        .collect();
    sampled.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut starts = vec![closed_form_start(problem, u_prior)];
    starts.extend(sampled.into_iter().take(EXTRA_STARTS).map(|(_, u)| u));
    starts
}

/// The best point Levenberg–Marquardt reaches from any of `starts`, with
/// every event taking part.
pub(super) fn refine(
    problem: &Problem,
    starts: &[Vec<f64>],
    u_prior: &[f64],
    active: &[usize],
) -> Point {
    let mut best = (u_prior.to_vec(), f64::INFINITY);
    for start in starts {
        let (u, cost) = problem.solve(start, active, Candidate::All);
        if cost < best.1 {
            best = (u, cost);
        }
    }
    best
}

/// With a record: refit from `best` with each adjacent pair of measured,
/// or modelled, events dropped, and keep the drop that cuts the misfit
/// tenfold (saying so in `notes`); else `best` with every event.
pub(super) fn set_aside_bad_edge(
    problem: &Problem,
    best: Point,
    active: &[usize],
    notes: &mut Vec<String>,
) -> (Candidate, Point) {
    let Some(measured) = &problem.measured else {
        return (Candidate::All, best);
    };
    let n_model = problem.evaluate(&best.0).map_or(0, |e| e.model.len());
    let mut alternatives = Vec::new();
    for j in 0..measured.len().saturating_sub(1) {
        alternatives.push(Candidate::DropMeasured(j));
    }
    for j in 0..n_model.saturating_sub(1) {
        alternatives.push(Candidate::DropModel(j));
    }
    let mut chosen = (Candidate::All, best.clone());
    for c in alternatives {
        let (u, cost) = problem.solve(&best.0, active, c);
        if cost < 0.1 * best.1 && cost < chosen.1.1 {
            chosen = (c, (u, cost));
        }
    }
    if chosen.0 != Candidate::All {
        notes.push(match chosen.0 {
            Candidate::DropMeasured(j) => format!(
                "set aside the measured {} at {:.6e} s and the {} after it as a spurious glitch",
                measured[j].kind.as_str(),
                measured[j].time,
                measured[j + 1].kind.as_str()
            ),
            _ => {
                "the model has one bounce the record lacks (a missed edge pair); matched without it"
                    .to_owned()
            }
        });
    }
    chosen
}

/// Hold the keys the data cannot see at their priors, one per
/// near-singular direction of JᵀJ, refitting the rest after each (and
/// saying so in `notes`); `active` loses the held keys.
pub(super) fn hold_blind_keys(
    problem: &Problem,
    mut best: Point,
    candidate: Candidate,
    u_prior: &[f64],
    active: &mut Vec<usize>,
    notes: &mut Vec<String>,
) -> Held {
    let keys = &problem.keys;
    let data_rows = problem.data_len();
    let mut held = vec![false; keys.len()];
    let mut jacobian = None;
    for _ in 0..keys.len() {
        let f = |x: &[f64]| problem.data_residuals(x, candidate);
        let Some(j) = problem.jacobian(&best.0, active, f, data_rows) else {
            break;
        };
        let (eigenvalues, eigenvectors) = j.gram().symmetric_eigen();
        let max = eigenvalues.iter().cloned().fold(0.0, f64::max);
        let (imin, min) =
            eigenvalues
                .iter()
                .cloned()
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |acc, (i, v)| if v < acc.1 { (i, v) } else { acc },
                );
        if max > 0.0 && min > SINGULAR_RATIO * max {
            jacobian = Some(j);
            break;
        }
        // The key with the largest share of the blind direction; on a tie
        // (a pure ratio) the later key in the free list.
        let v = eigenvectors.column(imin);
        let mut pick = 0;
        for i in 0..active.len() {
            if v[i].abs() >= v[pick].abs() - 1e-6 {
                pick = i;
            }
        }
        let k = active[pick];
        let partners: Vec<String> = active
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != pick && v[i].abs() > 0.1)
            .map(|(_, &a)| format!("`{}`", keys[a]))
            .collect();
        held[k] = true;
        active.retain(|&a| a != k);
        best.0[k] = u_prior[k];
        notes.push(format!(
            "`{}` is not determined by the evidence (it moves only together with {}); held at its prior {}",
            keys[k],
            if partners.is_empty() { "nothing: the evidence does not depend on it".to_owned() } else { partners.join(", ") },
            problem.prior[k]
        ));
        best = problem.solve(&best.0, active, candidate);
        if active.is_empty() {
            break;
        }
    }
    Held {
        best,
        held,
        jacobian,
    }
}
