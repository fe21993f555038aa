//! The JSON Schemas in docs/schema/ describe what the commands really
//! print: every document below, from real runs (ngspice included), must
//! validate, and the schemas forbid keys they do not list, so a field
//! added to the output without its schema fails here.
//!
//! The validator covers the part of JSON Schema (2020-12) the schemas use:
//! `type`, `properties`, `required`, `additionalProperties`, `items`,
//! `enum`, `oneOf`, `minimum` and `$ref`s into a schema's own `$defs` or a
//! sibling file's.

use crate::common;

use std::path::PathBuf;

use assert_cmd::Command;
use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn schema(name: &str) -> Value {
    let path = root()
        .join("docs/schema")
        .join(format!("{name}.schema.json"));
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// Errors of `value` against `schema` (whose `$defs` resolve `$ref`s), as
/// JSON-pointer-ish paths with a reason.
fn validate(root: &Value, schema: &Value, value: &Value, at: &str, errors: &mut Vec<String>) {
    if let Some(r) = schema.get("$ref").and_then(Value::as_str) {
        // `#/$defs/name` in this file, or `other.schema.json#/$defs/name`
        // in a sibling (the definitions shared by the documents live once).
        let (file, name) = r.split_once("#/$defs/").expect("refs into $defs only");
        if file.is_empty() {
            validate(root, &root["$defs"][name], value, at, errors);
        } else {
            let other = self::schema(file.strip_suffix(".schema.json").expect("a sibling schema"));
            validate(&other, &other["$defs"][name], value, at, errors);
        }
    }
    if let Some(t) = schema.get("type") {
        let types: Vec<&str> = match t {
            Value::String(s) => vec![s.as_str()],
            Value::Array(a) => a.iter().filter_map(Value::as_str).collect(),
            _ => panic!("bad type in schema at {at}"),
        };
        let ok = types.iter().any(|t| match *t {
            "null" => value.is_null(),
            "boolean" => value.is_boolean(),
            "string" => value.is_string(),
            "number" => value.is_number(),
            "integer" => value.is_i64() || value.is_u64(),
            "array" => value.is_array(),
            "object" => value.is_object(),
            other => panic!("unknown type {other}"),
        });
        if !ok {
            errors.push(format!("{at}: {value} is not {types:?}"));
            return;
        }
    }
    if let Some(options) = schema.get("enum").and_then(Value::as_array) {
        if !options.contains(value) {
            errors.push(format!("{at}: {value} is not one of {options:?}"));
        }
    }
    if let (Some(min), Some(x)) = (
        schema.get("minimum").and_then(Value::as_f64),
        value.as_f64(),
    ) {
        if x < min {
            errors.push(format!("{at}: {x} < minimum {min}"));
        }
    }
    if let Some(options) = schema.get("oneOf").and_then(Value::as_array) {
        let passing = options
            .iter()
            .filter(|s| {
                let mut e = Vec::new();
                validate(root, s, value, at, &mut e);
                e.is_empty()
            })
            .count();
        if passing != 1 {
            errors.push(format!(
                "{at}: {passing} of the oneOf alternatives match {value}"
            ));
        }
    }
    if let (Some(items), Some(array)) = (schema.get("items"), value.as_array()) {
        for (i, v) in array.iter().enumerate() {
            validate(root, items, v, &format!("{at}[{i}]"), errors);
        }
    }
    if let Some(object) = value.as_object() {
        let properties = schema.get("properties").and_then(Value::as_object);
        if let Some(required) = schema.get("required").and_then(Value::as_array) {
            for key in required.iter().filter_map(Value::as_str) {
                if !object.contains_key(key) {
                    errors.push(format!("{at}: missing `{key}`"));
                }
            }
        }
        for (key, v) in object {
            match properties.and_then(|p| p.get(key)) {
                Some(s) => validate(root, s, v, &format!("{at}.{key}"), errors),
                None => match schema.get("additionalProperties") {
                    Some(Value::Bool(false)) => {
                        errors.push(format!("{at}: `{key}` is not in the schema"));
                    }
                    Some(s @ Value::Object(_)) => {
                        validate(root, s, v, &format!("{at}.{key}"), errors);
                    }
                    _ => {}
                },
            }
        }
    }
}

fn assert_valid(name: &str, doc: &Value, what: &str) {
    let schema = schema(name);
    let mut errors = Vec::new();
    validate(&schema, &schema, doc, "$", &mut errors);
    assert!(errors.is_empty(), "{what} against {name}: {errors:#?}");
}

fn json_of(args: &[&str], code: i32) -> Value {
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(args)
        .assert()
        .code(code);
    serde_json::from_slice(&out.get_output().stdout).unwrap()
}

fn example(name: &str) -> String {
    root()
        .join("examples/scenarios")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

#[test]
fn the_validator_rejects_what_the_schemas_forbid() {
    let mut doc = json_of(&["bounce", "--format", "json"], 0);
    assert_valid("bounce", &doc, "default bounce");
    doc["undocumented"] = Value::Bool(true);
    let s = schema("bounce");
    let mut errors = Vec::new();
    validate(&s, &s, &doc, "$", &mut errors);
    assert!(
        errors.iter().any(|e| e.contains("undocumented")),
        "{errors:?}"
    );
    doc.as_object_mut().unwrap().remove("undocumented");
    doc["outcome"] = Value::String("sideways".into());
    doc["impacts"][0]["impact_time"] = Value::String("soon".into());
    let mut errors = Vec::new();
    validate(&s, &s, &doc, "$", &mut errors);
    assert_eq!(errors.len(), 2, "{errors:?}");
}

#[test]
fn bounce_output_matches_its_schema() {
    for scenario in ["rigid.toml", "kelvin-voigt.toml", "hunt-crossley.toml"] {
        let doc = json_of(&["bounce", &example(scenario), "--format", "json"], 0);
        assert_valid("bounce", &doc, scenario);
    }
}

#[test]
fn run_and_check_output_match_their_schemas() {
    let Some(_) = common::ngspice() else { return };
    let default = json_of(&["run", "--format", "json"], 0);
    assert_valid("run", &default, "default run");
    // Every example's run and check: the test of every command below. A
    // check of a circuit carries its run.
    let check = json_of(
        &[
            "check",
            &example("relay-driver-zener.toml"),
            "--format",
            "json",
        ],
        0,
    );
    assert_valid("check", &check, "coil check");
    assert!(check["run"].is_object());
    let scenario = format!(
        "{}/tests/data/scenarios/im_mcu_envelope.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    for command in ["check", "run"] {
        let doc = json_of(
            &[
                command,
                &scenario,
                "--envelope",
                "--samples",
                "8",
                "--format",
                "json",
            ],
            0,
        );
        assert!(doc["envelope"]["quantities"].is_object());
        assert_valid(command, &doc, "an envelope");
    }
}

#[test]
fn sweep_summaries_match_their_schema() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    let text = chatterspice::scenario::DEFAULT_SCENARIO_TOML.replace(
        "../netlists/mcu_input.cir",
        &root().join("netlists/mcu_input.cir").to_string_lossy(),
    );
    let path = dir.path().join("relay.toml");
    std::fs::write(
        &path,
        format!(
            "{text}\n[limits]\nmax_bounces = 4\n\n[sweep]\nsamples = 6\n[sweep.vary]\n\
             \"mechanics.mass\" = 0.2\n"
        ),
    )
    .unwrap();
    for (name, extra) in [("mech", vec!["--mechanics-only"]), ("ngspice", vec![])] {
        let out = dir.path().join(name);
        let mut cmd = Command::cargo_bin("chatterspice").unwrap();
        cmd.arg("sweep")
            .arg(&path)
            .args(&extra)
            .arg("--out")
            .arg(&out)
            .assert()
            .code(1);
        let summary: Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_valid("sweep-summary", &summary, name);
    }
}

#[test]
fn raw_summaries_of_every_test_file_match_their_schema() {
    let mut n = 0;
    for dir in ["tests/data/raw", "tests/data/ltspice"] {
        for entry in std::fs::read_dir(root().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "raw") {
                continue;
            }
            let out = Command::cargo_bin("chatterspice")
                .unwrap()
                .args(["raw", path.to_str().unwrap(), "--format", "json"])
                .output()
                .unwrap();
            if !out.status.success() {
                continue;
            }
            let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
            assert_valid("raw", &doc, &path.display().to_string());
            n += 1;
        }
    }
    assert!(n >= 20, "{n} raw files");
}

/// A scope trace of a bouncing contact pulling 3.3 V low, with noise.
fn scope_csv(dir: &std::path::Path) -> PathBuf {
    let edges = [1e-3, 1.05e-3, 1.3e-3, 1.34e-3, 1.6e-3];
    let mut text = String::from("time,v\n");
    for k in 0..3000 {
        let t = k as f64 * 1e-6;
        let closed = edges.iter().filter(|&&e| e <= t).count() % 2 == 1;
        let noise = 0.01 * ((k * 7919 % 101) as f64 / 50.0 - 1.0);
        let v = if closed { 0.0 } else { 3.3 } + noise;
        text.push_str(&format!("{t:e},{v}\n"));
    }
    let path = dir.join("scope.csv");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn capture_and_fit_output_match_their_schemas() {
    let dir = tempfile::tempdir().unwrap();
    let scope = scope_csv(dir.path());
    let scope = scope.to_str().unwrap();
    let capture = json_of(&["capture", scope, "--format", "json"], 0);
    assert_eq!(capture["bounce_count"], 2, "{capture}");
    assert_valid("capture", &capture, "capture");
    let record = dir.path().join("record.csv");
    Command::cargo_bin("chatterspice")
        .unwrap()
        .args([
            "capture",
            scope,
            "--format",
            "csv",
            "-o",
            record.to_str().unwrap(),
        ])
        .assert()
        .success();
    // A record fit and a datasheet fit.
    let fit = json_of(
        &[
            "fit",
            &example("kelvin-voigt.toml"),
            "--measured",
            record.to_str().unwrap(),
            "--free",
            "surface.damping,mechanics.force",
            "--format",
            "json",
        ],
        0,
    );
    assert_valid("fit", &fit, "record fit");
    // A prior with a breaking curve, so the fit reports its breaking terms
    // (this one fits in a few thousand evaluations; the G5LE's takes 10 s).
    let prior = root().join("parts/priors/te-v23145-12v.toml");
    let fit = json_of(&["fit", prior.to_str().unwrap(), "--format", "json"], 0);
    assert_valid("fit", &fit, "datasheet fit");
    assert!(
        fit["breaking"]["rows"]
            .as_array()
            .is_some_and(|r| !r.is_empty()),
        "{fit}"
    );
}

#[test]
fn the_parts_list_and_every_part_match_their_schemas() {
    let list = json_of(&["parts", "--format", "json"], 0);
    assert_valid("parts", &list, "parts");
    let names: Vec<String> = list
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap().to_owned())
        .collect();
    assert!(names.len() >= 6);
    for name in names {
        let part = json_of(&["parts", &name, "--format", "json"], 0);
        assert_valid("part", &part, &name);
        assert_eq!(part["name"], name.as_str());
        assert!(part["scenario"]["mechanics"]["mass"].is_number(), "{part}");
    }
}

/// Every command's JSON on every bundled example and every bundled part
/// (blades, pole faces, arcs, coils, envelopes included) validates: a
/// field added to any output without its schema fails here.
#[test]
fn every_command_on_every_example_and_part_matches_its_schema() {
    let Some(_) = common::ngspice() else { return };
    let mut examples: Vec<PathBuf> = std::fs::read_dir(root().join("examples/scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    examples.sort();
    assert!(examples.len() >= 12, "{examples:?}");
    let mut validated = 0;
    let mut validate_command = |command: &str, name: &str, path: &str, extra: &[&str]| {
        let out = Command::cargo_bin("chatterspice")
            .unwrap()
            .args([command, path, "--format", "json"])
            .args(extra)
            .output()
            .unwrap();
        // A command that refuses the scenario (`run` without a circuit,
        // `bounce` of a coil relay without a drive voltage) prints no JSON.
        if out.status.code() == Some(2) {
            return false;
        }
        let doc: Value =
            serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{command} {path}: {e}"));
        assert_valid(name, &doc, &format!("{command} {path}"));
        validated += 1;
        true
    };
    // The electrical life is left out: its document is validated on its
    // own (`life`) and inside `check` (min_electrical_life) by the tests
    // above, and pricing the examples' endurance figures (life.toml,
    // valve-24v*.toml) took half of this test's time.
    let no_life = ["--no-life"];
    for path in &examples {
        let path = path.to_str().unwrap();
        validate_command("bounce", "bounce", path, &[]);
        // `check` carries its run (its schema holds it to the run's) and the
        // life: `run` itself is validated where `check` has no document.
        if !validate_command("check", "check", path, &no_life) {
            validate_command("run", "run", path, &no_life);
        }
    }
    let dir = tempfile::tempdir().unwrap();
    for part in chatterspice::calibrate::parts::all().iter().map(|p| p.name) {
        let path = dir.path().join(format!("{part}.toml"));
        std::fs::write(
            &path,
            format!("base = \"part:{part}\"\n[limits]\nmax_bounces = 1000\n"),
        )
        .unwrap();
        let path = path.to_str().unwrap();
        validate_command("bounce", "bounce", path, &[]);
        validate_command("check", "check", path, &[]);
        validate_command("check", "check", path, &["--envelope", "--samples", "4"]);
    }
    assert!(validated >= 60, "{validated} documents validated");
}

/// `raw --signal … --format json`: the probe analysis of a raw file.
#[test]
fn raw_signal_analysis_matches_its_schema() {
    let raw = root().join("tests/data/raw");
    let mut n = 0;
    for entry in std::fs::read_dir(&raw).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "raw") {
            continue;
        }
        let stats = Command::cargo_bin("chatterspice")
            .unwrap()
            .args(["raw", path.to_str().unwrap(), "--format", "json"])
            .output()
            .unwrap();
        if !stats.status.success() {
            continue;
        }
        let doc: Value = serde_json::from_slice(&stats.stdout).unwrap();
        // The first voltage of a transient plot, against fixed thresholds.
        if doc["plots"][0]["name"] != "Transient Analysis" {
            continue;
        }
        let Some(vector) = doc["plots"][0]["variables"].as_array().and_then(|v| {
            v.iter()
                .find(|x| x["name"].as_str().is_some_and(|n| n.starts_with("v(")))
        }) else {
            continue;
        };
        let name = vector["name"].as_str().unwrap();
        let out = Command::cargo_bin("chatterspice")
            .unwrap()
            .args([
                "raw",
                path.to_str().unwrap(),
                "--signal",
                name,
                "--low",
                "0.3",
                "--high",
                "0.6",
            ])
            .args(["--format", "json"])
            .output()
            .unwrap();
        if !out.status.success() {
            continue;
        }
        let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_valid("raw-signal", &doc, &path.display().to_string());
        n += 1;
    }
    assert!(n >= 3, "{n} raw files analysed");
}

/// `life` on the built-in relay: two printed figures at the same DC load
/// put the same arc energy into the contacts, so calibrated on the first
/// the model predicts the second at the first's operations; an AC figure
/// is averaged over the phases asked for; the scenario's own circuit gets
/// B / E_op; the JSON is as its schema says; figures that cannot be
/// simulated name their key.
#[test]
fn life_calibrates_on_one_figure_and_predicts_the_others() {
    if common::ngspice().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let netlist = dir.path().join("load.cir");
    std::fs::write(
        &netlist,
        "30 V, 30 ohm\nV1 vcc 0 30\nR1 vcc a 30\nX1 a 0 CONTACT\n.tran 1u 20m 0 2u\n.end\n",
    )
    .unwrap();
    let base = chatterspice::scenario::DEFAULT_SCENARIO_TOML;
    let cut = base.find("[circuit]").unwrap();
    let text = format!(
        "{}[circuit]\nnetlist = {:?}\n\n[arc]\nmaterial = \"Ag\"\n\n[datasheet]\n\
         electrical_endurance = [\n\
           {{ operations = 1.0e5, voltage = 30.0, current = 1.0, supply = \"dc\" }},\n\
           {{ operations = 4.0e5, voltage = 30.0, current = 1.0, supply = \"dc\" }},\n\
           {{ operations = 5.0e4, voltage = 125.0, current = 10.0, supply = \"ac\", frequency = 60.0 }},\n\
         ]\nweibull_shape = 2.0\n",
        &base[..cut],
        netlist.display().to_string()
    );
    let path = dir.path().join("life.toml");
    std::fs::write(&path, &text).unwrap();
    let doc = json_of(
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
    assert_valid("life", &doc, "life");
    let figures = doc["figures"].as_array().unwrap();
    let e1 = figures[0]["energy_per_operation"].as_f64().unwrap();
    let w1 = figures[0]["wear_per_operation"].as_f64().unwrap();
    assert!(e1 > 0.0 && w1 > 0.0, "{doc}");
    let b = doc["constant_j"].as_f64().unwrap();
    // A DC operation counts DC_TRANSFER times its wear, an AC one
    // (V/250 V)^q: at 125 V, 2^-q.
    let dc = chatterspice::life::DC_TRANSFER;
    let q = chatterspice::life::VOLTAGE_EXPONENT;
    assert_eq!(doc["dc_wear_factor"].as_f64(), Some(dc));
    assert_eq!(doc["voltage_exponent"].as_f64(), Some(q));
    assert_eq!(figures[0]["wear_factor"].as_f64(), Some(dc));
    let ac = figures[2]["wear_factor"].as_f64().unwrap();
    assert!((ac - 0.5f64.powf(q)).abs() < 1e-12, "{doc}");
    assert!((b / (1.0e5 * w1 * dc) - 1.0).abs() < 1e-12);
    let w3 = figures[2]["wear_per_operation"].as_f64().unwrap();
    assert!((figures[2]["predicted"].as_f64().unwrap() * w3 * ac / b - 1.0).abs() < 1e-12);
    // An arc wears E·(Ī/1 A)^p: the wear of an operation lies between its
    // energy times the least and the largest of its arcs' currents to the
    // p, so the 10 A figure's wear per joule exceeds the 1 A one's.
    let p = doc["current_exponent"].as_f64().unwrap();
    assert_eq!(p, chatterspice::life::CURRENT_EXPONENT);
    let e3 = figures[2]["energy_per_operation"].as_f64().unwrap();
    assert!(w3 / e3 > w1 / e1, "{doc}");
    assert!((figures[0]["ratio"].as_f64().unwrap() - 1.0).abs() < 1e-12);
    // The same load, printed four times longer: predicted at the first's.
    assert!(
        (figures[1]["predicted"].as_f64().unwrap() / 1.0e5 - 1.0).abs() < 1e-9,
        "{doc}"
    );
    assert!((figures[1]["ratio"].as_f64().unwrap() - 0.25).abs() < 1e-9);
    assert_eq!(figures[0]["phases"], 1);
    assert_eq!(figures[2]["phases"], 2);
    // 10 A at 125 V AC burns far longer than 1 A at 30 V DC breaks.
    assert!(
        figures[2]["energy_per_operation"].as_f64().unwrap() > 10.0 * e1,
        "{doc}"
    );
    let own = &doc["life"];
    let w_own = own["wear_per_operation"].as_f64().unwrap();
    assert!(own["energy_per_operation"].as_f64().unwrap() > 0.0 && w_own > 0.0);
    let n = own["operations"].as_f64().unwrap();
    // The circuit is DC: no sine source.
    assert_eq!(own["wear_factor"].as_f64(), Some(dc));
    assert!((n * w_own * dc / b - 1.0).abs() < 1e-12);
    let expected_b10 = chatterspice::life::b10(n, 2.0);
    assert!((own["b10"].as_f64().unwrap() / expected_b10 - 1.0).abs() < 1e-12);

    // `check` holds the circuit's life to min_electrical_life.
    for (limit, code) in [(0.5 * n, 0), (2.0 * n, 1)] {
        std::fs::write(
            &path,
            format!("{text}\n[limits]\nmin_electrical_life = {limit}\n"),
        )
        .unwrap();
        let out = Command::cargo_bin("chatterspice")
            .unwrap()
            // The AC figure's phases as `life` above took them (B is the
            // DC figure's, the circuit is DC: the phases move neither).
            .args(["check", path.to_str().unwrap(), "--format", "json"])
            .args(["--life-phases", "2"])
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(code),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let verdict: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_valid("check", &verdict, "check with min_electrical_life");
        let row = verdict["checks"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["key"] == "limits.min_electrical_life")
            .expect("the life check");
        assert!(
            (row["actual"].as_f64().unwrap() / n - 1.0).abs() < 0.05,
            "{row}"
        );
    }

    // Bad figures: exit 2, naming what to fix.
    for (bad, says) in [
        (
            text.replacen("current = 1.0, supply", "current = -1.0, supply", 1),
            "electrical_endurance[0].current",
        ),
        (
            text.replace("supply = \"ac\"", "supply = \"ac\", load = \"motor\""),
            "resistive",
        ),
        (
            text.replace("weibull_shape = 2.0", "weibull_shape = -1.0"),
            "weibull_shape",
        ),
    ] {
        std::fs::write(&path, &bad).unwrap();
        let out = Command::cargo_bin("chatterspice")
            .unwrap()
            .args(["life", path.to_str().unwrap()])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(says), "{says}: {stderr}");
    }
}
