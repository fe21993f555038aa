//! The bounce result as JSON: the contract of docs/output.md.
//!
//! The contract's fields come first and in its order (`outcome`,
//! `first_impact`, `settle_time`, `bounce_count`, `impacts`, `intervals`),
//! then the additions `shortfall`, `accumulation_time`, `t_end` and, when
//! known, a `dimensionless` object with the paper's groups. Absent values
//! are `null`, never omitted, so every document has the same keys. Floats
//! are serde_json's shortest round-trip form.

use serde::Serialize;

use crate::analysis::{Comparison, ProbeAnalysis};
use crate::arc::{ArcEvent, ArcModel, ArcTotals, Breakdown};
use crate::chatter::Chatter;
use crate::check::{Evidence, Verdict};
use crate::coil::{Closing, Operation};
use crate::mechanics::Dimensionless;
use crate::pipeline::coupled::Iteration;
use crate::pipeline::{RunResult, Simulation};

/// The bounce object, ready to serialize alone or to embed (as `bounce`)
/// in a larger document such as `run`'s.
#[derive(Debug, Serialize)]
pub struct BounceJson<'a> {
    #[serde(flatten)]
    chatter: &'a Chatter,
    #[serde(skip_serializing_if = "Option::is_none")]
    dimensionless: Option<DimensionlessJson>,
    /// A relay with a pole face: the armature's impacts on it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pole_face_impacts: Option<Vec<PoleFaceJson>>,
}

/// One impact of the armature on the pole face.
#[derive(Debug, Serialize)]
struct PoleFaceJson {
    /// s
    time: f64,
    /// m/s, the armature's speed at the impact (> 0).
    velocity: f64,
    /// s, when it leaves the pole face again; `null` if it stays.
    release_time: Option<f64>,
    /// m/s, its velocity then (< 0); `null` with `release_time`.
    release_velocity: Option<f64>,
}

impl<'a> BounceJson<'a> {
    /// The object for `chatter`, with the relay's dimensionless groups
    /// when given.
    pub fn new(chatter: &'a Chatter, dimensionless: Option<&Dimensionless>) -> Self {
        BounceJson {
            chatter,
            dimensionless: dimensionless.map(DimensionlessJson::from),
            pole_face_impacts: None,
        }
    }

    /// The same object with the pole face's impacts.
    pub fn with_pole_face(mut self, impacts: &[crate::chatter::Impact]) -> Self {
        self.pole_face_impacts = Some(
            impacts
                .iter()
                .map(|i| PoleFaceJson {
                    time: i.impact_time,
                    velocity: i.impact_velocity,
                    release_time: i.release_time,
                    release_velocity: i.release_velocity,
                })
                .collect(),
        );
        self
    }
}

/// [`Dimensionless`] under the names of docs/model.md §1–3.
#[derive(Debug, Serialize)]
struct DimensionlessJson {
    omega_n: f64,
    zeta: f64,
    static_deflection: f64,
    k0: f64,
    zeta0: Option<f64>,
    beta: Option<f64>,
    sigma: Option<f64>,
    zeta_prime: Option<f64>,
    gamma: Option<f64>,
}

impl From<&Dimensionless> for DimensionlessJson {
    fn from(d: &Dimensionless) -> Self {
        DimensionlessJson {
            omega_n: d.omega_n,
            zeta: d.zeta,
            static_deflection: d.static_deflection,
            k0: d.k0,
            zeta0: d.zeta0,
            beta: d.beta,
            sigma: d.sigma,
            zeta_prime: d.zeta_prime,
            gamma: d.gamma,
        }
    }
}

/// Pretty-printed JSON with a trailing newline.
pub fn render(chatter: &Chatter, dimensionless: Option<&Dimensionless>) -> String {
    let mut text = serde_json::to_string_pretty(&BounceJson::new(chatter, dimensionless))
        // Only maps with non-string keys or a failing writer can fail, and
        // these types have neither.
        .expect("a chatter result always serializes");
    text.push('\n');
    text
}

/// [`render`] with the pole face's impacts, when given.
pub fn render_with_pole_face(
    chatter: &Chatter,
    dimensionless: Option<&Dimensionless>,
    pole_face: Option<&[crate::chatter::Impact]>,
) -> String {
    let mut json = BounceJson::new(chatter, dimensionless);
    if let Some(impacts) = pole_face {
        json = json.with_pole_face(impacts);
    }
    let mut text = serde_json::to_string_pretty(&json).expect("a chatter result always serializes");
    text.push('\n');
    text
}

/// The `run` document: the contract's `probes`, `bounce` and `ngspice`
/// first, then the contact waveform's figures, the netlist and any
/// warnings.
#[derive(Debug, Serialize)]
pub struct RunJson<'a> {
    probes: Vec<ProbeJson<'a>>,
    bounce: BounceJson<'a>,
    ngspice: NgspiceJson<'a>,
    contact: ContactJson<'a>,
    netlist: String,
    warnings: &'a [String],
    /// The coupling's passes, for a coil-driven relay.
    #[serde(skip_serializing_if = "Option::is_none")]
    coupling: Option<&'a [Iteration]>,
    /// Each closing and release of a coil-driven relay, with its timing.
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    operations: &'a [Operation],
    /// The drop-out and pick-up levels a coil-driven relay's drive was
    /// read against, with the coil's time constant.
    #[serde(skip_serializing_if = "Option::is_none")]
    coil_levels: Option<&'a crate::coil::CoilLevels>,
    /// The first closing's operate, bounce and settle time, from the
    /// coil being energized (or the force step).
    timing: Closing,
    /// With `[arc]`: every arc at the contact.
    #[serde(skip_serializing_if = "Option::is_none")]
    arcs: Option<&'a [ArcEvent]>,
    /// With `[arc]`: the totals (count, energy, breakdowns, ...).
    #[serde(skip_serializing_if = "Option::is_none")]
    arc_totals: Option<&'a ArcTotals>,
    /// With `[arc]`: every breakdown of the open gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    breakdowns: Option<&'a [Breakdown]>,
    /// With `[arc]`: the numbers the arcs were simulated with.
    #[serde(skip_serializing_if = "Option::is_none")]
    arc_model: Option<&'a ArcModel>,
    /// Every make: its peak current, the force then and the spot.
    makes: &'a [crate::arc::making::Make],
    /// The run's energy ledger: the sources, the stores, the resistors,
    /// the arcs and breakdowns, the rest.
    energy: &'a crate::pipeline::ledger::EnergyLedger,
    /// With `[datasheet] electrical_endurance`: the electrical life at
    /// this circuit (the `life` document).
    #[serde(skip_serializing_if = "Option::is_none")]
    life: Option<&'a crate::life::LifeReport>,
}

/// One probe: the contract's fields (flattened from the analysis), then
/// the ideal contact's analysis and what the bounce added to it.
#[derive(Debug, Serialize)]
struct ProbeJson<'a> {
    #[serde(flatten)]
    analysis: &'a ProbeAnalysis,
    ideal: Option<&'a ProbeAnalysis>,
    bounce_added: Option<&'a Comparison>,
}

#[derive(Debug, Serialize)]
struct NgspiceJson<'a> {
    version: Option<&'a str>,
    /// s, wall time of the bounced run.
    elapsed: f64,
    /// Time points of the bounced run.
    points: usize,
    ideal_elapsed: Option<f64>,
    ideal_points: Option<usize>,
}

#[derive(Debug, Serialize)]
struct ContactJson<'a> {
    element: &'a str,
    subckt: &'a str,
    points: usize,
    pwl_sources: usize,
    make_edges: usize,
    break_edges: usize,
    merged_openings: usize,
    widened_closures: usize,
}

impl<'a> RunJson<'a> {
    /// The object for `run`; its bounce carries the relay's
    /// dimensionless groups when given.
    pub fn new(run: &'a RunResult, dimensionless: Option<&Dimensionless>) -> Self {
        let sim = |s: &'a Simulation| (s.elapsed.as_secs_f64(), s.plot.points());
        RunJson {
            probes: run
                .probes
                .iter()
                .map(|p| ProbeJson {
                    analysis: &p.analysis,
                    ideal: p.ideal.as_ref(),
                    bounce_added: p.comparison.as_ref(),
                })
                .collect(),
            bounce: match &run.pole_face {
                Some(impacts) => {
                    BounceJson::new(&run.chatter, dimensionless).with_pole_face(impacts)
                }
                None => BounceJson::new(&run.chatter, dimensionless),
            },
            ngspice: NgspiceJson {
                version: run.simulation.version.as_deref(),
                elapsed: sim(&run.simulation).0,
                points: sim(&run.simulation).1,
                ideal_elapsed: run.ideal.as_ref().map(|s| sim(s).0),
                ideal_points: run.ideal.as_ref().map(|s| sim(s).1),
            },
            contact: ContactJson {
                element: run.include.element.as_str(),
                subckt: &run.include.subckt,
                points: run.include.points,
                pwl_sources: run.include.pwl_sources,
                make_edges: run.waveform.make_edges(),
                break_edges: run.waveform.break_edges(),
                merged_openings: run.waveform.merged_openings(),
                widened_closures: run.waveform.widened_closures(),
            },
            netlist: run.netlist.display().to_string(),
            warnings: &run.warnings,
            coupling: run.coupling.as_deref(),
            operations: &run.operations,
            coil_levels: run.coil_levels.as_ref(),
            timing: Closing::first(&run.chatter, &run.operations),
            arcs: run.arcs.as_ref().map(|a| a.arcs.as_slice()),
            arc_totals: run.arcs.as_ref().map(|a| &a.totals),
            breakdowns: run.arcs.as_ref().map(|a| a.breakdowns.as_slice()),
            arc_model: run.arcs.as_ref().map(|a| &a.model),
            makes: &run.makes,
            energy: &run.energy,
            life: None,
        }
    }
}

/// The `check` document: the verdict (`passed`, `failed`, `checks`), the
/// bounce, and the whole run when the circuit was simulated (`null` when
/// the limits needed the mechanics only).
#[derive(Debug, Serialize)]
pub struct CheckJson<'a> {
    #[serde(flatten)]
    verdict: &'a Verdict,
    bounce: BounceJson<'a>,
    /// The first closing's times, from the coil being energized.
    timing: Closing,
    run: Option<RunJson<'a>>,
    /// With `[datasheet] electrical_endurance`: the electrical life at the
    /// circuit (the `life` document; the nested run leaves it out).
    #[serde(skip_serializing_if = "Option::is_none")]
    life: Option<&'a crate::life::LifeReport>,
}

/// The `check` result as pretty-printed JSON with a trailing newline.
pub fn render_check(
    verdict: &Verdict,
    evidence: &Evidence,
    dimensionless: Option<&Dimensionless>,
) -> String {
    render_check_with_life(verdict, evidence, dimensionless, None)
}

/// [`render_check`] with the electrical life `life` estimated for the
/// check, at the top level of the document.
pub fn render_check_with_life(
    verdict: &Verdict,
    evidence: &Evidence,
    dimensionless: Option<&Dimensionless>,
    life: Option<&crate::life::LifeReport>,
) -> String {
    let bounce = BounceJson::new(evidence.chatter(), dimensionless);
    let pole_face = match evidence {
        Evidence::Run(run) => run.pole_face.as_deref(),
        Evidence::Mechanics(_, pole_face) => pole_face.as_deref(),
    };
    let doc = CheckJson {
        verdict,
        bounce: match pole_face {
            Some(impacts) => bounce.with_pole_face(impacts),
            None => bounce,
        },
        timing: Closing::first(evidence.chatter(), evidence.operations()),
        run: match evidence {
            Evidence::Run(run) => Some(RunJson::new(run, dimensionless)),
            Evidence::Mechanics(..) => None,
        },
        life,
    };
    let mut text = serde_json::to_string_pretty(&doc).expect("a check result always serializes");
    text.push('\n');
    text
}

/// The `run` result as pretty-printed JSON with a trailing newline.
pub fn render_run(run: &RunResult, dimensionless: Option<&Dimensionless>) -> String {
    render_run_with_life(run, dimensionless, None)
}

/// [`render_run`] with the electrical life `life` estimated at the run's
/// circuit.
pub fn render_run_with_life(
    run: &RunResult,
    dimensionless: Option<&Dimensionless>,
    life: Option<&crate::life::LifeReport>,
) -> String {
    let doc = RunJson {
        life,
        ..RunJson::new(run, dimensionless)
    };
    let mut text = serde_json::to_string_pretty(&doc).expect("a run result always serializes");
    text.push('\n');
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::{Mechanics, Surface};
    use crate::report::fixtures;

    #[test]
    fn never_closes_is_exactly_this() {
        let expected = r#"{
  "outcome": "never_closes",
  "first_impact": null,
  "settle_time": null,
  "bounce_count": 0,
  "impacts": [],
  "intervals": [
    {
      "state": "open",
      "start": 0.0,
      "end": 0.02
    }
  ],
  "shortfall": 0.000025,
  "accumulation_time": null,
  "t_end": 0.02
}
"#;
        assert_eq!(render(&fixtures::never_closes(), None), expected);
    }

    #[test]
    fn contract_keys_come_first_in_contract_order() {
        let text = render(&fixtures::stuck(), None);
        let top: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("  \"") && !l.starts_with("   "))
            .map(|l| l.trim().split('"').nth(1).unwrap())
            .collect();
        assert_eq!(
            top,
            [
                "outcome",
                "first_impact",
                "settle_time",
                "bounce_count",
                "impacts",
                "intervals",
                "shortfall",
                "accumulation_time",
                "t_end"
            ]
        );
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let impact = &v["impacts"][0];
        // The CSV's columns are the JSON's impact fields.
        for key in super::super::csv::HEADER {
            assert!(impact.get(key).is_some(), "impact lacks {key}");
        }
        assert_eq!(v["impacts"][2]["release_time"], serde_json::Value::Null);
        assert_eq!(v["intervals"][5]["state"], "closed");
        assert_eq!(v["settle_time"], 0.0016);
    }

    /// The numbers written after `"key": ` in `text`, read back with
    /// Rust's correctly rounded parser (serde_json's default parser is not
    /// exact in the last bit, so it cannot judge a round trip).
    fn numbers(text: &str, key: &str) -> Vec<f64> {
        let tag = format!("\"{key}\": ");
        text.lines()
            .filter_map(|l| l.trim().strip_prefix(&tag))
            .filter_map(|n| n.trim_end_matches(',').parse().ok())
            .collect()
    }

    #[test]
    fn floats_round_trip_exactly() {
        let chatter = fixtures::stuck();
        let text = render(&chatter, None);
        let times: Vec<f64> = chatter.impacts.iter().map(|i| i.impact_time).collect();
        assert_eq!(numbers(&text, "impact_time"), times);
        let e: Vec<f64> = chatter
            .impacts
            .iter()
            .filter_map(|i| i.restitution)
            .collect();
        assert_eq!(numbers(&text, "restitution"), e);
        assert_eq!(e[0], 0.26 / 0.31, "a value with all 17 digits");
    }

    #[test]
    fn output_is_deterministic() {
        let c = fixtures::stuck();
        assert_eq!(render(&c, None), render(&c.clone(), None));
    }

    #[test]
    fn dimensionless_groups_are_added_when_given() {
        let m = Mechanics {
            mass: 2e-4,
            stiffness: 800.0,
            damping: 0.04,
            force: 0.5,
            gap: 4.5e-4,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        };
        let s = Surface::KelvinVoigt {
            stiffness: 8e4,
            damping: 0.37536,
        };
        let d = Dimensionless::of(&m, &s);
        let text = render(&fixtures::stuck(), Some(&d));
        assert_eq!(numbers(&text, "omega_n"), [2000.0]);
        assert_eq!(numbers(&text, "zeta"), [d.zeta]);
        assert_eq!(numbers(&text, "k0"), [d.k0]);
        assert_eq!(numbers(&text, "beta"), [101.0]);
        assert_eq!(numbers(&text, "zeta_prime"), [d.zeta_prime.unwrap()]);
        let rigid = Dimensionless::of(&m, &Surface::Rigid { restitution: 0.5 });
        let v: serde_json::Value =
            serde_json::from_str(&render(&fixtures::stuck(), Some(&rigid))).unwrap();
        assert_eq!(v["dimensionless"]["beta"], serde_json::Value::Null);
    }
}
