//! The engine against references written for the test: fixed-step
//! Runge–Kutta integrations of the model's equations that share no code
//! with the engine, over chosen relays and over many seeded random ones.
//!
//! A crate of its own because its references are numerical work done in
//! the test itself (millions of fixed steps a relay): it is compiled
//! optimised like the library, while the integration tests, whose work is
//! the library's and ngspice's, are compiled without optimisation
//! (scripts/rustc-wrapper).

mod differential;
mod two_stage;
