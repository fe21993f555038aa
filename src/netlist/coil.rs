//! The coil include: `.subckt COIL a b`, the relay coil as the user's
//! driver sees it (docs/model.md §7). The winding resistance R_c is in series
//! with a flux linkage ψ = L(x)·i whose inductance follows the armature,
//! L(x) = μ0 N² A / (g_a − x + l_eq).
//!
//! ngspice has no inductor whose inductance follows an outside signal, so
//! the flux linkage is a circuit state of its own: a 1 F capacitor on node
//! `psi`, charged by a current equal to the coil's inductive voltage, holds
//! V(psi) = ∫ v dt = ψ; the winding then draws i = ψ / L(x), a behavioural
//! current that only multiplies by 1/L(x) = (g_a − x + l_eq)/(μ0 N² A),
//! finite for every position the armature reaches (x ≤ g < g_a). The
//! back-EMF i·L'(x)·ẋ needs no term of its own: as x moves, the same ψ
//! means a different current. At the DC operating point the capacitor is
//! open and its leak resistor closes the loop, which makes the coil the
//! short an inductor is at DC.
//!
//! The armature position x(t) drives node `xmm` as a PWL source in
//! millimetres (volts): in metres the whole stroke would sit below
//! ngspice's voltage tolerance. Every corner is a breakpoint.
//!
//! The coil current is measured by a zero-volt source `VI` in series:
//! `i(v.<instance>.vi)` in the raw file (e.g. `i(v.x2.vi)`); the voltage
//! across the coil is repeated on node `vt`, `v(<instance>.vt)`, which
//! tells when the driver switched the coil on and off.

use super::contact::check_subckt_name;
use super::contact::{comment, line, pairs};
use super::error::NetlistError;
use crate::coil::MU0;
use crate::scenario::CoilSection;
use crate::waveform::format_time;

/// The include for `coil` as subcircuit `subckt`, its armature following
/// `trajectory`: (time in s, position x in m) with strictly increasing
/// times; held at its first and last values outside them.
pub fn coil_include(
    coil: &CoilSection,
    subckt: &str,
    trajectory: &[(f64, f64)],
) -> Result<String, NetlistError> {
    coil_text(coil, subckt, Some(trajectory))
}

/// The include for `coil` as subcircuit `subckt`, its armature's position
/// (mm, on node `xmm`) an external source `V_X` that the caller of
/// ngspice's shared library answers at every time point (the lock-step
/// coupling).
pub fn coil_include_external(coil: &CoilSection, subckt: &str) -> Result<String, NetlistError> {
    coil_text(coil, subckt, None)
}

fn coil_text(
    coil: &CoilSection,
    subckt: &str,
    trajectory: Option<&[(f64, f64)]>,
) -> Result<String, NetlistError> {
    check_subckt_name(subckt)?;
    let points = trajectory.map_or(0, <[_]>::len);
    let trajectory = trajectory.unwrap_or(&[(0.0, 0.0)]);
    if trajectory.is_empty() {
        return Err(NetlistError::EmptyTrajectory);
    }
    for (index, w) in trajectory.windows(2).enumerate() {
        let forward = w[1].0 > w[0].0;
        if !forward || !w[1].1.is_finite() {
            return Err(NetlistError::BadTrajectory {
                index: index + 1,
                time: w[1].0,
                previous: w[0].0,
            });
        }
    }
    let turns = f64::from(coil.turns);
    let n2a = MU0 * turns * turns * coil.pole_area;
    let mut out = String::new();
    comment(
        &mut out,
        &format!(
            "chatterspice coil subcircuit: R_c = {} ohm, N = {}, A = {} m^2, g_a = {} m, \
             l_eq = {} m; L(x) = mu0 N^2 A / (g_a - x + l_eq), from {} H at rest. \
             {}. Instantiate it as: X2 a b {subckt}; \
             its current is i(v.x2.vi).",
            format_time(coil.resistance),
            coil.turns,
            format_time(coil.pole_area),
            format_time(coil.air_gap),
            format_time(coil.iron_gap),
            format_time(n2a / (coil.air_gap + coil.iron_gap)),
            if points == 0 {
                "The armature's position is asked of the mechanics at every time point".to_owned()
            } else {
                format!("The armature follows {points} points")
            }
        ),
    );
    line(&mut out, &format!(".subckt {subckt} a b"));
    line(
        &mut out,
        &format!("R_C a n1 {}", format_time(coil.resistance)),
    );
    line(&mut out, "VI n1 n2 0");
    comment(
        &mut out,
        "the voltage across the coil, for its switching instants",
    );
    line(&mut out, "E_VT vt 0 a b 1");
    comment(
        &mut out,
        "flux linkage: V(psi) = integral of the inductive voltage",
    );
    line(&mut out, "G_PSI 0 psi n2 b 1");
    line(&mut out, "C_PSI psi 0 1");
    line(&mut out, "R_PSI psi 0 1e12");
    comment(&mut out, "the winding: i = psi / L(x), x in mm on node xmm");
    line(
        &mut out,
        &format!(
            "B_L n2 b I = V(psi) * ({} - V(xmm) * 1e-3) / {}",
            format_time(coil.air_gap + coil.iron_gap),
            format_time(n2a)
        ),
    );
    if points == 0 {
        // ngspice 39 takes `external` as the whole value: `dc 0 external`
        // crashes it.
        line(&mut out, "V_X xmm 0 external");
    } else {
        line(&mut out, "V_X xmm 0 PWL(");
        pairs(&mut out, trajectory.iter().map(|&(t, x)| (t, x * 1e3)));
    }
    line(&mut out, ".ends");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn coil() -> CoilSection {
        CoilSection {
            resistance: 70.0,
            turns: 3000,
            pole_area: 2e-5,
            air_gap: 6e-4,
            iron_gap: 5e-5,
            drive_voltage: None,
        }
    }

    #[test]
    fn the_include_is_deterministic_and_names_its_parts() {
        let traj = [(0.0, 0.0), (1e-3, 0.0), (2e-3, 4.5e-4)];
        let a = coil_include(&coil(), "COIL", &traj).unwrap();
        assert_eq!(a, coil_include(&coil(), "COIL", &traj).unwrap());
        assert!(a.contains(".subckt COIL a b\n"), "{a}");
        assert!(a.contains("R_C a n1 7e1\n"), "{a}");
        assert!(a.contains("2e-3 4.5e-1"), "x in mm: {a}");
        assert!(a.trim_end().ends_with(".ends"));
    }

    #[test]
    fn a_trajectory_must_move_forward_in_time() {
        let err = coil_include(&coil(), "COIL", &[(0.0, 0.0), (0.0, 1e-4)]).unwrap_err();
        assert!(err.to_string().contains("time"), "{err}");
        assert!(coil_include(&coil(), "COIL", &[]).is_err());
        assert!(coil_include(&coil(), "1COIL", &[(0.0, 0.0)]).is_err());
    }
}
