//! Helpers shared by the integration tests: ngspice or a skip, scenarios
//! and scripts in a test directory, and KiCad's S-expressions.

use chatterspice::spice::Ngspice;

/// ngspice, or `None` with a visible note when it is missing; a panic
/// instead when `REQUIRE_NGSPICE=1` (CI sets it), so that no test that
/// needs ngspice can pass by skipping.
pub fn ngspice() -> Option<Ngspice> {
    match Ngspice::find() {
        Ok(n) => Some(n),
        Err(e) if std::env::var("REQUIRE_NGSPICE").as_deref() == Ok("1") => {
            panic!("REQUIRE_NGSPICE=1 but ngspice is unusable: {e}")
        }
        Err(e) => {
            // Written to the stderr handle, not eprintln!, which the test
            // harness captures: the skip must be visible.
            use std::io::Write;
            let _ = writeln!(
                std::io::stderr(),
                "note: skipping a test that needs ngspice (set REQUIRE_NGSPICE=1 to fail instead): {e}"
            );
            None
        }
    }
}

/// An error and its causes, one per line: what a failed test should show.
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut msg = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        msg.push_str(&format!("\n  caused by: {s}"));
        source = s.source();
    }
    msg
}

/// `let ng = ngspice_or_skip!();` at the top of a test.
macro_rules! ngspice_or_skip {
    () => {
        match $crate::common::ngspice() {
            Some(n) => n,
            None => return,
        }
    };
}

/// A scenario in `dir` (created if needed) using the default relay, with
/// `netlist` as its `[circuit]` netlist text (written to `circuit.cir`)
/// and one probe, `v(sw)`.
pub fn scenario_with_netlist(dir: &std::path::Path, netlist: &str) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
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

/// An executable shell script `dir/name` running `body`.
pub fn script(dir: &std::path::Path, name: &str, body: &str) -> std::path::PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join(name);
    std::fs::write(&path, format!("#!/bin/sh\n{body}")).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

/// An S-expression (KiCad's files): an atom or a list.
#[derive(Debug)]
pub enum Sexp {
    Atom(String),
    List(Vec<Sexp>),
}

pub fn parse_sexp(text: &str) -> Sexp {
    fn list(chars: &mut std::iter::Peekable<std::str::Chars>) -> Vec<Sexp> {
        let mut out = Vec::new();
        while let Some(&c) = chars.peek() {
            match c {
                '(' => {
                    chars.next();
                    out.push(Sexp::List(list(chars)));
                }
                ')' => {
                    chars.next();
                    return out;
                }
                '"' => {
                    chars.next();
                    let mut s = String::new();
                    while let Some(c) = chars.next() {
                        match c {
                            '\\' => s.extend(chars.next()),
                            '"' => break,
                            c => s.push(c),
                        }
                    }
                    out.push(Sexp::Atom(s));
                }
                c if c.is_whitespace() => {
                    chars.next();
                }
                _ => {
                    let mut s = String::new();
                    while let Some(&c) = chars.peek() {
                        if c.is_whitespace() || c == '(' || c == ')' {
                            break;
                        }
                        s.push(c);
                        chars.next();
                    }
                    out.push(Sexp::Atom(s));
                }
            }
        }
        panic!("unbalanced S-expression");
    }
    let mut chars = text.trim().chars().peekable();
    assert_eq!(chars.next(), Some('('));
    let top = Sexp::List(list(&mut chars));
    assert!(chars.next().is_none(), "text after the S-expression");
    top
}

pub fn head(s: &Sexp) -> Option<&str> {
    match s {
        Sexp::List(items) => match items.first() {
            Some(Sexp::Atom(a)) => Some(a),
            _ => None,
        },
        Sexp::Atom(_) => None,
    }
}

pub fn atom(s: &Sexp, k: usize) -> Option<&str> {
    match s {
        Sexp::List(items) => match items.get(k) {
            Some(Sexp::Atom(a)) => Some(a),
            _ => None,
        },
        Sexp::Atom(_) => None,
    }
}

/// Every list under `s` whose head is `name`.
pub fn all<'a>(s: &'a Sexp, name: &str, out: &mut Vec<&'a Sexp>) {
    if let Sexp::List(items) = s {
        if head(s) == Some(name) {
            out.push(s);
        }
        for item in items {
            all(item, name, out);
        }
    }
}

/// Whether `text` has consecutive whitespace-separated words, each
/// accepted by its matcher in turn (a plain pattern for the words a test
/// expects, without a regular-expression engine).
pub fn has_words(text: &str, matchers: &[&dyn Fn(&str) -> bool]) -> bool {
    let words: Vec<&str> = text.split_whitespace().collect();
    words
        .windows(matchers.len())
        .any(|w| w.iter().zip(matchers).all(|(word, m)| m(word)))
}

/// A matcher of exactly `expected`.
pub fn word(expected: &'static str) -> impl Fn(&str) -> bool {
    move |w: &str| w == expected
}
