//! The relay's parameters as the engines take them: the moving contact
//! and its drive ([`Mechanics`]), the two stops it meets ([`Stops`]), when
//! to stop and what is too small to matter ([`Settings`]), the paper's
//! dimensionless view ([`Dimensionless`]), and the checks every engine
//! runs first, each naming the scenario key at fault ([`validate`]).

use super::error::MechanicsError;
use super::surface::Surface;

/// The moving contact and its drive (docs/model.md §1). SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mechanics {
    /// kg, effective moving mass `m`.
    pub mass: f64,
    /// N/m, suspension (contact-spring) stiffness `s`.
    pub stiffness: f64,
    /// N·s/m, structural damping `r` (may be 0).
    pub damping: f64,
    /// N, closing force `f`, a step at t = 0.
    pub force: f64,
    /// m, travel from rest to the fixed contact `g`.
    pub gap: f64,
    /// m, `x(0)`.
    pub initial_position: f64,
    /// m/s, `ẋ(0)`.
    pub initial_velocity: f64,
    /// N, return-spring preload `p` holding the armature on its rest stop;
    /// with a step force it simply subtracts from `f`.
    pub preload: f64,
}

/// How far a closing that is closed at `t_end`, but not yet proven to
/// stay closed, is followed on to prove it: to this many times `t_end`
/// (with the drive as it is). Stuck, with its settle time before `t_end`,
/// only when proven before any further event; else `end_of_time`, saying
/// that the contact was closed.
pub const PROOF_SPAN: f64 = 30.0;

/// When to stop and what is too small to matter (docs/model.md §4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// s, the simulated horizon.
    pub t_end: f64,
    /// s, an opening shorter than this ends the sequence as `resolved`.
    pub min_open_time: f64,
    /// m, an opening smaller than this ends the sequence as `resolved`.
    pub min_gap: f64,
}

impl Default for Settings {
    /// 20 ms horizon (a signal relay settles in ≤ 5 ms); 1 ns and 1 nm are
    /// far below what any circuit or contact surface can resolve.
    fn default() -> Self {
        Settings {
            t_end: 0.02,
            min_open_time: 1e-9,
            min_gap: 1e-9,
        }
    }
}

/// The paper's dimensionless groups (docs/model.md §1–2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dimensionless {
    /// rad/s, ωn = √(s/m); dimensionless time is τ = ωn t.
    pub omega_n: f64,
    /// ζ = r / (2√(m s)).
    pub zeta: f64,
    /// m, F = (f − p)/s, the static deflection under the closing force.
    pub static_deflection: f64,
    /// k0 = g/F.
    pub k0: f64,
    /// ζ0 = r0 / (2√(m s)) (Kelvin–Voigt only).
    pub zeta0: Option<f64>,
    /// β = 1 + s0/s (Kelvin–Voigt only).
    pub beta: Option<f64>,
    /// σ = ζ + ζ0 (Kelvin–Voigt only).
    pub sigma: Option<f64>,
    /// ζ' = σ/√β, the damping ratio of the in-contact oscillation.
    pub zeta_prime: Option<f64>,
    /// γ = (1 + k0 s0/s)/β: the in-contact equilibrium is γF.
    pub gamma: Option<f64>,
}

impl Dimensionless {
    /// The dimensionless view of a relay and surface.
    pub fn of(m: &Mechanics, surface: &Surface) -> Dimensionless {
        let omega_n = (m.stiffness / m.mass).sqrt();
        let crit = 2.0 * (m.mass * m.stiffness).sqrt();
        let zeta = m.damping / crit;
        let f_net = m.force - m.preload;
        let static_deflection = f_net / m.stiffness;
        let k0 = m.gap / static_deflection;
        let (zeta0, beta, sigma, zeta_prime, gamma) = match *surface {
            Surface::KelvinVoigt { stiffness, damping } => {
                let zeta0 = damping / crit;
                let beta = 1.0 + stiffness / m.stiffness;
                let sigma = zeta + zeta0;
                let gamma = (1.0 + k0 * stiffness / m.stiffness) / beta;
                (
                    Some(zeta0),
                    Some(beta),
                    Some(sigma),
                    Some(sigma / beta.sqrt()),
                    Some(gamma),
                )
            }
            _ => (None, None, None, None, None),
        };
        Dimensionless {
            omega_n,
            zeta,
            static_deflection,
            k0,
            zeta0,
            beta,
            sigma,
            zeta_prime,
            gamma,
        }
    }
}

/// How the armature meets the two stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stops {
    /// The fixed NO contact at x = g.
    pub make: Surface,
    /// The rest stop at x = 0; `None`: inelastic, held at once.
    pub back: Option<Surface>,
}

/// `value` of key `name` is finite and `ok`, or the error naming the key
/// and what it must satisfy.
pub(crate) fn check(
    name: &'static str,
    value: f64,
    ok: bool,
    requirement: &'static str,
) -> Result<(), MechanicsError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(MechanicsError::InvalidParameter {
            name,
            value,
            requirement,
        })
    }
}

/// Check every parameter the engine relies on.
pub fn validate(m: &Mechanics, surface: &Surface, s: &Settings) -> Result<(), MechanicsError> {
    check("mechanics.mass", m.mass, m.mass > 0.0, "a mass in kg, > 0")?;
    check(
        "mechanics.stiffness",
        m.stiffness,
        m.stiffness > 0.0,
        "a suspension stiffness in N/m, > 0",
    )?;
    check(
        "mechanics.damping",
        m.damping,
        m.damping >= 0.0,
        "a damping in N·s/m, ≥ 0",
    )?;
    check("mechanics.force", m.force, true, "a finite force in N")?;
    check("mechanics.gap", m.gap, m.gap > 0.0, "a gap in m, > 0")?;
    check(
        "mechanics.initial_position",
        m.initial_position,
        m.initial_position < m.gap,
        "a position in m below the gap (the contact starts open)",
    )?;
    check(
        "mechanics.initial_velocity",
        m.initial_velocity,
        true,
        "a finite velocity in m/s",
    )?;
    check(
        "mechanics.preload",
        m.preload,
        m.preload >= 0.0,
        "a preload in N, ≥ 0",
    )?;
    match *surface {
        Surface::Rigid { restitution } => check(
            "surface.restitution",
            restitution,
            (0.0..=1.0).contains(&restitution),
            "a coefficient of restitution in [0, 1]",
        )?,
        Surface::KelvinVoigt { stiffness, damping } => {
            check(
                "surface.stiffness",
                stiffness,
                stiffness > 0.0,
                "a surface stiffness in N/m, > 0",
            )?;
            check(
                "surface.damping",
                damping,
                damping >= 0.0,
                "a surface damping in N·s/m, ≥ 0",
            )?;
        }
        Surface::HuntCrossley {
            stiffness,
            exponent,
            chi,
        } => {
            check(
                "surface.stiffness",
                stiffness,
                stiffness > 0.0,
                "a surface stiffness in N/mⁿ, > 0",
            )?;
            check(
                "surface.exponent",
                exponent,
                (1.0..=3.0).contains(&exponent),
                "an exponent n in [1, 3] (1: linear spring, 1.5: Hertz)",
            )?;
            check("surface.chi", chi, chi >= 0.0, "χ = λ/k in s/m, ≥ 0")?;
        }
    }
    check(
        "simulation.t_end",
        s.t_end,
        s.t_end > 0.0,
        "a horizon in s, > 0",
    )?;
    check(
        "simulation.min_open_time",
        s.min_open_time,
        s.min_open_time >= 0.0,
        "a time in s, ≥ 0",
    )?;
    check(
        "simulation.min_gap",
        s.min_gap,
        s.min_gap >= 0.0,
        "a distance in m, ≥ 0",
    )?;
    Ok(())
}
