//! What ships beside the code: the licence files the manifest names, and
//! shell completions that know every command.

use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_chatterspice"))
}

#[test]
fn both_licences_the_manifest_names_ship() {
    let root = env!("CARGO_MANIFEST_DIR");
    let manifest = std::fs::read_to_string(format!("{root}/Cargo.toml")).unwrap();
    assert!(manifest.contains(r#"license = "MIT OR Apache-2.0""#));
    let mit = std::fs::read_to_string(format!("{root}/LICENSE-MIT")).unwrap();
    assert!(mit.contains("Permission is hereby granted, free of charge"));
    let apache = std::fs::read_to_string(format!("{root}/LICENSE-APACHE")).unwrap();
    assert!(apache.contains("Apache License") && apache.contains("Version 2.0"));
}

#[test]
fn completions_know_every_command_and_bash_parses_its_script() {
    let commands = [
        "run",
        "bounce",
        "pwl",
        "check",
        "raw",
        "sweep",
        "merge",
        "capture",
        "fit",
        "parts",
        "completions",
    ];
    for shell in ["bash", "zsh", "fish"] {
        let out = bin().args(["completions", shell]).output().unwrap();
        assert!(out.status.success(), "{shell}");
        let text = String::from_utf8(out.stdout).unwrap();
        for c in commands {
            assert!(text.contains(c), "{shell} completion lacks {c}");
        }
        if shell == "bash" && Command::new("bash").arg("--version").output().is_ok() {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("chatterspice.bash");
            std::fs::write(&path, &text).unwrap();
            let check = Command::new("bash").arg("-n").arg(&path).status().unwrap();
            assert!(check.success(), "bash -n rejects the script");
        }
    }
    let bad = bin().args(["completions", "tcsh"]).output().unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
