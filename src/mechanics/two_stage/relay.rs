//! The relay as it is built beyond the one-mass model: the contact blade,
//! the pole face and how a surface lets go, with their checks naming the
//! scenario key at fault.

use crate::mechanics::error::MechanicsError;
use crate::mechanics::parameters::{Mechanics, Settings, check, validate};
use crate::mechanics::surface::Surface;

/// The contact blade: the leaf spring between the armature and the moving
/// contact. SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blade {
    /// kg, the blade's mass at the contact point `m_b`.
    pub mass: f64,
    /// N/m, the blade's stiffness `s_b` between armature and contact point.
    pub stiffness: f64,
    /// N·s/m, the blade's damping `r_b` (may be 0).
    pub damping: f64,
}

/// How a deformable contact surface lets go.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Release {
    /// The paper's rule: the contact ends when the moving contact is back
    /// at the surface, moving out. A Kelvin–Voigt surface may pull just
    /// before (its force is not clamped).
    #[default]
    Position,
    /// The contact ends when its force falls to 0; the surface keeps no
    /// memory: a contact still pressed in re-engages when the force law
    /// turns positive again (a new impact).
    Force,
}

impl Release {
    /// The contract name (`surface.release`).
    pub fn as_str(self) -> &'static str {
        match self {
            Release::Position => "position",
            Release::Force => "force",
        }
    }
}

/// The armature's stop past the contact: the pole face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoleFace {
    /// m, the armature's travel from the contact's gap to the pole face `o`.
    pub overtravel: f64,
    /// The pole face's surface law.
    pub surface: Surface,
    /// How the pole face lets go of the armature.
    pub release: Release,
}

/// Everything the relay has beyond the one-mass model: a blade, a pole
/// face, and the contact's release rule.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TwoStage {
    /// The contact blade; `None`: the contact is on the armature.
    pub blade: Option<Blade>,
    /// The pole face (needs a blade).
    pub pole_face: Option<PoleFace>,
    /// How the contact surface lets go.
    pub release: Release,
}

impl TwoStage {
    /// Whether this is the paper's one-mass model exactly (no blade, no
    /// pole face, released by position): then the one-mass engines run it.
    pub fn is_one_mass(&self) -> bool {
        self.blade.is_none() && self.pole_face.is_none() && self.release == Release::Position
    }

    /// Check the blade and the pole face, naming the scenario key at fault.
    pub fn validate(&self, contact: &Surface) -> Result<(), MechanicsError> {
        if let Some(b) = &self.blade {
            check("blade.mass", b.mass, b.mass > 0.0, "a mass in kg, > 0")?;
            check(
                "blade.stiffness",
                b.stiffness,
                b.stiffness > 0.0,
                "a blade stiffness in N/m, > 0",
            )?;
            check(
                "blade.damping",
                b.damping,
                b.damping >= 0.0,
                "a damping in N·s/m, ≥ 0",
            )?;
        }
        if let Some(p) = &self.pole_face {
            if self.blade.is_none() {
                return Err(MechanicsError::InvalidParameter {
                    name: "pole_face.overtravel",
                    value: p.overtravel,
                    requirement: "a pole face needs a [blade]: without one the contact itself \
                                  stops the armature",
                });
            }
            check(
                "pole_face.overtravel",
                p.overtravel,
                p.overtravel > 0.0,
                "an overtravel in m, > 0",
            )?;
            check_surface("pole_face", &p.surface)?;
        }
        check_surface("surface", contact)?;
        Ok(())
    }
}

/// The keys of one surface law, under `section`.
fn check_surface(section: &'static str, surface: &Surface) -> Result<(), MechanicsError> {
    let key = |name: &'static str| -> &'static str {
        match (section, name) {
            ("pole_face", "restitution") => "pole_face.restitution",
            ("pole_face", "stiffness") => "pole_face.stiffness",
            ("pole_face", "damping") => "pole_face.damping",
            ("pole_face", "exponent") => "pole_face.exponent",
            ("pole_face", "chi") => "pole_face.chi",
            (_, "restitution") => "surface.restitution",
            (_, "stiffness") => "surface.stiffness",
            (_, "damping") => "surface.damping",
            (_, "exponent") => "surface.exponent",
            _ => "surface.chi",
        }
    };
    let bad = |name: &'static str, value: f64, requirement: &'static str| {
        Err(MechanicsError::InvalidParameter {
            name: key(name),
            value,
            requirement,
        })
    };
    match *surface {
        Surface::Rigid { restitution } if !(0.0..=1.0).contains(&restitution) => bad(
            "restitution",
            restitution,
            "a coefficient of restitution in [0, 1]",
        ),
        Surface::KelvinVoigt { stiffness, .. } if !(stiffness > 0.0 && stiffness.is_finite()) => {
            bad("stiffness", stiffness, "a surface stiffness in N/m, > 0")
        }
        Surface::KelvinVoigt { damping, .. } if !(damping >= 0.0 && damping.is_finite()) => {
            bad("damping", damping, "a surface damping in N·s/m, ≥ 0")
        }
        Surface::HuntCrossley { stiffness, .. } if !(stiffness > 0.0 && stiffness.is_finite()) => {
            bad("stiffness", stiffness, "a surface stiffness, > 0")
        }
        Surface::HuntCrossley { exponent, .. } if !(exponent >= 1.0 && exponent.is_finite()) => {
            bad("exponent", exponent, "an exponent ≥ 1")
        }
        Surface::HuntCrossley { chi, .. } if !(chi >= 0.0 && chi.is_finite()) => {
            bad("chi", chi, "a damping factor χ in s/m, ≥ 0")
        }
        _ => Ok(()),
    }
}

/// A mechanics and its two-stage parts, checked together.
pub(crate) fn validate_all(
    m: &Mechanics,
    build: &TwoStage,
    contact: &Surface,
    settings: &Settings,
) -> Result<(), MechanicsError> {
    let unforced = Mechanics { force: 0.0, ..*m };
    validate(&unforced, contact, settings)?;
    build.validate(contact)
}
