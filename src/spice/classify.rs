//! Reading an ngspice log: did the run fail, and why.
//!
//! ngspice's exit code alone is not enough: parse errors exit 0 in batch
//! mode without `-o`, and a failed `tran` inside `.control` keeps going.
//! Its stderr is not enough either: it is full of `Note:` and `Warning:`
//! lines (gmin stepping, "singular matrix" that gmin then cures, "Using
//! SPARSE") that are *not* failures — treating them as errors is the
//! classic wrapper bug. So [`classify`] looks for the messages that mean a
//! failure and reads the numbers out of them:
//!
//! - `Error on line N ...` + the offending text + the reason (parse errors);
//!   `Error: unknown subckt`, `Could not find include file`,
//!   `circuit not parsed`;
//! - `doAnalyses: TRAN:  Timestep too small; time = T, timestep = S:
//!   trouble with node "x"`;
//! - the operating point failing (`doAnalyses: OP: ...`, or the transient's
//!   initial point), which is a singular matrix when ngspice warned
//!   `singular matrix: check node x` on the way, no convergence otherwise;
//! - `run simulation(s) aborted` with nothing more specific;
//! - a signal or exit code 3 (crash), any other `Error` line, any other
//!   non-zero exit.
//!
//! The function is pure (text in, verdict out) and tested on logs captured
//! from ngspice 39 (`tests/data/logs/`).

use std::fmt;

/// How the ngspice process ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exit {
    /// Exited with this status code.
    Code(i32),
    /// Killed by a signal (Unix), e.g. 11 for a segmentation fault.
    Signal(i32),
}

/// A failed run, as read from the log.
#[derive(Debug, Clone, PartialEq)]
pub enum Failure {
    /// The deck did not parse.
    Netlist {
        /// Line in the deck (the title is line 1), when ngspice names one.
        line: Option<usize>,
        /// The offending element line, as ngspice echoes it (lowercased).
        text: Option<String>,
        /// What ngspice says is wrong.
        reason: String,
    },
    /// `.include`/`.lib` of a file ngspice cannot find.
    MissingInclude {
        /// The file, as ngspice names it.
        file: String,
    },
    /// The time step collapsed (to 1e-11·TMAX) during an analysis.
    TimestepTooSmall {
        /// `TRAN`, ...
        analysis: String,
        /// s, simulated time where it happened.
        time: Option<f64>,
        /// s, the step ngspice gave up at.
        timestep: Option<f64>,
        /// The node or branch ngspice blames, when it names one.
        node: Option<String>,
    },
    /// The circuit matrix is singular: a node without a DC path, or a loop
    /// of voltage sources/inductors.
    SingularMatrix {
        /// The analysis it happened in (`OP`, `TRAN`, ...), when known.
        analysis: Option<String>,
        /// The node or branch ngspice blames, when it names one.
        node: Option<String>,
    },
    /// No operating point: gmin and source stepping both failed.
    NoConvergence {
        /// The analysis that needed it (`OP`, `TRAN`, ...).
        analysis: String,
        /// The node or branch ngspice blames, when it names one.
        node: Option<String>,
    },
    /// `run simulation(s) aborted` without a recognised cause.
    Aborted,
    /// Killed by a signal or exit code 3 (ngspice's crash exit).
    Crashed {
        /// The signal or the exit code.
        exit: Exit,
    },
    /// An `Error` line no other class covers, e.g. from a `.control` block.
    ErrorMessage {
        /// The line, as ngspice printed it.
        message: String,
    },
    /// Non-zero exit with no recognised message.
    ExitStatus {
        /// The exit status.
        code: i32,
    },
}

fn fmt_opt_node(node: &Option<String>) -> String {
    node.as_deref()
        .map(|n| format!(", trouble with node \"{n}\""))
        .unwrap_or_default()
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::Netlist { line, text, reason } => {
                write!(f, "netlist error")?;
                if let Some(line) = line {
                    write!(f, " on line {line}")?;
                }
                if let Some(text) = text {
                    write!(f, " `{text}`")?;
                }
                write!(
                    f,
                    ": {reason}; fix the deck (line numbers count the title as line 1)"
                )
            }
            Failure::MissingInclude { file } => write!(
                f,
                "the deck includes `{file}`, which ngspice cannot find: pass its contents with \
                 the run request's includes, or give an absolute path"
            ),
            Failure::TimestepTooSmall {
                analysis,
                time,
                timestep,
                node,
            } => {
                write!(f, "{analysis} analysis stopped: timestep too small")?;
                if let Some(t) = time {
                    write!(f, " at t = {t:e} s")?;
                }
                if let Some(s) = timestep {
                    write!(f, " (step {s:e} s)")?;
                }
                write!(
                    f,
                    "{}; look for a discontinuity there (an ideal switch, a step without rise \
                     time, a behavioural source with a jump): give it a finite edge or a small \
                     capacitance to ground, or raise TMAX",
                    fmt_opt_node(node)
                )
            }
            Failure::SingularMatrix { analysis, node } => {
                write!(f, "singular matrix")?;
                if let Some(a) = analysis {
                    write!(f, " in the {a} analysis")?;
                }
                if let Some(n) = node {
                    write!(f, " (ngspice points at node \"{n}\")")?;
                }
                write!(
                    f,
                    ": a node has no DC path to ground, or voltage sources/inductors form a loop"
                )
            }
            Failure::NoConvergence { analysis, node } => write!(
                f,
                "{analysis}: no operating point found (gmin and source stepping failed){}; \
                 check behavioural sources and feedback loops, or help with .nodeset/.ic",
                fmt_opt_node(node)
            ),
            Failure::Aborted => write!(
                f,
                "ngspice aborted the simulation without naming a cause (see the log)"
            ),
            Failure::Crashed { exit } => match exit {
                Exit::Signal(s) => write!(f, "ngspice was killed by signal {s} (crash)"),
                Exit::Code(c) => write!(f, "ngspice crashed (exit code {c})"),
            },
            Failure::ErrorMessage { message } => write!(f, "ngspice reported: {message}"),
            Failure::ExitStatus { code } => write!(
                f,
                "ngspice exited with status {code} without a recognised error message"
            ),
        }
    }
}

/// Lines ngspice prints that never mean failure on their own.
pub fn is_benign(line: &str) -> bool {
    let l = line.trim_start();
    l.starts_with("Note:") || l.starts_with("Warning:") || l.starts_with("Using SPARSE")
}

/// The `Warning:` messages of a log, once each, in order of appearance.
pub fn warnings(log: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for line in log.lines() {
        // gmin-stepping chatter puts warnings mid-line ("Trying gmin = ... Warning: ...").
        if let Some(i) = line.find("Warning:") {
            let w = line[i..].trim().to_string();
            if !out.contains(&w) {
                out.push(w);
            }
        }
    }
    out
}

/// The failure a run ended with, or `None` for a successful run.
pub fn classify(exit: Exit, log: &str) -> Option<Failure> {
    if matches!(exit, Exit::Signal(_) | Exit::Code(3)) {
        return Some(Failure::Crashed { exit });
    }
    let lines: Vec<&str> = log.lines().map(str::trim).collect();
    if let Some(f) = netlist_failure(&lines) {
        return Some(f);
    }
    if let Some(f) = analysis_failure(&lines) {
        return Some(f);
    }
    if let Some(line) = lines
        .iter()
        .find(|l| l.starts_with("Error") || l.starts_with("ERROR"))
    {
        return Some(Failure::ErrorMessage {
            message: line.to_string(),
        });
    }
    match exit {
        Exit::Code(0) => None,
        Exit::Code(code) => Some(Failure::ExitStatus { code }),
        Exit::Signal(_) => Some(Failure::Crashed { exit }),
    }
}

fn netlist_failure(lines: &[&str]) -> Option<Failure> {
    // stdout and stderr arrive on two pipes: ngspice's stdout banner (its
    // notes, the circuit's title and the blank lines around them) can land
    // between an error and its text, in any order.
    let lines: Vec<&str> = lines
        .iter()
        .copied()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("Note: ") && !l.starts_with("Circuit: "))
        .collect();
    for (i, l) in lines.iter().enumerate() {
        if let Some(rest) = l.strip_prefix("Error on line ") {
            let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
            let text = lines
                .get(i + 1)
                .filter(|t| !t.is_empty())
                .map(|t| t.to_string());
            let reason = lines
                .get(i + 2)
                .filter(|r| !r.is_empty() && !r.starts_with("Simulation interrupted"))
                .map_or_else(
                    || "ngspice could not parse it".to_string(),
                    |r| r.to_string(),
                );
            return Some(Failure::Netlist {
                line: digits.parse().ok(),
                text,
                reason,
            });
        }
        if let Some(file) = l.strip_prefix("Error: Could not find include file") {
            return Some(Failure::MissingInclude {
                file: file.trim().to_string(),
            });
        }
        if let Some(text) = l.strip_prefix("Error: unknown subckt:") {
            return Some(Failure::Netlist {
                line: None,
                text: Some(text.trim().to_string()),
                reason: "unknown subcircuit: define it with .subckt or include its file".into(),
            });
        }
    }
    lines
        .iter()
        .find(|l| l.starts_with("Error: circuit not parsed"))
        .map(|_| Failure::Netlist {
            line: None,
            text: None,
            reason: "ngspice could not parse the circuit".into(),
        })
}

/// `trouble with node "x"` → `x`.
fn quoted_node(s: &str) -> Option<String> {
    let rest = &s[s.find("trouble with node")? + "trouble with node".len()..];
    let rest = rest.trim_start().trim_start_matches('"');
    let node: String = rest.chars().take_while(|&c| c != '"').collect();
    let node = node.trim().to_string();
    (!node.is_empty()).then_some(node)
}

/// `... name = 1.5e-6, ...` → 1.5e-6.
fn number_after(s: &str, name: &str) -> Option<f64> {
    let rest = &s[s.find(name)? + name.len()..];
    let num: String = rest
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '+' | '-'))
        .collect();
    num.parse().ok()
}

fn analysis_failure(lines: &[&str]) -> Option<Failure> {
    let singular_node = lines.iter().rev().find_map(|l| {
        let i = l.find("singular matrix:")?;
        let rest = &l[i..];
        let node = rest.split("check node").nth(1)?.trim();
        Some(node.split_whitespace().next()?.to_string())
    });
    let singular = singular_node.is_some() || lines.iter().any(|l| l.contains("singular matrix"));

    if let Some(l) = lines.iter().find(|l| l.starts_with("doAnalyses:")) {
        let body = l.trim_start_matches("doAnalyses:").trim();
        let analysis = body.split(':').next().unwrap_or("").trim().to_string();
        let node = quoted_node(body);
        let time = number_after(body, "time =");
        if time.is_some() {
            return Some(Failure::TimestepTooSmall {
                analysis,
                time,
                timestep: number_after(body, "timestep ="),
                node,
            });
        }
        // No time: the operating point (of .op, or the transient's first point).
        if singular && node.is_none() {
            return Some(Failure::SingularMatrix {
                analysis: Some(analysis),
                node: singular_node,
            });
        }
        return Some(Failure::NoConvergence { analysis, node });
    }
    if lines.iter().any(|l| l.contains("simulation(s) aborted")) {
        if singular {
            return Some(Failure::SingularMatrix {
                analysis: None,
                node: singular_node,
            });
        }
        return Some(Failure::Aborted);
    }
    None
}

#[cfg(test)]
#[path = "classify_tests.rs"]
mod tests;
