//! The batch runner against real ngspice: a good run, each failure class
//! from a deliberately broken deck, a timeout, parallel runs; and, with
//! small shell scripts standing in for ngspice, a crash, a flood of output,
//! a truncated and a garbage raw file.
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use chatterspice::spice::{Exit, Failure, Ngspice, RunRequest, Runner, SpiceError};

const RC: &str =
    "RC step\nV1 in 0 PWL(0 0 1n 1)\nR1 in out 1k\nC1 out 0 1u\n.tran 50u 5m 0 50u\n.end\n";

fn failure_of(result: Result<chatterspice::spice::RunOutput, SpiceError>) -> (Failure, String) {
    match result {
        Err(e @ SpiceError::Failed { .. }) => (e.failure().unwrap().clone(), e.to_string()),
        Err(e) => panic!("expected a classified failure, got: {e}"),
        Ok(_) => panic!("expected a failure, the run succeeded"),
    }
}

#[test]
fn good_run_returns_the_raw_file_version_and_no_workdir() {
    let ng = ngspice_or_skip!();
    assert!(ng.version().is_some(), "ngspice -v names its version");
    let out = ng.run(&RunRequest::new(RC)).unwrap();
    assert_eq!(out.version.as_deref(), ng.version());
    assert!(out.workdir.is_none());
    let p = &out.raw.plots[0];
    let v = p.real("v(out)").unwrap();
    // 5 time constants: 1 − e⁻⁵ within ngspice's RELTOL.
    assert!((v[v.len() - 1] - (1.0 - (-5f64).exp())).abs() < 1e-3);
    assert!(out.log.contains("Circuit: rc step"), "{}", out.log);
    assert!(
        !out.log.contains("Reference value"),
        "progress lines are dropped"
    );
}

#[test]
fn kept_workdir_holds_deck_includes_and_raw() {
    let ng = ngspice_or_skip!();
    let mut req = RunRequest::new(
        "RC with its parts in an include\n.include parts.inc\nV1 in 0 DC 1\nX1 in out RCSTAGE\n.op\n.end\n",
    );
    req.includes.push((
        "parts.inc".into(),
        ".subckt RCSTAGE a b\nR1 a b 1k\nR2 b 0 3k\n.ends\n".into(),
    ));
    req.keep_workdir = true;
    let out = ng.run(&req).unwrap();
    let dir = out.workdir.clone().expect("kept");
    for f in ["deck.cir", "parts.inc", "out.raw"] {
        assert!(dir.join(f).is_file(), "{f} in {}", dir.display());
    }
    assert!((out.raw.plots[0].real("v(out)").unwrap()[0] - 0.75).abs() < 1e-12);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn include_names_with_directories_are_refused() {
    let ng = ngspice_or_skip!();
    let mut req = RunRequest::new(RC);
    req.includes.push(("../escape.inc".into(), String::new()));
    assert!(matches!(ng.run(&req), Err(SpiceError::IncludeName { .. })));
}

#[test]
fn netlist_error_names_the_line_the_workdir_and_the_log() {
    let ng = ngspice_or_skip!();
    let deck = "Bad netlist\nV1 in 0 DC 1\nR1 in out 1kxyz+\nC1 out 0 1u\n.tran 1u 1m\n.end\n";
    let (failure, msg) = failure_of(ng.run(&RunRequest::new(deck)));
    assert_eq!(
        failure,
        Failure::Netlist {
            line: Some(3),
            text: Some("r1 in out 1kxyz+".into()),
            reason: "unknown parameter (+)".into()
        }
    );
    eprintln!("{msg}");
    assert!(msg.contains("work directory: "), "{msg}");
    assert!(msg.contains("chatterspice-"), "{msg}");
    assert!(msg.contains("ngspice log (last lines)"), "{msg}");
}

#[test]
fn missing_include_is_its_own_failure() {
    let ng = ngspice_or_skip!();
    let deck = "Missing include\n.include nosuchfile.lib\nV1 in 0 DC 1\nR1 in 0 1k\n.op\n.end\n";
    let (failure, _) = failure_of(ng.run(&RunRequest::new(deck)));
    assert_eq!(
        failure,
        Failure::MissingInclude {
            file: "nosuchfile.lib".into()
        }
    );
}

#[test]
fn timestep_too_small_reports_time_and_node() {
    let ng = ngspice_or_skip!();
    let deck = std::fs::read_to_string(data("decks/timestep.cir")).unwrap();
    let (failure, msg) = failure_of(ng.run(&RunRequest::new(deck)));
    match failure {
        Failure::TimestepTooSmall {
            analysis,
            time: Some(t),
            timestep: Some(_),
            node: Some(node),
        } => {
            assert_eq!(analysis, "TRAN");
            assert!(t > 0.0 && t < 2e-3, "{t}");
            assert_eq!(node, "a");
        }
        other => panic!("{other:?}"),
    }
    eprintln!("{msg}");
    assert!(msg.contains("timestep too small at t = "), "{msg}");
}

#[test]
fn singular_matrix_names_the_node() {
    let ng = ngspice_or_skip!();
    let deck = std::fs::read_to_string(data("decks/singular_op.cir")).unwrap();
    let (failure, _) = failure_of(ng.run(&RunRequest::new(deck)));
    assert!(
        matches!(&failure, Failure::SingularMatrix { node: Some(n), .. } if n == "v1#branch"),
        "{failure:?}"
    );
}

#[test]
fn operating_point_without_convergence() {
    let ng = ngspice_or_skip!();
    let deck = std::fs::read_to_string(data("decks/no_convergence.cir")).unwrap();
    let (failure, _) = failure_of(ng.run(&RunRequest::new(deck)));
    assert!(
        matches!(failure, Failure::NoConvergence { ref analysis, .. } if analysis == "OP"),
        "{failure:?}"
    );
}

#[test]
fn warnings_alone_are_not_a_failure() {
    let ng = ngspice_or_skip!();
    let deck = std::fs::read_to_string(data("decks/ok_with_warnings.cir")).unwrap();
    let out = ng.run(&RunRequest::new(deck)).unwrap();
    assert!(
        out.warnings.iter().any(|w| w.contains("singular matrix")),
        "{:?}",
        out.warnings
    );
}

#[test]
fn deck_without_analysis_writes_no_raw_file() {
    let ng = ngspice_or_skip!();
    let err = ng
        .run(&RunRequest::new(
            "No analysis\nV1 a 0 DC 1\nR1 a 0 1k\n.end\n",
        ))
        .unwrap_err();
    assert!(matches!(err, SpiceError::MissingRaw { .. }), "{err}");
    assert!(err.to_string().contains("analysis line"), "{err}");
}

#[test]
fn a_run_of_hours_is_killed_at_the_timeout() {
    let ng = ngspice_or_skip!();
    // TSTART just before TSTOP: ngspice integrates ~1e12 steps and saves
    // nothing until then, so the raw file stays empty while it grinds.
    let deck = "Hours of work\nV1 in 0 SIN(0 1 1k)\nR1 in out 1k\nC1 out 0 1u\n.tran 1n 1000 999 1n\n.end\n";
    let mut req = RunRequest::new(deck);
    req.timeout = Duration::from_secs(2);
    let started = Instant::now();
    let err = ng.run(&req).unwrap_err();
    let elapsed = started.elapsed();
    assert!(matches!(err, SpiceError::Timeout { .. }), "{err}");
    assert!(
        elapsed >= Duration::from_secs(2) && elapsed < Duration::from_secs(6),
        "{elapsed:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("2 s timeout") && msg.contains("work directory"),
        "{msg}"
    );
    let dir = &err.context().unwrap().workdir;
    assert!(!dir.exists(), "work directory removed after the kill");
}

#[test]
fn parallel_runs_do_not_mix() {
    let ng = ngspice_or_skip!();
    std::thread::scope(|s| {
        let handles: Vec<_> = (1..=6)
            .map(|k| {
                let ng = &ng;
                s.spawn(move || {
                    // Divider with R2 = k kΩ: v(mid) = k/(1+k).
                    let deck = format!(
                        "Divider {k}\nV1 in 0 DC 1\nR1 in mid 1k\nR2 mid 0 {k}k\n.op\n.end\n"
                    );
                    let out = ng.run(&RunRequest::new(deck)).unwrap();
                    let v = out.raw.plots[0].real("v(mid)").unwrap()[0];
                    (k, v)
                })
            })
            .collect();
        for h in handles {
            let (k, v) = h.join().unwrap();
            let expect = k as f64 / (1.0 + k as f64);
            assert!((v - expect).abs() < 1e-12, "k = {k}: {v} vs {expect}");
        }
    });
}

#[test]
fn missing_binary_names_the_install_command() {
    let err = Ngspice::locate(Some(Path::new("/nonexistent/bin/ngspice"))).unwrap_err();
    assert!(matches!(err, SpiceError::NotFound { .. }));
    let msg = err.to_string();
    assert!(msg.contains("apt-get install -y ngspice"), "{msg}");
}

fn data(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(rel)
}

/// A shell script standing in for ngspice; it is called as
/// `script -b -r out.raw deck.cir` (and `script -v` for the probe).
#[cfg(unix)]
fn fake_ngspice(dir: &Path, body: &str) -> Ngspice {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join("fake-ngspice");
    std::fs::write(&path, format!("#!/bin/sh\n{body}\n")).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    Ngspice::locate(Some(&path)).unwrap()
}

#[cfg(unix)]
#[test]
fn a_signal_is_a_crash() {
    let tmp = tempfile::tempdir().unwrap();
    let ng = fake_ngspice(tmp.path(), "[ \"$1\" = -v ] && exit 0\nkill -SEGV $$");
    let (failure, _) = failure_of(ng.run(&RunRequest::new(RC)));
    assert_eq!(
        failure,
        Failure::Crashed {
            exit: Exit::Signal(11)
        }
    );
    let ng = fake_ngspice(tmp.path(), "echo 'fatal: oops' >&2\nexit 3");
    let (failure, msg) = failure_of(ng.run(&RunRequest::new(RC)));
    assert_eq!(
        failure,
        Failure::Crashed {
            exit: Exit::Code(3)
        }
    );
    assert!(
        msg.contains("fatal: oops"),
        "the log tail is in the message: {msg}"
    );
}

#[cfg(unix)]
#[test]
fn megabytes_on_both_streams_do_not_stall_the_child() {
    let tmp = tempfile::tempdir().unwrap();
    let raw = data("raw/rc_tran.raw");
    let body = format!(
        "i=0\nwhile [ $i -lt 20000 ]; do echo \"Warning: noise line $i on stderr\" >&2; \
         echo \"Note: noise line $i on stdout\"; i=$((i+1)); done\ncp '{}' \"$3\"",
        raw.display()
    );
    let ng = fake_ngspice(tmp.path(), &body);
    let mut req = RunRequest::new(RC);
    req.timeout = Duration::from_secs(30);
    let out = ng.run(&req).unwrap();
    assert_eq!(out.raw.plots[0].points(), 128);
    assert!(out.log.contains("noise line 19999 on stderr"));
    assert!(out.log.contains("noise line 19999 on stdout"));
}

#[cfg(unix)]
#[test]
fn truncated_or_garbage_raw_files_are_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let cut = data("raw/killed_binary.raw");
    let ng = fake_ngspice(tmp.path(), &format!("cp '{}' \"$3\"", cut.display()));
    let err = ng.run(&RunRequest::new(RC)).unwrap_err();
    assert!(matches!(err, SpiceError::TruncatedRaw { .. }), "{err}");

    let ng = fake_ngspice(tmp.path(), "echo 'not a raw file' > \"$3\"");
    let err = ng.run(&RunRequest::new(RC)).unwrap_err();
    assert!(matches!(err, SpiceError::BadRaw { .. }), "{err}");
    assert!(err.to_string().contains("line 1"), "{err}");
}

/// An RC stage of `r` ohms whose capacitor is in an include named
/// `parts.inc` (the same name in every deck, a different text).
#[cfg(unix)]
fn rc_with_include(r: u32) -> RunRequest {
    let mut req = RunRequest::new(format!(
        "RC {r}\nV1 in 0 PWL(0 0 1n 1)\nR1 in out {r}\n.include parts.inc\n.tran 50u 5m 0 50u\n.end\n"
    ));
    req.includes
        .push(("parts.inc".into(), format!("C1 out 0 {}n\n", r / 2)));
    req
}

/// ngspice behind a script that counts its runs (the version probe aside).
#[cfg(unix)]
fn counted_ngspice(dir: &Path) -> (Ngspice, PathBuf) {
    let count = dir.join("runs");
    let body = format!(
        "[ \"$1\" = -v ] && exec ngspice -v\necho run >> '{}'\nexec ngspice \"$@\"",
        count.display()
    );
    (fake_ngspice(dir, &body), count)
}

#[cfg(unix)]
fn runs(count: &Path) -> usize {
    std::fs::read_to_string(count).map_or(0, |s| s.lines().count())
}

#[cfg(unix)]
#[test]
fn many_decks_share_one_process_and_give_what_single_runs_give() {
    if ngspice_or_skip!().version().is_none() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let (ng, count) = counted_ngspice(tmp.path());
    let reqs: Vec<RunRequest> = [1000, 2000, 3000, 4000].map(rc_with_include).to_vec();
    let many = ng.run_many(&reqs);
    assert_eq!(runs(&count), 1, "four decks, one ngspice process");
    for (req, out) in reqs.iter().zip(many) {
        let out = out.unwrap();
        let alone = ng.run(req).unwrap();
        let (a, b) = (
            out.raw.last_transient().unwrap(),
            alone.raw.last_transient().unwrap(),
        );
        // Each deck read its own include: the same values, point for point.
        for name in ["time", "v(out)", "v(in)"] {
            assert_eq!(a.real(name), b.real(name), "{name} of {}", req.deck);
        }
        assert!(
            out.log.contains(&req.deck[..7].to_lowercase()),
            "{}",
            out.log
        );
    }
    assert_eq!(runs(&count), 5);
}

#[cfg(unix)]
#[test]
fn a_failing_deck_among_many_fails_as_it_would_alone_and_the_others_run() {
    if ngspice_or_skip!().version().is_none() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let (ng, count) = counted_ngspice(tmp.path());
    let broken = RunRequest::new("broken\nR1 in 0 1k\nQ1 a b\n.tran 1u 1m\n.end\n");
    // A deck with its own control block is never batched.
    let controlled = RunRequest::new(
        "controlled\nV1 in 0 DC 2\nR1 in 0 1k\n.tran 1u 1m\n.control\nrun\n.endc\n.end\n",
    );
    let reqs = vec![
        rc_with_include(1000),
        broken.clone(),
        rc_with_include(2000),
        controlled.clone(),
    ];
    let [first, second, third, fourth] = <[_; 4]>::try_from(ng.run_many(&reqs)).ok().unwrap();
    let (failure, _) = failure_of(second);
    let (alone, _) = failure_of(ng.run(&broken));
    assert_eq!(failure, alone);
    for good in [first, third] {
        let out = good.unwrap();
        let v = out.raw.last_transient().unwrap().real("v(out)").unwrap();
        assert!(*v.last().unwrap() > 0.9);
    }
    assert!(fourth.is_ok(), "{:?}", fourth.err().map(|e| e.to_string()));
    // The batch of three (its failure seen), then each again on its own,
    // the control deck alone, and the lone run of the broken deck.
    assert_eq!(runs(&count), 1 + 3 + 1 + 1);
}
