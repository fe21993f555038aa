//! Power loads end to end: the contact force at every make of a
//! coil-driven relay, the electrical life in `run` and `check`, the
//! breaking fit that reaches high-voltage figures, and the ratings the
//! bundled power parts carry (docs/arcs.md).
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use crate::common;

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use chatterspice::calibrate::parts;
use chatterspice::chatter::Chatter;
use chatterspice::pipeline::{self, RunOptions, RunResult};
use chatterspice::scenario::{DEFAULT_SCENARIO_TOML, Scenario};
use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn cli() -> Command {
    Command::cargo_bin("chatterspice").unwrap()
}

/// The impact of `chatter` that starts the closure at `time`.
fn impact_at(chatter: &Chatter, time: f64) -> &chatterspice::chatter::Impact {
    chatter
        .impacts
        .iter()
        .min_by(|a, b| {
            (a.impact_time - time)
                .abs()
                .total_cmp(&(b.impact_time - time).abs())
        })
        .expect("a make has its impact")
}

/// Every make of `run` has a contact force, pressing and never above the
/// peak the mechanics recorded for its impact, and the spot figures that
/// force gives on `material`.
fn assert_makes_have_their_force(run: &RunResult, material: chatterspice::arc::Material) {
    assert!(!run.makes.is_empty(), "no make");
    let spot = material.spot();
    for m in &run.makes {
        let force = m
            .force
            .unwrap_or_else(|| panic!("make at {} s has no force: {m:?}", m.time));
        let impact = impact_at(&run.chatter, m.time);
        assert!(
            (impact.impact_time - m.time).abs() < 1e-9,
            "make at {} s, impact at {} s",
            m.time,
            impact.impact_time
        );
        assert!(force > 0.0, "{m:?}");
        if let Some(peak) = impact.peak_force {
            assert!(
                force <= peak * (1.0 + 1e-6),
                "{m:?} above the peak {peak} N"
            );
        }
        let a = (force / (std::f64::consts::PI * spot.hardness)).sqrt();
        let u = m.peak_current * spot.resistivity / (2.0 * a);
        assert!((m.spot_voltage.unwrap() / u - 1.0).abs() < 1e-9, "{m:?}");
        assert!((m.weld_margin.unwrap() * u / spot.melting_voltage() - 1.0).abs() < 1e-9);
    }
}

/// A coil-driven relay (the 24 V valve through the example relay's
/// driver): every make of every operation, the first and each re-make,
/// carries the contact force of the coupled run's own motion, and each
/// operation's makes are its first make and one re-make per bounce.
#[test]
fn every_make_of_a_coil_driven_relay_has_its_force() {
    let ng = ngspice_or_skip!();
    let scenario = Scenario::load(&root().join("examples/scenarios/valve-24v.toml")).unwrap();
    let run = pipeline::run(&scenario, &ng, &RunOptions::default())
        .unwrap_or_else(|e| panic!("{}", common::chain(&e)));
    assert_makes_have_their_force(&run, chatterspice::arc::Material::AgNi);
    assert!(!run.operations.is_empty());
    for (k, op) in run.operations.iter().enumerate() {
        let mine: Vec<_> = run.makes.iter().filter(|m| m.operation == k).collect();
        if op.stroke.first_make.is_none() {
            assert!(mine.is_empty());
            continue;
        }
        assert_eq!(mine.len(), op.stroke.bounces + 1, "operation {k}: {mine:?}");
        for (n, m) in mine.iter().enumerate() {
            assert_eq!(m.bounce, n, "{m:?}");
        }
        assert_eq!(Some(mine[0].time), op.stroke.first_make);
    }
    // The trajectory the forces come from moves as the coupled run did.
    let coupled = pipeline::run_coupled(&scenario, &ng, &Default::default())
        .unwrap_or_else(|e| panic!("{}", common::chain(&e)));
    let plan = chatterspice::plan::Plan::new(scenario.clone()).unwrap();
    let trajectory = chatterspice::pipeline::make_force::coupled_trajectory(&plan, &coupled)
        .expect("the converged pass moves again under its own flux");
    assert_eq!(
        trajectory.chatter().intervals.len(),
        coupled.chatter.intervals.len()
    );
}

/// A coil-driven relay whose circuit holds only its contact closes on
/// the DC step of its coil: its makes carry the force of that closing.
#[test]
fn every_make_of_a_relay_on_its_coil_s_dc_step_has_its_force() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = dir.path().join("load.cir");
    std::fs::write(
        &netlist,
        "24 V into 10 uF through 2 ohm\nV1 vcc 0 24\nR1 vcc a 2\nX1 a c CONTACT\n\
         C1 c 0 10u IC=0\n.tran 1u 30m 0 2u uic\n.end\n",
    )
    .unwrap();
    let path = dir.path().join("rel.toml");
    std::fs::write(
        &path,
        format!(
            "base = \"part:te-rel-5v\"\n[circuit]\nnetlist = {:?}\n",
            netlist.display().to_string()
        ),
    )
    .unwrap();
    let scenario = Scenario::load(&path).unwrap();
    let run = pipeline::run(&scenario, &ng, &RunOptions::default())
        .unwrap_or_else(|e| panic!("{}", common::chain(&e)));
    assert!(run.coupling.is_none(), "the DC step, not a coupled run");
    assert_makes_have_their_force(&run, chatterspice::arc::REFERENCE_MATERIAL);
}

/// A scenario with a circuit, an arc and endurance figures: the default
/// relay on 30 V through 6 Ω, two DC figures and an AC one.
fn life_scenario(dir: &Path) -> String {
    let netlist = dir.join("load.cir");
    std::fs::write(
        &netlist,
        "30 V, 6 ohm\nV1 vcc 0 30\nR1 vcc a 6\nX1 a 0 CONTACT\n.tran 1u 20m 0 2u\n.end\n",
    )
    .unwrap();
    let cut = DEFAULT_SCENARIO_TOML.find("[circuit]").unwrap();
    format!(
        "{}[circuit]\nnetlist = {:?}\n\n[arc]\nmaterial = \"Ag\"\n\n[datasheet]\n\
         electrical_endurance = [\n\
           {{ operations = 1.0e5, voltage = 30.0, current = 5.0, supply = \"dc\" }},\n\
           {{ operations = 5.0e4, voltage = 125.0, current = 10.0, supply = \"ac\", frequency = 60.0 }},\n\
         ]\nweibull_shape = 2.5\n",
        &DEFAULT_SCENARIO_TOML[..cut],
        netlist.display().to_string()
    )
}

fn json(args: &[&str], code: i32) -> Value {
    let out = cli().args(args).output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(code),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Two life documents agree to rounding.
fn assert_same_life(a: &Value, b: &Value) {
    fn walk(a: &Value, b: &Value, at: &str) {
        match (a, b) {
            (Value::Object(x), Value::Object(y)) => {
                assert_eq!(
                    x.keys().collect::<Vec<_>>(),
                    y.keys().collect::<Vec<_>>(),
                    "{at}"
                );
                for (k, v) in x {
                    walk(v, &y[k], &format!("{at}.{k}"));
                }
            }
            (Value::Array(x), Value::Array(y)) => {
                assert_eq!(x.len(), y.len(), "{at}");
                for (k, (v, w)) in x.iter().zip(y).enumerate() {
                    walk(v, w, &format!("{at}[{k}]"));
                }
            }
            (Value::Number(x), Value::Number(y)) => {
                let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
                assert!(
                    (x - y).abs() <= 1e-9 * x.abs().max(y.abs()),
                    "{at}: {x} against {y}"
                );
            }
            _ => assert_eq!(a, b, "{at}"),
        }
    }
    walk(a, b, "life");
}

/// `run` and `check` carry the life `life` computes for the scenario's
/// own circuit (from their own run of it), `check` holds it to
/// min_electrical_life with its margin, and `--no-life` leaves it out.
#[test]
fn run_and_check_carry_the_life_of_their_circuit() {
    if common::ngspice().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let text = life_scenario(dir.path());
    let path = dir.path().join("life.toml");
    std::fs::write(&path, &text).unwrap();
    let p = path.to_str().unwrap();
    let life = json(&["life", p, "--phases", "2", "--format", "json"], 0);
    let own = life["life"]["operations"].as_f64().expect("a life at 30 V");
    assert_eq!(life["weibull_shape"], 2.5);
    assert!(life["life"]["b10"].as_f64().unwrap() < own);

    let run = json(&["run", p, "--life-phases", "2", "--format", "json"], 0);
    assert_same_life(&run["life"], &life);
    // Its own circuit's energy is the run's most energetic operation.
    let e = run["arc_totals"]["max_operation_energy"].as_f64().unwrap();
    assert_eq!(
        run["life"]["life"]["energy_per_operation"].as_f64(),
        Some(e)
    );
    // Its wear, priced here from the run's own arcs: each arc's energy
    // times its mean current (charge over duration) to the p, summed over
    // that operation.
    let p_exp = life["current_exponent"].as_f64().unwrap();
    let arcs = run["arcs"].as_array().unwrap();
    let per_operation = |op: u64| -> (f64, f64) {
        arcs.iter()
            .filter(|a| a["operation"].as_u64() == Some(op))
            .fold((0.0, 0.0), |(e, w), a| {
                let energy = a["energy"].as_f64().unwrap();
                let duration = a["duration"].as_f64().unwrap();
                let current = a["charge"].as_f64().unwrap() / duration;
                let wear = if duration > 0.0 && current > 0.0 {
                    energy * current.powf(p_exp)
                } else {
                    energy
                };
                (e + energy, w + wear)
            })
    };
    let last = arcs
        .iter()
        .filter_map(|a| a["operation"].as_u64())
        .max()
        .unwrap();
    let (_, wear) = (0..=last)
        .map(per_operation)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap();
    let reported = run["life"]["life"]["wear_per_operation"].as_f64().unwrap();
    assert!(
        (reported / wear - 1.0).abs() < 1e-9,
        "{reported} against {wear}"
    );
    assert!(
        wear > e,
        "the arcs carry more than 1 A: {wear} against {e} J"
    );
    let table = cli()
        .args(["run", p, "--life-phases", "2"])
        .output()
        .unwrap();
    let table = String::from_utf8_lossy(&table.stdout);
    assert!(
        table.contains("electrical life") && table.contains("Weibull shape 2.5"),
        "{table}"
    );
    let bare = json(&["run", p, "--no-life", "--format", "json"], 0);
    assert!(bare.get("life").is_none());
    // A life that cannot be estimated does not cost the run: a warning.
    let motor = dir.path().join("motor.toml");
    std::fs::write(
        &motor,
        text.replace("supply = \"dc\" }", "supply = \"dc\", load = \"motor\" }"),
    )
    .unwrap();
    let out = cli()
        .args(["run", motor.to_str().unwrap(), "--format", "json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(doc.get("life").is_none());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("electrical life was not estimated") && stderr.contains("resistive"),
        "{stderr}"
    );

    for (limit, code) in [(0.5 * own, 0), (2.0 * own, 1)] {
        std::fs::write(
            &path,
            format!("{text}\n[limits]\nmin_electrical_life = {limit}\n"),
        )
        .unwrap();
        let check = json(
            &["check", p, "--life-phases", "2", "--format", "json"],
            code,
        );
        assert_same_life(&check["life"], &life);
        assert!(check["run"].get("life").is_none(), "said once");
        let row = check["checks"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["key"] == "limits.min_electrical_life")
            .expect("the life check");
        let (actual, margin) = (
            row["actual"].as_f64().unwrap(),
            row["margin"].as_f64().unwrap(),
        );
        assert!((actual / own - 1.0).abs() < 1e-9, "{row}");
        assert!((margin - (actual - limit)).abs() <= 1e-9 * actual, "{row}");
        assert_eq!(row["passed"], code == 0);
    }
}

/// The Finder's printed DC1 curve, 8 A at 30 V, 0.3 A at 110 V and
/// 0.12 A at 220 V, is met at every voltage once the fit may lower the
/// minimum arc current: `fit` from silver's defaults, and the bundled part.
#[test]
fn the_finder_breaking_curve_is_met_at_high_voltage() {
    let part = parts::find("finder-40.52-12vdc").unwrap();
    let listed = parts::listing(&part);
    assert_eq!(listed.dc_breaking.len(), 3);
    for row in &listed.dc_breaking {
        let model = row.model.unwrap();
        assert!((model / row.printed - 1.0).abs() < 0.01, "{row:?}");
    }
    let dir = tempfile::tempdir().unwrap();
    let text = part
        .scenario
        .replace("field = ", "# field = ")
        .replace("low_current = ", "# low_current = ")
        .replace("i_min = ", "# i_min = ");
    let prior = dir.path().join("prior.toml");
    std::fs::write(&prior, &text).unwrap();
    assert_eq!(
        Scenario::load(&prior).unwrap().arc.unwrap().model().i_min,
        0.4
    );
    let fitted = dir.path().join("fitted.toml");
    let out = cli()
        .arg("fit")
        .arg(&prior)
        .args(["--free", "arc.field,arc.low_current,arc.i_min", "-o"])
        .arg(&fitted)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let model = Scenario::load(&fitted).unwrap().arc.unwrap().model();
    let gap = 0.3e-3;
    // I_min: the arc's current at the tangent of 220 V.
    let tangent = 2.0 * model.low_current_term(gap) / (220.0 - model.arc_voltage(gap));
    assert!((model.i_min / tangent - 1.0).abs() < 1e-9, "{model:?}");
    for (v, printed) in [(30.0, 8.0), (110.0, 0.3), (220.0, 0.12)] {
        let i = model.breaking_current(v, gap).unwrap();
        assert!((i / printed - 1.0).abs() < 0.01, "{v} V: {i} A");
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("arc.i_min"), "{stdout}");
}

/// The bundled power parts carry the ratings their datasheets print, and
/// `parts` shows them.
#[test]
fn power_parts_carry_their_printed_ratings() {
    let listed: Value = serde_json::from_slice(
        &cli()
            .args(["parts", "--format", "json"])
            .output()
            .unwrap()
            .stdout,
    )
    .unwrap();
    let part = |name: &str| {
        listed
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .unwrap_or_else(|| panic!("{name}"))
            .clone()
    };
    for (name, making, endurance) in [
        ("finder-40.52-12vdc", 15.0, 4),
        ("te-rt1-rt314012", 30.0, 2),
        ("te-rel-5v", 15.0, 2),
        ("te-card-e-v23057-12v", 15.0, 1),
        ("te-v23145-12v", 100.0, 1),
        ("omron-g8h-1c4t-r-12v", 60.0, 0),
    ] {
        let p = part(name);
        assert_eq!(p["datasheet"]["making_current"]["max"], making, "{name}");
        let figures = p["electrical_endurance"].as_array().map_or(0, Vec::len);
        assert_eq!(figures, endurance, "{name}");
    }
    let table = cli().arg("parts").output().unwrap();
    let table = String::from_utf8_lossy(&table.stdout);
    assert!(
        table.contains("endurance         1.500e5 operations at 10 A, 400 V AC"),
        "{table}"
    );
}

/// `life` on the Finder calibrates on its AC1 figure. Its DC1 figures
/// sit on the printed breaking curve the arc was fitted to: the model
/// either prices each from a break arc that goes out, or refuses it with
/// its reason (the arc standing at the tangent of its load line when the
/// test run ends), never prices one by how long the test ran. A load
/// beyond the curve (20 A and 40 A at 30 V, where it breaks 8 A) is
/// refused without a run.
#[test]
fn the_finder_life_prices_only_what_its_contact_breaks() {
    if common::ngspice().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("finder.toml");
    std::fs::write(
        &path,
        "base = \"part:finder-40.52-12vdc\"\n\n\
         [[datasheet.electrical_endurance]]\noperations = 1.0e5\nvoltage = 250.0\n\
         current = 8.0\nsupply = \"ac\"\n\n\
         [[datasheet.electrical_endurance]]\noperations = 1.0e5\nvoltage = 30.0\n\
         current = 8.0\nsupply = \"dc\"\n\n\
         [[datasheet.electrical_endurance]]\noperations = 5.0e4\nvoltage = 30.0\n\
         current = 20.0\nsupply = \"dc\"\n\n\
         [[datasheet.electrical_endurance]]\noperations = 2.0e4\nvoltage = 30.0\n\
         current = 40.0\nsupply = \"dc\"\n",
    )
    .unwrap();
    let doc = json(
        &[
            "life",
            path.to_str().unwrap(),
            "--phases",
            "2",
            "--format",
            "json",
        ],
        0,
    );
    let figures = doc["figures"].as_array().unwrap();
    assert_eq!(figures.len(), 4);
    assert_eq!(doc["calibrated_on"], 0);
    assert_eq!(figures[0]["ratio"], 1.0);
    let warnings = doc["warnings"].as_array().unwrap();
    let mut refused = 0;
    for f in &figures[1..] {
        match f["refused"].as_str() {
            Some(why) => {
                refused += 1;
                assert!(f["predicted"].is_null(), "{f}");
                assert!(why.contains("break"), "{f}");
                let load = f["load"].as_str().unwrap();
                assert!(
                    warnings.iter().any(|w| w.as_str().unwrap().contains(load)),
                    "{load}: {warnings:?}"
                );
            }
            None => assert!(f["predicted"].as_f64().unwrap() > 0.0, "{f}"),
        }
    }
    assert_eq!(refused, warnings.len());
    for f in &figures[2..] {
        assert!(
            f["refused"]
                .as_str()
                .unwrap()
                .contains("beyond the breaking capacity"),
            "{f}"
        );
        assert_eq!(f["phases"], 0, "not simulated: {f}");
    }
    assert_eq!(figures[2]["load"], "20 A 30 VDC resistive");
    assert!(doc["life"].is_null(), "no circuit of its own");
}

/// The erosion law on printed tables: each is calibrated on its first
/// figure and must predict the others within 2× (docs/arcs.md, "Which
/// erosion law"). Energy alone, with the DC wear of 3.5 the law had
/// before, misses the first two at these 4 phases (2.39× and 3.21×).
#[test]
fn printed_endurance_tables_come_within_twice() {
    if common::ngspice().is_none() {
        return;
    }
    let tables = [
        // TE PE014 (UL 508, NO, 85 °C): 1e5 at 5 A 240 VAC and at 5 A
        // 30 VDC, on the bundled 5 A PCB relay: a DC figure against an AC
        // one.
        (
            "te-rel-5v",
            "{ operations = 1.0e5, voltage = 240.0, current = 5.0, supply = \"ac\" },\n\
             { operations = 1.0e5, voltage = 30.0, current = 5.0, supply = \"dc\" }",
        ),
        // TE T9G (UL 508, NO): 2.5e5 at 22 A 250 VAC, 1e5 at 15.6 A
        // 480 VAC, on the bundled 16 A relay: a higher voltage at a lower
        // current.
        (
            "te-rt1-rt314012",
            "{ operations = 2.5e5, voltage = 250.0, current = 22.0, supply = \"ac\" },\n\
             { operations = 1.0e5, voltage = 480.0, current = 15.6, supply = \"ac\" }",
        ),
        // Zettler AZ942H (1 form A, 85 °C): 5e4 at 16 A and 1e5 at 12 A,
        // both 250 VAC: a lower current alone.
        (
            "te-rt1-rt314012",
            "{ operations = 5.0e4, voltage = 250.0, current = 16.0, supply = \"ac\" },\n\
             { operations = 1.0e5, voltage = 250.0, current = 12.0, supply = \"ac\" }",
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (k, (part, figures)) in tables.iter().enumerate() {
        let path = dir.path().join(format!("table{k}.toml"));
        std::fs::write(
            &path,
            format!(
                "base = \"part:{part}\"\n[datasheet]\nelectrical_endurance = [\n{figures},\n]\n"
            ),
        )
        .unwrap();
        let doc = json(
            &[
                "life",
                path.to_str().unwrap(),
                "--phases",
                "4",
                "--format",
                "json",
            ],
            0,
        );
        let figures = doc["figures"].as_array().unwrap();
        assert_eq!(doc["calibrated_on"], 0, "{doc}");
        for f in &figures[1..] {
            let ratio = f["ratio"].as_f64().unwrap_or_else(|| panic!("{doc}"));
            assert!((0.5..=2.0).contains(&ratio), "{part}: {f}");
        }
    }
}
