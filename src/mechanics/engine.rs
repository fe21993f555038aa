//! The event-driven chatter engine.
use super::{Mechanics, MechanicsError, Settings, Surface};
use crate::chatter::Chatter;

/// Simulate one closing.
pub fn simulate(
    _mechanics: &Mechanics,
    _surface: &Surface,
    _settings: &Settings,
) -> Result<Chatter, MechanicsError> {
    unimplemented!("in progress")
}
