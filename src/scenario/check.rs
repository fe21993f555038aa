//! Validation of a deserialized document: [`Check`] and the rules every
//! section shares. Each section's own rules are an `impl Check` in the
//! section's file; the order in which they run is in `document.rs`.

use std::path::Path;

use super::error::{Location, ScenarioError};
use super::keys::KeyIndex;
use super::numbers::ENVELOPE;

/// Validation of a deserialized document, in file order.
pub(super) struct Check<'a> {
    pub(super) origin: &'a Path,
    pub(super) index: &'a KeyIndex<'a>,
}
impl Check<'_> {
    pub(super) fn at(&self, key: &str) -> Location {
        Location {
            path: self.origin.to_owned(),
            line: self.index.line_of_key(key),
        }
    }

    pub(super) fn invalid(
        &self,
        key: &str,
        value: f64,
        requirement: impl Into<String>,
    ) -> ScenarioError {
        ScenarioError::Invalid {
            at: self.at(key),
            key: key.to_owned(),
            value,
            requirement: requirement.into(),
        }
    }

    /// `value` must be finite and satisfy `ok`; `requirement` says what to
    /// change when it does not.
    pub(super) fn number(
        &self,
        key: &str,
        value: f64,
        ok: bool,
        requirement: impl Into<String>,
    ) -> Result<(), ScenarioError> {
        if !value.is_finite() {
            return Err(self.invalid(key, value, "must be a finite number (not nan or inf)"));
        }
        if !ok {
            return Err(self.invalid(key, value, requirement));
        }
        Ok(())
    }

    pub(super) fn missing(&self, key: &str, help: &str) -> ScenarioError {
        ScenarioError::MissingKey {
            at: self.at(key),
            key: key.to_owned(),
            help: help.to_owned(),
            source: None,
        }
    }

    /// The range of numbers a relay model can mean (see [`ENVELOPE`]):
    /// beyond it the numbers overflow or the simulation never ends.
    pub(super) fn envelope(&self, key: &str, value: Option<f64>) -> Result<(), ScenarioError> {
        let Some(value) = value else { return Ok(()) };
        let Some(&(_, lo, hi, unit)) = ENVELOPE.iter().find(|(k, ..)| key.ends_with(k)) else {
            return Ok(());
        };
        // Non-finite values get the key's own "must be finite" message.
        if !value.is_finite() || (lo..=hi).contains(&value) {
            return Ok(());
        }
        Err(self.invalid(
            key,
            value,
            format!(
                "must lie within [{lo:e}, {hi:e}] {unit}: outside that no relay is modelled, and \
                 the simulation's numbers would overflow or never end"
            ),
        ))
    }

    pub(super) fn not_empty(
        &self,
        key: &str,
        value: &str,
        help: &'static str,
    ) -> Result<(), ScenarioError> {
        if value.trim().is_empty() {
            return Err(ScenarioError::Empty {
                at: self.at(key),
                key: key.to_owned(),
                help,
            });
        }
        Ok(())
    }
}
