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
    /// The operation it belongs to (0-based; each break, a release after
    /// the coil was switched off, starts the next), as the arcs count them.
    pub operation: usize,
    /// 0 for the operation's first make; N for the re-make after its N-th
    /// bounce opening.
    pub bounce: usize,
    /// s, when the current peaked during that closure (while the contacts
    /// press, where the force is known; the first instant within 0.1 % of
    /// the largest |i|).
    pub peak_time: f64,
    /// A, |i| through the contact then: the closure's largest, to 0.1 %.
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
        operation: 0,
        bounce: 0,
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

/// Relative tolerance of a closure's peak: the first sample within it of
/// the largest |i| is the peak (on a flat current, the make itself).
const PEAK_TOLERANCE: f64 = 1e-3;

/// (s, A, N): the peak of one closure sampled at `time` with current
/// `current`, starting at `start`, and the contact force then. Where the
/// force is known the peak is sought among the instants the contacts
/// press (force > 0): a Kelvin–Voigt contact pulls for a moment before it
/// releases, and a held contact's force fades to nothing at the break,
/// where no spot remains to speak of. Of the samples within
/// [`PEAK_TOLERANCE`] of the largest |i|, the first is the peak, so that
/// a load whose current is flat over the closure has its peak at the
/// make, not at whichever sample the rounding of ngspice's values favours.
fn closure_peak(
    time: &[f64],
    current: &[f64],
    start: f64,
    force_at: Option<&dyn Fn(f64) -> f64>,
) -> (f64, f64, Option<f64>) {
    let forces: Option<Vec<f64>> = force_at.map(|f| time.iter().map(|&t| f(t)).collect());
    let pressing = |k: usize| forces.as_ref().is_none_or(|f| f[k] > 0.0);
    // Without a pressing sample (a closure shorter than a sample, or a
    // contact that never presses), every sample.
    let candidates: Vec<usize> = if (0..time.len()).any(pressing) {
        (0..time.len()).filter(|&k| pressing(k)).collect()
    } else {
        (0..time.len()).collect()
    };
    let largest = candidates
        .iter()
        .map(|&k| current[k].abs())
        .fold(0.0f64, f64::max);
    match candidates
        .iter()
        .find(|&&k| current[k].abs() >= largest * (1.0 - PEAK_TOLERANCE))
    {
        Some(&k) => (time[k], current[k].abs(), forces.as_ref().map(|f| f[k])),
        None => (start, 0.0, force_at.map(|f| f(start))),
    }
}

/// Every make of the closures `closures` ((start, end) pairs, s, in
/// order) in a run sampled at `time` with contact current `current` (A),
/// with the contact force `force_at` (N at s) where the run knows it;
/// each closure's peak is sought while the contacts press (force > 0,
/// where the force is known), at the first instant within 0.1 % of the
/// largest |i| (on a flat current, the make itself).
/// `coil_offs` (s) are when the coil was switched off: a closure during
/// which the coil went off ends in a break, and the next make starts a new
/// operation (without a coil every make belongs to operation 0).
pub fn makes(
    time: &[f64],
    current: &[f64],
    closures: &[(f64, f64)],
    force_at: Option<&dyn Fn(f64) -> f64>,
    material: &SpotMaterial,
    coil_offs: &[f64],
) -> Vec<Make> {
    let n = time.len().min(current.len());
    let (mut operation, mut bounce) = (0, 0);
    let mut previous: Option<(f64, f64)> = None;
    closures
        .iter()
        .map(|&(start, end)| {
            if let Some((since, until)) = previous {
                if coil_offs.iter().any(|&t| t >= since && t <= until) {
                    operation += 1;
                    bounce = 0;
                } else {
                    bounce += 1;
                }
            }
            previous = Some((start, end));
            let first = time[..n].partition_point(|&t| t < start);
            let last = time[..n].partition_point(|&t| t <= end);
            let (peak_time, peak, force) =
                closure_peak(&time[first..last], &current[first..last], start, force_at);
            Make {
                operation,
                bounce,
                ..make(start, peak_time, peak, force, material)
            }
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
            &[],
        );
        assert_eq!(found.len(), 2);
        assert_eq!((found[0].peak_time, found[0].peak_current), (0.0, 10.0));
        assert_eq!(found[1].peak_current, 3.0);
        assert_eq!(found[1].force, Some(0.5 + found[1].peak_time));
        // Without a coil: one operation, the second closure a re-make.
        assert_eq!((found[0].operation, found[0].bounce), (0, 0));
        assert_eq!((found[1].operation, found[1].bounce), (0, 1));
    }

    #[test]
    fn a_coil_off_during_a_closure_starts_the_next_operation() {
        let time: Vec<f64> = (0..1000).map(|k| k as f64 * 1e-4).collect();
        let current = vec![1.0; time.len()];
        // Operation 0: a make and two re-makes; the coil goes off at 50 ms
        // in the third closure; operation 1: a make and one re-make.
        let closures = [
            (1e-3, 2e-3),
            (3e-3, 4e-3),
            (5e-3, 60e-3),
            (70e-3, 71e-3),
            (72e-3, 90e-3),
        ];
        let found = makes(
            &time,
            &current,
            &closures,
            None,
            &Material::Ag.spot(),
            &[50e-3],
        );
        // A flat current peaks at the make itself.
        assert!(
            found
                .iter()
                .all(|m| m.peak_time == time[time.partition_point(|&t| t < m.time)])
        );
        let tags: Vec<(usize, usize)> = found.iter().map(|m| (m.operation, m.bounce)).collect();
        assert_eq!(tags, [(0, 0), (0, 1), (0, 2), (1, 0), (1, 1)]);
        // No force known: no spot figures, however large the current.
        assert!(
            found
                .iter()
                .all(|m| m.force.is_none() && m.weld_margin.is_none())
        );
    }

    #[test]
    fn the_peak_is_sought_while_the_contacts_press() {
        // The current rises over the closure; the force is positive for
        // its first 80 % and pulls after (a Kelvin–Voigt contact about to
        // release).
        let time: Vec<f64> = (0..=100).map(|k| k as f64 * 1e-5).collect();
        let current: Vec<f64> = time.iter().map(|&t| 1.0 + 1e4 * t).collect();
        let force = |t: f64| 1.0 - t / 0.8e-3;
        let found = makes(
            &time,
            &current,
            &[(0.0, 1e-3)],
            Some(&force),
            &Material::Ag.spot(),
            &[],
        );
        let m = &found[0];
        let f = m.force.unwrap();
        assert!(f > 0.0, "{m:?}");
        // The last pressing sample carries the largest current.
        assert!((m.peak_time - 0.79e-3).abs() < 1e-12, "{m:?}");
        assert!(m.weld_margin.is_some());
        // Without the force, the closure's own peak at its end.
        let plain = makes(
            &time,
            &current,
            &[(0.0, 1e-3)],
            None,
            &Material::Ag.spot(),
            &[],
        );
        assert_eq!(plain[0].peak_time, 1e-3);
    }
}
