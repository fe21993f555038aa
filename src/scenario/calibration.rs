//! The scenario sections of calibration: `[datasheet]` (the figures a
//! relay's datasheet prints), `[fit]` (which keys a fit may move) and
//! `[provenance]` (what a fit fitted the scenario to, written by `fit`
//! and read back by every command).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::figure::PrintedFigure;

/// `[datasheet]`: a relay's published figures, in their IEC 61810
/// meanings, measured as a datasheet measures them (an ideal DC step on
/// the coil, no driver circuit). Any subset may be given. Each figure is
/// written as printed: a number (typical) or a table
/// `{ typ, min, max, tolerance }` ([`PrintedFigure`]).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasheetSection {
    /// V, the nominal coil voltage (the step the times are measured with).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coil_voltage: Option<f64>,
    /// Ω, the coil's resistance, usually with a tolerance (±10 %).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coil_resistance: Option<PrintedFigure>,
    /// V, must-operate voltage (usually a maximum).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pick_up_voltage: Option<PrintedFigure>,
    /// V, must-release voltage (usually a minimum).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drop_out_voltage: Option<PrintedFigure>,
    /// s, coil energized → first make (bounce excluded).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub operate_time: Option<PrintedFigure>,
    /// s, first make → closed for good.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bounce_time: Option<PrintedFigure>,
    /// s, coil de-energized → the normally-open contact opens.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub release_time: Option<PrintedFigure>,
    /// The DC breaking capacity as printed (resistive load): the largest
    /// current the contact breaks at each voltage.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dc_breaking: Vec<BreakingFigure>,
    /// A, the printed making (inrush) current rating: `{ max = ... }`, the
    /// peak current any make may carry; `check` holds every make to it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub making_current: Option<PrintedFigure>,
    /// The electrical endurance figures as printed (operations at a
    /// load), for `life`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub electrical_endurance: Vec<super::endurance::EnduranceFigure>,
    /// The Weibull shape β of the printed life, for its B10.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weibull_shape: Option<f64>,
}

/// One point of a printed DC breaking-capacity curve (resistive load).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BreakingFigure {
    /// V, the DC supply.
    pub voltage: f64,
    /// A, the largest current the contact breaks at that voltage.
    pub current: f64,
}

impl BreakingFigure {
    /// The figure as the breaking fit reads it.
    pub fn printed(&self) -> crate::arc::breaking::PrintedBreak {
        crate::arc::breaking::PrintedBreak {
            voltage: self.voltage,
            current: self.current,
        }
    }
}

impl DatasheetSection {
    /// The figures given, by key, in a fixed order: coil resistance,
    /// pick-up, drop-out, operate, bounce, release.
    pub fn figures(&self) -> Vec<(&'static str, PrintedFigure)> {
        [
            ("coil_resistance", self.coil_resistance),
            ("pick_up_voltage", self.pick_up_voltage),
            ("drop_out_voltage", self.drop_out_voltage),
            ("operate_time", self.operate_time),
            ("bounce_time", self.bounce_time),
            ("release_time", self.release_time),
        ]
        .into_iter()
        .filter_map(|(name, f)| f.map(|f| (name, f)))
        .collect()
    }
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
    /// smaller than its value), `"exactly"` when as many figures as free
    /// keys fix it; `false` for a key held at its prior.
    pub determined: Determined,
}

/// Whether the evidence determined a fitted key: written `false`, `true`
/// or `"exactly"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Determined {
    /// Not determined: held at its prior, or its 1σ exceeds its value.
    #[default]
    No,
    /// Determined by more evidence than free keys: its 1σ comes from the
    /// residual misfit.
    Yes,
    /// Fixed exactly by as many figures as free keys: the misfit is zero,
    /// and its 1σ comes from the figures' tolerances.
    Exactly,
}

impl Determined {
    /// Determined, exactly or not.
    pub fn is_determined(self) -> bool {
        self != Determined::No
    }
}

impl From<bool> for Determined {
    fn from(b: bool) -> Determined {
        if b { Determined::Yes } else { Determined::No }
    }
}

impl Serialize for Determined {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Determined::No => serializer.serialize_bool(false),
            Determined::Yes => serializer.serialize_bool(true),
            Determined::Exactly => serializer.serialize_str("exactly"),
        }
    }
}

impl<'de> Deserialize<'de> for Determined {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Flag(bool),
            Word(String),
        }
        match Raw::deserialize(deserializer)? {
            Raw::Flag(b) => Ok(b.into()),
            Raw::Word(w) if w == "exactly" => Ok(Determined::Exactly),
            Raw::Word(w) => Err(serde::de::Error::custom(format!(
                "`determined` is true, false or \"exactly\", not \"{w}\""
            ))),
        }
    }
}

impl super::check::Check<'_> {
    /// Every figure of `[datasheet]` says something and does not
    /// contradict itself; the coil voltage is positive.
    pub(super) fn datasheet(
        &self,
        d: &DatasheetSection,
    ) -> Result<(), super::error::ScenarioError> {
        if let Some(v) = d.coil_voltage {
            self.number(
                "datasheet.coil_voltage",
                v,
                v > 0.0,
                "must be > 0: the nominal coil voltage, in V",
            )?;
        }
        for (k, f) in d.electrical_endurance.iter().enumerate() {
            let key = |what: &str| format!("datasheet.electrical_endurance[{k}].{what}");
            for (what, value, unit) in [
                ("operations", f.operations, "operations"),
                ("voltage", f.voltage, "V"),
                ("current", f.current, "A"),
            ] {
                self.number(
                    &key(what),
                    value,
                    value > 0.0,
                    format!("must be > 0 (in {unit}): the printed endurance figure's {what}"),
                )?;
            }
            if let Some(h) = f.frequency {
                if f.supply == super::endurance::Supply::Dc {
                    return Err(self.invalid(
                        &key("frequency"),
                        h,
                        "a DC endurance figure has no frequency: remove it, or write \
                         supply = \"ac\" if the figure is for an AC supply",
                    ));
                }
                self.number(&key("frequency"), h, h > 0.0, "must be > 0 Hz")?;
            }
        }
        for (k, f) in d.dc_breaking.iter().enumerate() {
            for (what, value) in [("voltage", f.voltage), ("current", f.current)] {
                self.number(
                    &format!("datasheet.dc_breaking[{k}].{what}"),
                    value,
                    value > 0.0,
                    format!(
                        "figure {} of the DC breaking capacity: its {what} must be > 0 (in {})",
                        k + 1,
                        if what == "voltage" { "V" } else { "A" }
                    ),
                )?;
            }
        }
        if let Some(beta) = d.weibull_shape {
            self.number(
                "datasheet.weibull_shape",
                beta,
                beta > 0.0 && beta <= 20.0,
                "must be > 0 and at most 20: the Weibull shape β of the printed life",
            )?;
        }
        if let Some(m) = &d.making_current {
            if let Err((field, value, requirement)) = m.check() {
                let key = if field.is_empty() {
                    "datasheet.making_current".to_owned()
                } else {
                    format!("datasheet.making_current.{field}")
                };
                return Err(self.invalid(&key, value, requirement));
            }
        }
        for (name, figure) in d.figures() {
            if let Err((field, value, requirement)) = figure.check() {
                let key = if field.is_empty() {
                    format!("datasheet.{name}")
                } else {
                    format!("datasheet.{name}.{field}")
                };
                return Err(self.invalid(&key, value, requirement));
            }
        }
        Ok(())
    }
}
