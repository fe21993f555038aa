//! Adaptive integration.
