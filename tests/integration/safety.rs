//! What a hostile or careless file must never do, through the real
//! binary and real ngspice: run a command, destroy an input, hang the
//! tool, or leave processes and work directories behind.

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use predicates::prelude::*;

use crate::common::{scenario_with_netlist, script};

fn chatterspice() -> Command {
    Command::cargo_bin("chatterspice").unwrap()
}

/// `shell touch <marker>` as ngspice would run it.
fn touch(marker: &Path) -> String {
    format!("shell touch {}", marker.display())
}

/// Every way a command reaches ngspice from data: a `.control` block in an
/// include, in a nested include, in a `.lib` section, a `*#` line in an
/// include and at the top level, and a `.CONTROLS` spelled the way
/// ngspice's prefix match accepts. None runs; the circuit still does, and
/// each is named by file and line.
#[test]
fn no_command_in_any_included_file_runs() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let markers: Vec<PathBuf> = (0..6).map(|i| d.join(format!("ran{i}"))).collect();
    std::fs::create_dir(d.join("lib")).unwrap();
    std::fs::write(
        d.join("lib/inner.inc"),
        format!(
            "* nested\nR9 vdd 0 1meg\n.control\n{}\n.endc\n",
            touch(&markers[0])
        ),
    )
    .unwrap();
    std::fs::write(
        d.join("lib/board.inc"),
        format!(
            "* board\n.include inner.inc\n*# {}\nR1 vdd sw 10k\n.CONTROLS\n{}\n.endc\n.end\nR8 vdd 0 2meg\n",
            touch(&markers[1]),
            touch(&markers[2])
        ),
    )
    .unwrap();
    std::fs::write(
        d.join("lib/models.lib"),
        format!(
            ".lib other\n.control\n{}\n.endc\n.endl\n.lib typ\nR7 vdd 0 3meg\n.control\n{}\n.endc\n.endl typ\n",
            touch(&markers[3]),
            touch(&markers[4])
        ),
    )
    .unwrap();
    let netlist = format!(
        "pull-up\n*# {}\nVDD vdd 0 DC 3.3\n.inc lib/board.inc\n.lib lib/models.lib typ\nX1 sw 0 CONTACT\n.tran 100n 5m\n.end\n",
        touch(&markers[5])
    );
    let scenario = scenario_with_netlist(d, &netlist);
    let out = chatterspice()
        .current_dir(d)
        .args(["run", "--format", "json", "--no-ideal"])
        .arg(&scenario)
        .assert()
        .success();
    for m in &markers {
        assert!(!m.exists(), "{} was created: a command ran", m.display());
        // ngspice lower-cases `*#` commands before it runs them.
        let lower = PathBuf::from(m.to_string_lossy().to_lowercase());
        assert!(!lower.exists(), "{}", lower.display());
    }
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    for (file, line) in [
        ("inner.inc", "lines 3-5"),
        ("board.inc", "line 3"),
        ("board.inc", "lines 5-7"),
        ("models.lib", "lines 8-10"),
        ("circuit.cir", "line 2"),
    ] {
        assert!(
            stderr
                .lines()
                .any(|l| l.contains(file) && l.contains(line) && l.contains("left out")),
            "no warning for {file} {line}:\n{stderr}"
        );
    }
    // The circuit itself ran: the contact's edges reached v(sw).
    let report: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    assert!(
        report["probes"][0]["edges"].as_u64().unwrap() > 1,
        "{report}"
    );
}

/// A netlist whose first line makes ngspice read it as a script is refused
/// before ngspice sees it.
#[test]
fn an_ng_script_title_is_refused() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let marker = dir.path().join("script_ran");
    let scenario = scenario_with_netlist(
        dir.path(),
        &format!(
            "*NG_SCRIPT\n{}\nVDD vdd 0 DC 3.3\nR1 vdd sw 10k\nX1 sw 0 CONTACT\n.tran 100n 5m\n.end\n",
            touch(&marker)
        ),
    );
    let out = chatterspice()
        .args(["run", "--no-ideal"])
        .arg(&scenario)
        .assert()
        .code(2);
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(
        stderr.contains("circuit.cir: line 1") && stderr.contains("*ng_script"),
        "{stderr}"
    );
    assert!(!marker.exists());
}

/// Includes that include each other are an error naming the line, not a
/// hang.
#[test]
fn an_include_cycle_is_refused() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.inc"), "R1 a 0 1k\n.include b.inc\n").unwrap();
    std::fs::write(d.join("b.inc"), "R2 a 0 1k\n.include a.inc\n").unwrap();
    let scenario = scenario_with_netlist(
        d,
        "t\nVDD vdd 0 DC 3.3\n.include a.inc\nR1 vdd sw 10k\nX1 sw 0 CONTACT\n.tran 100n 5m\n.end\n",
    );
    let out = chatterspice()
        .args(["run", "--no-ideal"])
        .arg(&scenario)
        .timeout(std::time::Duration::from_secs(20))
        .assert()
        .code(2);
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(
        stderr.contains("b.inc: line 2") && stderr.contains("circle"),
        "{stderr}"
    );
}

/// A stand-in for ngspice: answers the version check, then runs `body`.
fn fake_ngspice(dir: &Path, body: &str) -> PathBuf {
    script(
        dir,
        "fake-ngspice.sh",
        &format!("if [ \"$1\" = -v ]; then echo '** ngspice-39 : fake'; exit 0; fi\n{body}"),
    )
}

/// Whether process `pid` is running (a zombie is not).
fn running(pid: &str) -> bool {
    let stat = std::fs::read_to_string(format!("/proc/{}/stat", pid.trim())).unwrap_or_default();
    let state = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .next();
    !matches!(state, None | Some("Z") | Some("X"))
}

fn work_dirs(tmp: &Path) -> Vec<String> {
    std::fs::read_dir(tmp)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("chatterspice"))
        .collect()
}

/// Waits for the child to exit, at most `limit`; kills it and fails the
/// test when it does not.
fn wait_for(
    child: &mut std::process::Child,
    limit: std::time::Duration,
) -> std::process::ExitStatus {
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("still running {limit:?} after the signal");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// SIGINT to the whole process group (Ctrl-C) and SIGTERM or SIGINT to the
/// tool alone: every ngspice it started is gone, its work directories are
/// removed, and it exits with 130/143 within 3 s.
#[test]
fn a_signal_stops_ngspice_and_removes_the_work_directories() {
    use std::os::unix::process::CommandExt;
    for (signal, whole_group, code) in [
        (libc::SIGINT, true, 130),
        (libc::SIGTERM, false, 143),
        (libc::SIGINT, false, 130),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let tmp = dir.path().join("tmp");
        std::fs::create_dir(&tmp).unwrap();
        let pids = dir.path().join("pids");
        let ngspice = fake_ngspice(
            dir.path(),
            &format!("echo $$ >> '{}'\nexec sleep 60\n", pids.display()),
        );
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("chatterspice"))
            .args(["run", "--timeout", "100", "--ngspice"])
            .arg(&ngspice)
            .env("TMPDIR", &tmp)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .process_group(0)
            .spawn()
            .unwrap();
        // Both runs (bounced and ideal) under way.
        let start = std::time::Instant::now();
        while std::fs::read_to_string(&pids)
            .unwrap_or_default()
            .lines()
            .count()
            < 2
        {
            assert!(start.elapsed().as_secs() < 20, "ngspice never started");
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        assert_eq!(work_dirs(&tmp).len(), 2);
        let pid = child.id() as i32;
        // SAFETY: kill(2) reads no memory of ours.
        unsafe { libc::kill(if whole_group { -pid } else { pid }, signal) };
        let status = wait_for(&mut child, std::time::Duration::from_secs(3));
        assert_eq!(status.code(), Some(code), "signal {signal}");
        for ngspice_pid in std::fs::read_to_string(&pids).unwrap().lines() {
            assert!(
                !running(ngspice_pid),
                "ngspice {ngspice_pid} outlived signal {signal}"
            );
        }
        assert_eq!(work_dirs(&tmp), Vec::<String>::new(), "signal {signal}");
    }
}

/// An ngspice that prints without end, with or without newlines, is
/// stopped at `--timeout` with exit 2, and the tool stays small.
#[test]
fn endless_ngspice_output_is_bounded_and_timed_out() {
    for body in [
        "exec yes 'Warning: again and again'\n",
        "exec cat /dev/zero\n",
    ] {
        let dir = tempfile::tempdir().unwrap();
        let ngspice = fake_ngspice(dir.path(), body);
        let started = std::time::Instant::now();
        let out = std::process::Command::new(assert_cmd::cargo::cargo_bin("chatterspice"))
            .args(["run", "--no-ideal", "--timeout", "2", "--ngspice"])
            .arg(&ngspice)
            .output()
            .unwrap();
        let elapsed = started.elapsed();
        assert_eq!(out.status.code(), Some(2), "{body}");
        assert!(elapsed.as_secs_f64() < 4.0, "{body}: {elapsed:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("timeout"), "{stderr}");
        assert!(stderr.len() < 64 * 1024, "{} bytes of error", stderr.len());
    }
    // The largest resident size of any child this test process waited
    // for, chatterspice and its ngspice included.
    // SAFETY: getrusage writes the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    assert_eq!(
        unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) },
        0
    );
    assert!(
        usage.ru_maxrss < 500 * 1024,
        "max RSS {} kB",
        usage.ru_maxrss
    );
}

/// ngspice unable to write its raw file (a full disk) is reported as
/// that, naming the work directory, with no convergence wording.
#[test]
fn a_raw_file_write_failure_is_named_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let ngspice = fake_ngspice(
        dir.path(),
        "echo 'binary raw file \"out.raw\"'\necho 'Warning: rawfile write error !!'\n\
         echo 'doAnalyses: pause requested'\necho 'run simulation interrupted'\nexit 1\n",
    );
    let out = chatterspice()
        .args(["run", "--no-ideal", "--ngspice"])
        .arg(&ngspice)
        .env("TMPDIR", dir.path())
        .assert()
        .code(2);
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    let named = stderr.find("could not write its raw file").expect(&stderr);
    assert!(
        stderr[named..].contains(&dir.path().display().to_string()),
        "{stderr}"
    );
    assert!(named < stderr.find("ngspice log").unwrap(), "{stderr}");
    assert!(!stderr.contains("operating point"), "{stderr}");
}

/// ngspice crashes when HOME is unset; the run gives it one.
#[test]
fn a_run_works_with_home_unset() {
    let _ng = ngspice_or_skip!();
    chatterspice()
        .args(["run", "--no-ideal"])
        .env_remove("HOME")
        .assert()
        .success();
    chatterspice()
        .args(["run", "--no-ideal", "--no-spiceinit"])
        .env_remove("HOME")
        .assert()
        .success();
}

/// A directory where the last file of `run --out` goes: with --force the
/// run is refused before it starts, the earlier bundle and the directory
/// stay, and a rerun after moving it works without --force.
#[test]
fn a_run_bundle_is_all_or_nothing() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    chatterspice()
        .args(["run", "--no-ideal", "--out"])
        .arg(&out)
        .assert()
        .success();
    let report = std::fs::read(out.join("report.json")).unwrap();
    std::fs::remove_file(out.join("plot.png")).unwrap();
    std::fs::create_dir(out.join("plot.png")).unwrap();
    std::fs::write(out.join("plot.png/mine.txt"), "mine").unwrap();
    chatterspice()
        .args(["run", "--no-ideal", "--force", "--out"])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(predicates::str::contains("plot.png").and(predicates::str::contains("in the way")));
    assert_eq!(std::fs::read(out.join("report.json")).unwrap(), report);
    assert_eq!(
        std::fs::read(out.join("plot.png/mine.txt")).unwrap(),
        b"mine"
    );
    // Nothing of ours but the bundle: no lock, no temporary file.
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "contact.inc",
            "netlist.cir",
            "plot.png",
            "plot.svg",
            "report.json",
            "waveforms.csv",
            "waveforms.raw"
        ]
    );
    // A fresh directory: a run that fails leaves nothing to block its rerun.
    let fresh = dir.path().join("fresh");
    chatterspice()
        .args([
            "run",
            "--no-ideal",
            "--ngspice",
            "/nonexistent/ngspice",
            "--out",
        ])
        .arg(&fresh)
        .assert()
        .code(2);
    chatterspice()
        .args(["run", "--no-ideal", "--out"])
        .arg(&fresh)
        .assert()
        .success();
}

/// The solenoid example with a 10 µg armature: bounded in steps and
/// memory, exit 2 within seconds naming `mechanics.mass`.
#[test]
fn a_featherweight_armature_ends_with_exit_2_naming_the_mass() {
    let _ng = ngspice_or_skip!();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios");
    let text = std::fs::read_to_string(examples.join("solenoid.toml")).unwrap();
    let netlists = Path::new(env!("CARGO_MANIFEST_DIR")).join("netlists");
    let light: String = text
        .lines()
        .map(|l| {
            if l.starts_with("mass =") {
                "mass = 1e-8".to_owned()
            } else {
                l.replace("../../netlists/", &format!("{}/", netlists.display()))
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("light.toml");
    std::fs::write(&path, light).unwrap();
    let started = std::time::Instant::now();
    let out = chatterspice()
        .args(["run", "--no-ideal"])
        .arg(&path)
        .timeout(std::time::Duration::from_secs(60))
        .assert()
        .code(2);
    assert!(started.elapsed().as_secs() < 20, "{:?}", started.elapsed());
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(stderr.contains("`mechanics.mass` = 1e-8"), "{stderr}");
}

/// A FIFO given as any input is refused at once (exit 2, naming it),
/// not waited on for a writer that never comes.
#[test]
fn a_fifo_as_any_input_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fifo = d.join("pipe");
    let c = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).unwrap();
    // SAFETY: mkfifo reads the NUL-terminated path only.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    // A scenario whose netlist is the FIFO.
    let relay = chatterspice::scenario::DEFAULT_SCENARIO_TOML;
    let cut = relay.find("[circuit]").unwrap();
    let scenario = d.join("relay.toml");
    std::fs::write(
        &scenario,
        format!(
            "{}[circuit]\nnetlist = \"pipe\"\n\n[[probe]]\nsignal = \"v(sw)\"\nlow = 1\nhigh = 2\n",
            &relay[..cut]
        ),
    )
    .unwrap();
    // An include that is the FIFO.
    let with_include = scenario_with_netlist(
        &d.join("inc"),
        "t\n.include ../pipe\nX1 sw 0 CONTACT\n.tran 1u 5m\n.end\n",
    );
    let cases: Vec<(Vec<std::ffi::OsString>, &str)> = vec![
        (vec!["bounce".into(), fifo.clone().into()], "pipe"),
        (
            vec!["run".into(), "--no-ideal".into(), scenario.clone().into()],
            "pipe",
        ),
        (
            vec!["run".into(), "--no-ideal".into(), with_include.into()],
            "pipe",
        ),
        (vec!["capture".into(), fifo.clone().into()], "pipe"),
        (
            vec!["bounce".into(), "--measured".into(), fifo.clone().into()],
            "pipe",
        ),
        (vec!["raw".into(), fifo.clone().into()], "pipe"),
        (
            vec![
                "fit".into(),
                scenario.clone().into(),
                "--measured".into(),
                fifo.clone().into(),
            ],
            "pipe",
        ),
    ];
    for (args, name) in cases {
        let started = std::time::Instant::now();
        let out = chatterspice()
            .args(&args)
            .timeout(std::time::Duration::from_secs(10))
            .output()
            .unwrap();
        assert!(started.elapsed().as_secs() < 5, "{args:?}");
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains(name)
                && (stderr.contains("FIFO") || stderr.contains("not a regular file")),
            "{args:?}: {stderr}"
        );
    }
}
