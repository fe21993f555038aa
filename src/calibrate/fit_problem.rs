//! The fitting problem: the free keys in log form with their priors and
//! bounds, the evidence they are held against, and the residuals of one
//! point (the record's event times matched in order, the datasheet's
//! figures as the datasheet measures them).

use super::dense::Matrix;
use super::{
    COUNT_PENALTY, DatasheetSection, Event, FitError, FitRequest, JACOBIAN_STEP, PRIOR_WEIGHT,
    RELATIVE_SCALE, TIME_SCALE, coil_tolerance_corner, datasheet_figures, events_of, model_events,
};
use crate::scenario::Scenario;

/// Which events take part: none dropped, or one adjacent pair of the
/// measured or of the modelled events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Candidate {
    All,
    DropMeasured(usize),
    DropModel(usize),
}

pub(super) fn drop_pair(events: &[Event], j: usize) -> Vec<Event> {
    events
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != j && i != j + 1)
        .map(|(_, e)| *e)
        .collect()
}

/// The fitting problem: the prior scenario, the free keys in log form,
/// and the evidence.
pub(super) struct Problem<'a> {
    pub(super) base: &'a Scenario,
    pub(super) keys: Vec<String>,
    pub(super) prior: Vec<f64>,
    pub(super) low: Vec<f64>,
    pub(super) high: Vec<f64>,
    pub(super) measured: Option<Vec<Event>>,
    pub(super) datasheet: Option<DatasheetSection>,
    pub(super) voltage: Option<f64>,
    pub(super) evaluations: std::cell::Cell<usize>,
}

/// What one evaluation produced, for the residuals and the report.
pub(super) struct Evaluation {
    pub(super) model: Vec<Event>,
    pub(super) figures: Vec<(&'static str, Option<f64>)>,
}

impl Problem<'_> {
    pub(super) fn scenario_at(&self, u: &[f64]) -> Option<Scenario> {
        let mut s = self.base.clone();
        let values: Vec<(&str, f64)> = self
            .keys
            .iter()
            .zip(u)
            .zip(&self.prior)
            // A key at its prior keeps the prior's exact bits.
            .map(|((k, &v), &p)| (k.as_str(), if v == p.ln() { p } else { v.exp() }))
            .collect();
        s.set_numbers(&values).ok()?;
        Some(s)
    }

    pub(super) fn evaluate(&self, u: &[f64]) -> Option<Evaluation> {
        self.evaluations.set(self.evaluations.get() + 1);
        let s = self.scenario_at(u)?;
        let model = match &self.measured {
            Some(_) => model_events(&s, self.voltage).ok()?,
            None => Vec::new(),
        };
        let figures = match &self.datasheet {
            Some(d) => datasheet_figures(&s, d),
            None => Vec::new(),
        };
        Some(Evaluation { model, figures })
    }

    /// The events of a candidate: (measured, model).
    pub(super) fn matched(&self, e: &Evaluation, c: Candidate) -> (Vec<Event>, Vec<Event>) {
        let measured = self.measured.clone().unwrap_or_default();
        match c {
            Candidate::All => (measured, e.model.clone()),
            Candidate::DropMeasured(j) => (drop_pair(&measured, j), e.model.clone()),
            Candidate::DropModel(j) => (measured, drop_pair(&e.model, j)),
        }
    }

    pub(super) fn data_len(&self) -> usize {
        self.measured.as_ref().map_or(0, |m| m.len() + 1)
            + self.datasheet.as_ref().map_or(0, |d| d.figures().len())
    }

    /// The scaled data residuals (no prior rows); `None` when the
    /// scenario is invalid at `u`.
    pub(super) fn data_residuals(&self, u: &[f64], c: Candidate) -> Option<Vec<f64>> {
        let e = self.evaluate(u)?;
        let mut r = Vec::with_capacity(self.data_len());
        if self.measured.is_some() {
            let (measured, model) = self.matched(&e, c);
            let (rows, _) = event_residuals(&measured, &model);
            r.extend(rows.iter().map(|x| x / TIME_SCALE));
            // A dropped pair shortens the measured list: pad so that every
            // candidate has the same length.
            r.resize(self.measured.as_ref().map_or(0, |m| m.len() + 1), 0.0);
        }
        if let Some(d) = &self.datasheet {
            for ((name, figure), (_, model)) in d.figures().iter().zip(&e.figures) {
                r.push(match model {
                    Some(m) => {
                        figure.misfit(coil_tolerance_corner(d, name, figure, *m)) / RELATIVE_SCALE
                    }
                    // Shown, not fitted (see `datasheet_figures`).
                    None if *name == "release_time" => 0.0,
                    None => 1.0 / RELATIVE_SCALE,
                });
            }
        }
        Some(r)
    }

    /// Data residuals then the prior rows of the active keys.
    pub(super) fn residuals(&self, u: &[f64], active: &[usize], c: Candidate) -> Option<Vec<f64>> {
        let mut r = self.data_residuals(u, c)?;
        let prior = self.prior.iter().map(|p| p.ln());
        for (k, p) in prior.enumerate() {
            if active.contains(&k) {
                r.push(PRIOR_WEIGHT * (u[k] - p));
            }
        }
        Some(r)
    }

    pub(super) fn clamp(&self, u: &mut [f64]) {
        for (k, x) in u.iter_mut().enumerate() {
            *x = x.clamp(self.low[k].ln(), self.high[k].ln());
        }
    }

    /// Central-difference Jacobian of `f` over the active keys.
    pub(super) fn jacobian(
        &self,
        u: &[f64],
        active: &[usize],
        f: impl Fn(&[f64]) -> Option<Vec<f64>>,
        rows: usize,
    ) -> Option<Matrix> {
        let mut j = Matrix::zeros(rows, active.len());
        for (col, &k) in active.iter().enumerate() {
            let mut up = u.to_vec();
            let mut down = u.to_vec();
            up[k] += JACOBIAN_STEP;
            down[k] -= JACOBIAN_STEP;
            let (a, b) = (f(&up)?, f(&down)?);
            for row in 0..rows {
                j[(row, col)] = (a[row] - b[row]) / (2.0 * JACOBIAN_STEP);
            }
        }
        Some(j)
    }

    /// Levenberg–Marquardt from `u0` over the active keys; the best point
    /// and its cost (sum of squares, prior rows included).
    pub(super) fn solve(&self, u0: &[f64], active: &[usize], c: Candidate) -> (Vec<f64>, f64) {
        let mut u = u0.to_vec();
        self.clamp(&mut u);
        let f = |x: &[f64]| self.residuals(x, active, c);
        let Some(mut r) = f(&u) else {
            return (u, f64::INFINITY);
        };
        let mut cost = r.iter().map(|x| x * x).sum::<f64>();
        if active.is_empty() {
            return (u, cost);
        }
        let mut lambda = 1e-3;
        for _ in 0..100 {
            let Some(j) = self.jacobian(&u, active, f, r.len()) else {
                break;
            };
            let a = j.gram();
            let minus_g: Vec<f64> = j.tr_mul(&r).iter().map(|x| -x).collect();
            let mut improved = false;
            while lambda < 1e12 {
                let mut damped = a.clone();
                for d in 0..active.len() {
                    damped[(d, d)] += lambda * (a[(d, d)] + 1e-12);
                }
                let Some(step) = damped.solve(&minus_g) else {
                    lambda *= 10.0;
                    continue;
                };
                let mut trial = u.clone();
                for (col, &k) in active.iter().enumerate() {
                    trial[k] += step[col];
                }
                self.clamp(&mut trial);
                match f(&trial) {
                    Some(rt) => {
                        let ct = rt.iter().map(|x| x * x).sum::<f64>();
                        if ct < cost {
                            let gain = cost - ct;
                            let moved = trial
                                .iter()
                                .zip(&u)
                                .map(|(a, b)| (a - b).abs())
                                .fold(0.0, f64::max);
                            u = trial;
                            r = rt;
                            cost = ct;
                            lambda = (lambda / 3.0).max(1e-12);
                            improved = gain > 1e-12 * cost.max(1e-30) && moved > 1e-10;
                            break;
                        }
                        lambda *= 4.0;
                    }
                    None => lambda *= 4.0,
                }
            }
            if !improved {
                break;
            }
        }
        (u, cost)
    }
}

/// Halton point `i` (from 1) in base `b`: a deterministic, even spread.
pub(super) fn halton(mut i: usize, b: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

/// The event residuals (s) of `measured` against `model` matched in order,
/// and the time offset (s, model time of the record's zero). One residual
/// per measured event and one for the model's extra events.
pub(super) fn event_residuals(measured: &[Event], model: &[Event]) -> (Vec<f64>, f64) {
    let n = measured.len();
    let k = n.min(model.len());
    let offset = if k > 0 {
        (0..k)
            .map(|i| model[i].time - measured[i].time)
            .sum::<f64>()
            / k as f64
    } else {
        0.0
    };
    let last = model.last().map_or(0.0, |e| e.time);
    let mut r = Vec::with_capacity(n + 1);
    for (i, e) in measured.iter().enumerate() {
        r.push(if i < k {
            let kind = if model[i].kind == e.kind {
                0.0
            } else {
                COUNT_PENALTY
            };
            model[i].time - offset - e.time + kind
        } else {
            (last - offset - e.time) - COUNT_PENALTY
        });
    }
    r.push(if model.len() > n && n > 0 {
        (last - model[n - 1].time) + COUNT_PENALTY * (model.len() - n) as f64
    } else {
        0.0
    });
    (r, offset)
}

/// The free keys with their priors and their bounds, in the key's unit.
pub(super) struct FreeKeys {
    pub(super) keys: Vec<String>,
    pub(super) prior: Vec<f64>,
    pub(super) low: Vec<f64>,
    pub(super) high: Vec<f64>,
}

/// What the fit is held against: the record's events, the datasheet (when
/// it gives a figure) and the coil voltage of both.
pub(super) struct Evidence {
    pub(super) measured: Option<Vec<Event>>,
    pub(super) datasheet: Option<DatasheetSection>,
    pub(super) voltage: Option<f64>,
}

/// The point a stage reached and the cost there (sum of squares, prior
/// rows included).
pub(super) type Point = (Vec<f64>, f64);

/// The outcome of holding the keys the data cannot see: the refitted
/// point, which keys are held, and the data Jacobian once every direction
/// left is determined (`None` when that never happened).
pub(super) struct Held {
    pub(super) best: Point,
    pub(super) held: Vec<bool>,
    pub(super) jacobian: Option<Matrix>,
}

impl<'a> Problem<'a> {
    /// The problem of fitting `scenario` as `request` asks; an error for a
    /// request that cannot start (no free key, no evidence, a prior that
    /// does not simulate).
    pub(super) fn new(
        scenario: &'a Scenario,
        request: &FitRequest,
    ) -> Result<Problem<'a>, FitError> {
        let path = scenario.origin.display().to_string();
        let FreeKeys {
            keys,
            prior,
            low,
            high,
        } = free_keys(scenario, request, &path)?;
        let Evidence {
            measured,
            datasheet,
            voltage,
        } = evidence(scenario, request, &path)?;
        let problem = Problem {
            base: scenario,
            keys,
            prior,
            low,
            high,
            measured,
            datasheet,
            voltage,
            evaluations: std::cell::Cell::new(0),
        };
        let u_prior: Vec<f64> = problem.prior.iter().map(|p| p.ln()).collect();
        if problem.data_residuals(&u_prior, Candidate::All).is_none() {
            let message = match scenario.clone().set_numbers(&[]) {
                Err(e) => e.to_string(),
                Ok(()) => "its parameters are invalid".to_owned(),
            };
            return Err(FitError::Prior { path, message });
        }
        Ok(problem)
    }
}

/// The free keys (the request's, else the scenario's `[fit] free`), each
/// with its prior and its bounds (`[fit] bounds`, else a decade either
/// side of the prior), checked.
pub(super) fn free_keys(
    scenario: &Scenario,
    request: &FitRequest,
    path: &str,
) -> Result<FreeKeys, FitError> {
    let section = scenario.fit.clone().unwrap_or_default();
    let keys = if request.free.is_empty() {
        section.free.clone()
    } else {
        request.free.clone()
    };
    if keys.is_empty() {
        return Err(FitError::NoFreeKeys);
    }
    let (mut prior, mut low, mut high) = (Vec::new(), Vec::new(), Vec::new());
    for key in &keys {
        let value = scenario
            .number(key)
            .map_err(|source| FitError::UnknownKey {
                path: path.to_owned(),
                key: key.clone(),
                source: Box::new(source),
            })?
            .ok_or_else(|| FitError::NoPrior {
                path: path.to_owned(),
                key: key.clone(),
            })?;
        if !(value > 0.0 && value.is_finite()) {
            return Err(FitError::NotPositive {
                path: path.to_owned(),
                key: key.clone(),
                value,
            });
        }
        let [lo, hi] = section
            .bounds
            .get(key)
            .copied()
            .unwrap_or([value / 10.0, value * 10.0]);
        if !(lo > 0.0 && lo <= value && value <= hi && hi.is_finite()) {
            return Err(FitError::Bounds {
                path: path.to_owned(),
                key: key.clone(),
                low: lo,
                high: hi,
                prior: value,
            });
        }
        prior.push(value);
        low.push(lo);
        high.push(hi);
    }
    Ok(FreeKeys {
        keys,
        prior,
        low,
        high,
    })
}

/// The evidence: the record's events and the datasheet's figures, checked
/// (positive figures, a coil for the figures, a coil voltage for the
/// times and for a coil-driven record, at least one of the two).
pub(super) fn evidence(
    scenario: &Scenario,
    request: &FitRequest,
    path: &str,
) -> Result<Evidence, FitError> {
    let datasheet = scenario
        .datasheet
        .clone()
        .filter(|d| !d.figures().is_empty());
    if let Some(d) = &scenario.datasheet {
        let all = [("coil_voltage", d.coil_voltage)]
            .into_iter()
            .chain(d.figures().into_iter().map(|(n, f)| (n, Some(f.nominal()))));
        for (figure, v) in all {
            if let Some(value) = v
                && !(value > 0.0 && value.is_finite())
            {
                return Err(FitError::BadFigure {
                    path: path.to_owned(),
                    figure,
                    value,
                });
            }
        }
    }
    if let Some(d) = &datasheet {
        if scenario.coil.is_none() {
            return Err(FitError::NeedsCoil {
                path: path.to_owned(),
                figure: d.figures()[0].0,
            });
        }
        let timed = d.operate_time.is_some() || d.bounce_time.is_some();
        if timed && d.coil_voltage.is_none() {
            return Err(FitError::NeedsVoltage {
                path: path.to_owned(),
            });
        }
    }
    let voltage = scenario.datasheet.as_ref().and_then(|d| d.coil_voltage);
    let measured = match &request.record {
        Some(record) => {
            let events = events_of(&record.intervals);
            if events.is_empty() {
                return Err(FitError::EmptyRecord {
                    name: record.name.clone(),
                });
            }
            if scenario.coil.is_some() && voltage.is_none() {
                return Err(FitError::NeedsVoltage {
                    path: path.to_owned(),
                });
            }
            Some(events)
        }
        None => None,
    };
    if measured.is_none() && datasheet.is_none() {
        return Err(FitError::NoEvidence);
    }
    Ok(Evidence {
        measured,
        datasheet,
        voltage,
    })
}
