//! The fit's report, from the point it reached: the uncertainties of the
//! free keys, the record's events and the datasheet's figures against the
//! fitted model's, and the misfit.

use std::time::Instant;

use super::{
    BounceCount, Candidate, Evaluation, Event, EventKind, EventRow, FigureRow, FitReport,
    FitRequest, Held, ParameterRow, Problem, event_residuals, figures, pick_up_of,
};
use crate::coil::Coil;
use crate::scenario::Scenario;

/// One row per free key: its fitted value and, unless it is held, its
/// 1σ from the covariance `(JᵀJ)⁻¹·rms²` at the fitted point.
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
    let ssr: f64 = data.iter().map(|x| x * x).sum();
    let dof = problem.data_len().saturating_sub(active.len()).max(1);
    let rms2 = ssr / dof as f64;
    let covariance = jacobian
        .as_ref()
        .and_then(|j| (j.transpose() * j).try_inverse());
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
                (Some(c), Some(col)) => value * (c[(col, col)] * rms2).sqrt(),
                _ => f64::INFINITY,
            })
        };
        let determined = sigma.is_some_and(|s| s.is_finite() && s < value);
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
    for ((figure, target), (_, model)) in figures(d).into_iter().zip(&e.figures) {
        datasheet_rows.push(FigureRow {
            figure,
            target,
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
    if let (Some(_), Some(c), Some((pu, line))) = (d.pick_up_voltage, &fitted.coil, pick) {
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
    let worst = datasheet_rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.figure != "release_time")
        .map(|(i, r)| (i, r.residual.map_or(f64::INFINITY, f64::abs)))
        .fold(
            (usize::MAX, -1.0),
            |acc, (i, v)| if v > acc.1 { (i, v) } else { acc },
        );
    if let Some(row) = datasheet_rows.get_mut(worst.0) {
        row.binds = true;
    }
    (datasheet_rows, pick_up_binds)
}

/// The rms of the relative misfits of the fitted figures (`release_time`
/// is not fitted; a figure the model does not show counts as 1).
fn relative_rms(rows: &[FigureRow]) -> f64 {
    let rel: Vec<f64> = rows
        .iter()
        .filter(|r| r.figure != "release_time")
        .map(|r| r.residual.unwrap_or(1.0))
        .collect();
    (rel.iter().map(|x| x * x).sum::<f64>() / rel.len().max(1) as f64).sqrt()
}
