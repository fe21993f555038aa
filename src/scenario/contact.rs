//! `[contact]` and `[contact.holm]`: the contact as a resistor. The law
//! itself ([`Holm`], [`ContactModel`]) lives in the waveform stage; this
//! file reads and checks its numbers.

use serde::Deserialize;

use super::check::Check;
use super::error::ScenarioError;
use crate::waveform::{ContactModel, Holm};

/// `[contact]`: the contact as a resistor (docs/model.md §5).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactSection {
    /// Ω
    pub r_closed: f64,
    /// Ω
    pub r_open: f64,
    /// s, duration of each make or break edge.
    pub edge_time: f64,
    /// `[contact.holm]`: the closed resistance follows the contact force
    /// instead of being `r_closed`.
    pub holm: Option<HolmSection>,
}

/// `[contact.holm]`: R = r_film + r_ref·(f_ref/F)^exponent (docs/model.md §5).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HolmSection {
    /// Ω, the film resistance no force removes (default 0).
    #[serde(default)]
    pub r_film: f64,
    /// Ω, the constriction resistance at `f_ref`.
    pub r_ref: f64,
    /// N
    pub f_ref: f64,
    /// 1/2 for plastic contact spots (default), 1/3 for elastic.
    #[serde(default = "default_holm_exponent")]
    pub exponent: f64,
}

pub(super) fn default_holm_exponent() -> f64 {
    0.5
}

impl From<&HolmSection> for Holm {
    fn from(h: &HolmSection) -> Holm {
        Holm {
            r_film: h.r_film,
            r_ref: h.r_ref,
            f_ref: h.f_ref,
            exponent: h.exponent,
        }
    }
}

impl Default for ContactSection {
    /// 50 mΩ is the low end of datasheet closed resistance, 1 GΩ is above
    /// any datasheet's open minimum, and 10 ns edges are far shorter than
    /// any bounce yet long enough for ngspice to step through.
    fn default() -> Self {
        ContactSection {
            r_closed: 0.05,
            r_open: 1.0e9,
            edge_time: 1.0e-8,
            holm: None,
        }
    }
}

impl From<&ContactSection> for ContactModel {
    fn from(c: &ContactSection) -> Self {
        ContactModel {
            r_closed: c.r_closed,
            r_open: c.r_open,
            edge_time: c.edge_time,
        }
    }
}

impl Check<'_> {
    pub(super) fn contact(&self, c: &ContactSection) -> Result<(), ScenarioError> {
        self.number(
            "contact.r_closed",
            c.r_closed,
            c.r_closed > 0.0,
            "must be > 0: the closed contact resistance, in Ω (datasheets: 0.05–0.1)",
        )?;
        self.number(
            "contact.r_open",
            c.r_open,
            c.r_open > c.r_closed,
            format!(
                "must exceed `contact.r_closed` = {:?} Ω: the open contact resistance, in Ω",
                c.r_closed
            ),
        )?;
        self.number(
            "contact.edge_time",
            c.edge_time,
            c.edge_time > 0.0,
            "must be > 0: the duration of each make or break edge, in s",
        )?;
        let Some(h) = &c.holm else {
            return Ok(());
        };
        self.number(
            "contact.holm.r_film",
            h.r_film,
            h.r_film >= 0.0,
            "must be >= 0: the film resistance that no force removes, in Ω",
        )?;
        self.number(
            "contact.holm.r_ref",
            h.r_ref,
            h.r_ref > 0.0,
            "must be > 0: the constriction resistance at `f_ref`, in Ω",
        )?;
        self.number(
            "contact.holm.f_ref",
            h.f_ref,
            h.f_ref > 0.0,
            "must be > 0: the contact force at which the constriction is `r_ref`, in N",
        )?;
        self.number(
            "contact.holm.exponent",
            h.exponent,
            h.exponent > 0.0 && h.exponent <= 1.0,
            "must be in (0, 1]: 0.5 for plastic contact spots, 1/3 (0.3333) for elastic",
        )
    }
}
