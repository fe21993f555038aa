//! The arc constants fitted in closed form to the printed DC breaking
//! capacity (`[datasheet] dc_breaking`) at the contact's full gap: the
//! low-current term (D, read as growing with the gap; C instead when only
//! `arc.low_current` is free), the column gradient E with two figures or
//! more, and I_min lowered where the figures call for it
//! ([`crate::arc::breaking`] does the physics).

use super::{FitError, FitReport, ParameterRow};
use crate::arc::breaking::{self, FreeArcKeys, PrintedBreak};
use crate::scenario::{Determined, Scenario};

/// The arc keys the breaking fit can move.
const ARC_KEYS: [&str; 4] = [
    "arc.low_current_gap",
    "arc.low_current",
    "arc.field",
    "arc.i_min",
];

/// The arc constants `keys` of `scenario` fitted to its breaking curve,
/// into `report`.
pub(super) fn fit_breaking(
    scenario: &Scenario,
    keys: &[String],
    report: &mut FitReport,
) -> Result<(), FitError> {
    let path = scenario.origin.display().to_string();
    let failure = |problem: String| FitError::Breaking {
        path: path.clone(),
        problem,
    };
    if let Some(key) = keys.iter().find(|k| !ARC_KEYS.contains(&k.as_str())) {
        return Err(failure(format!(
            "free key `{key}`: of the arc, only {} are fitted (to [datasheet] dc_breaking)",
            ARC_KEYS.join(", ")
        )));
    }
    let figures: Vec<PrintedBreak> = scenario
        .datasheet
        .as_ref()
        .map(|d| d.dc_breaking.iter().map(|f| f.printed()).collect())
        .unwrap_or_default();
    if figures.is_empty() {
        return Err(failure(
            "the arc's keys are fitted to the DC breaking capacity: add [datasheet] \
             dc_breaking = [{ voltage = ..., current = ... }, ...]"
                .to_owned(),
        ));
    }
    let has = |key: &str| keys.iter().any(|k| k == key);
    let section = scenario.arc.unwrap_or_default();
    let model = section.model();
    let gap = report.fitted.mechanics.gap;
    let free = FreeArcKeys {
        low_current: has("arc.low_current") && !has("arc.low_current_gap"),
        field: has("arc.field"),
        i_min: has("arc.i_min"),
    };
    let fitted = breaking::fit(&model, gap, &figures, free).map_err(|e| failure(e.to_string()))?;
    if has("arc.low_current") && has("arc.low_current_gap") {
        report.notes.push(
            "arc.low_current held at its value: figures at one gap fix the low-current term \
             there, C + D·gap, and it is read as growing with the gap (D fitted)"
                .to_owned(),
        );
    }
    // I_min is bounded by the figures, not fitted through them.
    let through = keys.iter().filter(|k| *k != "arc.i_min").count();
    let determined = if figures.len() == through {
        Determined::Exactly
    } else {
        Determined::Yes
    };
    let mut rows = Vec::new();
    if free.field && fitted.field_fitted {
        rows.push(ParameterRow {
            key: "arc.field".to_owned(),
            prior: model.field,
            value: fitted.field,
            sigma: None,
            determined,
        });
    } else if free.field && fitted.held.is_empty() {
        report.notes.push(
            "arc.field held at its value: one DC breaking figure fixes the low-current term only"
                .to_owned(),
        );
    }
    report.notes.extend(fitted.held.iter().cloned());
    rows.push(if free.low_current {
        ParameterRow {
            key: "arc.low_current".to_owned(),
            prior: model.low_current,
            value: fitted.low_current,
            sigma: None,
            determined,
        }
    } else {
        ParameterRow {
            key: "arc.low_current_gap".to_owned(),
            prior: model.low_current_gap,
            value: fitted.low_current_gap,
            sigma: None,
            determined,
        }
    });
    if free.i_min {
        rows.push(ParameterRow {
            key: "arc.i_min".to_owned(),
            prior: model.i_min,
            value: fitted.i_min,
            sigma: None,
            determined: if fitted.i_min_fitted {
                Determined::Yes
            } else {
                Determined::No
            },
        });
        report.notes.push(if fitted.i_min_fitted {
            format!(
                "arc.i_min lowered to {:.4} A, the arc's current at the tangent of the highest \
                 printed voltage: the largest minimum arc current that lets every printed figure \
                 be set by the tangent (an upper bound; any smaller value breaks the same \
                 currents)",
                fitted.i_min
            )
        } else {
            "arc.i_min held at its value: the arc burns above it at every printed figure's \
             tangent"
                .to_owned()
        });
    }
    report.parameters.extend(rows);
    report.fitted.arc = Some(crate::arc::ArcSection {
        field: Some(fitted.field),
        low_current: Some(fitted.low_current),
        low_current_gap: Some(fitted.low_current_gap),
        i_min: if fitted.i_min_fitted {
            Some(fitted.i_min)
        } else {
            section.i_min
        },
        ..section
    });
    if report.fitted_to.is_empty() {
        report.fitted_to = "dc_breaking".to_owned();
    } else if !report.fitted_to.contains("dc_breaking") {
        report.fitted_to.push_str(" + dc_breaking");
    }
    report.breaking = Some(fitted);
    report.fitted.provenance = Some(report.provenance());
    Ok(())
}
