//! What each make of the contact carries: its peak current (a new inrush
//! at every re-make after a bounce), the contact force at that instant,
//! and what the current does to the spot it flows through (docs/arcs.md,
//! "Making").
//!
//! A contact of force F on a material of hardness H touches on a spot of
//! radius a = √(F/(π·H)) (plastic flow of the asperities); the current
//! constricts through it with the resistance R_s = ρ/(2a). The voltage
//! U = |i|·R_s across the constriction fixes the hottest temperature of
//! the spot by the ψ–θ relation of a Wiedemann–Franz conductor,
//! T_max = √(T0² + U²/(4L)) (L the Lorenz number), so the spot melts
//! when U reaches U_m = 2·√(L·(T_m² − T0²)). U_m/U at each make is its
//! static-weld margin; it is a lower bound on the weld risk, as the weld
//! of a bounce arc's molten pool is not modelled.

use serde::Serialize;

use super::model::Material;

/// V²/K², the Lorenz number of the Wiedemann–Franz law.
pub const LORENZ: f64 = 2.45e-8;

/// K, the bulk temperature of the contact (20 °C).
pub const AMBIENT: f64 = 293.15;

/// A contact material's bulk properties for the spot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpotMaterial {
    /// Ω·m, electrical resistivity at 20 °C.
    pub resistivity: f64,
    /// Pa, hardness (Vickers, annealed or soft).
    pub hardness: f64,
    /// K, melting point.
    pub melting_point: f64,
}

impl SpotMaterial {
    /// V, the melting voltage U_m = 2·√(L·(T_m² − T0²)).
    pub fn melting_voltage(&self) -> f64 {
        2.0 * (LORENZ * (self.melting_point.powi(2) - AMBIENT.powi(2))).sqrt()
    }
}

/// Pa per Vickers unit (kgf/mm²).
const VICKERS: f64 = 9.80665e6;

impl Material {
    /// The bulk properties of the spot (docs/arcs.md, materials table:
    /// resistivity and melting point from the CRC Handbook of Chemistry
    /// and Physics; hardness from manufacturers' contact-material sheets
    /// for AgSnO2, typical annealed values otherwise).
    pub fn spot(self) -> SpotMaterial {
        let (resistivity, vickers, melting_point) = match self {
            Material::Ag => (1.59e-8, 27.0, 1234.93),
            Material::AgNi => (1.98e-8, 60.0, 1234.93),
            Material::AgSnO2 => (2.13e-8, 62.0, 1234.93),
            Material::Au => (2.21e-8, 25.0, 1337.33),
            Material::Cu => (1.68e-8, 45.0, 1357.77),
            Material::Pd => (1.05e-7, 42.0, 1828.05),
            Material::W => (5.3e-8, 400.0, 3695.0),
        };
        SpotMaterial {
            resistivity,
            hardness: vickers * VICKERS,
            melting_point,
        }
    }
}

/// One make of the contact.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Make {
    /// s, when the contact closed.
    pub time: f64,
    /// s, when the current peaked during that closure.
    pub peak_time: f64,
    /// A, the largest |i| through the contact during that closure.
    pub peak_current: f64,
    /// N, the contact force at the peak (`null` where the run has no
    /// force: a coil-driven or measured relay).
    pub force: Option<f64>,
    /// V, the constriction voltage |i|·ρ/(2a) at the peak.
    pub spot_voltage: Option<f64>,
    /// K, the spot's hottest temperature at the peak.
    pub t_max: Option<f64>,
    /// U_m/U: above 1 the spot does not melt (a static-weld margin).
    pub weld_margin: Option<f64>,
}

/// The make of a closure starting at `time` whose current peaks at
/// `peak_current` (A) at `peak_time`, where the contact force is `force`.
pub fn make(
    time: f64,
    peak_time: f64,
    peak_current: f64,
    force: Option<f64>,
    material: &SpotMaterial,
) -> Make {
    let spot = force.filter(|&f| f > 0.0 && f.is_finite()).map(|f| {
        let radius = (f / (std::f64::consts::PI * material.hardness)).sqrt();
        let u = peak_current.abs() * material.resistivity / (2.0 * radius);
        let t_max = (AMBIENT * AMBIENT + u * u / (4.0 * LORENZ)).sqrt();
        (u, t_max)
    });
    Make {
        time,
        peak_time,
        peak_current: peak_current.abs(),
        force,
        spot_voltage: spot.map(|s| s.0),
        t_max: spot.map(|s| s.1),
        weld_margin: spot.map(|(u, _)| {
            if u > 0.0 {
                material.melting_voltage() / u
            } else {
                f64::MAX
            }
        }),
    }
}

/// Every make of the closures `closures` ((start, end) pairs, s) in a run
/// sampled at `time` with contact current `current` (A).
pub fn makes(
    time: &[f64],
    current: &[f64],
    closures: &[(f64, f64)],
    force_at: Option<&dyn Fn(f64) -> f64>,
    material: &SpotMaterial,
) -> Vec<Make> {
    let n = time.len().min(current.len());
    closures
        .iter()
        .map(|&(start, end)| {
            let first = time[..n].partition_point(|&t| t < start);
            let last = time[..n].partition_point(|&t| t <= end);
            let (peak_time, peak) = (first..last).map(|k| (time[k], current[k].abs())).fold(
                (start, 0.0f64),
                |best, x| if x.1 > best.1 { x } else { best },
            );
            make(
                start,
                peak_time,
                peak,
                force_at.map(|f| f(peak_time)),
                material,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn silver_melts_at_0_376_volts() {
        let ag = Material::Ag.spot();
        assert!(
            (ag.melting_voltage() - 0.376).abs() < 1e-3,
            "{}",
            ag.melting_voltage()
        );
        // U = U_m puts the spot at the melting point exactly.
        let t = (AMBIENT.powi(2) + ag.melting_voltage().powi(2) / (4.0 * LORENZ)).sqrt();
        assert!((t - ag.melting_point).abs() < 1e-9);
    }

    #[test]
    fn a_make_s_spot_from_its_force_and_current() {
        let ag = Material::Ag.spot();
        // 1 N on silver: a = √(1/(π·27·9.80665e6)) = 34.6 µm,
        // R_s = 1.59e-8/(2a) = 0.229 mΩ; 100 A gives 22.9 mV.
        let m = make(1e-3, 1.001e-3, -100.0, Some(1.0), &ag);
        let a = (1.0 / (std::f64::consts::PI * ag.hardness)).sqrt();
        assert!((a - 34.6e-6).abs() < 0.1e-6, "{a}");
        let u = m.spot_voltage.unwrap();
        assert!((u - 100.0 * ag.resistivity / (2.0 * a)).abs() < 1e-15);
        assert_eq!(m.peak_current, 100.0);
        assert!((m.weld_margin.unwrap() - ag.melting_voltage() / u).abs() < 1e-12);
        assert!(m.t_max.unwrap() > AMBIENT && m.t_max.unwrap() < ag.melting_point);
        // Four times the force halves the spot voltage (a ∝ √F).
        let stiff = make(1e-3, 1.001e-3, 100.0, Some(4.0), &ag);
        assert!((stiff.spot_voltage.unwrap() / u - 0.5).abs() < 1e-12);
        // No force known: no spot figures.
        let none = make(1e-3, 1e-3, 100.0, None, &ag);
        assert!(none.spot_voltage.is_none() && none.weld_margin.is_none());
    }

    #[test]
    fn each_closure_s_peak_is_its_own() {
        let time: Vec<f64> = (0..100).map(|k| k as f64 * 1e-4).collect();
        let current: Vec<f64> = time
            .iter()
            .map(|&t| {
                if t < 5e-3 {
                    10.0 * (-t / 1e-3).exp()
                } else {
                    -3.0
                }
            })
            .collect();
        let found = makes(
            &time,
            &current,
            &[(0.0, 4e-3), (6e-3, 9.9e-3)],
            Some(&|t: f64| 0.5 + t),
            &Material::Cu.spot(),
        );
        assert_eq!(found.len(), 2);
        assert_eq!((found[0].peak_time, found[0].peak_current), (0.0, 10.0));
        assert_eq!(found[1].peak_current, 3.0);
        assert_eq!(found[1].force, Some(0.5 + found[1].peak_time));
    }
}
