//! `[mechanics]`: the moving contact, and its drive (a step force, or
//! the `[coil]` of `coil.rs`).

use serde::Deserialize;

use super::check::Check;
use super::coil::CoilSection;
use super::error::ScenarioError;

/// `[mechanics]`: the moving contact (docs/model.md §1). SI units.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MechanicsSection {
    /// kg
    pub mass: f64,
    /// N/m
    pub stiffness: f64,
    /// N·s/m, may be 0.
    pub damping: f64,
    /// N, the step closing force; `None` when `[coil]` drives the contact.
    pub force: Option<f64>,
    /// m
    pub gap: f64,
    /// m
    #[serde(default)]
    pub initial_position: f64,
    /// m/s
    #[serde(default)]
    pub initial_velocity: f64,
    /// N, return-spring force holding the armature on its rest stop.
    #[serde(default)]
    pub preload: f64,
}

impl Check<'_> {
    pub(super) fn mechanics(&self, m: &MechanicsSection) -> Result<(), ScenarioError> {
        self.number(
            "mechanics.mass",
            m.mass,
            m.mass > 0.0,
            "must be > 0: the effective moving mass, in kg",
        )?;
        self.number(
            "mechanics.stiffness",
            m.stiffness,
            m.stiffness > 0.0,
            "must be > 0: the contact-spring stiffness, in N/m",
        )?;
        self.number(
            "mechanics.damping",
            m.damping,
            m.damping >= 0.0,
            "must be ≥ 0: damping removes energy, it cannot add it",
        )?;
        self.number(
            "mechanics.gap",
            m.gap,
            m.gap > 0.0,
            "must be > 0: the travel from rest to the fixed contact, in m",
        )?;
        self.number(
            "mechanics.initial_position",
            m.initial_position,
            m.initial_position < m.gap,
            format!(
                "must be less than `mechanics.gap` = {:?} m: the contact has to start open",
                m.gap
            ),
        )?;
        self.number("mechanics.initial_velocity", m.initial_velocity, true, "")?;
        self.number(
            "mechanics.preload",
            m.preload,
            m.preload >= 0.0,
            "must be ≥ 0: the return spring holds the armature on its rest stop",
        )?;
        for (key, value) in [
            ("mechanics.mass", Some(m.mass)),
            ("mechanics.stiffness", Some(m.stiffness)),
            ("mechanics.damping", Some(m.damping)),
            ("mechanics.force", m.force),
            ("mechanics.gap", Some(m.gap)),
            ("mechanics.initial_position", Some(m.initial_position)),
            ("mechanics.initial_velocity", Some(m.initial_velocity)),
            ("mechanics.preload", Some(m.preload)),
        ] {
            self.envelope(key, value)?;
        }
        Ok(())
    }

    /// Exactly one of a step force and a coil.
    pub(super) fn drive(
        &self,
        m: &MechanicsSection,
        coil: Option<&CoilSection>,
    ) -> Result<(), ScenarioError> {
        match (m.force, coil) {
            (Some(_), Some(_)) => Err(ScenarioError::Conflict {
                at: self.at("mechanics.force"),
                key: "mechanics.force".to_owned(),
                other: "coil".to_owned(),
                why: "with [coil] the closing force comes from the coil current, and a \
                      coil-driven relay has no step force",
                advice: "remove `mechanics.force` or the [coil] section (a [coil] written \
                         over a base's step force replaces it by itself)",
            }),
            (None, None) => Err(self.missing(
                "mechanics.force",
                "give the step closing force in N, or a [coil] section that produces it",
            )),
            (Some(force), None) => {
                self.number(
                    "mechanics.force",
                    force,
                    force >= 0.0,
                    "must be ≥ 0: the step closing force, in N",
                )?;
                // The preload holds the armature only while it rests on its
                // stop: one that starts off it, or moving toward the
                // contact, flies whatever the force (a free impact).
                let at_rest = m.initial_position <= 0.0 && m.initial_velocity <= 0.0;
                self.number(
                    "mechanics.force",
                    force,
                    force > m.preload || !at_rest,
                    format!(
                        "must exceed `mechanics.preload` = {:?} N for an armature that starts at \
                         rest on its stop, or it never leaves it; for a free impact start it \
                         off the stop (`mechanics.initial_position` > 0) or moving toward the \
                         contact (`mechanics.initial_velocity` > 0)",
                        m.preload
                    ),
                )
            }
            (None, Some(c)) => self.coil(c, m.gap),
        }
    }
}
