//! The scenario sections of calibration: `[datasheet]` (the figures a
//! relay's datasheet prints), `[fit]` (which keys a fit may move) and
//! `[provenance]` (what a fit fitted the scenario to, written by `fit`
//! and read back by every command).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// `[datasheet]`: a relay's published figures, in their IEC 61810
/// meanings, measured as a datasheet measures them (an ideal DC step on
/// the coil, no driver circuit). Any subset may be given.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasheetSection {
    /// V, the nominal coil voltage (the step the times are measured with).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coil_voltage: Option<f64>,
    /// V, must-operate voltage.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pick_up_voltage: Option<f64>,
    /// V, must-release voltage.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drop_out_voltage: Option<f64>,
    /// s, coil energized → first make (bounce excluded).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub operate_time: Option<f64>,
    /// s, first make → closed for good.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bounce_time: Option<f64>,
    /// s, coil de-energized → the normally-open contact opens.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub release_time: Option<f64>,
}

/// `[fit]`: the keys a fit may move (scenario number keys such as
/// `surface.damping`) and optional bounds per key (else a decade either
/// side of the prior).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitSection {
    /// `fit.free`: the number keys the fit may move (`--free` replaces the
    /// list); each needs a positive value in the scenario, its prior.
    #[serde(default)]
    pub free: Vec<String>,
    /// `fit.bounds`: per free key, the `[low, high]` it may move within, in
    /// the key's unit; a key without bounds moves within a decade either
    /// side of its prior.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub bounds: BTreeMap<String, [f64; 2]>,
}

/// `[provenance]`: what a fit fitted the scenario to and how well.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProvenanceSection {
    /// The capture or state file, and/or "datasheet".
    pub fitted_to: String,
    /// The root-mean-square residual: s for a capture fit, relative
    /// (dimensionless) for a datasheet-only fit.
    pub rms_residual: f64,
    /// s, where the record's time zero fell in model time (capture fits).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_offset: Option<f64>,
    /// Where the fitted relay's pick-up binds along the armature's travel
    /// (`at rest (x = 0)`, or `part-way, at x = … mm of the … mm travel`),
    /// when the fit was given a pick-up voltage.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pick_up_binds: Option<String>,
    /// Per free key: its prior, fitted value, 1σ and whether the evidence
    /// determined it.
    #[serde(default)]
    pub parameters: BTreeMap<String, FittedParameter>,
}

/// One free key's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FittedParameter {
    /// `prior`: the key's value before the fit, in its unit.
    pub prior: f64,
    /// `value`: the fitted value, in the key's unit; the prior when the key
    /// was held.
    pub value: f64,
    /// 1σ, same unit as the value; absent when the key was held at its
    /// prior because the evidence does not determine it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma: Option<f64>,
    /// `determined`: whether the evidence determined the key (its 1σ is
    /// smaller than its value); `false` for a key held at its prior.
    pub determined: bool,
}
