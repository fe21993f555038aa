//! `[mechanics]`, `[coil]` and `[simulation]`: the moving contact, its
//! magnetic drive and when to stop.

use super::*;

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

/// `[coil]`: the magnetic drive of docs/model.md §7, instead of a step force.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoilSection {
    /// Ω
    pub resistance: f64,
    pub turns: u32,
    /// m²
    pub pole_area: f64,
    /// m, armature air gap at rest.
    pub air_gap: f64,
    /// m, the iron path as an equivalent air gap.
    pub iron_gap: f64,
}

/// `[simulation]`: the engine's [`Settings`].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulationSection {
    /// s
    pub t_end: f64,
    /// s
    pub min_open_time: f64,
    /// m
    pub min_gap: f64,
}

impl Default for SimulationSection {
    /// The engine's own defaults, so that the file and the library agree.
    fn default() -> Self {
        let s = Settings::default();
        SimulationSection {
            t_end: s.t_end,
            min_open_time: s.min_open_time,
            min_gap: s.min_gap,
        }
    }
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
                advice: "with [coil] the closing force comes from the coil current; \
                         remove `mechanics.force` or the [coil] section",
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

    pub(super) fn coil(&self, c: &CoilSection, gap: f64) -> Result<(), ScenarioError> {
        self.number(
            "coil.resistance",
            c.resistance,
            c.resistance > 0.0,
            "must be > 0: the coil's DC resistance, in Ω",
        )?;
        if c.turns == 0 {
            return Err(self.invalid(
                "coil.turns",
                0.0,
                "must be at least 1: the number of turns of the coil",
            ));
        }
        self.number(
            "coil.pole_area",
            c.pole_area,
            c.pole_area > 0.0,
            "must be > 0: the pole face area, in m²",
        )?;
        self.number(
            "coil.air_gap",
            c.air_gap,
            c.air_gap > gap,
            format!(
                "must exceed `mechanics.gap` = {gap:?} m: a residual air gap must remain \
                 when the contacts close"
            ),
        )?;
        self.number(
            "coil.iron_gap",
            c.iron_gap,
            c.iron_gap >= 0.0,
            "must be ≥ 0: the iron path as an equivalent air gap, in m",
        )
    }

    pub(super) fn simulation(&self, s: &SimulationSection) -> Result<(), ScenarioError> {
        self.number(
            "simulation.t_end",
            s.t_end,
            s.t_end > 0.0,
            "must be > 0: the simulated horizon, in s",
        )?;
        self.number(
            "simulation.min_open_time",
            s.min_open_time,
            s.min_open_time >= 0.0,
            "must be ≥ 0: the shortest opening worth resolving, in s",
        )?;
        self.number(
            "simulation.min_gap",
            s.min_gap,
            s.min_gap >= 0.0,
            "must be ≥ 0: the smallest opening worth resolving, in m",
        )?;
        for (key, value) in [
            ("simulation.t_end", s.t_end),
            ("simulation.min_open_time", s.min_open_time),
            ("simulation.min_gap", s.min_gap),
        ] {
            self.envelope(key, Some(value))?;
        }
        Ok(())
    }
}
