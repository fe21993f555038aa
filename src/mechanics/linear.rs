//! Linear pieces.
