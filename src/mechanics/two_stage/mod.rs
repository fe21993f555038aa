//! The relay as it is built: the armature, the contact blade it carries,
//! the overtravel and the pole face (docs/model.md, "The two-stage relay").
//!
//! The one-mass model moves the armature and the moving contact together.
//! In a relay the moving contact sits on a leaf spring, the blade, carried
//! by the armature. The blade's contact point makes the contact; the
//! armature travels on (the overtravel), bending the blade, and stops on
//! the pole face. That second impact shakes the blade and may open the
//! contact again: a second burst of bounces.
//!
//! Coordinates toward closing, both 0 at rest: `x_a` (the armature,
//! measured at the contact) and `x_b` (the blade's contact point).
//!
//! ```text
//! F_b = s_b (x_a − x_b) + r_b (ẋ_a − ẋ_b)            the blade's spring
//! m ẍ_a + r ẋ_a + s x_a + p = F(t, x_a) − F_b − F_pole(x_a − g − o, ẋ_a)
//! m_b ẍ_b = F_b − F_c(x_b − g, ẋ_b)
//! ```
//!
//! with `F_c` the contact's surface law and `F_pole` the pole face's. The
//! same engine also runs the one-mass model with the contact released by
//! its force (`surface.release = "force"`): without a blade the contact
//! law acts on the armature itself.
//!
//! The engine ([`engine`]) is event-driven: between events the motion is
//! integrated by DOP853 with dense output; every impact, release,
//! lift-off and landing is located on the dense output by bisection to
//! adjacent floats, and the state after it is set exactly on the surface.
//! A closing ends when an energy bound (docs/model.md §11) proves that the
//! contact can no longer release (`stuck`), or reach the contact again
//! (`ends_open`).

pub(crate) mod energy;
pub mod engine;
pub(crate) mod linear;

use super::cycle::Stroke;
use super::{DriveError, Mechanics, MechanicsError, Surface};
use crate::chatter::{Chatter, Impact};

pub use engine::{Horizon, simulate_two_stage};

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
        use super::engine::check;
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

/// A two-stage run.
#[derive(Debug, Clone, PartialEq)]
pub struct TwoStageRun {
    /// The contact's record: the blade's contact point on the fixed
    /// contact (the armature's without a blade), both bursts.
    pub contact: Chatter,
    /// The armature's impacts on the pole face, in time order (velocities
    /// of the armature; a release velocity is negative, away from it).
    pub pole_face: Vec<Impact>,
    /// The armature on its rest stop (the normally-closed side): its
    /// landings (a driven cycle only; empty under a step force).
    pub back: Chatter,
    /// Every stroke of the armature (a driven run).
    pub strokes: Vec<Stroke>,
    /// s, the first lift-off from the rest stop.
    pub lift_off: Option<f64>,
    /// Integration steps taken.
    pub steps: usize,
    /// The motion, step by step, for [`super::Trajectory`].
    pub(crate) pieces: Vec<engine::Span>,
}

impl TwoStageRun {
    /// (m, m/s, m, m/s): armature position and velocity, blade contact
    /// point position and velocity at `t` (s), held at the ends.
    pub fn state(&self, t: f64, gap: f64) -> (f64, f64, f64, f64) {
        let y = engine::state_at(&self.pieces, t);
        (gap + y[0], y[1], gap + y[2], y[3])
    }
}

/// A mechanics and its two-stage parts, checked together.
pub(crate) fn validate_all(
    m: &Mechanics,
    build: &TwoStage,
    contact: &Surface,
    settings: &super::Settings,
) -> Result<(), MechanicsError> {
    let unforced = Mechanics { force: 0.0, ..*m };
    super::validate(&unforced, contact, settings)?;
    build.validate(contact)
}

#[cfg(test)]
mod tests;

/// The closing of `m` under its step force onto `surface`, built as
/// `build`: the exact one-mass engine when `build` is the one-mass model
/// (the same numbers to the last digit), else the two-stage engine.
pub fn step_closing(
    m: &Mechanics,
    build: &TwoStage,
    surface: &Surface,
    settings: &super::Settings,
) -> Result<super::Trajectory, DriveError> {
    if build.is_one_mass() {
        return Ok(super::Trajectory::of_step(m, surface, settings)?);
    }
    let stops = super::cycle::Stops {
        make: *surface,
        back: None,
    };
    let run = simulate_two_stage(
        m,
        build,
        &stops,
        settings,
        super::Drive::Step,
        Horizon::Closing,
    )?;
    Ok(super::Trajectory::of_two_stage(m, &stops, settings, run))
}

/// The whole run of `m` under a force `F(t, x)` (N toward closing at the
/// armature's position `x`), built as `build`: the one-mass cycle engine
/// when `build` is the one-mass model, else the two-stage engine to
/// `settings.t_end`.
pub fn driven_run(
    m: &Mechanics,
    build: &TwoStage,
    stops: &super::cycle::Stops,
    settings: &super::Settings,
    force: &dyn Fn(f64, f64) -> f64,
) -> Result<super::Trajectory, DriveError> {
    if build.is_one_mass() {
        return super::simulate_drive(m, stops, settings, super::Drive::Force(force));
    }
    let run = simulate_two_stage(
        m,
        build,
        stops,
        settings,
        super::Drive::Force(force),
        Horizon::Cycle,
    )?;
    Ok(super::Trajectory::of_two_stage(m, stops, settings, run))
}
