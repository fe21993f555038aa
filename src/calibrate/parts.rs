//! Bundled relay parts: one scenario per common class of relay, each
//! fitted (`chatterspice fit`, datasheet figures only) to the figures its
//! manufacturer's datasheet prints, with the `[provenance]` of that fit.
//!
//! A datasheet prints the coil (voltage, resistance), pick-up and drop-out
//! voltages and operate/release times; it does not print the armature's
//! mass, travel or magnet geometry, nor the contact blade and the
//! overtravel to the pole face every part has (docs/model.md §11). Those
//! are generic assumptions of each part's prior (`parts/priors/`), from the
//! class ranges of small relays, and the fit moves the preload, the
//! spring stiffness and (when an operate time is printed) the mass until
//! the figures are met. The pick-up is computed over the armature's whole
//! load line ([`crate::coil::pick_up`]), and each part's `[provenance]`
//! says where it binds. The parts are regenerated with
//! `scripts/fit-parts`.

use std::path::Path;

use std::collections::BTreeMap;

use serde::Serialize;
use thiserror::Error;

use super::fit::{datasheet_figures, pick_up_of};
use super::printed::{printed_text, unit_of};
use crate::report::units::engineering;
use crate::scenario::{PrintedFigure, Scenario, ScenarioError, bundled_part_text};

/// No bundled part of that name.
#[derive(Debug, Error)]
#[error("no bundled part `{name}`; the parts are: {known}")]
pub struct UnknownPart {
    /// The name asked for.
    pub name: String,
    /// The bundled parts' names, comma-separated.
    pub known: String,
}

/// One bundled part.
#[derive(Debug, Clone, Copy)]
pub struct Part {
    /// The name `parts NAME` takes.
    pub name: &'static str,
    /// The relay class it stands for.
    pub class: &'static str,
    /// Manufacturer, part number and the document the figures come from.
    pub source: &'static str,
    /// The contact rating as printed.
    pub contact_rating: &'static str,
    /// Anything about the figures a user should know.
    pub remark: &'static str,
    /// The fitted scenario (TOML).
    pub scenario: &'static str,
}

impl Part {
    /// The part's scenario, parsed.
    pub fn load(&self) -> Result<Scenario, ScenarioError> {
        Scenario::parse(
            self.scenario,
            Path::new(&format!("parts/{}.toml", self.name)),
        )
    }
}

const PARTS: &[Part] = &[
    Part {
        name: "omron-g5le-1-dc5",
        class: "sugar-cube 10 A PCB power relay",
        source: "Omron G5LE-1 DC5; Omron datasheet \"G5LE PCB Power Relay: Cubic, Single-pole 10A Power Relay\" (coil ratings: 5 VDC, 79.4 mA, 63 Ω, must operate 75 % max., must release 10 % min.; operate time 10 ms max., release time 5 ms max.; rated load, resistive: 8 A at 30 VDC, the arc's low-current term fitted to it; AgSnO2 contacts as the earlier edition prints)",
        contact_rating: "single-pole 10 A power relay (SPDT)",
        remark: "times are maxima: the fitted relay is the slowest the datasheet allows",
        scenario: bundled_part_text("omron-g5le-1-dc5"),
    },
    Part {
        name: "songle-srd-05vdc-sl-c",
        class: "sugar-cube 10 A PCB power relay (hobby modules)",
        source: "Songle SRD-05VDC-SL-C; Ningbo Songle Relay SRD datasheet, coil data chart (high sensitivity 0.36 W: 5 VDC, 71.4 mA, 70 Ω ±10 %, pull-in 75 % max., drop-out 10 % min.; operation time 10 ms max., release time 5 ms max.; contact rating, form C resistive: 7 A 28 VDC, the arc's low-current term fitted to it; AgCdO contacts, modelled as silver)",
        contact_rating: "10 A 125 VAC / 10 A 30 VDC resistive (form C)",
        remark: "times are maxima: the fitted relay is the slowest the datasheet allows",
        scenario: bundled_part_text("songle-srd-05vdc-sl-c"),
    },
    Part {
        name: "panasonic-tq4-5v",
        class: "DIP signal relay",
        source: "Panasonic TQ4-5V; Panasonic (NAIS) datasheet \"TQ-RELAYS: Low profile 2 Form C relay\", 4 Form C single side stable coil table (5 V DC, 56.2 mA, 89 Ω, pick-up 3.75 V max., drop-out 0.5 V min.; operate time max. 3 ms (approx. 2 ms), release time max. 3 ms (approx. 1 ms))",
        contact_rating: "1 A 30 V DC / 0.5 A 125 V AC resistive",
        remark: "fitted to the typical operate time (approx. 2 ms)",
        scenario: bundled_part_text("panasonic-tq4-5v"),
    },
    Part {
        name: "finder-40.52-12vdc",
        class: "industrial PCB/plug-in relay",
        source: "Finder 40.52.9.012.0000; Finder datasheet \"40 Series - Miniature PCB/Plug-in relays 8 - 10 - 12 - 16 A\" (DC coil 0.65 W, operating range 0.73…1.5 U_N, must drop-out 0.1 U_N, operate/release time 7/3 ms); coil resistance 220 Ω as listed for 40.52.9.012.0000; contact specification, \"Breaking capacity DC1: 30/110/220 V\" 8/0.3/0.12 A and \"Rated current/Maximum peak current\" 8/15 A for 40.52, AgNi contacts (the arc's field, low-current term and minimum arc current fitted to those three figures at the part's 0.3 mm gap); electrical endurance (edition VI-2014): page 3, \"Electrical life at rated load AC1 100·10³ cycles\" (AC1 2000 VA at 250 V: 8 A), page 7, H 40, \"an electrical life of 100·10³ can be expected\" on the DC1 curve",
        contact_rating: "2 CO 8 A 250 VAC",
        remark: "pick-up 8.76 V = 0.73 × 12 V (the lower end of the operating range)",
        scenario: bundled_part_text("finder-40.52-12vdc"),
    },
    Part {
        name: "coto-9104-05",
        class: "reed relay (SIP)",
        source: "Coto Technology 9104 (5 V); Coto 9100/9104 series reed relay datasheet, model 9104 4-pin SIP (5 VDC, coil 175 Ω ±10 %, must operate 3.75 V max., must release 0.5 V min.; operate time including bounce 0.75 ms typ., release time 0.5 ms typ.)",
        contact_rating: "10 W, 0.5 A switching, 1000 V max. (DC/peak AC, resistive)",
        remark: "the printed operate time includes bounce; it is fitted as the time to first make. A reed has no separate armature or pole face: the blade stands for the reed's contact tip and the pole face for the seating of the overlapping tips just past the make",
        scenario: bundled_part_text("coto-9104-05"),
    },
    Part {
        name: "te-v23145-12v",
        class: "automotive plug-in Micro ISO relay",
        source: "TE Connectivity Micro Relay Low Noise V23145 (coil code *01-402); TE datasheet \"Automotive Relays, Plug-in Micro ISO Relays, Micro Relay Low Noise\" (12 VDC, operate 7.2 V, release 1.4 V, 181 Ω ±10 %, 796 mW; limiting breaking current 30 A at 13.5 VDC, the most for a 12 VDC load, the arc's low-current term fitted to it; silver-based contacts; page 1, 1 form A: \"Limiting making current\" 100 A, \"Electrical endurance, resistive load at 14VDC 15A >1x10⁵ ops.\")",
        contact_rating: "20 A NO at 23 °C, 12 VDC",
        remark: "no operate, bounce or release time printed in the coil data: the mass is the prior's",
        scenario: bundled_part_text("te-v23145-12v"),
    },
    Part {
        name: "te-axicom-im-5v",
        class: "signal relay (telecom, 2 form C)",
        source: "TE Connectivity AXICOM IM, standard 5 VDC 140 mW; TE datasheet \"AXICOM Signal Relays IM Relay\" Rev. 0917 (operate time typ. 1 ms, max. 3 ms; release time typ. 1 ms, max. 3 ms; bounce time typ. 1 ms, max. 5 ms) and catalog 1308242 (max. operate 3.5 V for 5 V)",
        contact_rating: "2 A, 60 W / 62.5 VA, 220 VDC / 250 VAC (PdRu, gold covered, twin contacts)",
        remark: "fitted to the typical operate and bounce times (1 ms each); the coil resistance is 5 V squared over 140 mW, not a printed figure",
        scenario: bundled_part_text("te-axicom-im-5v"),
    },
    Part {
        name: "te-rt1-rt314012",
        class: "power PCB relay 16 A (industrial)",
        source: "TE Connectivity Schrack RT1 RT314012 (12 VDC); TE datasheet \"Power PCB Relay RT1\" F0144-C Rev. HK1 (operate/release time max. 8/6 ms, bounce time NO/NC max. 4/6 ms) and coil table F0144-B (12 V: pull-in 8.4 V, release 1.2 V, 360 Ω ±10 %); F0144-C page 1: \"Limiting making current, max. 4s, duty factor 10%\" 30 A, NO-contact ratings (IEC 61810) 30x10³ at 16 A 250 VAC and 150x10³ at 10 A 400 VAC, resistive",
        contact_rating: "1 CO 12 A / 16 A, 250 VAC (AgNi 90/10)",
        remark: "every figure is a bound and the prior (blade and pole face included) meets them all, so the fit held every key: the nominal relay is an assumption inside the datasheet, and the envelope is the honest answer; the NO contact's bounce time is the one held",
        scenario: bundled_part_text("te-rt1-rt314012"),
    },
    Part {
        name: "omron-g8h-1c4t-r-12v",
        class: "automotive Micro ISO plug-in relay",
        source: "Omron G8H-1C4T-R (12 VDC); Omron datasheet \"Micro ISO Automotive Relay G8H\" (coil 100 Ω ±10 %, 1440 mW, pull-in < 7.0 V, drop-out > 0.7 V; operate time 20 ms max., release time 10 ms max., bounce time at operate 5 ms max.; page 2: inrush 60 A (NO), the making current held; its electrical durability prints no test voltage and is left out)",
        contact_rating: "20 A (NO) / 10 A (NC) steady, 60 A inrush, 16 V max. (AgSnO2)",
        remark: "every figure is a bound and the prior meets them all, so the fit held every key: the nominal relay is an assumption inside the datasheet, and the envelope is the honest answer",
        scenario: bundled_part_text("omron-g8h-1c4t-r-12v"),
    },
    Part {
        name: "te-card-e-v23057-12v",
        class: "industrial I/O relay (Card E)",
        source: "TE Connectivity Schrack Card E V23057, coil code 002 (12 VDC); TE datasheet \"Power PCB Relay Card E\" F0151-B Rev. 0411 (operate 8.0 V, release 1.2 V, 330 Ω ±10 %; operate/release time typ. 7/3 ms; bounce time typ. form A/form B 0.5/3 ms; page 1: \"Limiting making current, max 4 s, duty factor 10%\" 15 A, AgNi20 NO contact 30x10³ at 8 A 250 VAC resistive)",
        contact_rating: "1 CO 8 A, 250 VAC (AgCdO / AgNi20)",
        remark: "fitted to the typical operate time and the form A (closing) contact's typical bounce time",
        scenario: bundled_part_text("te-card-e-v23057-12v"),
    },
    Part {
        name: "te-rel-5v",
        class: "miniature PCB relay (white goods, industrial)",
        source: "TE Connectivity Schrack REL, 5 VDC; TE datasheet \"Miniature PCB Relay REL\" Rev. 0511 (5 V: operate 3.75 V, release 0.5 V, 70 Ω ±10 %, 357 mW; operate/release time max. 10/5 ms; bounce time max. 4 ms; page 1: \"Limiting making current, max 4s, duty factor 10%\" 15 A, REL30 NO contact 100x10³ at 5 A 250 VAC and 400x10³ at 3 A 400 VAC, resistive)",
        contact_rating: "1 form A 5 A, 250 VAC (AgNi 90/10, AgCdO)",
        remark: "every time is a maximum: the nominal relay is the prior inside them, with the preload moved to the printed operate voltage",
        scenario: bundled_part_text("te-rel-5v"),
    },
];

/// Every bundled part, in a fixed order.
pub fn all() -> &'static [Part] {
    PARTS
}

/// The part called `name`.
pub fn find(name: &str) -> Result<Part, UnknownPart> {
    PARTS
        .iter()
        .find(|p| p.name == name)
        .copied()
        .ok_or_else(|| UnknownPart {
            name: name.to_owned(),
            known: PARTS.iter().map(|p| p.name).collect::<Vec<_>>().join(", "),
        })
}

/// One part as `parts --format json` lists it.
#[derive(Debug, Clone, Serialize)]
pub struct Listing {
    /// As [`Part::name`].
    pub name: &'static str,
    /// As [`Part::class`].
    pub class: &'static str,
    /// Every figure the datasheet prints, by key, as printed: a number
    /// (typical) or `{typ, min, max, tolerance}`. `coil_voltage` is the
    /// nominal voltage.
    pub datasheet: BTreeMap<&'static str, PrintedFigure>,
    /// The nominal relay's value of each printed figure, same unit;
    /// `null` for a figure the model does not show (`release_time`).
    pub model: BTreeMap<&'static str, Option<f64>>,
    /// Whether the nominal relay meets each printed figure it shows
    /// (inside its bounds; a typical value alone within ±20 %).
    pub met: BTreeMap<&'static str, bool>,
    /// As [`Part::contact_rating`].
    pub contact_rating: &'static str,
    /// As [`Part::source`].
    pub source: &'static str,
    /// As [`Part::remark`].
    pub remark: &'static str,
    /// Where the part's pick-up binds along the armature's travel (at rest,
    /// or part-way at which position), computed from its scenario.
    pub pick_up_binds: Option<String>,
    /// The ranges of the keys its datasheet does not fix, with their
    /// source, for `run --envelope` and `check --envelope`.
    pub envelope: Option<crate::scenario::EnvelopeSection>,
    /// The printed DC breaking capacity (resistive), each figure with the
    /// part's arc model's largest breakable current at its voltage and
    /// the full contact gap (`model`; `null`: breaks any current).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dc_breaking: Vec<crate::arc::breaking::BreakingRow>,
    /// The printed electrical endurance figures (operations at a
    /// resistive test load), for `life`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub electrical_endurance: Vec<crate::scenario::EnduranceFigure>,
}

/// The listing of `part`: its datasheet figures against its scenario's.
pub fn listing(part: &Part) -> Listing {
    let scenario = part.load().expect("a bundled part's scenario is valid");
    let d = scenario.datasheet.clone().unwrap_or_default();
    let modelled = datasheet_figures(&scenario, &d);
    let mut datasheet = BTreeMap::new();
    let mut model = BTreeMap::new();
    let mut met = BTreeMap::new();
    if let Some(v) = d.coil_voltage {
        datasheet.insert("coil_voltage", PrintedFigure::typical(v));
        model.insert("coil_voltage", Some(v));
    }
    if let Some(m) = d.making_current {
        // A rating of the contact: the run's makes are held to it.
        datasheet.insert("making_current", m);
        model.insert("making_current", None);
    }
    for ((name, printed), (_, value)) in d.figures().into_iter().zip(modelled) {
        datasheet.insert(name, printed);
        model.insert(name, value);
        if let Some(v) = value {
            met.insert(name, printed.met_by_nominal(v));
        }
    }
    Listing {
        name: part.name,
        class: part.class,
        datasheet,
        model,
        met,
        contact_rating: part.contact_rating,
        source: part.source,
        remark: part.remark,
        pick_up_binds: pick_up_of(&scenario).map(|(pu, line)| pu.binding_text(&line)),
        envelope: scenario.envelope.clone(),
        dc_breaking: crate::arc::breaking::rows(
            &scenario.arc.unwrap_or_default().model(),
            scenario.mechanics.gap,
            &d.dc_breaking
                .iter()
                .map(|f| f.printed())
                .collect::<Vec<_>>(),
        ),
        electrical_endurance: d.electrical_endurance.clone(),
    }
}

/// `parts --format json`.
pub fn json() -> String {
    let list: Vec<Listing> = PARTS.iter().map(listing).collect();
    let mut text = serde_json::to_string_pretty(&list).expect("the parts serialize");
    text.push('\n');
    text
}

/// One part as JSON: its listing (as in [`json`]) and its fitted
/// scenario under `scenario`, the TOML's tables as JSON objects.
pub fn part_json(part: &Part) -> String {
    let mut value = serde_json::to_value(listing(part)).expect("a part serializes");
    let scenario: toml::Value =
        toml::from_str(part.scenario).expect("the bundled scenarios are valid TOML");
    if let serde_json::Value::Object(map) = &mut value {
        map.insert(
            "scenario".to_owned(),
            serde_json::to_value(scenario).expect("TOML values serialize"),
        );
    }
    let mut text = serde_json::to_string_pretty(&value).expect("a part serializes");
    text.push('\n');
    text
}

/// `parts` as a table: one block per part.
pub fn table() -> String {
    use std::fmt::Write;
    let mut out = String::new();
    for part in PARTS {
        let l = listing(part);
        let _ = writeln!(out, "{}  ({})", l.name, l.class);
        for (name, printed) in &l.datasheet {
            let unit = unit_of(name);
            let model = match l.model.get(name).copied().flatten() {
                Some(m) => format!("model {}", engineering(m, unit)),
                None if *name == "making_current" => {
                    "a rating: `check` holds every make of a run to it".to_owned()
                }
                None => "not modelled".to_owned(),
            };
            let verdict = match l.met.get(name) {
                Some(true) => ", met",
                Some(false) => ", NOT MET",
                None => "",
            };
            let _ = writeln!(
                out,
                "  {name:<17} {}  ({model}{verdict})",
                printed_text(printed, unit)
            );
        }
        out.push_str(&super::render::breaking_rows(&l.dc_breaking));
        for f in &l.electrical_endurance {
            let _ = writeln!(out, "  endurance         {}", endurance_text(f));
        }
        if let Some(binds) = &l.pick_up_binds {
            let _ = writeln!(out, "  pick-up binds     {binds}");
        }
        let _ = writeln!(out, "  contacts          {}", l.contact_rating);
        let _ = writeln!(out, "  source            {}", l.source);
        let _ = writeln!(out, "  note              {}\n", l.remark);
    }
    out
}

/// A printed endurance figure: `1e5 operations at 8 A, 250 V AC 50 Hz
/// (resistive)`.
fn endurance_text(f: &crate::scenario::EnduranceFigure) -> String {
    let supply = match f.supply {
        crate::scenario::Supply::Dc => "DC".to_owned(),
        crate::scenario::Supply::Ac => match f.frequency {
            Some(hz) => format!("AC {hz} Hz"),
            None => "AC (no frequency printed: 50 Hz)".to_owned(),
        },
    };
    format!(
        "{:.3e} operations at {}, {} {} ({})",
        f.operations,
        engineering(f.current, "A"),
        engineering(f.voltage, "V"),
        supply,
        f.load
    )
}
