//! The arc's physics: contact materials and their minimum arc voltage
//! and current, the arc model, and the breakdown voltage of the gap.

use serde::{Deserialize, Serialize};

/// A contact material with published minimum arc voltage and current.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Material {
    /// Silver.
    Ag,
    /// Silver–nickel.
    AgNi,
    /// Silver–tin oxide.
    AgSnO2,
    /// Gold.
    Au,
    /// Copper.
    Cu,
    /// Palladium.
    Pd,
    /// Tungsten.
    W,
}

impl Material {
    /// Every material, in the order above.
    pub const ALL: [Material; 7] = [
        Material::Ag,
        Material::AgNi,
        Material::AgSnO2,
        Material::Au,
        Material::Cu,
        Material::Pd,
        Material::W,
    ];

    /// The name used in scenario files, e.g. `AgSnO2`.
    pub fn as_str(self) -> &'static str {
        match self {
            Material::Ag => "Ag",
            Material::AgNi => "AgNi",
            Material::AgSnO2 => "AgSnO2",
            Material::Au => "Au",
            Material::Cu => "Cu",
            Material::Pd => "Pd",
            Material::W => "W",
        }
    }

    /// V, the minimum arc voltage (docs/arcs.md, materials table). The
    /// silver composites take silver's value: their arc roots stand on
    /// the silver matrix.
    pub fn v_min(self) -> f64 {
        match self {
            Material::Ag | Material::AgNi | Material::AgSnO2 => 12.0,
            Material::Au | Material::Pd | Material::W => 15.0,
            Material::Cu => 13.0,
        }
    }

    /// V·A, the default low-current term C of the arc voltage at zero
    /// gap: [`DEFAULT_LOW_CURRENT`] (0) for every material.
    pub fn low_current(self) -> f64 {
        DEFAULT_LOW_CURRENT
    }

    /// V·A/m, the default growth D of the low-current term with the gap:
    /// silver's [`DEFAULT_LOW_CURRENT_GAP`] for every material, as no
    /// breaking curve of the others has been fitted (docs/arcs.md).
    pub fn low_current_gap(self) -> f64 {
        DEFAULT_LOW_CURRENT_GAP
    }

    /// A, the minimum arc current (docs/arcs.md, materials table).
    pub fn i_min(self) -> f64 {
        match self {
            Material::Ag | Material::AgNi | Material::AgSnO2 => 0.40,
            Material::Au => 0.38,
            Material::Cu => 0.43,
            Material::Pd => 0.50,
            Material::W => 1.0,
        }
    }
}

/// V/m, the default column gradient E: short low-current arcs in air
/// have gradients of a few kV/m (docs/arcs.md).
pub const DEFAULT_FIELD: f64 = 2.0e3;

/// V·A, the default low-current term at zero gap, C, of the arc voltage
/// V_arc = V_min + E·d + (C + D·d)/|i|: 0. Ayrton's low-current term
/// belongs to the arc column and grows with its length; a metal-vapour
/// arc across a gap of micrometres (a bounce opening) burns near V_min
/// (docs/arcs.md, "The short arc").
pub const DEFAULT_LOW_CURRENT: f64 = 0.0;

/// V·A/m, the default growth of the low-current term with the gap, D:
/// the value with which the default column gradient and a 0.3 mm contact
/// gap break 8 A at 30 V DC on a resistive load (K = D·0.3 mm ≈ 20 V·A),
/// the DC rating that small silver-contact power relays print (Omron
/// G5LE, Finder 40.52 DC1 curve; docs/arcs.md).
pub const DEFAULT_LOW_CURRENT_GAP: f64 = 6.7e4;

/// F, the default capacitance between a relay's open contacts: of order
/// 1 pF (datasheets of signal and power relays print 0.5–2 pF between open
/// contacts, e.g. TE Axicom IM: 1 pF, "capacitance between open
/// contacts"). Without it an inductive break with no other capacitance
/// rings at the integrator's frequency instead of a physical one.
pub const DEFAULT_CAPACITANCE: f64 = 1e-12;

/// m/s, how fast the gap opens and closes where no trajectory is known
/// (a measured record of states): a typical contact separation speed.
pub const DEFAULT_OPENING_SPEED: f64 = 0.3;

/// The material whose V_min and I_min judge a run without `[arc]` (the
/// commonest power-contact family).
pub const REFERENCE_MATERIAL: Material = Material::Ag;

/// `[arc]`: the contact arcs (docs/arcs.md).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArcSection {
    /// Sets `v_min` and `i_min` (each may still be given to override).
    /// Neither material nor the two numbers: silver.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<Material>,
    /// V, the minimum arc voltage (electrode drops).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v_min: Option<f64>,
    /// A, the minimum arc current: below it the arc goes out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub i_min: Option<f64>,
    /// V/m, the column gradient E: V_arc = V_min + E·gap.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<f64>,
    /// m/s, the gap's opening speed for a measured record of states,
    /// which has no trajectory; a simulated relay uses its own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub opening_speed: Option<f64>,
    /// V·A, Ayrton's low-current term at zero gap, C: the arc burns
    /// higher the lower its current, by (C + D·gap)/|i|. Default 0; 0 here
    /// and in `low_current_gap` gives the arc voltage V_min + E·gap alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub low_current: Option<f64>,
    /// V·A/m, the low-current term's growth with the gap, D (default
    /// [`DEFAULT_LOW_CURRENT_GAP`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub low_current_gap: Option<f64>,
    /// F, the open contact's own capacitance between its electrodes
    /// (default [`DEFAULT_CAPACITANCE`]; 0 leaves it out).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capacitance: Option<f64>,
}

impl ArcSection {
    /// The section with every number given: the material's (or the
    /// defaults) where the file left one out. Its [`ArcSection::model`] is
    /// the same.
    pub fn resolved(&self) -> ArcSection {
        let m = self.model();
        ArcSection {
            material: self.material,
            v_min: Some(m.v_min),
            i_min: Some(m.i_min),
            field: Some(m.field),
            opening_speed: Some(m.opening_speed),
            low_current: Some(m.low_current),
            low_current_gap: Some(m.low_current_gap),
            capacitance: Some(m.capacitance),
        }
    }

    /// The numbers the run uses.
    pub fn model(&self) -> ArcModel {
        let material = self.material.unwrap_or(REFERENCE_MATERIAL);
        ArcModel {
            v_min: self.v_min.unwrap_or(material.v_min()),
            i_min: self.i_min.unwrap_or(material.i_min()),
            field: self.field.unwrap_or(DEFAULT_FIELD),
            opening_speed: self.opening_speed.unwrap_or(DEFAULT_OPENING_SPEED),
            low_current: self.low_current.unwrap_or(material.low_current()),
            low_current_gap: self.low_current_gap.unwrap_or(material.low_current_gap()),
            capacitance: self.capacitance.unwrap_or(DEFAULT_CAPACITANCE),
        }
    }
}

/// The resolved arc numbers, SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArcModel {
    /// V
    pub v_min: f64,
    /// A
    pub i_min: f64,
    /// V/m
    pub field: f64,
    /// m/s
    pub opening_speed: f64,
    /// V·A, C
    pub low_current: f64,
    /// V·A/m, D
    pub low_current_gap: f64,
    /// F, the open contact's own capacitance
    pub capacitance: f64,
}

impl ArcModel {
    /// V, the current-independent part of the burning voltage at gap
    /// `gap` (m): V_min + E·gap, what the arc burns at when its current
    /// is large.
    pub fn arc_voltage(&self, gap: f64) -> f64 {
        self.v_min + self.field * gap.max(0.0)
    }

    /// V·A, the low-current term's numerator at gap `gap` (m): C + D·gap.
    pub fn low_current_term(&self, gap: f64) -> f64 {
        self.low_current + self.low_current_gap * gap.max(0.0)
    }

    /// Whether the arc voltage depends on the current (C or D not 0).
    pub fn has_low_current_term(&self) -> bool {
        self.low_current != 0.0 || self.low_current_gap != 0.0
    }

    /// V, the burning voltage at gap `gap` (m) and current `current` (A):
    /// V_min + E·gap + (C + D·gap)/|i|, with |i| taken as at least I_min
    /// (below it the arc is out).
    pub fn burning_voltage(&self, gap: f64, current: f64) -> f64 {
        self.arc_voltage(gap) + self.low_current_term(gap) / current.abs().max(self.i_min)
    }

    /// A, the largest current a contact open to gap `gap` (m) breaks on a
    /// resistive DC load of `voltage` (V), or `None` when it breaks any.
    ///
    /// With a = V_min + E·d and K = C + D·d, an arc on the load V, R burns
    /// at the larger root i_s of R·i² − (V − a)·i + K = 0, and goes out
    /// when there is none (the load line no longer meets the arc's
    /// characteristic: R above R_t = (V − a)²/(4K), the tangent) or when
    /// i_s falls below I_min (R above R_m = ((V − a)·I_min − K)/I_min², when
    /// I_min is the larger root there). The answer is V/min(R_t, R_m).
    pub fn breaking_current(&self, voltage: f64, gap: f64) -> Option<f64> {
        let v = voltage.abs();
        let margin = v - self.arc_voltage(gap);
        if margin <= 0.0 {
            return None;
        }
        let k = self.low_current_term(gap);
        let i_min = self.i_min;
        let r_m = (margin * i_min - k) / (i_min * i_min);
        if r_m > 0.0 && 2.0 * r_m * i_min >= margin {
            return Some(v / r_m);
        }
        Some(4.0 * v * k / (margin * margin))
    }

    /// V, the most an open gap `gap` (m) holds before it conducts: the
    /// breakdown voltage, never below V_min + (C + D·gap)/I_min. Less
    /// cannot sustain a discharge that carries I_min, the least current an
    /// arc burns with: a breakdown below it is a spark that collapses at
    /// once, whose energy is negligible (with C = D = 0 the floor is V_min).
    pub fn hold_voltage(&self, gap: f64) -> f64 {
        breakdown_voltage(gap).max(self.v_min + self.low_current_term(gap) / self.i_min)
    }
}

/// V/m, the breakdown field of sub-micrometre gaps in air, where field
/// emission from the cathode starts the discharge (Peschot et al. 2014:
/// a nearly constant 350 V/µm below 1 µm).
pub const FIELD_EMISSION_FIELD: f64 = 350e6;

/// V, the Paschen minimum of air (≈ 327 V near 7–8 µm at 1 atm).
pub const PASCHEN_MINIMUM: f64 = 327.0;

/// bar, standard atmosphere.
const ATMOSPHERE_BAR: f64 = 1.01325;

/// V, the breakdown voltage of a gap of `gap` m in air at 1 atm and room
/// temperature, between flat electrodes:
///
/// - below ~1 µm, field emission: V = 350 V/µm · d;
/// - from there to ~17 µm the Paschen minimum, 327 V;
/// - above, the uniform-field law of air,
///   V = 24.36·(pd) + 6.72·√(pd) kV with pd in bar·cm (4.6 kV at 1 mm,
///   31 kV at 1 cm).
///
/// `gap ≤ 0` gives 0.
pub fn breakdown_voltage(gap: f64) -> f64 {
    if gap.is_nan() || gap <= 0.0 {
        return 0.0;
    }
    let pd = ATMOSPHERE_BAR * gap * 100.0; // bar·cm
    let uniform = 1e3 * (24.36 * pd + 6.72 * pd.sqrt());
    (FIELD_EMISSION_FIELD * gap).min(uniform.max(PASCHEN_MINIMUM))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn breakdown_follows_its_three_regimes() {
        // Field emission: linear through the origin.
        assert!((breakdown_voltage(0.5e-6) - 175.0).abs() < 1e-9);
        // The Paschen minimum plateau.
        assert_eq!(breakdown_voltage(5e-6), PASCHEN_MINIMUM);
        assert_eq!(breakdown_voltage(10e-6), PASCHEN_MINIMUM);
        // Uniform-field air: 1 mm ≈ 4.6 kV, 1 cm ≈ 31 kV.
        assert!((breakdown_voltage(1e-3) / 4.61e3 - 1.0).abs() < 0.01);
        assert!((breakdown_voltage(1e-2) / 31.4e3 - 1.0).abs() < 0.01);
        assert_eq!(breakdown_voltage(0.0), 0.0);
        assert_eq!(breakdown_voltage(-1.0), 0.0);
        // Continuous and non-decreasing.
        let mut last = breakdown_voltage(1e-8);
        for k in 1..2000 {
            let d = 1e-8 * 1.01f64.powi(k);
            let v = breakdown_voltage(d);
            assert!(v >= last, "at {d}");
            assert!(v - last < 0.05 * v.max(1.0) + 1.0, "jump at {d}");
            last = v;
        }
    }

    #[test]
    fn materials_and_overrides() {
        let silver = ArcSection::default().model();
        assert_eq!((silver.v_min, silver.i_min), (12.0, 0.40));
        let w = ArcSection {
            material: Some(Material::W),
            i_min: Some(2.0),
            ..ArcSection::default()
        }
        .model();
        assert_eq!((w.v_min, w.i_min), (15.0, 2.0));
        assert_eq!(w.arc_voltage(1e-3), 15.0 + DEFAULT_FIELD * 1e-3);
        assert_eq!(w.hold_voltage(0.0), 15.0 + DEFAULT_LOW_CURRENT / 2.0);
        // The low-current term grows with the gap from ≈ 0 at contact.
        assert_eq!(silver.low_current_term(0.0), DEFAULT_LOW_CURRENT);
        assert!((silver.low_current_term(0.3e-3) - 20.1).abs() < 1e-9);
        for m in Material::ALL {
            assert!(m.v_min() >= 12.0 && m.i_min() >= 0.38, "{}", m.as_str());
        }
    }
}
