//! `[blade]`, `[pole_face]` and `surface.release`: the relay as it is
//! built (docs/model.md, "The two-stage relay"). The release rule itself
//! ([`ReleaseRule`]) is in `law.rs`, beside the surface laws.

use serde::Deserialize;

use super::check::Check;
use super::error::ScenarioError;
use super::law::{ReleaseRule, SurfaceLaw};
use super::surface::SurfaceSection;
use crate::mechanics::two_stage::{Blade, PoleFace, TwoStage};

/// `[blade]`: the moving contact on its leaf spring. SI units.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BladeSection {
    /// kg, the blade's mass at the contact point.
    pub mass: f64,
    /// N/m, the blade's stiffness between armature and contact point.
    pub stiffness: f64,
    /// N·s/m, the blade's damping (default 0).
    #[serde(default)]
    pub damping: f64,
}

/// `[pole_face]`: the armature's stop past the contact, `overtravel`
/// beyond the contact's gap, with a surface law of its own (the keys of
/// `[surface]`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoleFaceSection {
    /// m, from the contact's gap to the pole face.
    pub overtravel: f64,
    /// The pole face's law, as `surface.law`.
    pub law: SurfaceLaw,
    /// N/m (Kelvin–Voigt) or N/mⁿ (Hunt–Crossley).
    pub stiffness: Option<f64>,
    /// N·s/m, Kelvin–Voigt.
    pub damping: Option<f64>,
    /// Rigid e, or Hunt–Crossley e at `reference_velocity`.
    pub restitution: Option<f64>,
    /// Hunt–Crossley n.
    pub exponent: Option<f64>,
    /// s/m, Hunt–Crossley χ.
    pub chi: Option<f64>,
    /// m/s, where the Hunt–Crossley `restitution` holds.
    pub reference_velocity: Option<f64>,
    /// How the pole face lets go (default `"position"`).
    pub release: Option<ReleaseRule>,
}

impl PoleFaceSection {
    /// The surface keys, as a `[surface]`-like section.
    pub fn surface(&self) -> SurfaceSection {
        SurfaceSection {
            law: self.law,
            stiffness: self.stiffness,
            damping: self.damping,
            restitution: self.restitution,
            exponent: self.exponent,
            chi: self.chi,
            reference_velocity: self.reference_velocity,
            release: self.release,
        }
    }
}

impl Check<'_> {
    /// `[blade]` and `[pole_face]`, and the release rules: the relay as
    /// built.
    pub(super) fn two_stage(
        &self,
        blade: Option<&BladeSection>,
        pole_face: Option<&PoleFaceSection>,
        surface: &SurfaceSection,
        gap: f64,
    ) -> Result<TwoStage, ScenarioError> {
        if let Some(b) = blade {
            self.number(
                "blade.mass",
                b.mass,
                b.mass > 0.0 && b.mass <= 1e3,
                "must be > 0: the blade's mass at the contact point, in kg (10–100 mg in a \
                 small relay)",
            )?;
            self.number(
                "blade.stiffness",
                b.stiffness,
                b.stiffness > 0.0 && b.stiffness <= 1e12,
                "must be > 0: the blade's stiffness, in N/m (0.5–5 kN/m in a small relay)",
            )?;
            self.number(
                "blade.damping",
                b.damping,
                b.damping >= 0.0 && b.damping <= 1e9,
                "must be ≥ 0: the blade's damping, in N·s/m",
            )?;
        }
        if surface.release.is_some() && surface.law == SurfaceLaw::Rigid {
            return Err(ScenarioError::NotForLaw {
                at: self.at("surface.release"),
                key: "surface.release".to_owned(),
                law: SurfaceLaw::Rigid,
                takes: SurfaceLaw::Rigid.keys_described(),
            });
        }
        let pole = match pole_face {
            None => None,
            Some(p) => {
                if blade.is_none() {
                    return Err(ScenarioError::MissingKey {
                        at: self.at("pole_face"),
                        key: "blade".to_owned(),
                        help: "a pole face stops the armature after the contact blade has \
                               made; without a [blade] the contact itself stops it: add \
                               [blade] (mass, stiffness) or remove [pole_face]"
                            .to_owned(),
                        source: None,
                    });
                }
                self.number(
                    "pole_face.overtravel",
                    p.overtravel,
                    p.overtravel > 0.0 && p.overtravel <= 1.0,
                    "must be > 0: the armature's travel from the contact's gap to the pole \
                     face, in m (0.1–0.5 mm in a small relay)",
                )?;
                let section = p.surface();
                if p.release.is_some() && p.law == SurfaceLaw::Rigid {
                    return Err(ScenarioError::NotForLaw {
                        at: self.at("pole_face.release"),
                        key: "pole_face.release".to_owned(),
                        law: SurfaceLaw::Rigid,
                        takes: SurfaceLaw::Rigid.keys_described(),
                    });
                }
                let law = self.surface("pole_face", &section)?;
                Some(PoleFace {
                    overtravel: p.overtravel,
                    surface: law,
                    release: p.release.unwrap_or_default().into(),
                })
            }
        };
        let _ = gap;
        Ok(TwoStage {
            blade: blade.map(|b| Blade {
                mass: b.mass,
                stiffness: b.stiffness,
                damping: b.damping,
            }),
            pole_face: pole,
            release: surface.release.unwrap_or_default().into(),
        })
    }
}
