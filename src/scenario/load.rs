//! Loading a scenario: [`Scenario::load`] and [`Scenario::parse`] (TOML
//! syntax, then shape, then physics, with the bases merged in), and the
//! built-in scenario ([`Scenario::builtin_default`]).

use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::de::DeTable;

use super::base::{self, lexically_normal};
use super::builtin::{
    DEFAULT_NETLIST, DEFAULT_NETLIST_NAME, DEFAULT_SCENARIO_ORIGIN, DEFAULT_SCENARIO_TOML,
    builtin_netlist,
};
use super::check::Check;
use super::circuit::CircuitSection;
use super::document::Document;
use super::error::{Location, ScenarioError};
use super::keys::{KeyIndex, duplicate_message, line_column};
use super::model::Scenario;

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
        let own = tree.get_ref();
        if own.get("base").is_none() && own.get("unset").is_none() {
            return Scenario::parse_tree(tree, text, origin);
        }
        let Some(expanded) = base::expand(text, origin)? else {
            return Scenario::parse_tree(tree, text, origin);
        };
        let merged = &expanded.text;
        let scenario = syntax(merged, origin)
            .and_then(|tree| Scenario::parse_tree(tree, merged, origin))
            .map_err(|e| expanded.relocate(e))?;
        Ok(scenario)
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
            netlist: match builtin_netlist(origin, &c.netlist.to_string_lossy()) {
                Some(name) => PathBuf::from(name),
                None => lexically_normal(&base.join(&c.netlist)),
            },
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
        .with_builtin_netlist()
        .with_checked_sweep(&check)
    }

    /// The built-in scenario (`scenarios/default.toml`, compiled in): a
    /// small signal relay with a Kelvin–Voigt contact switching an MCU
    /// input.
    pub fn builtin_default() -> Scenario {
        // The unit tests parse it, so a broken file never ships.
        Scenario::parse(DEFAULT_SCENARIO_TOML, Path::new(DEFAULT_SCENARIO_ORIGIN))
            .expect("the built-in scenario is valid")
    }

    /// A circuit that is the built-in one keeps its compiled-in text, so
    /// that it runs wherever the binary is.
    fn with_builtin_netlist(self) -> Scenario {
        let embedded = self
            .circuit
            .as_ref()
            .filter(|c| c.netlist == Path::new(DEFAULT_NETLIST_NAME))
            .map(|_| DEFAULT_NETLIST);
        Scenario {
            embedded_netlist: embedded,
            ..self
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
