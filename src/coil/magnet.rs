//! The magnet: the relay coil and its single-air-gap magnetic circuit
//! ([`Coil`]): inductance, flux and pull at any armature position, and the
//! checks of its parameters.

/// H/m, the vacuum permeability (CODATA 2018; 4π·10⁻⁷ to 6e-10).
pub const MU0: f64 = 1.256_637_062_12e-6;

/// The relay coil and its magnetic circuit (docs/model.md §7). SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coil {
    /// Ω, the coil's DC resistance `R_c`.
    pub resistance: f64,
    /// Number of turns `N`.
    pub turns: f64,
    /// m², pole face area `A`.
    pub pole_area: f64,
    /// m, armature air gap at rest `g_a` (larger than the contact travel,
    /// so a residual gap remains when the contacts close).
    pub air_gap: f64,
    /// m, the iron path as an equivalent air gap `l_eq = l_fe/μr`.
    pub iron_gap: f64,
}

impl Coil {
    /// H·m, `k = μ0 N² A`: the inductance is `k` over the total
    /// equivalent gap.
    pub fn permeance_length(&self) -> f64 {
        MU0 * self.turns * self.turns * self.pole_area
    }

    /// m, the total equivalent gap `g_a − x + l_eq` with the armature at
    /// `x`.
    pub fn total_gap(&self, x: f64) -> f64 {
        self.air_gap + self.iron_gap - x
    }

    /// H, `L(x) = μ0 N² A / (g_a − x + l_eq)`.
    pub fn inductance(&self, x: f64) -> f64 {
        self.permeance_length() / self.total_gap(x)
    }

    /// H/m, `L'(x) = μ0 N² A / (g_a − x + l_eq)²`.
    pub fn d_inductance(&self, x: f64) -> f64 {
        let gap = self.total_gap(x);
        self.permeance_length() / (gap * gap)
    }

    /// N, the pull toward closing at current `i` (A) and position `x` (m):
    /// `½ i² L'(x)`.
    pub fn force(&self, i: f64, x: f64) -> f64 {
        0.5 * i * i * self.d_inductance(x)
    }

    /// N, the same pull from the flux linkage ψ (Wb): `ψ²/(2 μ0 N² A)`,
    /// independent of the position.
    pub fn force_from_flux(&self, flux: f64) -> f64 {
        0.5 * flux * flux / self.permeance_length()
    }

    /// A, the current that carries flux linkage `flux` (Wb) at `x` (m).
    pub fn current(&self, flux: f64, x: f64) -> f64 {
        flux / self.inductance(x)
    }

    /// Check every parameter; `gap` is the contact travel `mechanics.gap`
    /// (m), which the air gap must exceed.
    pub fn validate(&self, gap: f64) -> Result<(), CoilError> {
        check(
            "coil.resistance",
            self.resistance,
            self.resistance > 0.0,
            "must be > 0: the coil's DC resistance, in Ω",
        )?;
        check(
            "coil.turns",
            self.turns,
            self.turns >= 1.0,
            "must be at least 1: the number of turns of the coil",
        )?;
        check(
            "coil.pole_area",
            self.pole_area,
            self.pole_area > 0.0,
            "must be > 0: the pole face area, in m²",
        )?;
        check(
            "coil.air_gap",
            self.air_gap,
            self.air_gap > gap,
            "must exceed `mechanics.gap`: a residual air gap must remain when the contacts close",
        )?;
        check(
            "coil.iron_gap",
            self.iron_gap,
            self.iron_gap >= 0.0,
            "must be ≥ 0: the iron path as an equivalent air gap, in m",
        )
    }
}

/// What the coupled solvers can fail on: the driven mechanics' own
/// errors ([`crate::mechanics::DriveError`], under the name the coil has
/// always used).
pub use crate::mechanics::DriveError as CoilError;

fn check(
    name: &'static str,
    value: f64,
    ok: bool,
    requirement: &'static str,
) -> Result<(), CoilError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(CoilError::InvalidParameter {
            name,
            value,
            requirement,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference() -> Coil {
        Coil {
            resistance: 70.0,
            turns: 3000.0,
            pole_area: 2e-5,
            air_gap: 0.6e-3,
            iron_gap: 0.05e-3,
        }
    }

    #[test]
    fn inductance_derivative_and_force_agree() {
        let c = reference();
        // L(0) = μ0·9e6·2e-5 / 0.65e-3 ≈ 0.348 H: a small relay coil.
        assert!((c.inductance(0.0) - 0.347_991_8).abs() < 1e-7);
        for x in [0.0, 1e-4, 4.5e-4] {
            let h = 1e-9;
            let fd = (c.inductance(x + h) - c.inductance(x - h)) / (2.0 * h);
            assert!((fd / c.d_inductance(x) - 1.0).abs() < 1e-7, "{x}");
            // The pull from the current and from the flux is one force.
            let i = 0.03;
            let psi = c.inductance(x) * i;
            let f = c.force(i, x);
            assert!((c.force_from_flux(psi) / f - 1.0).abs() < 1e-14);
            assert!((c.current(psi, x) - i).abs() < 1e-16);
        }
    }

    #[test]
    fn validation_names_the_key() {
        let bad = Coil {
            turns: 0.0,
            ..reference()
        };
        match bad.validate(4.5e-4) {
            Err(CoilError::InvalidParameter { name, .. }) => assert_eq!(name, "coil.turns"),
            other => panic!("{other:?}"),
        }
        let shallow = Coil {
            air_gap: 4e-4,
            ..reference()
        };
        let err = shallow.validate(4.5e-4).unwrap_err();
        assert!(err.to_string().contains("coil.air_gap"), "{err}");
        assert!(reference().validate(4.5e-4).is_ok());
        let nan = Coil {
            iron_gap: f64::NAN,
            ..reference()
        };
        assert!(nan.validate(4.5e-4).is_err());
    }
}
