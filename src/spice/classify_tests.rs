//! The tests of `classify.rs`: in a file of their own, so that the
//! checkout's test data they name stays out of the module's code.

use super::*;

fn log(name: &str) -> String {
    let path = format!("{}/tests/data/logs/{name}.log", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

#[test]
fn successful_runs_with_notes_and_warnings_are_not_failures() {
    assert_eq!(classify(Exit::Code(0), &log("ok")), None);
    let noisy = log("ok_with_warnings");
    assert!(noisy.contains("Warning: singular matrix"));
    assert_eq!(classify(Exit::Code(0), &noisy), None);
    assert!(warnings(&noisy).contains(&"Warning: singular matrix:  check node b".to_string()));
    assert_eq!(
        classify(
            Exit::Code(0),
            "Using SPARSE 1.3 as Direct Linear Solver\nNote: x\n"
        ),
        None
    );
}

#[test]
fn parse_error_names_line_text_and_reason() {
    assert_eq!(
        classify(Exit::Code(1), &log("bad_model_line")),
        Some(Failure::Netlist {
            line: Some(5),
            text: Some("q1 out in".into()),
            reason: "could not find a valid modelname".into()
        })
    );
    assert_eq!(
        classify(Exit::Code(1), &log("bad_value")),
        Some(Failure::Netlist {
            line: Some(3),
            text: Some("r1 in out 1kxyz+".into()),
            reason: "unknown parameter (+)".into()
        })
    );
    // Parse errors do not always fail the exit code: the text decides.
    assert!(matches!(
        classify(Exit::Code(0), &log("bad_value")),
        Some(Failure::Netlist { line: Some(3), .. })
    ));
}

/// The banner ngspice writes on stdout, landing anywhere among the
/// error's lines on stderr, changes nothing.
#[test]
fn a_parse_error_reads_the_same_however_the_two_pipes_interleave() {
    let alone = classify(Exit::Code(1), &log("bad_model_line"));
    assert!(matches!(
        alone,
        Some(Failure::Netlist { text: Some(_), .. })
    ));
    let text = log("bad_model_line");
    let lines: Vec<&str> = text.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with("Error on line"))
        .expect("the log has the error");
    for banner in [
        "",
        "Note: No compatibility mode selected!",
        "Circuit: broken",
    ] {
        for after in [at, at + 1] {
            let mut mixed = lines.clone();
            mixed.insert(after + 1, banner);
            mixed.insert(after + 1, "");
            let mixed = mixed.join("\n");
            assert_eq!(classify(Exit::Code(1), &mixed), alone, "{mixed}");
        }
    }
}

#[test]
fn missing_include_and_unknown_subcircuit() {
    assert_eq!(
        classify(Exit::Code(1), &log("bad_include")),
        Some(Failure::MissingInclude {
            file: "nosuchfile.lib".into()
        })
    );
    assert!(matches!(
        classify(Exit::Code(1), &log("bad_subckt")),
        Some(Failure::Netlist { text: Some(t), .. }) if t == "x1 in 0 nosuch"
    ));
}

#[test]
fn timestep_too_small_carries_time_step_and_node() {
    assert_eq!(
        classify(Exit::Code(1), &log("timestep")),
        Some(Failure::TimestepTooSmall {
            analysis: "TRAN".into(),
            time: Some(1.15193e-10),
            timestep: Some(8.10458e-19),
            node: Some("a".into())
        })
    );
}

#[test]
fn singular_matrix_in_op_and_tran() {
    for name in ["singular_op", "singular_tran"] {
        let f = classify(Exit::Code(1), &log(name));
        assert!(
            matches!(&f, Some(Failure::SingularMatrix { node: Some(n), .. }) if n == "v1#branch"),
            "{name}: {f:?}"
        );
    }
}

#[test]
fn operating_point_without_convergence() {
    assert_eq!(
        classify(Exit::Code(1), &log("no_convergence")),
        Some(Failure::NoConvergence {
            analysis: "OP".into(),
            node: Some("out".into())
        })
    );
}

#[test]
fn crashes_and_unexplained_exits() {
    assert_eq!(
        classify(Exit::Signal(11), "anything"),
        Some(Failure::Crashed {
            exit: Exit::Signal(11)
        })
    );
    assert!(matches!(
        classify(Exit::Code(3), ""),
        Some(Failure::Crashed { .. })
    ));
    assert_eq!(
        classify(Exit::Code(1), "Note: fine\n"),
        Some(Failure::ExitStatus { code: 1 })
    );
    assert!(matches!(
        classify(Exit::Code(0), "Error: no such vector v(x)\n"),
        Some(Failure::ErrorMessage { .. })
    ));
}

#[test]
fn messages_say_what_to_change() {
    let f = classify(Exit::Code(1), &log("timestep"))
        .unwrap()
        .to_string();
    assert!(
        f.contains("t = 1.15193e-10 s") && f.contains("node \"a\""),
        "{f}"
    );
    let f = classify(Exit::Code(1), &log("bad_include"))
        .unwrap()
        .to_string();
    assert!(f.contains("includes"), "{f}");
}
