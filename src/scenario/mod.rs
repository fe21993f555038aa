//! The scenario file: one TOML file that describes a relay, its contact
//! surface and, optionally, the circuit it switches (docs/scenario.md).
//! Every command starts here.
//!
//! Loading has three steps, and every error names the file, the line when
//! there is one, and the dotted key (`mechanics.mass`, `probe[0].low`):
//! 1. TOML syntax, parsed into a tree that remembers where each key is;
//! 2. shape: serde structs with `deny_unknown_fields`, so a misspelt key
//!    is an error instead of a silently ignored line;
//! 3. physics: every number finite and in range, sections consistent
//!    (a step `force` or a `[coil]`, the keys of one surface law).
//!
//! A validated [`Scenario`] converts into the library's inputs:
//! [`Scenario::mechanics`], [`Scenario::surface`], [`Scenario::settings`].

mod arc;
mod base;
#[cfg(test)]
mod base_tests;
mod builder;
mod calibration;
mod check;
mod circuit;
mod coil;
mod contact;
mod envelope;
mod error;
mod figure;
mod keys;
mod limits;
mod mechanics;
mod numbers;
mod probes;
mod simulation;
mod surface;
mod sweep;
#[cfg(test)]
mod tests;
mod two_stage;

pub use base::{BUNDLED_PARTS, bundled_part, bundled_part_text};
pub use builder::ScenarioBuilder;
pub use calibration::{
    DatasheetSection, Determined, FitSection, FittedParameter, ProvenanceSection,
};
pub use circuit::CircuitSection;
pub use coil::CoilSection;
pub use contact::{ContactSection, HolmSection};
pub use envelope::{EnvelopeRange, EnvelopeSection};
pub use error::{Location, ScenarioError};
pub use figure::{FigureKind, PRINTED_PRECISION, PrintedFigure, TYPICAL_BAND};
pub use limits::LimitsSection;
pub use mechanics::MechanicsSection;
pub use numbers::{ENVELOPE, NUMBER_KEYS, unit_of};
pub use probes::Probe;
pub use simulation::SimulationSection;
pub use surface::{SurfaceLaw, SurfaceSection};
pub use sweep::{GridAxis, SweepSection, Tolerance};
pub use two_stage::{BladeSection, PoleFaceSection, ReleaseRule};

use check::Check;
use keys::*;
use numbers::*;

pub use crate::arc::ArcSection;
use std::collections::BTreeMap;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use thiserror::Error;
use toml::de::{DeTable, DeValue};

use crate::mechanics::{Mechanics, Settings, Surface};

/// The text of the built-in scenario: a small signal relay switching an
/// MCU input. Exposed so that a command can write it out for the user to
/// edit.
pub const DEFAULT_SCENARIO_TOML: &str = include_str!("../../scenarios/default.toml");

/// Where the built-in scenario lives in the source tree. Its relative
/// `circuit.netlist` resolves against this directory.
const DEFAULT_SCENARIO_ORIGIN: &str =
    concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/default.toml");

/// The built-in scenario's circuit (`netlists/mcu_input.cir`), compiled in
/// so that `run` with no scenario works wherever the binary is.
pub const DEFAULT_NETLIST: &str = include_str!("../../netlists/mcu_input.cir");

/// The built-in scenario's `circuit.netlist`, relative to its file.
const DEFAULT_NETLIST_PATH: &str = "../netlists/mcu_input.cir";

/// The file as serde sees it; [`Scenario`] adds the origin and the
/// resolved surface law.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Document {
    mechanics: MechanicsSection,
    coil: Option<CoilSection>,
    surface: SurfaceSection,
    back_stop: Option<SurfaceSection>,
    blade: Option<BladeSection>,
    pole_face: Option<PoleFaceSection>,
    #[serde(default)]
    contact: ContactSection,
    #[serde(default)]
    simulation: SimulationSection,
    circuit: Option<CircuitSection>,
    #[serde(default)]
    probe: Vec<Probe>,
    limits: Option<LimitsSection>,
    sweep: Option<SweepSection>,
    datasheet: Option<DatasheetSection>,
    fit: Option<FitSection>,
    provenance: Option<ProvenanceSection>,
    arc: Option<ArcSection>,
    envelope: Option<EnvelopeSection>,
}

/// A loaded and validated scenario file.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// The file it came from (for messages, and the base of relative paths).
    pub origin: PathBuf,
    /// `[mechanics]`: the moving contact and, without a `[coil]`, its step
    /// force.
    pub mechanics: MechanicsSection,
    /// `[coil]`: the magnetic drive of a coil-driven relay, instead of
    /// `mechanics.force`.
    pub coil: Option<CoilSection>,
    /// `[surface]`: the fixed contact's surface law as written; the
    /// resolved law is [`Scenario::surface`].
    pub surface: SurfaceSection,
    /// `[back_stop]`: the rest stop's own surface law, where the armature
    /// lands on release (the normally-closed contact). Only with `[coil]`:
    /// a step force never releases.
    pub back_stop: Option<SurfaceSection>,
    /// `[blade]`: the moving contact on its leaf spring, carried by the
    /// armature (a two-stage relay).
    pub blade: Option<BladeSection>,
    /// `[pole_face]`: the armature's stop past the contact (needs
    /// `[blade]`).
    pub pole_face: Option<PoleFaceSection>,
    /// `[contact]`: the contact as a resistor (the defaults when the file
    /// has no such section).
    pub contact: ContactSection,
    /// `[simulation]`: when to stop (the defaults when the file has no such
    /// section).
    pub simulation: SimulationSection,
    /// `[circuit]`: the netlist the contact switches, `circuit.netlist`
    /// already resolved against the scenario file's directory.
    pub circuit: Option<CircuitSection>,
    /// The `[[probe]]` tables, in file order.
    pub probes: Vec<Probe>,
    /// `[limits]`, for `check`.
    pub limits: Option<LimitsSection>,
    /// `[sweep]`, for `chatterspice sweep`.
    pub sweep: Option<SweepSection>,
    /// `[datasheet]`: the relay's published figures, for `fit`.
    pub datasheet: Option<DatasheetSection>,
    /// `[fit]`: which keys `fit` may move, and within what bounds.
    pub fit: Option<FitSection>,
    /// `[provenance]`: what a `fit` fitted this scenario to.
    pub provenance: Option<ProvenanceSection>,
    /// `[arc]`: the contact arcs at every opening (docs/arcs.md).
    pub arc: Option<ArcSection>,
    /// `[envelope]`: the ranges of the keys the datasheet does not fix,
    /// for `run --envelope` and `check --envelope`.
    pub envelope: Option<EnvelopeSection>,
    /// Computed once during validation: converting a Hunt–Crossley
    /// restitution into χ is a root solve that can fail.
    resolved_surface: Surface,
    /// `[back_stop]`'s law, resolved as `resolved_surface`.
    resolved_back_stop: Option<Surface>,
    /// The built-in scenario carries its netlist's text, used when the
    /// file is not on disk (an installed binary).
    embedded_netlist: Option<&'static str>,
}

impl Scenario {
    /// Read, parse and validate a scenario file.
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        let text = crate::input::read_to_string(path).map_err(|source| ScenarioError::Read {
            path: path.to_owned(),
            source,
        })?;
        Scenario::parse(&text, path)
    }

    /// Parse and validate scenario text. `origin` names it in errors, and
    /// relative paths in it (`circuit.netlist`) are resolved against
    /// `origin`'s directory.
    pub fn parse(text: &str, origin: &Path) -> Result<Scenario, ScenarioError> {
        let tree = syntax(text, origin)?;
        if tree.get_ref().get("base").is_none() {
            return Scenario::parse_tree(tree, text, origin);
        }
        let Some(expanded) = base::expand(text, origin)? else {
            return Scenario::parse_tree(tree, text, origin);
        };
        let merged = &expanded.text;
        let scenario = syntax(merged, origin)
            .and_then(|tree| Scenario::parse_tree(tree, merged, origin))
            .map_err(|e| expanded.relocate(e))?;
        // A circuit that is the built-in default's keeps its compiled-in
        // text, so that it runs wherever the binary is.
        let default_netlist = lexically_normal(
            &Path::new(DEFAULT_SCENARIO_ORIGIN)
                .parent()
                .unwrap_or(Path::new(""))
                .join(DEFAULT_NETLIST_PATH),
        );
        let embedded = scenario
            .circuit
            .as_ref()
            .filter(|c| c.netlist == default_netlist)
            .map(|_| DEFAULT_NETLIST);
        Ok(Scenario {
            embedded_netlist: embedded,
            ..scenario
        })
    }

    /// Shape and physics of a scenario whose syntax is already checked.
    fn parse_tree(
        tree: toml::Spanned<DeTable<'_>>,
        text: &str,
        origin: &Path,
    ) -> Result<Scenario, ScenarioError> {
        let index = KeyIndex::new(&tree, text);
        let document = Document::deserialize(toml::de::Deserializer::from(tree))
            .map_err(|e| index.shape_error(e, origin))?;
        let check = Check {
            origin,
            index: &index,
        };
        let (resolved_surface, resolved_back_stop) = check.all(&document)?;

        let base = origin.parent().unwrap_or(Path::new(""));
        let circuit = document.circuit.map(|c| CircuitSection {
            netlist: lexically_normal(&base.join(&c.netlist)),
            ..c
        });
        Scenario {
            origin: origin.to_owned(),
            mechanics: document.mechanics,
            coil: document.coil,
            surface: document.surface,
            back_stop: document.back_stop,
            blade: document.blade,
            pole_face: document.pole_face,
            contact: document.contact,
            simulation: document.simulation,
            circuit,
            probes: document.probe,
            limits: document.limits,
            sweep: document.sweep,
            datasheet: document.datasheet,
            fit: document.fit,
            provenance: document.provenance,
            // The material's numbers filled in, so that every arc number
            // has a value to sweep or fit around.
            arc: document.arc.map(|a| a.resolved()),
            envelope: document.envelope,
            resolved_surface,
            resolved_back_stop,
            embedded_netlist: None,
        }
        .with_checked_sweep(&check)
    }

    /// The built-in scenario (`scenarios/default.toml`, compiled in): a
    /// small signal relay with a Kelvin–Voigt contact switching an MCU
    /// input.
    pub fn builtin_default() -> Scenario {
        // The unit tests parse it, so a broken file never ships.
        let scenario = Scenario::parse(DEFAULT_SCENARIO_TOML, Path::new(DEFAULT_SCENARIO_ORIGIN))
            .expect("the built-in scenario is valid");
        Scenario {
            embedded_netlist: Some(DEFAULT_NETLIST),
            ..scenario
        }
    }

    /// The `[circuit]` netlist: its path (for messages and relative
    /// includes) and its text. `None` when the scenario has no `[circuit]`.
    pub fn netlist(&self) -> Option<Result<(PathBuf, String), ScenarioError>> {
        let circuit = self.circuit.as_ref()?;
        let path = circuit.netlist.clone();
        Some(
            match (crate::input::read_to_string(&path), self.embedded_netlist) {
                (Ok(text), _) => Ok((path, text)),
                (Err(_), Some(text)) => Ok((path, text.to_owned())),
                (Err(source), None) => Err(ScenarioError::NetlistRead {
                    path,
                    scenario: self.origin.clone(),
                    source,
                }),
            },
        )
    }

    /// The step-force mechanics for the engine. Fails for a coil-driven
    /// scenario, which the engine does not simulate yet: silently running
    /// it with some other force would give a plausible but wrong answer.
    pub fn mechanics(&self) -> Result<Mechanics, ScenarioError> {
        let force = self
            .mechanics
            .force
            .ok_or_else(|| ScenarioError::CoilDriveUnsupported {
                path: self.origin.clone(),
            })?;
        Ok(Mechanics {
            force,
            ..self.armature()
        })
    }

    /// The armature's mechanics whatever drives it: [`Scenario::mechanics`]
    /// with the force of a coil-driven relay at 0 (its coil makes it).
    pub fn armature(&self) -> Mechanics {
        let m = &self.mechanics;
        Mechanics {
            mass: m.mass,
            stiffness: m.stiffness,
            damping: m.damping,
            force: m.force.unwrap_or(0.0),
            gap: m.gap,
            initial_position: m.initial_position,
            initial_velocity: m.initial_velocity,
            preload: m.preload,
        }
    }

    /// V, the ideal DC step a coil-driven relay gets without its driver
    /// circuit: `coil.drive_voltage`, else `datasheet.coil_voltage`;
    /// `None` without a `[coil]` or without either key.
    pub fn dc_step_voltage(&self) -> Option<f64> {
        self.coil.as_ref()?;
        self.coil
            .as_ref()
            .and_then(|c| c.drive_voltage)
            .or(self.datasheet.as_ref().and_then(|d| d.coil_voltage))
    }

    /// The surface law, with a Hunt–Crossley restitution already converted
    /// to χ.
    pub fn surface(&self) -> Surface {
        self.resolved_surface
    }

    /// The relay as built: `[blade]`, `[pole_face]` and the release rules
    /// (validated with the rest of the file). Without them, the one-mass
    /// model ([`crate::mechanics::two_stage::TwoStage::is_one_mass`]).
    pub fn two_stage(&self) -> crate::mechanics::two_stage::TwoStage {
        use crate::mechanics::two_stage::{Blade, PoleFace, TwoStage};
        let pole_face = self.pole_face.as_ref().map(|p| PoleFace {
            overtravel: p.overtravel,
            surface: surface::resolve(&p.surface()),
            release: p.release.unwrap_or_default().into(),
        });
        TwoStage {
            blade: self.blade.as_ref().map(|b| Blade {
                mass: b.mass,
                stiffness: b.stiffness,
                damping: b.damping,
            }),
            pole_face,
            release: self.surface.release.unwrap_or_default().into(),
        }
    }

    /// The back stop's law (`[back_stop]`), resolved like
    /// [`Scenario::surface`]; `None`: the armature lands inelastically.
    pub fn back_stop(&self) -> Option<Surface> {
        self.resolved_back_stop
    }

    /// The engine settings from `[simulation]`.
    pub fn settings(&self) -> Settings {
        let s = &self.simulation;
        Settings {
            t_end: s.t_end,
            min_open_time: s.min_open_time,
            min_gap: s.min_gap,
        }
    }
}

/// The scenario text's TOML syntax, with the place of the first error
/// (a duplicate key names the line that set it first).
fn syntax<'t>(text: &'t str, origin: &Path) -> Result<toml::Spanned<DeTable<'t>>, ScenarioError> {
    DeTable::parse(text).map_err(|source| {
        let start = source.span().map_or(0, |s| s.start);
        let (line, column) = line_column(text, start);
        let mut message = source.message().trim_end().to_owned();
        if message == "duplicate key" {
            // Name the key, and the line that set it first.
            let name = source
                .span()
                .and_then(|s| text.get(s))
                .unwrap_or("")
                .trim()
                .to_owned();
            message = duplicate_message(text, &name, line);
        }
        ScenarioError::Syntax {
            at: Location {
                path: origin.to_owned(),
                line: Some(line),
            },
            column,
            message,
            source: Box::new(source),
        }
    })
}

/// `path` with `.` dropped and `dir/..` folded, without touching the file
/// system: `scenarios/../netlists/a.cir` → `netlists/a.cir`, which reads
/// better in messages. A `..` with nothing to fold stays.
fn lexically_normal(path: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => match out.components().next_back() {
                Some(Component::Normal(_)) => {
                    out.pop();
                }
                Some(Component::RootDir | Component::Prefix(_)) => {}
                _ => out.push(".."),
            },
            other => out.push(other),
        }
    }
    out
}
