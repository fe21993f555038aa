//! What a hostile or careless file must never do, through the real
//! binary and real ngspice: run a command, destroy an input, hang the
//! tool, or leave processes and work directories behind.

mod common;

use std::path::{Path, PathBuf};

use assert_cmd::Command;

fn chatterspice() -> Command {
    Command::cargo_bin("chatterspice").unwrap()
}

/// A scenario in `dir` using the default relay, with `netlist` as its
/// `[circuit]` netlist (written to `circuit.cir`) and one probe.
fn scenario_with_netlist(dir: &Path, netlist: &str) -> PathBuf {
    std::fs::write(dir.join("circuit.cir"), netlist).unwrap();
    let relay = chatterspice::scenario::DEFAULT_SCENARIO_TOML;
    let cut = relay.find("[circuit]").unwrap();
    let text = format!(
        "{}[circuit]\nnetlist = \"circuit.cir\"\n\n[[probe]]\nsignal = \"v(sw)\"\nlow = 0.99\nhigh = 2.31\n",
        &relay[..cut]
    );
    let path = dir.join("relay.toml");
    std::fs::write(&path, text).unwrap();
    path
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
