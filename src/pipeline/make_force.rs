//! The contact force at the makes of a coil-driven relay (docs/arcs.md,
//! "Making").
//!
//! A step-force relay's trajectory gives its contact force at every
//! instant. A coil-driven relay's force comes from its armature's motion
//! under the coil's pull, which the coupled run computes from the flux
//! linkage ngspice returns: the converged pass moves the armature under
//! ψ(t) of the last circuit run, and that run's plot is the one the
//! coupled result carries. Moving the armature again under the same ψ(t)
//! gives the same trajectory, and with it the contact force (the surface
//! law at the contact's penetration and rate, or the held contact's
//! force); a relay closed on the ideal DC step of its coil (no driver in
//! the circuit) has the direct solver's state at every instant instead.

use crate::coil::samples::Interpolator;
use crate::coil::{Coil, Source};
use crate::mechanics::cycle::Stops;
use crate::mechanics::surface::surface_force;
use crate::mechanics::two_stage::{TwoStageRun, driven_run};
use crate::mechanics::{Mechanics, Surface, Trajectory};
use crate::pipeline::coupled::Coupled;
use crate::plan::Plan;
use crate::rawfile::Vector;

/// N at s: the contact force of the normally-open contact, positive
/// pressing the contacts together.
pub type ForceAt = Box<dyn Fn(f64) -> f64>;

/// s, how far the re-run's contact events may lie from the coupled run's
/// before its forces are not trusted (a hundredth of the coupling's
/// default tolerance).
const EVENT_TOLERANCE: f64 = 1e-9;

/// The armature of `plan`'s scenario with the force the coil gives it.
fn armature(plan: &Plan) -> Mechanics {
    Mechanics {
        force: 0.0,
        ..plan.scenario().armature()
    }
}

/// The trajectory of a coupled run's converged pass: the armature moved
/// again under the flux linkage of the run's last circuit pass. `None`
/// when the scenario has no coil, the plot lacks the flux, or the re-run
/// does not make and break where the coupled run did (then its forces
/// would belong to another motion).
pub fn coupled_trajectory(plan: &Plan, coupled: &Coupled) -> Option<Trajectory> {
    let coil = Coil::from(plan.scenario().coil.as_ref()?);
    let Some(Vector::Real(time)) = coupled.plot.scale() else {
        return None;
    };
    let psi = coupled.plot.real(&crate::pipeline::coupled::flux_vector(
        &coupled.coil_instance,
    ))?;
    let flux: Vec<(f64, f64)> = time.iter().copied().zip(psi.iter().copied()).collect();
    let flux_at = Interpolator::new(&flux);
    let pull = |t: f64, _x: f64| coil.force_from_flux(flux_at.at(t));
    let stops = Stops {
        make: plan.surface(),
        back: plan.back_stop(),
    };
    let trajectory = driven_run(
        &armature(plan),
        &plan.two_stage(),
        &stops,
        &plan.settings(),
        &pull,
    )
    .ok()?;
    same_events(trajectory.chatter(), &coupled.chatter).then_some(trajectory)
}

/// Whether two records of the contact make and break at the same
/// instants, within [`EVENT_TOLERANCE`].
fn same_events(a: &crate::chatter::Chatter, b: &crate::chatter::Chatter) -> bool {
    a.intervals.len() == b.intervals.len()
        && a.intervals.iter().zip(&b.intervals).all(|(x, y)| {
            x.state == y.state
                && (x.start - y.start).abs() <= EVENT_TOLERANCE
                && (x.end - y.end).abs() <= EVENT_TOLERANCE
        })
}

/// The contact force of a coupled run's relay ([`coupled_trajectory`]).
pub fn coupled(plan: &Plan, coupled: &Coupled) -> Option<ForceAt> {
    let trajectory = coupled_trajectory(plan, coupled)?;
    Some(Box::new(move |t| trajectory.contact_force(t)))
}

/// The contact force of a relay closed on the ideal DC step `source` of
/// its coil `coil`: for a relay with a blade or a pole face its
/// two-stage run `two_stage`, for the one-mass relay the direct solver's
/// state (position and rate) in the surface law. A rigid one-mass
/// contact has no force history (its touches are impulses): `None`.
pub fn dc_step(
    plan: &Plan,
    coil: &Coil,
    source: &Source,
    two_stage: Option<TwoStageRun>,
) -> Option<ForceAt> {
    let m = Mechanics {
        initial_position: 0.0,
        initial_velocity: 0.0,
        ..armature(plan)
    };
    let surface = plan.surface();
    let settings = plan.settings();
    if let Some(run) = two_stage {
        let stops = Stops {
            make: surface,
            back: None,
        };
        let trajectory = Trajectory::of_two_stage(&m, &stops, &settings, run);
        return Some(Box::new(move |t| trajectory.contact_force(t)));
    }
    if matches!(surface, Surface::Rigid { .. }) {
        return None;
    }
    let run = crate::coil::direct::simulate_direct(coil, source, &m, &surface, &settings).ok()?;
    let gap = m.gap;
    Some(Box::new(move |t| {
        run.state_at(t).map_or(0.0, |s| {
            if s.position >= gap {
                surface_force(&surface, s.position - gap, s.velocity)
            } else {
                0.0
            }
        })
    }))
}
