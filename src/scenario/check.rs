//! Validation of a deserialized document: the shared rules, and the
//! order in which every section is checked.

use super::*;

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

    /// Everything; returns the resolved surface laws of the contact and
    /// of the back stop.
    pub(super) fn all(&self, d: &Document) -> Result<(Surface, Option<Surface>), ScenarioError> {
        self.mechanics(&d.mechanics)?;
        self.drive(&d.mechanics, d.coil.as_ref())?;
        let surface = self.surface("surface", &d.surface)?;
        let back_stop = self.back_stop(d.back_stop.as_ref(), d.coil.is_some())?;
        self.two_stage(
            d.blade.as_ref(),
            d.pole_face.as_ref(),
            &d.surface,
            d.mechanics.gap,
        )?;
        self.contact(&d.contact)?;
        self.simulation(&d.simulation)?;
        if let Some(circuit) = &d.circuit {
            self.circuit(circuit)?;
            if circuit.nc_subckt.is_some() && d.coil.is_none() {
                return Err(ScenarioError::Conflict {
                    at: self.at("circuit.nc_subckt"),
                    key: "circuit.nc_subckt".to_owned(),
                    other: "mechanics.force".to_owned(),
                    advice: "the normally-closed contact follows the armature back to its \
                             rest stop on release, which needs a [coil]; give one or remove \
                             the key",
                });
            }
        }
        for (i, probe) in d.probe.iter().enumerate() {
            self.probe(i, probe)?;
        }
        if let Some(limits) = &d.limits {
            self.limits(limits)?;
            self.release_limits(limits, d.coil.is_some())?;
        }
        if let Some(arc) = &d.arc {
            self.arc(arc)?;
        }
        if let Some(datasheet) = &d.datasheet {
            self.datasheet(datasheet)?;
        }
        if let Some(envelope) = &d.envelope {
            self.envelope_ranges(envelope)?;
        }
        if let Some(limits) = d.limits.as_ref().filter(|_| d.arc.is_none()) {
            let given = [
                ("limits.max_arc_energy", limits.max_arc_energy.is_some()),
                ("limits.max_arc_count", limits.max_arc_count.is_some()),
            ];
            if let Some((key, _)) = given.iter().find(|(_, set)| *set) {
                return Err(ScenarioError::MissingKey {
                    at: self.at(key),
                    key: "arc".to_owned(),
                    help: format!(
                        "`{key}` holds the arcs that [arc] models: add an [arc] section \
                         (e.g. material = \"Ag\") or remove the limit"
                    ),
                    source: None,
                });
            }
        }
        Ok((surface, back_stop))
    }
}
