//! `[surface]` and `[back_stop]`: the surface laws of the fixed contact
//! and of the rest stop.

use serde::Deserialize;

use super::check::Check;
use super::error::ScenarioError;
use super::law::{ReleaseRule, SurfaceLaw};
use crate::mechanics::Surface;
use crate::mechanics::surface::hunt_crossley_chi;

/// `[surface]` as written: one law and the keys it needs (docs/model.md §2).
/// The keys are all optional here because which ones are required depends
/// on `law`; validation checks them and `Scenario::surface` gives the
/// resolved law.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSection {
    /// `surface.law` (or `back_stop.law`): which law, and so which of the
    /// other keys apply.
    pub law: SurfaceLaw,
    /// N/m (Kelvin–Voigt s0) or N/mⁿ (Hunt–Crossley k).
    pub stiffness: Option<f64>,
    /// N·s/m, Kelvin–Voigt r0.
    pub damping: Option<f64>,
    /// Rigid e, or Hunt–Crossley e at `reference_velocity`.
    pub restitution: Option<f64>,
    /// Hunt–Crossley n (default 1, the paper's linear spring).
    pub exponent: Option<f64>,
    /// s/m, Hunt–Crossley χ = λ/k.
    pub chi: Option<f64>,
    /// m/s, the impact speed at which the Hunt–Crossley `restitution` holds.
    pub reference_velocity: Option<f64>,
    /// How a deformable surface lets go (`"position"`, the paper's rule
    /// and the default, or `"force"`).
    pub release: Option<ReleaseRule>,
}

impl Check<'_> {
    /// `[back_stop]`, which only a coil-driven relay reaches (on release).
    pub(super) fn back_stop(
        &self,
        s: Option<&SurfaceSection>,
        coil: bool,
    ) -> Result<Option<Surface>, ScenarioError> {
        let Some(s) = s else { return Ok(None) };
        if !coil {
            return Err(ScenarioError::Conflict {
                at: self.at("back_stop"),
                key: "back_stop".to_owned(),
                other: "mechanics.force".to_owned(),
                why: "the armature comes back to its rest stop only on release, and a \
                      step force never releases",
                advice: "give a [coil] (the release follows its driver) or remove [back_stop]",
            });
        }
        if s.release.is_some() {
            return Err(ScenarioError::Conflict {
                at: self.at("back_stop.release"),
                key: "back_stop.release".to_owned(),
                other: "back_stop.law".to_owned(),
                why: "the rest stop lets go of the armature by position (back at the stop, \
                      moving away)",
                advice: "remove the key",
            });
        }
        self.surface("back_stop", s).map(Some)
    }

    pub(super) fn surface(
        &self,
        section: &str,
        s: &SurfaceSection,
    ) -> Result<Surface, ScenarioError> {
        let law = self.surface_law(section, s)?;
        for (name, value) in [
            ("stiffness", s.stiffness),
            ("damping", s.damping),
            ("chi", s.chi),
            ("reference_velocity", s.reference_velocity),
        ] {
            self.envelope(&format!("{section}.{name}"), value)?;
        }
        Ok(law)
    }

    pub(super) fn surface_law(
        &self,
        section: &str,
        s: &SurfaceSection,
    ) -> Result<Surface, ScenarioError> {
        let law = s.law;
        let given = [
            ("stiffness", s.stiffness),
            ("damping", s.damping),
            ("restitution", s.restitution),
            ("exponent", s.exponent),
            ("chi", s.chi),
            ("reference_velocity", s.reference_velocity),
        ];
        for (name, value) in given {
            if value.is_some() && !law.keys().contains(&name) {
                let key = format!("{section}.{name}");
                return Err(ScenarioError::NotForLaw {
                    at: self.at(&key),
                    key,
                    law,
                    takes: law.keys_described(),
                });
            }
        }
        let need = |name: &str, help: &str| {
            given
                .iter()
                .find(|(n, _)| *n == name)
                .and_then(|(_, v)| *v)
                .ok_or_else(|| self.missing(&format!("{section}.{name}"), help))
        };
        match law {
            SurfaceLaw::Rigid => {
                let e = need(
                    "restitution",
                    "law \"rigid\" needs the restitution e in [0, 1]",
                )?;
                self.number(
                    &format!("{section}.restitution"),
                    e,
                    (0.0..=1.0).contains(&e),
                    "must lie in [0, 1]: 0 is a dead impact, 1 a perfectly elastic one",
                )?;
                Ok(Surface::Rigid { restitution: e })
            }
            SurfaceLaw::KelvinVoigt => {
                let stiffness = need(
                    "stiffness",
                    "law \"kelvin-voigt\" needs the surface stiffness s0 in N/m",
                )?;
                self.number(
                    &format!("{section}.stiffness"),
                    stiffness,
                    stiffness > 0.0,
                    "must be > 0: the surface stiffness s0, in N/m",
                )?;
                let damping = need(
                    "damping",
                    "law \"kelvin-voigt\" needs the surface damping r0 in N·s/m (0 is allowed)",
                )?;
                self.number(
                    &format!("{section}.damping"),
                    damping,
                    damping >= 0.0,
                    "must be ≥ 0: the surface damping r0, in N·s/m",
                )?;
                Ok(Surface::KelvinVoigt { stiffness, damping })
            }
            SurfaceLaw::HuntCrossley => self.hunt_crossley(section, s),
        }
    }

    pub(super) fn hunt_crossley(
        &self,
        section: &str,
        s: &SurfaceSection,
    ) -> Result<Surface, ScenarioError> {
        let stiffness = s.stiffness.ok_or_else(|| {
            self.missing(
                &format!("{section}.stiffness"),
                "law \"hunt-crossley\" needs the surface stiffness k in N/mⁿ",
            )
        })?;
        self.number(
            &format!("{section}.stiffness"),
            stiffness,
            stiffness > 0.0,
            "must be > 0: the surface stiffness k, in N/mⁿ",
        )?;
        // n = 1 is the paper's linear surface spring (docs/model.md §2c).
        let exponent = s.exponent.unwrap_or(1.0);
        self.number(
            &format!("{section}.exponent"),
            exponent,
            exponent > 0.0,
            "must be > 0: 1 for a linear spring, 1.5 for Hertz contact",
        )?;
        let chi = match (s.chi, s.restitution, s.reference_velocity) {
            (Some(chi), None, None) => {
                self.number(
                    &format!("{section}.chi"),
                    chi,
                    chi >= 0.0,
                    "must be ≥ 0: χ = λ/k in s/m (0 is a lossless surface)",
                )?;
                chi
            }
            (Some(_), restitution, _) => {
                let other = if restitution.is_some() {
                    format!("{section}.restitution")
                } else {
                    format!("{section}.reference_velocity")
                };
                return Err(ScenarioError::Conflict {
                    at: self.at(&format!("{section}.chi")),
                    key: format!("{section}.chi"),
                    other,
                    why: "χ is given directly, or as `restitution` at `reference_velocity`",
                    advice: "keep one of the two",
                });
            }
            (None, Some(e), Some(v)) => {
                self.number(
                    &format!("{section}.restitution"),
                    e,
                    e > 0.0 && e <= 1.0,
                    "must lie in (0, 1]: the restitution at `reference_velocity`",
                )?;
                self.number(
                    &format!("{section}.reference_velocity"),
                    v,
                    v > 0.0,
                    "must be > 0: the impact speed, in m/s, at which `restitution` holds",
                )?;
                hunt_crossley_chi(e, v).ok_or_else(|| {
                    self.invalid(
                        &format!("{section}.restitution"),
                        e,
                        format!(
                            "cannot be reached at `reference_velocity` = {v:?} m/s; \
                             give `chi` directly"
                        ),
                    )
                })?
            }
            (None, Some(_), None) => {
                return Err(self.missing(
                    &format!("{section}.reference_velocity"),
                    "a Hunt–Crossley `restitution` holds at one impact speed; give it in m/s",
                ));
            }
            (None, None, Some(_)) => {
                return Err(self.missing(
                    &format!("{section}.restitution"),
                    "`reference_velocity` needs the restitution e in (0, 1] that holds at it",
                ));
            }
            (None, None, None) => {
                return Err(self.missing(
                    &format!("{section}.chi"),
                    "law \"hunt-crossley\" needs `chi` in s/m, or `restitution` with \
                     `reference_velocity` in m/s",
                ));
            }
        };
        Ok(Surface::HuntCrossley {
            stiffness,
            exponent,
            chi,
        })
    }
}

/// The law of a section that validation has accepted (a Hunt–Crossley
/// restitution converted to χ). Only for checked sections: an unchecked
/// one gets the nearest law it describes.
pub(super) fn resolve(s: &SurfaceSection) -> Surface {
    match s.law {
        SurfaceLaw::Rigid => Surface::Rigid {
            restitution: s.restitution.unwrap_or(0.0),
        },
        SurfaceLaw::KelvinVoigt => Surface::KelvinVoigt {
            stiffness: s.stiffness.unwrap_or(0.0),
            damping: s.damping.unwrap_or(0.0),
        },
        SurfaceLaw::HuntCrossley => Surface::HuntCrossley {
            stiffness: s.stiffness.unwrap_or(0.0),
            exponent: s.exponent.unwrap_or(1.0),
            chi: match (s.chi, s.restitution, s.reference_velocity) {
                (Some(chi), _, _) => chi,
                (None, Some(e), Some(v)) => hunt_crossley_chi(e, v).unwrap_or(0.0),
                _ => 0.0,
            },
        },
    }
}
