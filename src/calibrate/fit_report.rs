//! The fit's report, from the point it reached: the uncertainties of the
//! free keys, the record's events and the datasheet's figures against the
//! fitted model's, and the misfit.

use std::time::Instant;

use super::dense::Matrix;
use super::problem::{Evaluation, Held, event_residuals};
use super::{
    BounceCount, Candidate, DatasheetSection, Determined, Event, EventKind, EventRow, FigureRow,
    FitReport, FitRequest, ParameterRow, Problem, RELATIVE_SCALE, pick_up_of,
};
use crate::coil::Coil;
use crate::scenario::Scenario;

/// One row per free key: its fitted value and, unless it is held, its
/// 1σ. With a record, from the covariance `(JᵀJ)⁻¹·rms²` at the fitted
/// point. From a datasheet alone, from the figures' own spreads
/// ([`PrintedFigure::relative_sigma`]): `(JwᵀJw)⁻¹` with each figure's
/// row weighted by its spread, scaled up by the misfit per degree of
/// freedom when there are more figures than keys and they disagree; a
/// key fixed by as many figures as free keys with no misfit left is
/// determined `"exactly"`, its σ the figures' tolerances carried through.
pub(super) fn uncertainties(
    problem: &Problem,
    held: &Held,
    candidate: Candidate,
    u_prior: &[f64],
    active: &[usize],
) -> Vec<ParameterRow> {
    let Held {
        best,
        held,
        jacobian,
    } = held;
    let data = problem
        .data_residuals(&best.0, candidate)
        .unwrap_or_default();
    let (covariance, exactly) = match (&problem.datasheet, &problem.measured) {
        (Some(d), None) => figure_covariance(d, jacobian.as_ref(), &data, active.len()),
        _ => (
            residual_covariance(problem, jacobian.as_ref(), &data, active.len()),
            false,
        ),
    };
    let mut parameters = Vec::new();
    for (k, key) in problem.keys.iter().enumerate() {
        let prior = problem.prior[k];
        let value = if best.0[k] == u_prior[k] {
            prior
        } else {
            best.0[k].exp()
        };
        let sigma = if held[k] {
            None
        } else {
            let col = active.iter().position(|&a| a == k);
            Some(match (&covariance, col) {
                (Some(c), Some(col)) => value * c[(col, col)].sqrt(),
                _ => f64::INFINITY,
            })
        };
        // Fixed exactly is said whatever the σ: the figures fix the key,
        // and its σ says how well their tolerances let them.
        let determined = match sigma {
            Some(s) if s.is_finite() && exactly => Determined::Exactly,
            Some(s) if s.is_finite() && s < value => Determined::Yes,
            _ => Determined::No,
        };
        parameters.push(ParameterRow {
            key: key.clone(),
            prior,
            value,
            sigma: sigma.filter(|s| s.is_finite()),
            determined,
        });
    }
    parameters
}

/// The covariance of the log parameters from the residual misfit:
/// `(JᵀJ)⁻¹·rms²`, rms² the data's mean square per degree of freedom.
fn residual_covariance(
    problem: &Problem,
    jacobian: Option<&Matrix>,
    data: &[f64],
    active: usize,
) -> Option<Matrix> {
    let ssr: f64 = data.iter().map(|x| x * x).sum();
    let dof = problem.data_len().saturating_sub(active).max(1);
    let rms2 = ssr / dof as f64;
    jacobian
        .and_then(|j| j.gram().inverse())
        .map(|c| c.scaled(rms2))
}

/// The covariance of the log parameters from the datasheet figures'
/// spreads, and whether the keys are fixed exactly (as many figures that
/// see them as keys, and no misfit left).
fn figure_covariance(
    d: &DatasheetSection,
    jacobian: Option<&Matrix>,
    data: &[f64],
    active: usize,
) -> (Option<Matrix>, bool) {
    let Some(j) = jacobian else {
        return (None, false);
    };
    let figures = d.figures();
    let mut weighted = j.clone();
    let (mut chi2, mut seen) = (0.0, 0usize);
    for (row, (_, figure)) in figures.iter().enumerate().take(j.nrows()) {
        // The rows are misfits over RELATIVE_SCALE; back to relative
        // misfits, over the figure's own spread.
        let w = RELATIVE_SCALE / figure.relative_sigma();
        for col in 0..j.ncols() {
            weighted[(row, col)] *= w;
        }
        let misfit = data.get(row).copied().unwrap_or(0.0) * w;
        chi2 += misfit * misfit;
        if j.row(row).iter().any(|x| *x != 0.0) {
            seen += 1;
        }
    }
    let dof = seen.saturating_sub(active);
    let scale = if dof > 0 {
        (chi2 / dof as f64).max(1.0)
    } else {
        1.0
    };
    let worst = data
        .iter()
        .take(figures.len())
        .map(|x| (x * RELATIVE_SCALE).abs())
        .fold(0.0, f64::max);
    let exactly = seen == active && active > 0 && worst < EXACT_MISFIT;
    let covariance = weighted.gram().inverse().map(|c| c.scaled(scale));
    (covariance, exactly)
}

/// Relative misfit below which the figures are met exactly.
const EXACT_MISFIT: f64 = 1e-6;

/// The report of the fit that ended at `best` (log parameters) with
/// `candidate`'s events: the rows, the misfit, the fitted scenario with
/// its `[provenance]`; where the pick-up binds joins `notes`.
pub(super) fn assemble(
    problem: &Problem,
    request: &FitRequest,
    best: &[f64],
    candidate: Candidate,
    parameters: Vec<ParameterRow>,
    mut notes: Vec<String>,
    started: Instant,
) -> FitReport {
    let scenario = problem.base;
    let fitted = problem
        .scenario_at(best)
        .unwrap_or_else(|| scenario.clone());
    let evaluation = problem.evaluate(best);
    let EventRows {
        events,
        bounce_count,
        time_offset,
        rms: event_rms,
    } = event_rows(problem, evaluation.as_ref(), candidate).unwrap_or_default();
    let (datasheet_rows, pick_up_binds) =
        datasheet_rows(problem, evaluation.as_ref(), &fitted, &mut notes);
    let rms_residual = match event_rms {
        Some(r) => r,
        None => relative_rms(&datasheet_rows),
    };
    let mut fitted_to = Vec::new();
    if let Some(r) = &request.record {
        fitted_to.push(r.name.clone());
    }
    if problem.datasheet.is_some() {
        fitted_to.push("datasheet".to_owned());
    }
    let mut fitted = fitted;
    let report = FitReport {
        parameters,
        events,
        bounce_count,
        datasheet: datasheet_rows,
        time_offset,
        rms_residual,
        evaluations: problem.evaluations.get(),
        elapsed: started.elapsed().as_secs_f64(),
        pick_up_binds,
        notes,
        fitted: scenario.clone(),
        fitted_to: fitted_to.join(" + "),
        breaking: None,
        kept_provenance: None,
    };
    fitted.provenance = Some(report.provenance());
    FitReport { fitted, ..report }
}

/// The record's side of the report.
#[derive(Default)]
struct EventRows {
    /// Measured against modelled, in time order.
    events: Vec<EventRow>,
    bounce_count: Option<BounceCount>,
    /// s, model time minus record time.
    time_offset: Option<f64>,
    /// s, the rms of the event residuals.
    rms: Option<f64>,
}

/// The record's events against the model's at the fitted point, the one
/// bad pair (if `candidate` drops a measured one) marked; `None` without a
/// record or a model.
fn event_rows(
    problem: &Problem,
    evaluation: Option<&Evaluation>,
    candidate: Candidate,
) -> Option<EventRows> {
    let (Some(measured), Some(e)) = (&problem.measured, evaluation) else {
        return None;
    };
    let mut events = Vec::new();
    let (m, model) = problem.matched(e, candidate);
    let (rows, offset) = event_residuals(&m, &model);
    let k = m.len().min(model.len());
    let rms = (rows.iter().map(|x| x * x).sum::<f64>() / m.len() as f64).sqrt();
    let skipped = match candidate {
        Candidate::DropMeasured(j) => Some(j),
        _ => None,
    };
    let mut mi = 0;
    for (i, ev) in measured.iter().enumerate() {
        if skipped.is_some_and(|j| i == j || i == j + 1) {
            events.push(EventRow {
                kind: ev.kind,
                measured: Some(ev.time),
                model: None,
                residual: None,
                dropped: true,
            });
            continue;
        }
        let model_time = (mi < k).then(|| model[mi].time - offset);
        events.push(EventRow {
            kind: ev.kind,
            measured: Some(ev.time),
            model: model_time,
            residual: model_time.map(|t| t - ev.time),
            dropped: false,
        });
        mi += 1;
    }
    for extra in model.iter().skip(m.len()) {
        events.push(EventRow {
            kind: extra.kind,
            measured: None,
            model: Some(extra.time - offset),
            residual: None,
            dropped: false,
        });
    }
    let bounces = |ev: &[Event]| ev.iter().filter(|e| e.kind == EventKind::Break).count();
    Some(EventRows {
        events,
        bounce_count: Some(BounceCount {
            measured: bounces(&m),
            model: bounces(&e.model),
        }),
        time_offset: Some(offset),
        rms: Some(rms),
    })
}

/// The datasheet's figures against the fitted model's, the worst marked
/// as binding, and where the pick-up binds (also told in `notes`); empty
/// without a datasheet or a model.
fn datasheet_rows(
    problem: &Problem,
    evaluation: Option<&Evaluation>,
    fitted: &Scenario,
    notes: &mut Vec<String>,
) -> (Vec<FigureRow>, Option<String>) {
    let mut datasheet_rows = Vec::new();
    let mut pick_up_binds = None;
    let (Some(d), Some(e)) = (&problem.datasheet, evaluation) else {
        return (datasheet_rows, pick_up_binds);
    };
    let pick = pick_up_of(fitted);
    for ((figure, printed), (_, model)) in d.figures().into_iter().zip(&e.figures) {
        let target = printed.nominal();
        datasheet_rows.push(FigureRow {
            figure,
            target,
            printed,
            role: if printed.typ.is_some() {
                "target"
            } else {
                "bound"
            },
            met: model.map(|m| printed.met_by_nominal(m)),
            at_coil_tolerance: model
                .map(|m| super::coil_tolerance_corner(d, figure, &printed, m))
                .filter(|c| Some(*c) != *model),
            model: *model,
            residual: model.map(|m| (m - target) / target),
            binds: false,
            position: pick.and_then(|(pu, line)| match figure {
                "pick_up_voltage" => Some(pu.binding_position),
                "drop_out_voltage" => Some(line.closed_position()),
                _ => None,
            }),
        });
    }
    if let (Some(_), Some(c), Some((pu, line))) = (&d.pick_up_voltage, &fitted.coil, pick) {
        let text = pu.binding_text(&line);
        notes.push(if pu.at_rest() {
            format!("the pick-up binds {text}: the pull at rest against the preload")
        } else {
            let coil = Coil::from(c);
            let lift = coil.resistance * (2.0 * line.preload / coil.d_inductance(0.0)).sqrt();
            format!(
                "the pick-up binds {text}: the armature lifts off at {lift:.4} V but stalls there below {:.4} V",
                pu.voltage
            )
        });
        pick_up_binds = Some(text);
    }
    mark_binding(&mut datasheet_rows);
    (datasheet_rows, pick_up_binds)
}

/// Mark the figures that limit the fit: every bound the model sits on
/// (within 0.1 %) or crosses, and the target with the largest misfit;
/// `release_time` is shown, not fitted.
fn mark_binding(rows: &mut [FigureRow]) {
    let fitted = |r: &FigureRow| r.figure != "release_time" && r.figure != "coil_resistance";
    for r in rows.iter_mut().filter(|r| fitted(r) && r.role == "bound") {
        let (lo, hi) = r.printed.band();
        r.binds = r.at_coil_tolerance.or(r.model).is_none_or(|m| {
            let near = |b: f64| b.is_finite() && ((m - b) / b).abs() < 1e-3;
            near(lo) || near(hi) || !r.printed.holds(m)
        });
    }
    let worst = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| fitted(r) && r.role == "target")
        .map(|(i, r)| (i, r.residual.map_or(f64::INFINITY, f64::abs)))
        .fold(
            (usize::MAX, -1.0),
            |acc, (i, v)| if v > acc.1 { (i, v) } else { acc },
        );
    if let Some(row) = rows.get_mut(worst.0) {
        row.binds = true;
    }
}

/// The rms of the relative misfits of the fitted figures (`release_time`
/// is not fitted; a figure the model does not show counts as 1).
fn relative_rms(rows: &[FigureRow]) -> f64 {
    let rel: Vec<f64> = rows
        .iter()
        .filter(|r| r.figure != "release_time")
        .map(|r| r.model.map_or(1.0, |m| r.printed.misfit(m)))
        .collect();
    (rel.iter().map(|x| x * x).sum::<f64>() / rel.len().max(1) as f64).sqrt()
}
