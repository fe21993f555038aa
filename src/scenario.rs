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

pub use crate::arc::ArcSection;
pub use crate::calibrate::sections::{DatasheetSection, FitSection, ProvenanceSection};
use std::collections::BTreeMap;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

use serde::Deserialize;
use thiserror::Error;
use toml::de::{DeTable, DeValue};

use crate::mechanics::surface::hunt_crossley_chi;
use crate::mechanics::{Mechanics, Settings, Surface};
use crate::waveform::Holm;

/// The text of the built-in scenario: a small signal relay switching an
/// MCU input. Exposed so that a command can write it out for the user to
/// edit.
pub const DEFAULT_SCENARIO_TOML: &str = include_str!("../scenarios/default.toml");

/// Where the built-in scenario lives in the source tree. Its relative
/// `circuit.netlist` resolves against this directory.
const DEFAULT_SCENARIO_ORIGIN: &str =
    concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/default.toml");

/// The built-in scenario's circuit (`netlists/mcu_input.cir`), compiled in
/// so that `run` with no scenario works wherever the binary is.
pub const DEFAULT_NETLIST: &str = include_str!("../netlists/mcu_input.cir");

/// `[mechanics]`: the moving contact (docs/model.md §1). SI units.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MechanicsSection {
    /// kg
    pub mass: f64,
    /// N/m
    pub stiffness: f64,
    /// N·s/m, may be 0.
    pub damping: f64,
    /// N, the step closing force; `None` when `[coil]` drives the contact.
    pub force: Option<f64>,
    /// m
    pub gap: f64,
    /// m
    #[serde(default)]
    pub initial_position: f64,
    /// m/s
    #[serde(default)]
    pub initial_velocity: f64,
    /// N, return-spring force holding the armature on its rest stop.
    #[serde(default)]
    pub preload: f64,
}

/// `[coil]`: the magnetic drive of docs/model.md §7, instead of a step force.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoilSection {
    /// Ω
    pub resistance: f64,
    pub turns: u32,
    /// m²
    pub pole_area: f64,
    /// m, armature air gap at rest.
    pub air_gap: f64,
    /// m, the iron path as an equivalent air gap.
    pub iron_gap: f64,
}

/// `surface.law`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SurfaceLaw {
    Rigid,
    KelvinVoigt,
    HuntCrossley,
}

impl SurfaceLaw {
    /// The name used in the scenario file.
    pub fn as_str(self) -> &'static str {
        match self {
            SurfaceLaw::Rigid => "rigid",
            SurfaceLaw::KelvinVoigt => "kelvin-voigt",
            SurfaceLaw::HuntCrossley => "hunt-crossley",
        }
    }

    /// The `[surface]` keys (besides `law`) this law reads.
    fn keys(self) -> &'static [&'static str] {
        match self {
            SurfaceLaw::Rigid => &["restitution"],
            SurfaceLaw::KelvinVoigt => &["stiffness", "damping"],
            SurfaceLaw::HuntCrossley => &[
                "stiffness",
                "exponent",
                "chi",
                "restitution",
                "reference_velocity",
            ],
        }
    }

    /// The same keys, as a reader should see them in an error.
    fn keys_described(self) -> &'static str {
        match self {
            SurfaceLaw::Rigid => "`restitution`",
            SurfaceLaw::KelvinVoigt => "`stiffness` and `damping`",
            SurfaceLaw::HuntCrossley => {
                "`stiffness`, `exponent` and `chi` (or `restitution` with `reference_velocity`)"
            }
        }
    }
}

impl fmt::Display for SurfaceLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// `[surface]` as written: one law and the keys it needs (docs/model.md §2).
/// The keys are all optional here because which ones are required depends
/// on `law`; validation checks them and [`Scenario::surface`] gives the
/// resolved law.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSection {
    pub law: SurfaceLaw,
    /// N/m (Kelvin–Voigt s0) or N/mⁿ (Hunt–Crossley k).
    pub stiffness: Option<f64>,
    /// N·s/m, Kelvin–Voigt r0.
    pub damping: Option<f64>,
    /// Rigid e, or Hunt–Crossley e at `reference_velocity`.
    pub restitution: Option<f64>,
    /// Hunt–Crossley n (default 1, the paper's linear spring).
    pub exponent: Option<f64>,
    /// s/m, Hunt–Crossley χ = λ/k.
    pub chi: Option<f64>,
    /// m/s, the impact speed at which the Hunt–Crossley `restitution` holds.
    pub reference_velocity: Option<f64>,
}

/// `[contact]`: the contact as a resistor (docs/model.md §5).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactSection {
    /// Ω
    pub r_closed: f64,
    /// Ω
    pub r_open: f64,
    /// s, duration of each make or break edge.
    pub edge_time: f64,
    /// `[contact.holm]`: the closed resistance follows the contact force
    /// instead of being `r_closed`.
    pub holm: Option<HolmSection>,
}

/// `[contact.holm]`: R = r_film + r_ref·(f_ref/F)^exponent (docs/model.md §5).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HolmSection {
    /// Ω, the film resistance no force removes (default 0).
    #[serde(default)]
    pub r_film: f64,
    /// Ω, the constriction resistance at `f_ref`.
    pub r_ref: f64,
    /// N
    pub f_ref: f64,
    /// 1/2 for plastic contact spots (default), 1/3 for elastic.
    #[serde(default = "default_holm_exponent")]
    pub exponent: f64,
}

fn default_holm_exponent() -> f64 {
    0.5
}

impl From<&HolmSection> for Holm {
    fn from(h: &HolmSection) -> Holm {
        Holm {
            r_film: h.r_film,
            r_ref: h.r_ref,
            f_ref: h.f_ref,
            exponent: h.exponent,
        }
    }
}

impl Default for ContactSection {
    /// 50 mΩ is the low end of datasheet closed resistance, 1 GΩ is above
    /// any datasheet's open minimum, and 10 ns edges are far shorter than
    /// any bounce yet long enough for ngspice to step through.
    fn default() -> Self {
        ContactSection {
            r_closed: 0.05,
            r_open: 1.0e9,
            edge_time: 1.0e-8,
            holm: None,
        }
    }
}

/// `[simulation]`: the engine's [`Settings`].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimulationSection {
    /// s
    pub t_end: f64,
    /// s
    pub min_open_time: f64,
    /// m
    pub min_gap: f64,
}

impl Default for SimulationSection {
    /// The engine's own defaults, so that the file and the library agree.
    fn default() -> Self {
        let s = Settings::default();
        SimulationSection {
            t_end: s.t_end,
            min_open_time: s.min_open_time,
            min_gap: s.min_gap,
        }
    }
}

/// `[circuit]`: the netlist the contact is placed into.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircuitSection {
    /// The netlist file. Relative paths in the file are resolved against
    /// the scenario file's directory when it is loaded; the file need not
    /// exist until a command runs the circuit.
    pub netlist: PathBuf,
    /// The subcircuit name the netlist instantiates for the contact.
    #[serde(default = "default_subckt")]
    pub subckt: String,
    /// The subcircuit name the netlist instantiates for the coil.
    #[serde(default = "default_coil_subckt")]
    pub coil_subckt: String,
    /// With a `[coil]`: the subcircuit name of the normally-closed
    /// contact (the armature on its rest stop), for a changeover relay
    /// whose NC side switches part of the circuit. `None`: there is none.
    pub nc_subckt: Option<String>,
    /// `[circuit.params]`: values for the netlist's own `.param` names,
    /// set in the run deck (the netlist file is never edited).
    #[serde(default)]
    pub params: BTreeMap<String, f64>,
}

impl CircuitSection {
    /// The `[circuit.params]` as (name, value) pairs, sorted by name.
    pub fn param_list(&self) -> Vec<(&str, f64)> {
        self.params.iter().map(|(k, v)| (k.as_str(), *v)).collect()
    }
}

fn default_subckt() -> String {
    "CONTACT".to_owned()
}

fn default_coil_subckt() -> String {
    "COIL".to_owned()
}

/// `[[probe]]`: a measured signal, its Schmitt thresholds, and the limits
/// `check` holds it to (all optional).
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Probe {
    /// An ngspice vector name, e.g. `v(in)`.
    pub signal: String,
    /// V (A for a current): the Schmitt thresholds.
    pub low: f64,
    pub high: f64,
    /// Most Schmitt edges allowed (1 = one clean transition).
    #[serde(default)]
    pub max_edges: Option<u64>,
    /// Most glitches allowed (edges − 1).
    #[serde(default)]
    pub max_glitches: Option<u64>,
    /// Largest |value| allowed, in the signal's unit (inrush, spikes).
    #[serde(default)]
    pub max_peak: Option<f64>,
    /// Highest value allowed (e.g. an input's absolute maximum rating).
    #[serde(default)]
    pub max_value: Option<f64>,
    /// Lowest value allowed (e.g. −0.3 V below ground on an input).
    #[serde(default)]
    pub min_value: Option<f64>,
    /// s, the last edge must come by then (the signal has settled).
    #[serde(default)]
    pub max_last_edge: Option<f64>,
}

impl Probe {
    /// A probe with thresholds and no limits.
    pub fn new(signal: impl Into<String>, low: f64, high: f64) -> Probe {
        Probe {
            signal: signal.into(),
            low,
            high,
            ..Probe::default()
        }
    }

    /// Whether any limit is set.
    pub fn has_limits(&self) -> bool {
        self.max_edges.is_some()
            || self.max_glitches.is_some()
            || self.max_peak.is_some()
            || self.max_value.is_some()
            || self.min_value.is_some()
            || self.max_last_edge.is_some()
    }
}

/// `[limits]`: what `check` holds the relay to. SI units; all optional.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSection {
    /// s, settle time − first impact.
    pub max_bounce_time: Option<f64>,
    /// Most bounces (openings after the first impact).
    pub max_bounces: Option<u64>,
    /// s, the operate time as datasheets define it: from the coil being
    /// energized (or the force step) to the first make, bounce excluded.
    pub max_operate_time: Option<f64>,
    /// s, the same figure as `max_operate_time` (its older name).
    pub max_first_make: Option<f64>,
    /// s, from the coil being energized (or the force step) to closed for
    /// good: operate plus bounce time.
    pub max_settle_time: Option<f64>,
    /// s, coil off → the NO contact's break, in every operation (a
    /// coil-driven relay only).
    pub max_release_time: Option<f64>,
    /// s, the bounce of the armature on its rest stop (the NC contact)
    /// after each release, first touch to last.
    pub max_nc_bounce_time: Option<f64>,
    /// Most NC bounces after each release.
    pub max_nc_bounces: Option<u64>,
    /// J, the most arc energy in one operation, all its arcs together
    /// (needs `[arc]` and a run).
    pub max_arc_energy: Option<f64>,
    /// The most arcs in one operation (needs `[arc]` and a run).
    pub max_arc_count: Option<u64>,
}

/// The file as serde sees it; [`Scenario`] adds the origin and the
/// resolved surface law.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Document {
    mechanics: MechanicsSection,
    coil: Option<CoilSection>,
    surface: SurfaceSection,
    back_stop: Option<SurfaceSection>,
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
}

/// A loaded and validated scenario file.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// The file it came from (for messages, and the base of relative paths).
    pub origin: PathBuf,
    pub mechanics: MechanicsSection,
    pub coil: Option<CoilSection>,
    pub surface: SurfaceSection,
    /// `[back_stop]`: the rest stop's own surface law, where the armature
    /// lands on release (the normally-closed contact). Only with `[coil]`:
    /// a step force never releases.
    pub back_stop: Option<SurfaceSection>,
    pub contact: ContactSection,
    pub simulation: SimulationSection,
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
    /// Computed once during validation: converting a Hunt–Crossley
    /// restitution into χ is a root solve that can fail.
    resolved_surface: Surface,
    /// `[back_stop]`'s law, resolved as `resolved_surface`.
    resolved_back_stop: Option<Surface>,
    /// The built-in scenario carries its netlist's text, used when the
    /// file is not on disk (an installed binary).
    embedded_netlist: Option<&'static str>,
}

/// A place in a scenario file: the file and, when known, the 1-based line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    pub path: PathBuf,
    pub line: Option<usize>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}", self.path.display()),
            None => write!(f, "{}", self.path.display()),
        }
    }
}

/// Why a scenario file cannot be used. Each variant says where (`at`),
/// which key, and what to change.
#[derive(Debug, Error)]
pub enum ScenarioError {
    #[error("{}: cannot read the scenario file", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{at}: not valid TOML (column {column}): {message}")]
    Syntax {
        at: Location,
        column: usize,
        message: String,
        #[source]
        source: Box<toml::de::Error>,
    },
    #[error("{at}: unknown key `{key}` (misspelt?); {expected}")]
    UnknownKey {
        at: Location,
        key: String,
        expected: String,
        #[source]
        source: Box<toml::de::Error>,
    },
    #[error("{at}: `{key}` is missing: {help}")]
    MissingKey {
        at: Location,
        key: String,
        help: String,
        #[source]
        source: Option<Box<toml::de::Error>>,
    },
    #[error("{at}: bad value for `{key}`: {message}")]
    BadValue {
        at: Location,
        key: String,
        message: String,
        #[source]
        source: Box<toml::de::Error>,
    },
    #[error("{at}: `{key}` = {value:?} {requirement}")]
    Invalid {
        at: Location,
        key: String,
        value: f64,
        requirement: String,
    },
    #[error("{at}: `{key}` must not be empty: {help}")]
    Empty {
        at: Location,
        key: String,
        help: &'static str,
    },
    #[error("{at}: `{key}` and `{other}` cannot both be given: {advice}")]
    Conflict {
        at: Location,
        key: String,
        other: String,
        advice: &'static str,
    },
    #[error(
        "{at}: `{key}` is not a key of surface law \"{law}\", which takes {takes}; \
         remove it or change `surface.law`"
    )]
    NotForLaw {
        at: Location,
        key: String,
        law: SurfaceLaw,
        takes: &'static str,
    },
    #[error(
        "{}: a coil-driven relay ([coil], docs/model.md §7) is simulated only with its driver \
         circuit, by `run` (the coil coupled to the netlist); for the mechanics alone \
         replace [coil] with `mechanics.force`, the closing force in N",
        path.display()
    )]
    CoilDriveUnsupported { path: PathBuf },
    #[error("{at}: `{key}` is not a number of the scenario{within}; use one of: {known}")]
    UnknownNumber {
        at: Location,
        key: String,
        /// Where the key was named, e.g. " (in [sweep.vary])"; empty for a
        /// library call.
        within: &'static str,
        /// The keys that are numbers, comma-separated.
        known: String,
    },
    #[error("{at}: `{key}`: {problem}")]
    Sweep {
        at: Location,
        key: String,
        problem: String,
    },
    #[error(
        "{}: cannot read the netlist named by `circuit.netlist` in {} ({})",
        path.display(),
        scenario.display(),
        if scenario.as_os_str() == "<stdin>" {
            "the scenario came from standard input, so a relative path is relative to the \
             working directory"
        } else {
            "relative paths are relative to the scenario file"
        }
    )]
    NetlistRead {
        path: PathBuf,
        scenario: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl ScenarioError {
    /// The dotted key the error is about, if it is about one.
    pub fn key(&self) -> Option<&str> {
        match self {
            ScenarioError::UnknownKey { key, .. }
            | ScenarioError::MissingKey { key, .. }
            | ScenarioError::BadValue { key, .. }
            | ScenarioError::Invalid { key, .. }
            | ScenarioError::Empty { key, .. }
            | ScenarioError::Conflict { key, .. }
            | ScenarioError::NotForLaw { key, .. }
            | ScenarioError::UnknownNumber { key, .. }
            | ScenarioError::Sweep { key, .. } => Some(key),
            ScenarioError::Read { .. }
            | ScenarioError::Syntax { .. }
            | ScenarioError::CoilDriveUnsupported { .. } => None,
            ScenarioError::NetlistRead { .. } => Some("circuit.netlist"),
        }
    }
}

impl Scenario {
    /// Read, parse and validate a scenario file.
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Read {
            path: path.to_owned(),
            source,
        })?;
        Scenario::parse(&text, path)
    }

    /// Parse and validate scenario text. `origin` names it in errors, and
    /// relative paths in it (`circuit.netlist`) are resolved against
    /// `origin`'s directory.
    pub fn parse(text: &str, origin: &Path) -> Result<Scenario, ScenarioError> {
        let tree = DeTable::parse(text).map_err(|source| {
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
        })?;
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
            contact: document.contact,
            simulation: document.simulation,
            circuit,
            probes: document.probe,
            limits: document.limits,
            sweep: document.sweep,
            datasheet: document.datasheet,
            fit: document.fit,
            provenance: document.provenance,
            arc: document.arc,
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
            match (std::fs::read_to_string(&path), self.embedded_netlist) {
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
        let m = &self.mechanics;
        let force = m.force.ok_or_else(|| ScenarioError::CoilDriveUnsupported {
            path: self.origin.clone(),
        })?;
        Ok(Mechanics {
            mass: m.mass,
            stiffness: m.stiffness,
            damping: m.damping,
            force,
            gap: m.gap,
            initial_position: m.initial_position,
            initial_velocity: m.initial_velocity,
            preload: m.preload,
        })
    }

    /// The surface law, with a Hunt–Crossley restitution already converted
    /// to χ.
    pub fn surface(&self) -> Surface {
        self.resolved_surface
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

/// 1-based line and column of byte offset `at` in `text`.
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

fn line_column(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let before = &text.as_bytes()[..at];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let column = String::from_utf8_lossy(&before[line_start..])
        .chars()
        .count()
        + 1;
    (line, column)
}

/// Every key of the parsed file with its dotted path and where it is, so
/// that errors from serde (which know a byte span) and from validation
/// (which know a key) can both name the key and the line.
struct KeyIndex<'t> {
    text: &'t str,
    document_span: Range<usize>,
    entries: Vec<KeyEntry>,
}

struct KeyEntry {
    path: String,
    key_span: Range<usize>,
    value_span: Range<usize>,
}

impl<'t> KeyIndex<'t> {
    fn new(tree: &toml::Spanned<DeTable<'_>>, text: &'t str) -> Self {
        let mut entries = Vec::new();
        Self::walk(tree.get_ref(), "", &mut entries);
        KeyIndex {
            text,
            document_span: tree.span(),
            entries,
        }
    }

    fn walk(table: &DeTable<'_>, prefix: &str, out: &mut Vec<KeyEntry>) {
        for (key, value) in table.iter() {
            let path = join_key(prefix, key.get_ref());
            out.push(KeyEntry {
                path: path.clone(),
                key_span: key.span(),
                value_span: value.span(),
            });
            match value.get_ref() {
                DeValue::Table(inner) => Self::walk(inner, &path, out),
                DeValue::Array(items) => {
                    for (i, item) in items.into_iter().enumerate() {
                        let item_path = format!("{path}[{i}]");
                        out.push(KeyEntry {
                            path: item_path.clone(),
                            key_span: item.span(),
                            value_span: item.span(),
                        });
                        if let DeValue::Table(inner) = item.get_ref() {
                            Self::walk(inner, &item_path, out);
                        }
                    }
                }
                _ => {}
            }
        }
    }

    /// The line of `key`, or of its nearest ancestor present in the file
    /// (a missing key is reported at its section's header).
    fn line_of_key(&self, key: &str) -> Option<usize> {
        let mut key = key;
        loop {
            if let Some(e) = self.entries.iter().find(|e| e.path == key) {
                return Some(line_column(self.text, e.key_span.start).0);
            }
            key = &key[..key.rfind(['.', '['])?];
        }
    }

    /// The key an error span belongs to: exactly a key or value span if
    /// one matches, else the innermost value containing it; "" for the
    /// document itself.
    fn key_at(&self, span: &Range<usize>) -> &str {
        if *span == self.document_span {
            return "";
        }
        // Children follow their parent in `entries`, and an array of one
        // table can share its span with that table: search from the end
        // so that the deepest key wins.
        if let Some(e) = self
            .entries
            .iter()
            .rev()
            .find(|e| e.key_span == *span || e.value_span == *span)
        {
            return &e.path;
        }
        self.entries
            .iter()
            .filter(|e| e.value_span.start <= span.start && span.end <= e.value_span.end)
            .min_by_key(|e| e.value_span.len())
            .map_or("", |e| e.path.as_str())
    }

    /// Turn a serde error (unknown key, missing key, wrong type) into one
    /// that names the dotted key.
    fn shape_error(&self, mut source: toml::de::Error, origin: &Path) -> ScenarioError {
        // With the text, the error displays an excerpt with the key marked.
        source.set_input(Some(self.text));
        let span = source.span();
        let at = Location {
            path: origin.to_owned(),
            line: span.as_ref().map(|s| line_column(self.text, s.start).0),
        };
        let here = span.as_ref().map_or("", |s| self.key_at(s)).to_owned();
        let message = source.message().trim_end().to_owned();
        let source = Box::new(source);
        // serde's own wording (`de::Error::unknown_field`, `missing_field`)
        // is the only place the field name is available.
        let unknown = message
            .strip_prefix("unknown field `")
            .and_then(|rest| rest.split_once("`, "));
        if let Some((_, expected)) = unknown {
            return ScenarioError::UnknownKey {
                at,
                key: here,
                expected: expected.to_owned(),
                source,
            };
        }
        let missing = message
            .strip_prefix("missing field `")
            .and_then(|rest| rest.split_once('`'));
        if let Some((name, _)) = missing {
            let key = join_key(&here, name);
            return ScenarioError::MissingKey {
                at,
                help: key_help(&key).to_owned(),
                key,
                source: Some(source),
            };
        }
        ScenarioError::BadValue {
            at,
            key: here,
            message: plain_type_error(&message),
            source,
        }
    }
}

/// "duplicate key" said with the key's name and where it was first set:
/// the earlier line that starts with the same key (or table header).
fn duplicate_message(text: &str, name: &str, line: usize) -> String {
    if name.is_empty() {
        return "duplicate key: a key or table is given twice".to_owned();
    }
    let header = format!("[{name}]");
    let first = text.lines().take(line.saturating_sub(1)).position(|l| {
        let l = l.trim_start();
        l.starts_with(&header)
            || l.strip_prefix(name)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
    });
    let table = text
        .lines()
        .nth(line.saturating_sub(1))
        .is_some_and(|l| l.trim_start().starts_with('['));
    let what = if table {
        format!("the table `[{name}]` appears twice")
    } else {
        format!("duplicate key `{name}`: it is set twice in the same table")
    };
    match first {
        Some(n) => format!("{what} (first on line {}); keep one", n + 1),
        None => format!("{what}; keep one"),
    }
}

/// serde's "invalid type: string \"x\", expected f64" in a user's words.
fn plain_type_error(message: &str) -> String {
    let Some(rest) = message.strip_prefix("invalid type: ") else {
        return message.to_owned();
    };
    let Some((found, expected)) = rest.rsplit_once(", expected ") else {
        return message.to_owned();
    };
    let found = if let Some(s) = found.strip_prefix("string ") {
        format!("the text {s}")
    } else if let Some(n) = found.strip_prefix("integer ") {
        format!("the integer {}", n.trim_matches('`'))
    } else if let Some(n) = found.strip_prefix("floating point ") {
        format!("the number {}", n.trim_matches('`'))
    } else if let Some(b) = found.strip_prefix("boolean ") {
        b.trim_matches('`').to_owned()
    } else if found == "map" {
        "a table".to_owned()
    } else if found == "sequence" {
        "an array".to_owned()
    } else {
        found.to_owned()
    };
    let expected = match expected {
        "f64" | "f32" => "a number (e.g. 2.0e-4, no quotes)",
        "u64" | "u32" | "usize" | "u16" | "u8" | "i64" | "i32" => "a whole number (no quotes)",
        "a boolean" | "bool" => "true or false",
        "a string" => "text in quotes",
        other => other,
    };
    format!("found {found}, expected {expected}")
}

fn join_key(prefix: &str, name: &str) -> String {
    if prefix.is_empty() {
        name.to_owned()
    } else {
        format!("{prefix}.{name}")
    }
}

/// What a required key means, for "missing" messages.
fn key_help(key: &str) -> &'static str {
    match key {
        "mechanics" => "add a [mechanics] section: mass, stiffness, damping, force, gap",
        "surface" => "add a [surface] section with `law` and its keys",
        "mechanics.mass" => "the effective moving mass, in kg",
        "mechanics.stiffness" => "the contact-spring stiffness, in N/m",
        "mechanics.damping" => "the structural damping in N·s/m (0 is allowed)",
        "mechanics.gap" => "the contact travel from rest to the fixed contact, in m",
        "surface.law" => "one of \"rigid\", \"kelvin-voigt\", \"hunt-crossley\"",
        "circuit.netlist" => "the netlist file, relative to the scenario file",
        k if k.starts_with("coil.") => {
            "the [coil] section needs resistance, turns, pole_area, air_gap, iron_gap"
        }
        k if k.starts_with("probe") => "each [[probe]] needs signal, low and high",
        _ => "see docs/scenario.md for the keys of each section",
    }
}

/// Validation of a deserialized document, in file order.
struct Check<'a> {
    origin: &'a Path,
    index: &'a KeyIndex<'a>,
}

impl Check<'_> {
    fn at(&self, key: &str) -> Location {
        Location {
            path: self.origin.to_owned(),
            line: self.index.line_of_key(key),
        }
    }

    fn invalid(&self, key: &str, value: f64, requirement: impl Into<String>) -> ScenarioError {
        ScenarioError::Invalid {
            at: self.at(key),
            key: key.to_owned(),
            value,
            requirement: requirement.into(),
        }
    }

    /// `value` must be finite and satisfy `ok`; `requirement` says what to
    /// change when it does not.
    fn number(
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

    fn missing(&self, key: &str, help: &str) -> ScenarioError {
        ScenarioError::MissingKey {
            at: self.at(key),
            key: key.to_owned(),
            help: help.to_owned(),
            source: None,
        }
    }

    /// The range of numbers a relay model can mean (see [`ENVELOPE`]):
    /// beyond it the numbers overflow or the simulation never ends.
    fn envelope(&self, key: &str, value: Option<f64>) -> Result<(), ScenarioError> {
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

    fn not_empty(&self, key: &str, value: &str, help: &'static str) -> Result<(), ScenarioError> {
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
    fn all(&self, d: &Document) -> Result<(Surface, Option<Surface>), ScenarioError> {
        self.mechanics(&d.mechanics)?;
        self.drive(&d.mechanics, d.coil.as_ref())?;
        let surface = self.surface("surface", &d.surface)?;
        let back_stop = self.back_stop(d.back_stop.as_ref(), d.coil.is_some())?;
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

    /// `[back_stop]`, which only a coil-driven relay reaches (on release).
    fn back_stop(
        &self,
        s: Option<&SurfaceSection>,
        coil: bool,
    ) -> Result<Option<Surface>, ScenarioError> {
        let Some(s) = s else { return Ok(None) };
        if !coil {
            return Err(ScenarioError::Conflict {
                at: self.at("back_stop"),
                key: "back_stop".to_owned(),
                other: "mechanics.force".to_owned(),
                advice: "the armature comes back to its rest stop only on release, and a \
                         step force never releases: give a [coil] (the release follows its \
                         driver) or remove [back_stop]",
            });
        }
        self.surface("back_stop", s).map(Some)
    }

    fn mechanics(&self, m: &MechanicsSection) -> Result<(), ScenarioError> {
        self.number(
            "mechanics.mass",
            m.mass,
            m.mass > 0.0,
            "must be > 0: the effective moving mass, in kg",
        )?;
        self.number(
            "mechanics.stiffness",
            m.stiffness,
            m.stiffness > 0.0,
            "must be > 0: the contact-spring stiffness, in N/m",
        )?;
        self.number(
            "mechanics.damping",
            m.damping,
            m.damping >= 0.0,
            "must be ≥ 0: damping removes energy, it cannot add it",
        )?;
        self.number(
            "mechanics.gap",
            m.gap,
            m.gap > 0.0,
            "must be > 0: the travel from rest to the fixed contact, in m",
        )?;
        self.number(
            "mechanics.initial_position",
            m.initial_position,
            m.initial_position < m.gap,
            format!(
                "must be less than `mechanics.gap` = {:?} m: the contact has to start open",
                m.gap
            ),
        )?;
        self.number("mechanics.initial_velocity", m.initial_velocity, true, "")?;
        self.number(
            "mechanics.preload",
            m.preload,
            m.preload >= 0.0,
            "must be ≥ 0: the return spring holds the armature on its rest stop",
        )?;
        for (key, value) in [
            ("mechanics.mass", Some(m.mass)),
            ("mechanics.stiffness", Some(m.stiffness)),
            ("mechanics.damping", Some(m.damping)),
            ("mechanics.force", m.force),
            ("mechanics.gap", Some(m.gap)),
            ("mechanics.initial_position", Some(m.initial_position)),
            ("mechanics.initial_velocity", Some(m.initial_velocity)),
            ("mechanics.preload", Some(m.preload)),
        ] {
            self.envelope(key, value)?;
        }
        Ok(())
    }

    /// Exactly one of a step force and a coil.
    fn drive(&self, m: &MechanicsSection, coil: Option<&CoilSection>) -> Result<(), ScenarioError> {
        match (m.force, coil) {
            (Some(_), Some(_)) => Err(ScenarioError::Conflict {
                at: self.at("mechanics.force"),
                key: "mechanics.force".to_owned(),
                other: "coil".to_owned(),
                advice: "with [coil] the closing force comes from the coil current; \
                         remove `mechanics.force` or the [coil] section",
            }),
            (None, None) => Err(self.missing(
                "mechanics.force",
                "give the step closing force in N, or a [coil] section that produces it",
            )),
            (Some(force), None) => {
                self.number(
                    "mechanics.force",
                    force,
                    force >= 0.0,
                    "must be ≥ 0: the step closing force, in N",
                )?;
                // The preload holds the armature only while it rests on its
                // stop: one that starts off it, or moving toward the
                // contact, flies whatever the force (a free impact).
                let at_rest = m.initial_position <= 0.0 && m.initial_velocity <= 0.0;
                self.number(
                    "mechanics.force",
                    force,
                    force > m.preload || !at_rest,
                    format!(
                        "must exceed `mechanics.preload` = {:?} N for an armature that starts at \
                         rest on its stop, or it never leaves it; for a free impact start it \
                         off the stop (`mechanics.initial_position` > 0) or moving toward the \
                         contact (`mechanics.initial_velocity` > 0)",
                        m.preload
                    ),
                )
            }
            (None, Some(c)) => self.coil(c, m.gap),
        }
    }

    fn coil(&self, c: &CoilSection, gap: f64) -> Result<(), ScenarioError> {
        self.number(
            "coil.resistance",
            c.resistance,
            c.resistance > 0.0,
            "must be > 0: the coil's DC resistance, in Ω",
        )?;
        if c.turns == 0 {
            return Err(self.invalid(
                "coil.turns",
                0.0,
                "must be at least 1: the number of turns of the coil",
            ));
        }
        self.number(
            "coil.pole_area",
            c.pole_area,
            c.pole_area > 0.0,
            "must be > 0: the pole face area, in m²",
        )?;
        self.number(
            "coil.air_gap",
            c.air_gap,
            c.air_gap > gap,
            format!(
                "must exceed `mechanics.gap` = {gap:?} m: a residual air gap must remain \
                 when the contacts close"
            ),
        )?;
        self.number(
            "coil.iron_gap",
            c.iron_gap,
            c.iron_gap >= 0.0,
            "must be ≥ 0: the iron path as an equivalent air gap, in m",
        )
    }

    fn surface(&self, section: &str, s: &SurfaceSection) -> Result<Surface, ScenarioError> {
        let law = self.surface_law(section, s)?;
        for (name, value) in [
            ("stiffness", s.stiffness),
            ("damping", s.damping),
            ("chi", s.chi),
            ("reference_velocity", s.reference_velocity),
        ] {
            self.envelope(&format!("{section}.{name}"), value)?;
        }
        Ok(law)
    }

    fn surface_law(&self, section: &str, s: &SurfaceSection) -> Result<Surface, ScenarioError> {
        let law = s.law;
        let given = [
            ("stiffness", s.stiffness),
            ("damping", s.damping),
            ("restitution", s.restitution),
            ("exponent", s.exponent),
            ("chi", s.chi),
            ("reference_velocity", s.reference_velocity),
        ];
        for (name, value) in given {
            if value.is_some() && !law.keys().contains(&name) {
                let key = format!("{section}.{name}");
                return Err(ScenarioError::NotForLaw {
                    at: self.at(&key),
                    key,
                    law,
                    takes: law.keys_described(),
                });
            }
        }
        let need = |name: &str, help: &str| {
            given
                .iter()
                .find(|(n, _)| *n == name)
                .and_then(|(_, v)| *v)
                .ok_or_else(|| self.missing(&format!("{section}.{name}"), help))
        };
        match law {
            SurfaceLaw::Rigid => {
                let e = need(
                    "restitution",
                    "law \"rigid\" needs the restitution e in [0, 1]",
                )?;
                self.number(
                    &format!("{section}.restitution"),
                    e,
                    (0.0..=1.0).contains(&e),
                    "must lie in [0, 1]: 0 is a dead impact, 1 a perfectly elastic one",
                )?;
                Ok(Surface::Rigid { restitution: e })
            }
            SurfaceLaw::KelvinVoigt => {
                let stiffness = need(
                    "stiffness",
                    "law \"kelvin-voigt\" needs the surface stiffness s0 in N/m",
                )?;
                self.number(
                    &format!("{section}.stiffness"),
                    stiffness,
                    stiffness > 0.0,
                    "must be > 0: the surface stiffness s0, in N/m",
                )?;
                let damping = need(
                    "damping",
                    "law \"kelvin-voigt\" needs the surface damping r0 in N·s/m (0 is allowed)",
                )?;
                self.number(
                    &format!("{section}.damping"),
                    damping,
                    damping >= 0.0,
                    "must be ≥ 0: the surface damping r0, in N·s/m",
                )?;
                Ok(Surface::KelvinVoigt { stiffness, damping })
            }
            SurfaceLaw::HuntCrossley => self.hunt_crossley(section, s),
        }
    }

    fn hunt_crossley(&self, section: &str, s: &SurfaceSection) -> Result<Surface, ScenarioError> {
        let stiffness = s.stiffness.ok_or_else(|| {
            self.missing(
                &format!("{section}.stiffness"),
                "law \"hunt-crossley\" needs the surface stiffness k in N/mⁿ",
            )
        })?;
        self.number(
            &format!("{section}.stiffness"),
            stiffness,
            stiffness > 0.0,
            "must be > 0: the surface stiffness k, in N/mⁿ",
        )?;
        // n = 1 is the paper's linear surface spring (docs/model.md §2c).
        let exponent = s.exponent.unwrap_or(1.0);
        self.number(
            &format!("{section}.exponent"),
            exponent,
            exponent > 0.0,
            "must be > 0: 1 for a linear spring, 1.5 for Hertz contact",
        )?;
        let chi = match (s.chi, s.restitution, s.reference_velocity) {
            (Some(chi), None, None) => {
                self.number(
                    &format!("{section}.chi"),
                    chi,
                    chi >= 0.0,
                    "must be ≥ 0: χ = λ/k in s/m (0 is a lossless surface)",
                )?;
                chi
            }
            (Some(_), restitution, _) => {
                let other = if restitution.is_some() {
                    format!("{section}.restitution")
                } else {
                    format!("{section}.reference_velocity")
                };
                return Err(ScenarioError::Conflict {
                    at: self.at(&format!("{section}.chi")),
                    key: format!("{section}.chi"),
                    other,
                    advice: "give χ directly, or as `restitution` at `reference_velocity`, not both",
                });
            }
            (None, Some(e), Some(v)) => {
                self.number(
                    &format!("{section}.restitution"),
                    e,
                    e > 0.0 && e <= 1.0,
                    "must lie in (0, 1]: the restitution at `reference_velocity`",
                )?;
                self.number(
                    &format!("{section}.reference_velocity"),
                    v,
                    v > 0.0,
                    "must be > 0: the impact speed, in m/s, at which `restitution` holds",
                )?;
                hunt_crossley_chi(e, v).ok_or_else(|| {
                    self.invalid(
                        &format!("{section}.restitution"),
                        e,
                        format!(
                            "cannot be reached at `reference_velocity` = {v:?} m/s; \
                             give `chi` directly"
                        ),
                    )
                })?
            }
            (None, Some(_), None) => {
                return Err(self.missing(
                    &format!("{section}.reference_velocity"),
                    "a Hunt–Crossley `restitution` holds at one impact speed; give it in m/s",
                ));
            }
            (None, None, Some(_)) => {
                return Err(self.missing(
                    &format!("{section}.restitution"),
                    "`reference_velocity` needs the restitution e in (0, 1] that holds at it",
                ));
            }
            (None, None, None) => {
                return Err(self.missing(
                    &format!("{section}.chi"),
                    "law \"hunt-crossley\" needs `chi` in s/m, or `restitution` with \
                     `reference_velocity` in m/s",
                ));
            }
        };
        Ok(Surface::HuntCrossley {
            stiffness,
            exponent,
            chi,
        })
    }

    fn contact(&self, c: &ContactSection) -> Result<(), ScenarioError> {
        self.number(
            "contact.r_closed",
            c.r_closed,
            c.r_closed > 0.0,
            "must be > 0: the closed contact resistance, in Ω (datasheets: 0.05–0.1)",
        )?;
        self.number(
            "contact.r_open",
            c.r_open,
            c.r_open > c.r_closed,
            format!(
                "must exceed `contact.r_closed` = {:?} Ω: the open contact resistance, in Ω",
                c.r_closed
            ),
        )?;
        self.number(
            "contact.edge_time",
            c.edge_time,
            c.edge_time > 0.0,
            "must be > 0: the duration of each make or break edge, in s",
        )?;
        let Some(h) = &c.holm else {
            return Ok(());
        };
        self.number(
            "contact.holm.r_film",
            h.r_film,
            h.r_film >= 0.0,
            "must be >= 0: the film resistance that no force removes, in Ω",
        )?;
        self.number(
            "contact.holm.r_ref",
            h.r_ref,
            h.r_ref > 0.0,
            "must be > 0: the constriction resistance at `f_ref`, in Ω",
        )?;
        self.number(
            "contact.holm.f_ref",
            h.f_ref,
            h.f_ref > 0.0,
            "must be > 0: the contact force at which the constriction is `r_ref`, in N",
        )?;
        self.number(
            "contact.holm.exponent",
            h.exponent,
            h.exponent > 0.0 && h.exponent <= 1.0,
            "must be in (0, 1]: 0.5 for plastic contact spots, 1/3 (0.3333) for elastic",
        )
    }

    fn simulation(&self, s: &SimulationSection) -> Result<(), ScenarioError> {
        self.number(
            "simulation.t_end",
            s.t_end,
            s.t_end > 0.0,
            "must be > 0: the simulated horizon, in s",
        )?;
        self.number(
            "simulation.min_open_time",
            s.min_open_time,
            s.min_open_time >= 0.0,
            "must be ≥ 0: the shortest opening worth resolving, in s",
        )?;
        self.number(
            "simulation.min_gap",
            s.min_gap,
            s.min_gap >= 0.0,
            "must be ≥ 0: the smallest opening worth resolving, in m",
        )?;
        for (key, value) in [
            ("simulation.t_end", s.t_end),
            ("simulation.min_open_time", s.min_open_time),
            ("simulation.min_gap", s.min_gap),
        ] {
            self.envelope(key, Some(value))?;
        }
        Ok(())
    }

    fn circuit(&self, c: &CircuitSection) -> Result<(), ScenarioError> {
        self.not_empty(
            "circuit.netlist",
            &c.netlist.to_string_lossy(),
            "the netlist file, relative to the scenario file",
        )?;
        self.not_empty(
            "circuit.subckt",
            &c.subckt,
            "the subcircuit name the netlist uses for the contact",
        )?;
        self.not_empty(
            "circuit.coil_subckt",
            &c.coil_subckt,
            "the subcircuit name the netlist uses for the coil",
        )?;
        if let Some(nc) = &c.nc_subckt {
            self.not_empty(
                "circuit.nc_subckt",
                nc,
                "the subcircuit name the netlist uses for the normally-closed contact",
            )?;
            if nc.eq_ignore_ascii_case(&c.subckt) || nc.eq_ignore_ascii_case(&c.coil_subckt) {
                return Err(ScenarioError::Conflict {
                    at: self.at("circuit.nc_subckt"),
                    key: "circuit.nc_subckt".to_owned(),
                    other: "circuit.subckt".to_owned(),
                    advice: "the normally-closed contact needs a subcircuit name of its own, \
                             e.g. CONTACT_NC",
                });
            }
        }
        for (name, &value) in &c.params {
            let key = format!("{PARAMS_PREFIX}{name}");
            if !valid_param_name(name) {
                return Err(self.invalid(
                    &key,
                    value,
                    format!(
                        "`{name}` is not a SPICE parameter name: a letter or `_`, then \
                         letters, digits or `_`, as in the netlist's `.param`"
                    ),
                ));
            }
            self.number(&key, value, true, "")?;
        }
        Ok(())
    }

    fn probe(&self, i: usize, p: &Probe) -> Result<(), ScenarioError> {
        let key = |name: &str| format!("probe[{i}].{name}");
        self.not_empty(
            &key("signal"),
            &p.signal,
            "an ngspice vector name such as \"v(in)\"",
        )?;
        self.number(&key("high"), p.high, true, "")?;
        self.number(
            &key("low"),
            p.low,
            p.low < p.high,
            format!(
                "must be below `probe[{i}].high` = {:?} V: the Schmitt thresholds need low < high",
                p.high
            ),
        )?;
        if let Some(v) = p.max_peak {
            self.number(
                &key("max_peak"),
                v,
                v > 0.0,
                "must be > 0: the largest |value| allowed, in the signal's unit",
            )?;
        }
        if let Some(v) = p.max_last_edge {
            self.number(
                &key("max_last_edge"),
                v,
                v > 0.0,
                "must be > 0: the time by which the signal must have settled, in s",
            )?;
        }
        if let Some(v) = p.max_value {
            self.number(&key("max_value"), v, true, "")?;
        }
        if let Some(v) = p.min_value {
            let max = p.max_value.unwrap_or(f64::INFINITY);
            self.number(
                &key("min_value"),
                v,
                v < max,
                format!("must be below `probe[{i}].max_value` = {max:?}"),
            )?;
        }
        Ok(())
    }

    fn limits(&self, l: &LimitsSection) -> Result<(), ScenarioError> {
        for (key, value, what) in [
            (
                "limits.max_bounce_time",
                l.max_bounce_time,
                "the longest bounce time allowed (first make → closed for good), in s",
            ),
            (
                "limits.max_operate_time",
                l.max_operate_time,
                "the longest operate time allowed (coil on → first make), in s",
            ),
            (
                "limits.max_first_make",
                l.max_first_make,
                "the longest operate time allowed (coil on → first make), in s",
            ),
            (
                "limits.max_settle_time",
                l.max_settle_time,
                "the longest time allowed from coil on to closed for good, in s",
            ),
            (
                "limits.max_release_time",
                l.max_release_time,
                "the longest release time allowed (coil off → the NO contact breaks), in s",
            ),
            (
                "limits.max_nc_bounce_time",
                l.max_nc_bounce_time,
                "the longest NC bounce allowed after a release, in s",
            ),
            (
                "limits.max_arc_energy",
                l.max_arc_energy,
                "the most arc energy allowed in one operation, in J",
            ),
        ] {
            if let Some(v) = value {
                self.number(key, v, v > 0.0, format!("must be > 0: {what}"))?;
            }
        }
        Ok(())
    }

    /// `[arc]`: every number positive and within the envelope.
    fn arc(&self, a: &ArcSection) -> Result<(), ScenarioError> {
        for (key, value, ok, requirement) in [
            (
                "arc.v_min",
                a.v_min,
                a.v_min.is_some_and(|v| v > 0.0),
                "must be > 0: the minimum arc voltage, in V (silver: 12)",
            ),
            (
                "arc.i_min",
                a.i_min,
                a.i_min.is_some_and(|v| v > 0.0),
                "must be > 0: the minimum arc current, in A (silver: 0.4)",
            ),
            (
                "arc.field",
                a.field,
                a.field.is_some_and(|v| v >= 0.0),
                "must be ≥ 0: the arc column's voltage gradient, in V/m",
            ),
            (
                "arc.opening_speed",
                a.opening_speed,
                a.opening_speed.is_some_and(|v| v > 0.0),
                "must be > 0: how fast a measured record's contacts part, in m/s",
            ),
        ] {
            if let Some(v) = value {
                self.number(key, v, ok, requirement)?;
                self.envelope(key, value)?;
            }
        }
        Ok(())
    }

    /// The release limits need a coil: a step force never releases.
    fn release_limits(&self, l: &LimitsSection, coil: bool) -> Result<(), ScenarioError> {
        let given = [
            ("limits.max_release_time", l.max_release_time.is_some()),
            ("limits.max_nc_bounce_time", l.max_nc_bounce_time.is_some()),
            ("limits.max_nc_bounces", l.max_nc_bounces.is_some()),
        ];
        match given.iter().find(|(_, set)| *set) {
            Some((key, _)) if !coil => Err(ScenarioError::Conflict {
                at: self.at(key),
                key: (*key).to_owned(),
                other: "mechanics.force".to_owned(),
                advice: "a release needs a coil that is switched off: with a step force the \
                         contact never releases; give a [coil] or remove the limit",
            }),
            _ => Ok(()),
        }
    }
}

// ---------------------------------------------------------------------------
// `[sweep]` and setting single numbers: what `chatterspice sweep` varies.
// ---------------------------------------------------------------------------

/// `[sweep]`: a Monte Carlo or grid sweep over the scenario's numbers, for
/// `chatterspice sweep` (the sampling itself is [`crate::sweep`]).
///
/// ```toml
/// [sweep]
/// samples = 1000
/// seed = 7
/// [sweep.vary]
/// "mechanics.mass" = 0.1                # ±10 %, uniform
/// "surface.damping" = { normal = 0.05 } # σ = 5 %, normal
/// ```
/// or, instead of `vary`, a grid of one or two keys:
/// ```toml
/// [sweep.grid]
/// "mechanics.force" = { from = 0.5, to = 2.0, steps = 16 }
/// ```
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSection {
    /// Random samples to draw; `None` leaves it to the command line or
    /// the sweep's default. Not with `grid`, which runs all its points.
    pub samples: Option<u64>,
    /// Seed of the random draws; `None` leaves it to the command line or 0.
    pub seed: Option<u64>,
    /// Dotted number key (see [`NUMBER_KEYS`]) → its tolerance, sorted by key.
    #[serde(default)]
    pub vary: BTreeMap<String, Tolerance>,
    /// One or two dotted number keys → the values they step through; the
    /// first key (in sorted order) is the outer loop.
    #[serde(default)]
    pub grid: BTreeMap<String, GridAxis>,
}

/// How far one number varies around its value in the scenario (the
/// nominal), relative to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// `0.1` or `{ uniform = 0.1 }`: uniform within nominal·(1 ± 0.1).
    /// Must lie in (0, 1), so that the value keeps its sign.
    Uniform(f64),
    /// `{ normal = 0.05 }`: normal with mean nominal and σ = 5 % of it,
    /// truncated at ±4σ. σ must lie in (0, 0.25), so that the value keeps
    /// its sign.
    Normal(f64),
}

impl<'de> Deserialize<'de> for Tolerance {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::{self, MapAccess, Visitor};
        struct ToleranceVisitor;
        impl<'de> Visitor<'de> for ToleranceVisitor {
            type Value = Tolerance;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(
                    "a relative tolerance: a number (± uniform, 0.1 = ±10 %), \
                     { uniform = 0.1 } or { normal = 0.05 } (σ)",
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Tolerance, E> {
                Ok(Tolerance::Uniform(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Tolerance, E> {
                Ok(Tolerance::Uniform(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Tolerance, E> {
                Ok(Tolerance::Uniform(v as f64))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Tolerance, A::Error> {
                let mut found = None;
                while let Some(name) = map.next_key::<String>()? {
                    let value: f64 = map.next_value()?;
                    let tolerance = match name.as_str() {
                        "uniform" => Tolerance::Uniform(value),
                        "normal" => Tolerance::Normal(value),
                        // A custom message: serde's unknown-field error would be
                        // reported at the table, as if its key were the typo.
                        other => {
                            return Err(de::Error::custom(format!(
                                "`{other}` is not a distribution: give {{ uniform = r }} \
                                 or {{ normal = σ }}"
                            )));
                        }
                    };
                    if found.replace(tolerance).is_some() {
                        return Err(de::Error::custom(
                            "give one distribution: { uniform = r } or { normal = σ }, not both",
                        ));
                    }
                }
                found.ok_or_else(|| {
                    de::Error::custom("an empty table: give { uniform = r } or { normal = σ }")
                })
            }
        }
        deserializer.deserialize_any(ToleranceVisitor)
    }
}

/// One axis of `[sweep.grid]`: `steps` values from `from` to `to`, both
/// included, evenly spaced (geometrically with `log = true`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridAxis {
    pub from: f64,
    pub to: f64,
    pub steps: u32,
    /// Space the values geometrically (e.g. a stiffness over decades).
    #[serde(default)]
    pub log: bool,
}

impl GridAxis {
    /// The `j`-th value, `0 <= j < steps`; the ends are exact.
    pub fn value(&self, j: u32) -> f64 {
        if self.steps <= 1 || j == 0 {
            return self.from;
        }
        if j + 1 >= self.steps {
            return self.to;
        }
        let u = f64::from(j) / f64::from(self.steps - 1);
        if self.log {
            self.from * (self.to / self.from).powf(u)
        } else {
            self.from + (self.to - self.from) * u
        }
    }
}

/// The number keys that [`Scenario::set_number`] sets and `[sweep]`
/// varies, besides `probe[N].low` and `probe[N].high`. (`coil.turns` is an
/// integer and is left out.)
pub const NUMBER_KEYS: &[&str] = &[
    "mechanics.mass",
    "mechanics.stiffness",
    "mechanics.damping",
    "mechanics.force",
    "mechanics.gap",
    "mechanics.initial_position",
    "mechanics.initial_velocity",
    "mechanics.preload",
    "coil.resistance",
    "coil.pole_area",
    "coil.air_gap",
    "coil.iron_gap",
    "surface.stiffness",
    "surface.damping",
    "surface.restitution",
    "surface.exponent",
    "surface.chi",
    "surface.reference_velocity",
    "back_stop.stiffness",
    "back_stop.damping",
    "back_stop.restitution",
    "back_stop.exponent",
    "back_stop.chi",
    "back_stop.reference_velocity",
    "contact.r_closed",
    "contact.r_open",
    "contact.edge_time",
    "contact.holm.r_film",
    "contact.holm.r_ref",
    "contact.holm.f_ref",
    "contact.holm.exponent",
    "simulation.t_end",
    "simulation.min_open_time",
    "simulation.min_gap",
];

/// Every number key, for messages.
fn number_keys_described() -> String {
    let mut known = NUMBER_KEYS.join(", ");
    known.push_str(", probe[N].low, probe[N].high, circuit.params.NAME");
    known
}

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
            other => match probe_key(other) {
                Some((i, _)) if i >= s.probes.len() => Field::NoSection("[[probe]] of that number"),
                Some((i, true)) => Field::Plain($($r)* s.probes[i].low),
                Some((i, false)) => Field::Plain($($r)* s.probes[i].high),
                None => Field::Unknown,
            },
        }
    }};
}

/// The widest range of each number that still describes a relay, far
/// beyond any real one, so that every simulation stays finite and ends:
/// (key or key suffix, lowest, highest, unit). The other rules (> 0,
/// below the gap, ...) apply on top.
pub const ENVELOPE: &[(&str, f64, f64, &str)] = &[
    ("mechanics.mass", 0.0, 1e3, "kg"),
    ("mechanics.stiffness", 0.0, 1e12, "N/m"),
    ("mechanics.damping", 0.0, 1e9, "N·s/m"),
    ("mechanics.force", -1e9, 1e9, "N"),
    ("mechanics.gap", 0.0, 1.0, "m"),
    ("mechanics.initial_position", -1.0, 1.0, "m"),
    ("mechanics.initial_velocity", -1e4, 1e4, "m/s"),
    ("mechanics.preload", 0.0, 1e9, "N"),
    (".stiffness", 1e-6, 1e20, "N/m or N/mⁿ"),
    (".damping", 0.0, 1e12, "N·s/m"),
    (".chi", 0.0, 1e6, "s/m"),
    (".reference_velocity", 0.0, 1e4, "m/s"),
    ("simulation.t_end", 0.0, 1e6, "s"),
    ("simulation.min_open_time", 0.0, 1.0, "s"),
    ("simulation.min_gap", 0.0, 1.0, "m"),
    ("arc.v_min", 0.0, 1e4, "V"),
    ("arc.i_min", 0.0, 1e4, "A"),
    ("arc.field", 0.0, 1e8, "V/m"),
    ("arc.opening_speed", 0.0, 1e3, "m/s"),
];

/// Number keys under this prefix name a `.param` of the netlist.
const PARAMS_PREFIX: &str = "circuit.params.";

/// A SPICE parameter name: a letter or `_`, then letters, digits, `_`.
fn valid_param_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// `probe[N].low` → (N, true), `probe[N].high` → (N, false).
fn probe_key(key: &str) -> Option<(usize, bool)> {
    let rest = key.strip_prefix("probe[")?;
    let (index, name) = rest.split_once("].")?;
    let index = index.parse().ok()?;
    match name {
        "low" => Some((index, true)),
        "high" => Some((index, false)),
        _ => None,
    }
}

impl Scenario {
    /// The value of number `key` (one of [`NUMBER_KEYS`], or
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
    fn circuit_param(&self, key: &str, name: &str) -> Result<Option<f64>, ScenarioError> {
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
    fn revalidate(&self, probes: bool) -> Result<(Surface, Option<Surface>), ScenarioError> {
        let index = KeyIndex {
            text: "",
            document_span: 0..0,
            entries: Vec::new(),
        };
        let check = Check {
            origin: &self.origin,
            index: &index,
        };
        check.mechanics(&self.mechanics)?;
        check.drive(&self.mechanics, self.coil.as_ref())?;
        let surface = check.surface("surface", &self.surface)?;
        let back_stop = check.back_stop(self.back_stop.as_ref(), self.coil.is_some())?;
        check.contact(&self.contact)?;
        check.simulation(&self.simulation)?;
        if probes {
            for (i, probe) in self.probes.iter().enumerate() {
                check.probe(i, probe)?;
            }
        }
        Ok((surface, back_stop))
    }

    fn unknown_number(&self, key: &str, within: &'static str) -> ScenarioError {
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

    fn no_section(&self, key: &str, section: &'static str) -> ScenarioError {
        ScenarioError::Sweep {
            at: Location {
                path: self.origin.clone(),
                line: None,
            },
            key: key.to_owned(),
            problem: format!("the scenario has no {section} section: add it to set this key"),
        }
    }

    /// The `[sweep]` rules, which need the rest of the scenario (the
    /// nominal values the tolerances are relative to).
    fn with_checked_sweep(self, check: &Check) -> Result<Scenario, ScenarioError> {
        if let Some(sweep) = &self.sweep {
            check.sweep(sweep, &self)?;
        }
        Ok(self)
    }
}

impl Check<'_> {
    fn sweep_error(&self, key: &str, line_key: &str, problem: String) -> ScenarioError {
        ScenarioError::Sweep {
            at: self.at(line_key),
            key: key.to_owned(),
            problem,
        }
    }

    fn sweep(&self, sweep: &SweepSection, scenario: &Scenario) -> Result<(), ScenarioError> {
        if sweep.samples == Some(0) {
            return Err(self.invalid(
                "sweep.samples",
                0.0,
                "must be at least 1: the number of random samples",
            ));
        }
        if !sweep.grid.is_empty() {
            if !sweep.vary.is_empty() {
                return Err(ScenarioError::Conflict {
                    at: self.at("sweep.grid"),
                    key: "sweep.grid".to_owned(),
                    other: "sweep.vary".to_owned(),
                    advice: "a grid steps its keys instead of drawing random samples; \
                             keep [sweep.grid] or [sweep.vary], and sweep the other in a second run",
                });
            }
            if sweep.samples.is_some() {
                return Err(ScenarioError::Conflict {
                    at: self.at("sweep.samples"),
                    key: "sweep.samples".to_owned(),
                    other: "sweep.grid".to_owned(),
                    advice: "a grid runs each of its points once; remove `samples` \
                             (the number of points is the product of the `steps`)",
                });
            }
            if sweep.grid.len() > 2 {
                return Err(self.sweep_error(
                    "sweep.grid",
                    "sweep.grid",
                    format!(
                        "has {} keys; a grid steps one or two (for a plot against them): \
                         remove the others, or vary them with [sweep.vary] in another run",
                        sweep.grid.len()
                    ),
                ));
            }
        }
        for (key, tolerance) in &sweep.vary {
            let line_key = format!("sweep.vary.{key}");
            let nominal = self.sweep_nominal(key, &line_key, "[sweep.vary]", scenario)?;
            let shown = format!("sweep.vary.\"{key}\"");
            if nominal == 0.0 {
                return Err(self.sweep_error(
                    &shown,
                    &line_key,
                    format!(
                        "`{key}` is 0 in the scenario, and a tolerance relative to 0 \
                         varies nothing: step it with [sweep.grid] instead"
                    ),
                ));
            }
            let (value, ok, requirement) = match *tolerance {
                Tolerance::Uniform(r) => (
                    r,
                    r > 0.0 && r < 1.0,
                    "must lie in (0, 1): the relative half-width, 0.1 for ±10 %",
                ),
                Tolerance::Normal(sigma) => (
                    sigma,
                    sigma > 0.0 && sigma < 0.25,
                    "must lie in (0, 0.25): σ relative to the nominal value, 0.05 for 5 % \
                     (draws are kept within ±4σ, which must not reach 0)",
                ),
            };
            if !(value.is_finite() && ok) {
                return Err(ScenarioError::Invalid {
                    at: self.at(&line_key),
                    key: shown,
                    value,
                    requirement: requirement.to_owned(),
                });
            }
        }
        for (key, axis) in &sweep.grid {
            let line_key = format!("sweep.grid.{key}");
            self.sweep_nominal(key, &line_key, "[sweep.grid]", scenario)?;
            let shown = |field: &str| format!("sweep.grid.\"{key}\".{field}");
            if axis.steps == 0 {
                return Err(ScenarioError::Invalid {
                    at: self.at(&format!("{line_key}.steps")),
                    key: shown("steps"),
                    value: 0.0,
                    requirement: "must be at least 1: the number of values from `from` to `to`"
                        .to_owned(),
                });
            }
            for (field, value) in [("from", axis.from), ("to", axis.to)] {
                let field_line = format!("{line_key}.{field}");
                let log_ok = !axis.log || value > 0.0;
                if !(value.is_finite() && log_ok) {
                    return Err(ScenarioError::Invalid {
                        at: self.at(&field_line),
                        key: shown(field),
                        value,
                        requirement: if axis.log {
                            "must be a finite number > 0 on a `log = true` grid".to_owned()
                        } else {
                            "must be a finite number".to_owned()
                        },
                    });
                }
                // Each end on its own, the other keys nominal: a grid that
                // leaves the valid range fails here, not after hours.
                let mut probe = scenario.clone();
                if let Err(e) = probe.set_number(key, value) {
                    return Err(self.sweep_error(
                        &shown(field),
                        &field_line,
                        format!("{value:?} is not a valid `{key}`: {e}"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The scenario's value of a key named in `[sweep.*]`, which must be
    /// a number it has.
    fn sweep_nominal(
        &self,
        key: &str,
        line_key: &str,
        within: &'static str,
        scenario: &Scenario,
    ) -> Result<f64, ScenarioError> {
        let shown = format!("{}.\"{key}\"", &within[1..within.len() - 1]);
        match scenario.number(key) {
            Ok(Some(value)) => Ok(value),
            Ok(None) => Err(self.sweep_error(
                &shown,
                line_key,
                format!(
                    "the scenario gives no `{key}` to vary around (it is optional and not \
                     set, or not a key of this surface law): set it, or sweep another key"
                ),
            )),
            Err(ScenarioError::UnknownNumber { known, .. }) => Err(ScenarioError::UnknownNumber {
                at: self.at(line_key),
                key: key.to_owned(),
                within: if within == "[sweep.vary]" {
                    " (named in [sweep.vary])"
                } else {
                    " (named in [sweep.grid])"
                },
                known,
            }),
            Err(e) => Err(self.sweep_error(&shown, line_key, e.to_string())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ORIGIN: &str = "relays/test.toml";

    const VALID: &str = r#"[mechanics]
mass = 2.0e-4
stiffness = 800.0
damping = 0.04
force = 0.5
gap = 4.5e-4

[surface]
law = "kelvin-voigt"
stiffness = 8.0e4
damping = 0.37536

[circuit]
netlist = "net/input.cir"

[[probe]]
signal = "v(in)"
low = 0.99
high = 2.31
"#;

    const SURFACE: &str = "law = \"kelvin-voigt\"\nstiffness = 8.0e4\ndamping = 0.37536\n";

    fn parse(text: &str) -> Result<Scenario, ScenarioError> {
        Scenario::parse(text, Path::new(ORIGIN))
    }

    /// VALID with one piece of text replaced.
    fn edit(old: &str, new: &str) -> String {
        assert!(VALID.contains(old), "test edit `{old}` not in VALID");
        VALID.replacen(old, new, 1)
    }

    /// VALID with the body of [surface] replaced.
    fn with_surface(body: &str) -> String {
        edit(SURFACE, &format!("{body}\n"))
    }

    /// The text must fail on `key`, with a message naming the file and key.
    #[track_caller]
    fn fails_on(text: &str, key: &str) -> ScenarioError {
        let err = match parse(text) {
            Ok(_) => panic!("expected an error on `{key}`, but it parsed:\n{text}"),
            Err(e) => e,
        };
        let msg = err.to_string();
        assert_eq!(err.key(), Some(key), "wrong key in: {msg}");
        assert!(msg.contains(ORIGIN), "file not named in: {msg}");
        assert!(msg.contains(&format!("`{key}`")), "key not named in: {msg}");
        err
    }

    #[track_caller]
    fn line_of(err: &ScenarioError) -> Option<usize> {
        match err {
            ScenarioError::Syntax { at, .. }
            | ScenarioError::UnknownKey { at, .. }
            | ScenarioError::MissingKey { at, .. }
            | ScenarioError::BadValue { at, .. }
            | ScenarioError::Invalid { at, .. }
            | ScenarioError::Empty { at, .. }
            | ScenarioError::Conflict { at, .. }
            | ScenarioError::NotForLaw { at, .. }
            | ScenarioError::UnknownNumber { at, .. }
            | ScenarioError::Sweep { at, .. } => at.line,
            ScenarioError::Read { .. }
            | ScenarioError::CoilDriveUnsupported { .. }
            | ScenarioError::NetlistRead { .. } => None,
        }
    }

    #[test]
    fn the_netlist_is_read_from_beside_the_scenario_or_named_when_missing() {
        let dir = tempfile::tempdir().unwrap();
        let origin = dir.path().join("relay.toml");
        let s = Scenario::parse(VALID, &origin).unwrap();
        let err = s.netlist().unwrap().unwrap_err();
        assert_eq!(err.key(), Some("circuit.netlist"));
        assert!(err.to_string().contains("net/input.cir"), "{err}");

        std::fs::create_dir(dir.path().join("net")).unwrap();
        std::fs::write(dir.path().join("net/input.cir"), "title\n.end\n").unwrap();
        let (path, text) = s.netlist().unwrap().unwrap();
        assert_eq!(path, dir.path().join("net/input.cir"));
        assert_eq!(text, "title\n.end\n");

        let no_circuit = edit("[circuit]\nnetlist = \"net/input.cir\"\n", "");
        assert!(parse(&no_circuit).unwrap().netlist().is_none());
    }

    #[test]
    fn netlist_paths_are_folded_lexically() {
        for (given, folded) in [
            ("a/../b/c.cir", "b/c.cir"),
            ("./a/./c.cir", "a/c.cir"),
            ("../../c.cir", "../../c.cir"),
            ("a/../../c.cir", "../c.cir"),
            ("/x/../c.cir", "/c.cir"),
            ("/../c.cir", "/c.cir"),
        ] {
            assert_eq!(
                lexically_normal(Path::new(given)),
                Path::new(folded),
                "{given}"
            );
        }
    }

    #[test]
    fn the_builtin_default_carries_its_netlist() {
        let (path, text) = Scenario::builtin_default().netlist().unwrap().unwrap();
        assert!(
            path.ends_with("netlists/mcu_input.cir"),
            "{}",
            path.display()
        );
        assert_eq!(text, DEFAULT_NETLIST);
        assert!(text.contains(" CONTACT"));
    }

    #[test]
    fn valid_file_converts_to_library_types() {
        let s = parse(VALID).unwrap();
        let m = s.mechanics().unwrap();
        assert_eq!(m.mass, 2.0e-4);
        assert_eq!(m.force, 0.5);
        assert_eq!(m.gap, 4.5e-4);
        assert_eq!(
            s.surface(),
            Surface::KelvinVoigt {
                stiffness: 8.0e4,
                damping: 0.37536
            }
        );
        assert_eq!(s.probes.len(), 1);
        assert_eq!(s.probes[0].signal, "v(in)");
    }

    #[test]
    fn optional_keys_take_their_documented_defaults() {
        let s = parse(VALID).unwrap();
        let m = s.mechanics().unwrap();
        assert_eq!(
            (m.initial_position, m.initial_velocity, m.preload),
            (0.0, 0.0, 0.0)
        );
        assert_eq!(s.contact, ContactSection::default());
        assert_eq!(
            (s.contact.r_closed, s.contact.r_open, s.contact.edge_time),
            (0.05, 1e9, 1e-8)
        );
        assert_eq!(s.settings(), Settings::default());
        assert_eq!(
            (
                s.simulation.t_end,
                s.simulation.min_open_time,
                s.simulation.min_gap
            ),
            (0.02, 1e-9, 1e-9)
        );
        let c = s.circuit.unwrap();
        assert_eq!(
            (c.subckt.as_str(), c.coil_subckt.as_str()),
            ("CONTACT", "COIL")
        );
    }

    #[test]
    fn sections_other_than_mechanics_and_surface_are_optional() {
        let text = VALID.split("[circuit]").next().unwrap();
        let s = parse(text).unwrap();
        assert!(s.circuit.is_none());
        assert!(s.probes.is_empty());
    }

    #[test]
    fn explicit_settings_are_used() {
        let text =
            format!("{VALID}\n[simulation]\nt_end = 0.005\nmin_open_time = 0.0\nmin_gap = 1e-12\n");
        let s = parse(&text).unwrap().settings();
        assert_eq!((s.t_end, s.min_open_time, s.min_gap), (0.005, 0.0, 1e-12));
    }

    #[test]
    fn integers_are_accepted_where_numbers_are_expected() {
        let s = parse(&edit("stiffness = 800.0", "stiffness = 800")).unwrap();
        assert_eq!(s.mechanics.stiffness, 800.0);
    }

    #[test]
    fn netlist_resolves_against_the_scenario_directory() {
        let s = parse(VALID).unwrap();
        assert_eq!(
            s.circuit.unwrap().netlist,
            Path::new("relays").join("net/input.cir")
        );
        let abs = edit("\"net/input.cir\"", "\"/opt/net.cir\"");
        assert_eq!(
            parse(&abs).unwrap().circuit.unwrap().netlist,
            Path::new("/opt/net.cir")
        );
    }

    #[test]
    fn builtin_default_is_the_documented_relay() {
        let s = Scenario::builtin_default();
        let m = s.mechanics().unwrap();
        // What the file promises: a signal relay that bounces several
        // times for about a millisecond (datasheets: typ. 1 ms, ≤ 5 ms).
        assert!(matches!(s.surface(), Surface::KelvinVoigt { .. }));
        let c = crate::simulate(&m, &s.surface(), &s.settings()).unwrap();
        assert_eq!(c.outcome, crate::Outcome::Stuck);
        assert!((3..=8).contains(&c.bounce_count), "{}", c.bounce_count);
        let bounce_time = c.settle_time.unwrap() - c.first_impact.unwrap();
        assert!((0.5e-3..3e-3).contains(&bounce_time), "{bounce_time}");
        assert_eq!(s.settings().t_end, 0.02);
        let netlist = s.circuit.unwrap().netlist;
        assert_eq!(
            netlist,
            Path::new(env!("CARGO_MANIFEST_DIR")).join("netlists/mcu_input.cir")
        );
        assert!(netlist.is_file(), "{netlist:?}");
        assert_eq!(s.probes, vec![Probe::new("v(in)", 0.99, 2.31)]);
    }

    #[test]
    fn example_scenarios_parse() {
        let examples = [
            ("rigid", include_str!("../examples/scenarios/rigid.toml")),
            (
                "kelvin-voigt",
                include_str!("../examples/scenarios/kelvin-voigt.toml"),
            ),
            (
                "hunt-crossley",
                include_str!("../examples/scenarios/hunt-crossley.toml"),
            ),
        ];
        for (law, text) in examples {
            let s = Scenario::parse(text, Path::new("examples/scenarios/x.toml"))
                .unwrap_or_else(|e| panic!("{law}: {e}"));
            assert_eq!(s.surface.law.as_str(), law);
        }
    }

    // Shape errors: syntax, typos, missing keys, wrong kinds of value.

    #[test]
    fn syntax_error_names_the_line() {
        let err = parse(&edit("gap = 4.5e-4", "gap = = 4.5e-4")).unwrap_err();
        assert!(matches!(err, ScenarioError::Syntax { .. }), "{err:?}");
        assert_eq!(line_of(&err), Some(6));
        assert!(err.to_string().starts_with("relays/test.toml:6:"), "{err}");
    }

    #[test]
    fn misspelt_key_is_an_error_naming_key_and_line() {
        let err = fails_on(&edit("mass = 2.0e-4", "mas = 2.0e-4"), "mechanics.mas");
        assert!(matches!(err, ScenarioError::UnknownKey { .. }));
        assert_eq!(line_of(&err), Some(2));
        assert!(
            err.to_string().contains("`mass`"),
            "suggests the valid keys: {err}"
        );
    }

    #[test]
    fn unknown_section_and_unknown_probe_key_are_errors() {
        fails_on(&format!("{VALID}\n[mechancis]\nmass = 1.0\n"), "mechancis");
        let err = fails_on(
            &edit("high = 2.31", "high = 2.31\nhigh_v = 3"),
            "probe[0].high_v",
        );
        assert_eq!(line_of(&err), Some(20));
    }

    #[test]
    fn missing_required_keys_are_named() {
        let err = fails_on(&edit("mass = 2.0e-4\n", ""), "mechanics.mass");
        assert!(matches!(err, ScenarioError::MissingKey { .. }));
        fails_on(&edit("damping = 0.04\n", ""), "mechanics.damping");
        fails_on(&edit("gap = 4.5e-4\n", ""), "mechanics.gap");
        fails_on(&edit("law = \"kelvin-voigt\"\n", ""), "surface.law");
        fails_on(&edit("low = 0.99\n", ""), "probe[0].low");
        fails_on(
            &edit("netlist = \"net/input.cir\"\n", ""),
            "circuit.netlist",
        );
        let no_surface = edit(&format!("[surface]\n{SURFACE}"), "");
        fails_on(&no_surface, "surface");
    }

    #[test]
    fn wrong_kind_of_value_is_named() {
        let err = fails_on(&edit("mass = 2.0e-4", "mass = \"heavy\""), "mechanics.mass");
        assert!(matches!(err, ScenarioError::BadValue { .. }));
        assert_eq!(line_of(&err), Some(2));
    }

    #[test]
    fn unknown_surface_law_lists_the_laws() {
        let err = fails_on(
            &with_surface("law = \"hertz\"\nstiffness = 1.0"),
            "surface.law",
        );
        let msg = err.to_string();
        assert!(
            msg.contains("hunt-crossley") && msg.contains("rigid"),
            "{msg}"
        );
    }

    // Physics: every rule.

    #[test]
    fn mechanics_rules() {
        let cases = [
            ("mass = 2.0e-4", "mass = -2.0e-4", "mechanics.mass"),
            ("mass = 2.0e-4", "mass = 0.0", "mechanics.mass"),
            ("mass = 2.0e-4", "mass = nan", "mechanics.mass"),
            ("mass = 2.0e-4", "mass = inf", "mechanics.mass"),
            (
                "stiffness = 800.0",
                "stiffness = 0.0",
                "mechanics.stiffness",
            ),
            (
                "stiffness = 800.0",
                "stiffness = -inf",
                "mechanics.stiffness",
            ),
            ("damping = 0.04", "damping = -0.01", "mechanics.damping"),
            ("gap = 4.5e-4", "gap = 0.0", "mechanics.gap"),
            ("force = 0.5", "force = nan", "mechanics.force"),
            ("force = 0.5", "force = 0.0", "mechanics.force"),
            (
                "gap = 4.5e-4",
                "gap = 4.5e-4\ninitial_position = 4.5e-4",
                "mechanics.initial_position",
            ),
            (
                "gap = 4.5e-4",
                "gap = 4.5e-4\ninitial_velocity = inf",
                "mechanics.initial_velocity",
            ),
            (
                "gap = 4.5e-4",
                "gap = 4.5e-4\npreload = -0.1",
                "mechanics.preload",
            ),
            (
                "gap = 4.5e-4",
                "gap = 4.5e-4\npreload = 0.5",
                "mechanics.force",
            ),
        ];
        for (old, new, key) in cases {
            fails_on(&edit(old, new), key);
        }
        let err = fails_on(&edit("mass = 2.0e-4", "mass = nan"), "mechanics.mass");
        assert!(err.to_string().contains("finite"), "{err}");
        assert_eq!(line_of(&err), Some(2));
    }

    #[test]
    fn a_zero_damping_and_a_negative_start_are_allowed() {
        let text = edit("damping = 0.04", "damping = 0.0\ninitial_position = -1e-4");
        assert!(parse(&text).is_ok());
    }

    const COIL: &str = "\n[coil]\nresistance = 70.0\nturns = 3000\npole_area = 2.0e-5\nair_gap = 6.0e-4\niron_gap = 5.0e-5\n";

    #[test]
    fn force_and_coil_are_mutually_exclusive_and_one_is_required() {
        let err = fails_on(&format!("{VALID}{COIL}"), "mechanics.force");
        assert!(matches!(err, ScenarioError::Conflict { .. }), "{err:?}");
        let err = fails_on(&edit("force = 0.5\n", ""), "mechanics.force");
        assert!(matches!(err, ScenarioError::MissingKey { .. }), "{err:?}");
    }

    #[test]
    fn coil_scenario_parses_but_is_not_simulated_yet() {
        let s = parse(&format!("{}{COIL}", edit("force = 0.5\n", ""))).unwrap();
        assert_eq!(s.coil.as_ref().unwrap().turns, 3000);
        let err = s.mechanics().unwrap_err();
        assert!(matches!(err, ScenarioError::CoilDriveUnsupported { .. }));
        assert!(err.to_string().contains("mechanics.force"), "{err}");
    }

    #[test]
    fn a_back_stop_has_a_surface_law_of_its_own_and_needs_a_coil() {
        let coil = format!("{}{COIL}", edit("force = 0.5\n", ""));
        let back = "\n[back_stop]\nlaw = \"rigid\"\nrestitution = 0.4\n";
        let mut s = parse(&format!("{coil}{back}")).unwrap();
        assert_eq!(s.back_stop(), Some(Surface::Rigid { restitution: 0.4 }));
        assert_eq!(parse(&coil).unwrap().back_stop(), None);
        // Its keys are named as its own, and settable for sweeps.
        fails_on(
            &format!("{coil}{}", back.replace("0.4", "1.5")),
            "back_stop.restitution",
        );
        fails_on(&format!("{coil}{back}damping = 1.0\n"), "back_stop.damping");
        s.set_number("back_stop.restitution", 0.2).unwrap();
        assert_eq!(s.back_stop(), Some(Surface::Rigid { restitution: 0.2 }));
        assert!(s.set_number("back_stop.restitution", 2.0).is_err());
        assert_eq!(s.back_stop(), Some(Surface::Rigid { restitution: 0.2 }));
        // A step force never releases: a back stop or a release limit
        // without a coil is refused, naming what to change.
        let err = fails_on(&format!("{VALID}{back}"), "back_stop");
        assert!(err.to_string().contains("[coil]"), "{err}");
        fails_on(
            &format!("{VALID}\n[limits]\nmax_release_time = 1e-3\n"),
            "limits.max_release_time",
        );
        // So is a normally-closed contact in the circuit; with a coil it
        // needs a name of its own.
        let nc = "netlist = \"net/input.cir\"\nnc_subckt = \"CONTACT_NC\"\n";
        fails_on(
            &VALID.replace("netlist = \"net/input.cir\"\n", nc),
            "circuit.nc_subckt",
        );
        let with_nc = coil.replace("netlist = \"net/input.cir\"\n", nc);
        assert_eq!(
            parse(&with_nc)
                .unwrap()
                .circuit
                .unwrap()
                .nc_subckt
                .as_deref(),
            Some("CONTACT_NC")
        );
        fails_on(
            &with_nc.replace("\"CONTACT_NC\"", "\"contact\""),
            "circuit.nc_subckt",
        );
        let limits = "\n[limits]\nmax_release_time = 1e-3\nmax_nc_bounces = 3\n";
        let s = parse(&format!("{coil}{limits}")).unwrap();
        assert_eq!(s.limits.unwrap().max_nc_bounces, Some(3));
    }

    #[test]
    fn coil_rules() {
        let base = format!("{}{COIL}", edit("force = 0.5\n", ""));
        let cases = [
            ("resistance = 70.0", "resistance = 0.0", "coil.resistance"),
            ("turns = 3000", "turns = 0", "coil.turns"),
            ("turns = 3000", "turns = -3", "coil.turns"),
            ("pole_area = 2.0e-5", "pole_area = nan", "coil.pole_area"),
            ("air_gap = 6.0e-4", "air_gap = 4.0e-4", "coil.air_gap"),
            ("iron_gap = 5.0e-5", "iron_gap = -1e-6", "coil.iron_gap"),
        ];
        for (old, new, key) in cases {
            assert!(base.contains(old));
            fails_on(&base.replacen(old, new, 1), key);
        }
    }

    #[test]
    fn rigid_surface_rules() {
        let s = parse(&with_surface("law = \"rigid\"\nrestitution = 0.8")).unwrap();
        assert_eq!(s.surface(), Surface::Rigid { restitution: 0.8 });
        for e in ["0.0", "1.0"] {
            assert!(
                parse(&with_surface(&format!(
                    "law = \"rigid\"\nrestitution = {e}"
                )))
                .is_ok()
            );
        }
        fails_on(
            &with_surface("law = \"rigid\"\nrestitution = 1.5"),
            "surface.restitution",
        );
        fails_on(
            &with_surface("law = \"rigid\"\nrestitution = -0.1"),
            "surface.restitution",
        );
        fails_on(&with_surface("law = \"rigid\""), "surface.restitution");
        let err = fails_on(
            &with_surface("law = \"rigid\"\nrestitution = 0.8\nstiffness = 1e5"),
            "surface.stiffness",
        );
        assert!(matches!(err, ScenarioError::NotForLaw { .. }), "{err:?}");
    }

    #[test]
    fn kelvin_voigt_surface_rules() {
        let kv = |body: &str| with_surface(&format!("law = \"kelvin-voigt\"\n{body}"));
        assert!(parse(&kv("stiffness = 1e5\ndamping = 0.0")).is_ok());
        fails_on(&kv("stiffness = 0.0\ndamping = 0.3"), "surface.stiffness");
        fails_on(&kv("stiffness = 1e5\ndamping = -0.3"), "surface.damping");
        fails_on(&kv("damping = 0.3"), "surface.stiffness");
        fails_on(&kv("stiffness = 1e5"), "surface.damping");
        let err = fails_on(
            &kv("stiffness = 1e5\ndamping = 0.3\nrestitution = 0.8"),
            "surface.restitution",
        );
        assert!(err.to_string().contains("kelvin-voigt"), "{err}");
        fails_on(
            &kv("stiffness = 1e5\ndamping = 0.3\nchi = 0.1"),
            "surface.chi",
        );
    }

    #[test]
    fn hunt_crossley_surface_rules() {
        let hc =
            |body: &str| with_surface(&format!("law = \"hunt-crossley\"\nstiffness = 1e6\n{body}"));
        let s = parse(&hc("chi = 0.2")).unwrap();
        assert_eq!(
            s.surface(),
            Surface::HuntCrossley {
                stiffness: 1e6,
                exponent: 1.0,
                chi: 0.2
            }
        );
        let s = parse(&hc(
            "exponent = 1.5\nrestitution = 0.85\nreference_velocity = 0.3",
        ))
        .unwrap();
        let expected_chi = hunt_crossley_chi(0.85, 0.3).unwrap();
        assert_eq!(
            s.surface(),
            Surface::HuntCrossley {
                stiffness: 1e6,
                exponent: 1.5,
                chi: expected_chi
            }
        );
        assert!(parse(&hc("chi = 0.0")).is_ok());
        assert!(parse(&hc("restitution = 1.0\nreference_velocity = 0.3")).is_ok());

        fails_on(
            &with_surface("law = \"hunt-crossley\"\nstiffness = -1.0\nchi = 0.2"),
            "surface.stiffness",
        );
        fails_on(
            &with_surface("law = \"hunt-crossley\"\nchi = 0.2"),
            "surface.stiffness",
        );
        fails_on(&hc("chi = 0.2\nexponent = 0.0"), "surface.exponent");
        fails_on(&hc("chi = -0.2"), "surface.chi");
        fails_on(&hc("chi = nan"), "surface.chi");
        let err = fails_on(&hc("chi = 0.2\nrestitution = 0.8"), "surface.chi");
        assert!(matches!(err, ScenarioError::Conflict { .. }), "{err:?}");
        fails_on(&hc("chi = 0.2\nreference_velocity = 0.3"), "surface.chi");
        fails_on(&hc("restitution = 0.8"), "surface.reference_velocity");
        fails_on(&hc("reference_velocity = 0.3"), "surface.restitution");
        fails_on(&hc(""), "surface.chi");
        fails_on(
            &hc("restitution = 0.0\nreference_velocity = 0.3"),
            "surface.restitution",
        );
        fails_on(
            &hc("restitution = 1.5\nreference_velocity = 0.3"),
            "surface.restitution",
        );
        fails_on(
            &hc("restitution = 0.8\nreference_velocity = 0.0"),
            "surface.reference_velocity",
        );
        fails_on(&hc("chi = 0.2\ndamping = 0.1"), "surface.damping");
    }

    #[test]
    fn contact_rules() {
        let with = |body: &str| format!("{VALID}\n[contact]\n{body}\n");
        assert!(parse(&with("r_closed = 0.1")).is_ok());
        fails_on(&with("r_closed = 0.0"), "contact.r_closed");
        fails_on(&with("r_closed = 10.0\nr_open = 10.0"), "contact.r_open");
        fails_on(&with("r_open = inf"), "contact.r_open");
        fails_on(&with("edge_time = 0.0"), "contact.edge_time");

        let holm = |body: &str| format!("{VALID}\n[contact.holm]\n{body}\n");
        let s = parse(&holm("r_ref = 0.04\nf_ref = 1.0")).unwrap();
        assert_eq!(
            s.contact.holm,
            Some(HolmSection {
                r_film: 0.0,
                r_ref: 0.04,
                f_ref: 1.0,
                exponent: 0.5
            })
        );
        fails_on(&holm("r_ref = 0.0\nf_ref = 1.0"), "contact.holm.r_ref");
        fails_on(&holm("r_ref = 0.04\nf_ref = -1.0"), "contact.holm.f_ref");
        fails_on(
            &holm("r_ref = 0.04\nf_ref = 1.0\nr_film = -0.01"),
            "contact.holm.r_film",
        );
        fails_on(
            &holm("r_ref = 0.04\nf_ref = 1.0\nexponent = 2.0"),
            "contact.holm.exponent",
        );
        fails_on(
            &holm("r_ref = 0.04\nf_ref = 1.0\nfilm = 0.01"),
            "contact.holm.film",
        );
    }

    #[test]
    fn simulation_rules() {
        let with = |body: &str| format!("{VALID}\n[simulation]\n{body}\n");
        fails_on(&with("t_end = 0.0"), "simulation.t_end");
        fails_on(&with("t_end = inf"), "simulation.t_end");
        fails_on(&with("min_open_time = -1e-9"), "simulation.min_open_time");
        fails_on(&with("min_gap = -1e-9"), "simulation.min_gap");
    }

    #[test]
    fn circuit_and_probe_rules() {
        fails_on(
            &edit("netlist = \"net/input.cir\"", "netlist = \"\""),
            "circuit.netlist",
        );
        fails_on(
            &edit(
                "netlist = \"net/input.cir\"",
                "netlist = \"a.cir\"\nsubckt = \"\"",
            ),
            "circuit.subckt",
        );
        fails_on(
            &edit("signal = \"v(in)\"", "signal = \" \""),
            "probe[0].signal",
        );
        let err = fails_on(&edit("low = 0.99", "low = 2.31"), "probe[0].low");
        assert_eq!(line_of(&err), Some(18));
        fails_on(&edit("high = 2.31", "high = nan"), "probe[0].high");
        let second = format!("{VALID}\n[[probe]]\nsignal = \"v(out)\"\nlow = 3.0\nhigh = 1.0\n");
        let err = fails_on(&second, "probe[1].low");
        assert_eq!(line_of(&err), Some(23));
    }

    #[test]
    fn missing_file_names_the_path() {
        let err = Scenario::load(Path::new("no/such/scenario.toml")).unwrap_err();
        assert!(matches!(err, ScenarioError::Read { .. }));
        assert!(err.to_string().contains("no/such/scenario.toml"), "{err}");
    }
    // [sweep] and set_number.

    #[test]
    fn set_number_sets_and_validates_by_the_loader_s_rules() {
        let mut s = parse(VALID).unwrap();
        s.set_number("mechanics.mass", 3.0e-4).unwrap();
        assert_eq!(s.mechanics().unwrap().mass, 3.0e-4);
        assert_eq!(s.number("mechanics.mass").unwrap(), Some(3.0e-4));
        s.set_number("surface.stiffness", 9.0e4).unwrap();
        assert!(
            matches!(s.surface(), Surface::KelvinVoigt { stiffness, .. } if stiffness == 9.0e4)
        );
        s.set_number("probe[0].low", 1.2).unwrap();
        assert_eq!(s.probes[0].low, 1.2);

        let before = s.clone();
        let err = s.set_number("mechanics.mass", -1.0).unwrap_err();
        assert_eq!(err.key(), Some("mechanics.mass"));
        let err = s.set_number("probe[0].low", 5.0).unwrap_err();
        assert_eq!(err.key(), Some("probe[0].low"));
        let err = s.set_number("surface.restitution", 0.5).unwrap_err();
        assert!(matches!(err, ScenarioError::NotForLaw { .. }), "{err:?}");
        assert_eq!(s, before, "a failed set leaves the scenario as it was");

        // Together valid, one at a time not.
        s.set_numbers(&[("contact.r_open", 20.0), ("contact.r_closed", 10.0)])
            .unwrap();
        assert!(s.set_number("contact.r_closed", 30.0).is_err());
    }

    #[test]
    fn set_number_converts_a_hunt_crossley_restitution_again() {
        let text = with_surface(
            "law = \"hunt-crossley\"\nstiffness = 1e6\nrestitution = 0.85\nreference_velocity = 0.3",
        );
        let mut s = parse(&text).unwrap();
        s.set_number("surface.restitution", 0.6).unwrap();
        let chi = hunt_crossley_chi(0.6, 0.3).unwrap();
        assert!(matches!(s.surface(), Surface::HuntCrossley { chi: c, .. } if c == chi));
    }

    #[test]
    fn set_number_names_unknown_keys_and_missing_sections() {
        let mut s = parse(VALID).unwrap();
        let err = s.set_number("mechanics.mas", 1.0).unwrap_err();
        assert!(
            matches!(err, ScenarioError::UnknownNumber { .. }),
            "{err:?}"
        );
        let msg = err.to_string();
        assert!(
            msg.contains("`mechanics.mas`") && msg.contains("mechanics.mass"),
            "{msg}"
        );
        assert!(s.set_number("coil.resistance", 1.0).is_err());
        assert!(s.set_number("contact.holm.r_ref", 1.0).is_err());
        assert!(s.set_number("probe[3].low", 1.0).is_err());
        assert!(s.number("surface.restitution").unwrap().is_none());
    }

    #[test]
    fn every_number_key_reads_back_what_was_set() {
        let text = format!("{VALID}\n[contact.holm]\nr_ref = 0.04\nf_ref = 1.0\n");
        let s = parse(&text).unwrap();
        for key in NUMBER_KEYS {
            let Ok(Some(value)) = s.number(key) else {
                continue;
            };
            let mut t = s.clone();
            let new = if value == 0.0 { 1e-12 } else { value * 1.001 };
            t.set_number(key, new)
                .unwrap_or_else(|e| panic!("{key}: {e}"));
            assert_eq!(t.number(key).unwrap(), Some(new), "{key}");
        }
    }

    #[test]
    fn sweep_section_parses() {
        let text = format!(
            "{VALID}\n[sweep]\nsamples = 50\nseed = 7\n[sweep.vary]\n\"mechanics.mass\" = 0.1\n\
             \"surface.damping\" = {{ normal = 0.05 }}\n\"mechanics.force\" = {{ uniform = 0.2 }}\n"
        );
        let sweep = parse(&text).unwrap().sweep.unwrap();
        assert_eq!((sweep.samples, sweep.seed), (Some(50), Some(7)));
        let vary: Vec<_> = sweep.vary.iter().map(|(k, t)| (k.as_str(), *t)).collect();
        assert_eq!(
            vary,
            [
                ("mechanics.force", Tolerance::Uniform(0.2)),
                ("mechanics.mass", Tolerance::Uniform(0.1)),
                ("surface.damping", Tolerance::Normal(0.05)),
            ]
        );
        let grid = format!(
            "{VALID}\n[sweep.grid]\n\"mechanics.force\" = {{ from = 0.5, to = 2.0, steps = 4 }}\n"
        );
        let axis = parse(&grid).unwrap().sweep.unwrap().grid["mechanics.force"];
        let values: Vec<f64> = (0..4).map(|j| axis.value(j)).collect();
        assert_eq!(values, [0.5, 1.0, 1.5, 2.0]);
        let log = GridAxis {
            from: 1.0,
            to: 100.0,
            steps: 3,
            log: true,
        };
        assert!((log.value(1) - 10.0).abs() < 1e-12);
        assert_eq!(log.value(2), 100.0);
    }

    #[test]
    fn sweep_rules() {
        let with = |body: &str| format!("{VALID}\n{body}\n");
        let err = fails_on(
            &with("[sweep.vary]\n\"mechanics.mas\" = 0.1"),
            "mechanics.mas",
        );
        assert!(
            matches!(err, ScenarioError::UnknownNumber { .. }),
            "{err:?}"
        );
        assert_eq!(line_of(&err), Some(22));
        let msg = err.to_string();
        assert!(
            msg.contains("[sweep.vary]") && msg.contains("surface.damping"),
            "{msg}"
        );
        fails_on(
            &with("[sweep.grid]\n\"bogus\" = { from = 1, to = 2, steps = 2 }"),
            "bogus",
        );
        fails_on(
            &with("[sweep.vary]\n\"mechanics.mass\" = 1.5"),
            "sweep.vary.\"mechanics.mass\"",
        );
        fails_on(
            &with("[sweep.vary]\n\"mechanics.mass\" = { normal = 0.3 }"),
            "sweep.vary.\"mechanics.mass\"",
        );
        fails_on(
            &with("[sweep.vary]\n\"mechanics.mass\" = { sigma = 0.3 }"),
            "sweep.vary.mechanics.mass",
        );
        fails_on(
            &with("[sweep.vary]\n\"mechanics.preload\" = 0.1"),
            "sweep.vary.\"mechanics.preload\"",
        );
        fails_on(
            &with("[sweep.vary]\n\"surface.restitution\" = 0.1"),
            "sweep.vary.\"surface.restitution\"",
        );
        fails_on(&with("[sweep]\nsamples = 0"), "sweep.samples");
        fails_on(
            &with(
                "[sweep.vary]\n\"mechanics.mass\" = 0.1\n[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 2.0, steps = 4 }",
            ),
            "sweep.grid",
        );
        fails_on(
            &with(
                "[sweep]\nsamples = 3\n[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 2.0, steps = 4 }",
            ),
            "sweep.samples",
        );
        fails_on(
            &with("[sweep.grid]\n\"mechanics.force\" = { from = -0.5, to = 2.0, steps = 4 }"),
            "sweep.grid.\"mechanics.force\".from",
        );
        fails_on(
            &with("[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 2.0, steps = 0 }"),
            "sweep.grid.\"mechanics.force\".steps",
        );
        fails_on(
            &with(
                "[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 2.0, steps = 4 }\n\
                 \"mechanics.mass\" = { from = 1e-4, to = 2e-4, steps = 2 }\n\
                 \"mechanics.gap\" = { from = 1e-4, to = 2e-4, steps = 2 }",
            ),
            "sweep.grid",
        );
    }
}
