//! The coil drives the contact: the relay's magnetic pull and its two-way
//! coupling with the armature (docs/model.md §7).
//!
//! The step force of [`crate::mechanics`] is really the pull of a coil.
//! The magnetic circuit is the standard single-air-gap model (as in
//! Modelica.Magnetic.FluxTubes): the armature at `x` (m, toward the fixed
//! contact) leaves an air gap `g_a − x` in series with the iron path,
//! counted as an equivalent air gap `l_eq = l_fe/μr`. With
//! `k = μ0 N² A` (H·m) and `a = g_a + l_eq`:
//!
//! ```text
//! L(x)  = k / (a − x)            inductance, ψ = L(x) i (flux linkage)
//! v     = R i + dψ/dt = R i + L(x) di/dt + i L'(x) ẋ
//! F_m   = ½ i² L'(x) = ψ² / (2k) force toward closing
//! ```
//!
//! The last line is why the solvers here integrate the flux ψ rather than
//! the current: at constant flux the pull does not depend on the position
//! (the field in the gap is ψ/(N A) wherever the armature is), so the
//! coupled equations `ψ̇ = V − R ψ (a − x)/k`,
//! `m ẍ + r ẋ + s x + p + Fc = ψ²/(2k)` have no singularity, and the
//! back-EMF `i L'(x) ẋ` — which makes the well-known dip of the current
//! while the armature pulls in — needs no term of its own.
//!
//! This module keeps the magnet ([`Coil`], in `magnet.rs`), the coil's
//! electrical state and the coupling with the circuit; the armature's
//! event rules under a
//! drive that varies (the closing, the whole cycle, a force `F(t, x)`)
//! live with the rest of the mechanics in [`crate::mechanics`]
//! (one engine, [`crate::mechanics::cycle`], with its entry points in
//! [`crate::mechanics::forced`] and [`crate::mechanics::simulate_drive`]).
//!
//! - [`direct`]: a coil switched onto an ideal voltage source, solved as
//!   one ODE in (ψ, x, ẋ) with no circuit simulator: the independent
//!   cross-check of the coupled ngspice runs, and the reference case of
//!   docs/model.md §7.
//! - [`accelerate`]: the coupling's inner loop, which settles the
//!   mechanics against an estimate of the driver circuit between two
//!   ngspice passes; the passes themselves (the waveform relaxation that
//!   feeds the mechanics `F_m(i(t), x)`) are run by the pipeline, which
//!   owns the circuit simulator.
//! - [`pick_up`]: pick-up and drop-out against the armature's load line.
//! - [`samples`]: the sampled records those passes exchange.
//! - [`timing`]: each operation's times as datasheets define them.

pub mod accelerate;
pub mod direct;
mod magnet;
pub mod pick_up;
pub mod samples;
pub mod timing;

pub use crate::mechanics::cycle::{Cycle, Stops, Stroke};
pub use crate::mechanics::forced::{simulate_cycle, simulate_forced, simulate_forced_path};
pub use direct::{
    CoilEvents, CoilRun, CoilState, EnergyBalance, PullInDip, Source, simulate_direct,
};
pub use magnet::{Coil, CoilError, MU0};
pub use timing::{Closing, CoilLevels, Operation, Switching, operations};
