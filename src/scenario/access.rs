//! A loaded scenario's numbers by their dotted keys:
//! [`Scenario::number`], [`Scenario::set_number`] and
//! [`Scenario::set_numbers`], which validate the changed scenario again by
//! the loader's rules.

use super::check::Check;
use super::document::Physics;
use super::error::{Location, ScenarioError};
use super::keys::KeyIndex;
use super::model::Scenario;
use super::numbers::{PARAMS_PREFIX, number_keys_described, probe_key, valid_param_name};
use crate::mechanics::Surface;

/// Where a number key lives.
enum Field<P, O> {
    /// A number that always has a value.
    Plain(P),
    /// A number that may be absent (`mechanics.force`, the surface keys).
    Optional(O),
    /// A known key whose section the scenario does not have.
    NoSection(&'static str),
    Unknown,
}

/// The field of `key` in scenario `$s`, borrowed with `$($r)*` (`&` or
/// `&mut`), so that the getter and the setter share one table.
macro_rules! number_field {
    ($s:expr, $key:expr, $($r:tt)*) => {{
        let s = $s;
        match $key {
            "mechanics.mass" => Field::Plain($($r)* s.mechanics.mass),
            "mechanics.stiffness" => Field::Plain($($r)* s.mechanics.stiffness),
            "mechanics.damping" => Field::Plain($($r)* s.mechanics.damping),
            "mechanics.force" => Field::Optional($($r)* s.mechanics.force),
            "mechanics.gap" => Field::Plain($($r)* s.mechanics.gap),
            "mechanics.initial_position" => Field::Plain($($r)* s.mechanics.initial_position),
            "mechanics.initial_velocity" => Field::Plain($($r)* s.mechanics.initial_velocity),
            "mechanics.preload" => Field::Plain($($r)* s.mechanics.preload),
            "coil.resistance" | "coil.pole_area" | "coil.air_gap" | "coil.iron_gap" => {
                match $($r)* s.coil {
                    Some(c) => Field::Plain(match $key {
                        "coil.resistance" => $($r)* c.resistance,
                        "coil.pole_area" => $($r)* c.pole_area,
                        "coil.air_gap" => $($r)* c.air_gap,
                        _ => $($r)* c.iron_gap,
                    }),
                    None => Field::NoSection("[coil]"),
                }
            }
            "surface.stiffness" => Field::Optional($($r)* s.surface.stiffness),
            "surface.damping" => Field::Optional($($r)* s.surface.damping),
            "surface.restitution" => Field::Optional($($r)* s.surface.restitution),
            "surface.exponent" => Field::Optional($($r)* s.surface.exponent),
            "surface.chi" => Field::Optional($($r)* s.surface.chi),
            "surface.reference_velocity" => Field::Optional($($r)* s.surface.reference_velocity),
            "back_stop.stiffness" | "back_stop.damping" | "back_stop.restitution"
            | "back_stop.exponent" | "back_stop.chi" | "back_stop.reference_velocity" => {
                match $($r)* s.back_stop {
                    Some(b) => Field::Optional(match $key {
                        "back_stop.stiffness" => $($r)* b.stiffness,
                        "back_stop.damping" => $($r)* b.damping,
                        "back_stop.restitution" => $($r)* b.restitution,
                        "back_stop.exponent" => $($r)* b.exponent,
                        "back_stop.chi" => $($r)* b.chi,
                        _ => $($r)* b.reference_velocity,
                    }),
                    None => Field::NoSection("[back_stop]"),
                }
            }
            "blade.mass" | "blade.stiffness" | "blade.damping" => match $($r)* s.blade {
                Some(b) => Field::Plain(match $key {
                    "blade.mass" => $($r)* b.mass,
                    "blade.stiffness" => $($r)* b.stiffness,
                    _ => $($r)* b.damping,
                }),
                None => Field::NoSection("[blade]"),
            },
            "pole_face.overtravel" => match $($r)* s.pole_face {
                Some(p) => Field::Plain($($r)* p.overtravel),
                None => Field::NoSection("[pole_face]"),
            },
            "pole_face.stiffness" | "pole_face.damping" | "pole_face.restitution"
            | "pole_face.exponent" | "pole_face.chi" | "pole_face.reference_velocity" => {
                match $($r)* s.pole_face {
                    Some(p) => Field::Optional(match $key {
                        "pole_face.stiffness" => $($r)* p.stiffness,
                        "pole_face.damping" => $($r)* p.damping,
                        "pole_face.restitution" => $($r)* p.restitution,
                        "pole_face.exponent" => $($r)* p.exponent,
                        "pole_face.chi" => $($r)* p.chi,
                        _ => $($r)* p.reference_velocity,
                    }),
                    None => Field::NoSection("[pole_face]"),
                }
            }
            "contact.r_closed" => Field::Plain($($r)* s.contact.r_closed),
            "contact.r_open" => Field::Plain($($r)* s.contact.r_open),
            "contact.edge_time" => Field::Plain($($r)* s.contact.edge_time),
            "contact.holm.r_film" | "contact.holm.r_ref" | "contact.holm.f_ref"
            | "contact.holm.exponent" => match $($r)* s.contact.holm {
                Some(h) => Field::Plain(match $key {
                    "contact.holm.r_film" => $($r)* h.r_film,
                    "contact.holm.r_ref" => $($r)* h.r_ref,
                    "contact.holm.f_ref" => $($r)* h.f_ref,
                    _ => $($r)* h.exponent,
                }),
                None => Field::NoSection("[contact.holm]"),
            },
            "simulation.t_end" => Field::Plain($($r)* s.simulation.t_end),
            "simulation.min_open_time" => Field::Plain($($r)* s.simulation.min_open_time),
            "simulation.min_gap" => Field::Plain($($r)* s.simulation.min_gap),
            "arc.v_min" | "arc.i_min" | "arc.field" | "arc.opening_speed" | "arc.low_current"
            | "arc.low_current_gap" | "arc.capacitance" => match $($r)* s.arc {
                Some(a) => Field::Optional(match $key {
                    "arc.v_min" => $($r)* a.v_min,
                    "arc.i_min" => $($r)* a.i_min,
                    "arc.field" => $($r)* a.field,
                    "arc.low_current" => $($r)* a.low_current,
                    "arc.low_current_gap" => $($r)* a.low_current_gap,
                    "arc.capacitance" => $($r)* a.capacitance,
                    _ => $($r)* a.opening_speed,
                }),
                None => Field::NoSection("[arc]"),
            },
            other => match probe_key(other) {
                Some((i, _)) if i >= s.probes.len() => Field::NoSection("[[probe]] of that number"),
                Some((i, true)) => Field::Plain($($r)* s.probes[i].low),
                Some((i, false)) => Field::Plain($($r)* s.probes[i].high),
                None => Field::Unknown,
            },
        }
    }};
}

impl Scenario {
    /// The value of number `key` (one of [`NUMBER_KEYS`](super::numbers::NUMBER_KEYS), or
    /// `probe[N].low`/`.high`); `None` for an optional key the file does
    /// not give (e.g. `surface.restitution` of a Kelvin–Voigt surface).
    pub fn number(&self, key: &str) -> Result<Option<f64>, ScenarioError> {
        if let Some(name) = key.strip_prefix(PARAMS_PREFIX) {
            return self.circuit_param(key, name);
        }
        match number_field!(self, key, &) {
            Field::Plain(v) => Ok(Some(*v)),
            Field::Optional(v) => Ok(*v),
            Field::NoSection(section) => Err(self.no_section(key, section)),
            Field::Unknown => Err(self.unknown_number(key, "")),
        }
    }

    /// `circuit.params.NAME`: the scenario's value, else the netlist's own
    /// plain-number `.param NAME=value` (`None` when it gives an
    /// expression, or the netlist cannot be read yet).
    pub(super) fn circuit_param(
        &self,
        key: &str,
        name: &str,
    ) -> Result<Option<f64>, ScenarioError> {
        let Some(circuit) = &self.circuit else {
            return Err(self.no_section(key, "[circuit]"));
        };
        if !valid_param_name(name) {
            return Err(self.unknown_number(key, ""));
        }
        if let Some(v) = circuit.params.get(name) {
            return Ok(Some(*v));
        }
        Ok(match self.netlist() {
            Some(Ok((_, text))) => crate::netlist::param_value(&text, name),
            _ => None,
        })
    }

    /// Set number `key` (see [`Scenario::number`]) and validate the
    /// scenario again by the loader's rules, so that it stays one the file
    /// could have given (a Hunt–Crossley restitution is converted to χ
    /// again). On error the scenario is unchanged.
    pub fn set_number(&mut self, key: &str, value: f64) -> Result<(), ScenarioError> {
        self.set_numbers(&[(key, value)])
    }

    /// [`Scenario::set_number`] for several keys at once, validated once
    /// at the end: a change that is only valid together with another
    /// (`contact.r_closed` past the old `contact.r_open`) is accepted. On
    /// error the scenario is unchanged.
    pub fn set_numbers(&mut self, values: &[(&str, f64)]) -> Result<(), ScenarioError> {
        let mut old: Vec<(&str, Option<f64>)> = Vec::with_capacity(values.len());
        let mut failure = None;
        for &(key, value) in values {
            if let Some(name) = key.strip_prefix(PARAMS_PREFIX) {
                match self.circuit.as_mut() {
                    Some(c) if valid_param_name(name) => {
                        old.push((key, c.params.insert(name.to_owned(), value)));
                        continue;
                    }
                    Some(_) => {
                        failure = Some(self.unknown_number(key, ""));
                        break;
                    }
                    None => {
                        failure = Some(self.no_section(key, "[circuit]"));
                        break;
                    }
                }
            }
            match number_field!(&mut *self, key, &mut) {
                Field::Plain(v) => old.push((key, Some(std::mem::replace(v, value)))),
                Field::Optional(v) => old.push((key, v.replace(value))),
                Field::NoSection(section) => {
                    failure = Some(self.no_section(key, section));
                    break;
                }
                Field::Unknown => {
                    failure = Some(self.unknown_number(key, ""));
                    break;
                }
            }
        }
        let probes = values.iter().any(|(key, _)| key.starts_with("probe["));
        let result = match failure {
            Some(e) => Err(e),
            None => self.revalidate(probes),
        };
        match result {
            Ok((surface, back_stop)) => {
                self.resolved_surface = surface;
                self.resolved_back_stop = back_stop;
                Ok(())
            }
            Err(e) => {
                for &(key, value) in old.iter().rev() {
                    if let Some(name) = key.strip_prefix(PARAMS_PREFIX) {
                        let params = &mut self.circuit.as_mut().expect("set above").params;
                        match value {
                            Some(v) => params.insert(name.to_owned(), v),
                            None => params.remove(name),
                        };
                        continue;
                    }
                    match number_field!(&mut *self, key, &mut) {
                        Field::Plain(v) => *v = value.expect("a plain number had a value"),
                        Field::Optional(v) => *v = value,
                        Field::NoSection(_) | Field::Unknown => {
                            unreachable!("`{key}` was set above")
                        }
                    }
                }
                Err(e)
            }
        }
    }

    /// The loader's physics rules on the scenario as it now is; the
    /// probes only when asked (their keys are formatted, which allocates).
    pub(crate) fn revalidate(
        &self,
        probes: bool,
    ) -> Result<(Surface, Option<Surface>), ScenarioError> {
        let index = KeyIndex {
            text: "",
            document_span: 0..0,
            entries: Vec::new(),
        };
        let check = Check {
            origin: &self.origin,
            index: &index,
        };
        let (surface, back_stop) = check.physics(Physics {
            mechanics: &self.mechanics,
            coil: self.coil.as_ref(),
            surface: &self.surface,
            back_stop: self.back_stop.as_ref(),
            blade: self.blade.as_ref(),
            pole_face: self.pole_face.as_ref(),
            contact: &self.contact,
            simulation: &self.simulation,
        })?;
        if let Some(arc) = &self.arc {
            check.arc(arc)?;
        }
        if probes {
            for (i, probe) in self.probes.iter().enumerate() {
                check.probe(i, probe)?;
            }
        }
        Ok((surface, back_stop))
    }

    pub(super) fn unknown_number(&self, key: &str, within: &'static str) -> ScenarioError {
        ScenarioError::UnknownNumber {
            at: Location {
                path: self.origin.clone(),
                line: None,
            },
            key: key.to_owned(),
            within,
            known: number_keys_described(),
        }
    }

    pub(super) fn no_section(&self, key: &str, section: &'static str) -> ScenarioError {
        ScenarioError::Sweep {
            at: Location {
                path: self.origin.clone(),
                line: None,
            },
            key: key.to_owned(),
            problem: format!("the scenario has no {section} section: add it to set this key"),
        }
    }
}
