//! A runner that never starts ngspice: it answers with committed raw files
//! (or a canned failure), so the stages above ngspice — analysis, reports,
//! sweeps — are testable anywhere and fast.
//!
//! Rules are tried in order; the first whose needle occurs in the deck
//! answers (a rule without a needle answers everything). Every request is
//! recorded so tests can check the decks they generated.

use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Duration;

use super::classify::Failure;
use super::error::{RunContext, SpiceError};
use super::run::{RunOutput, RunRequest, Runner};
use crate::rawfile::RawFile;

#[derive(Debug, Clone)]
enum Answer {
    Raw(PathBuf),
    Fail(Failure),
    Timeout,
}

#[derive(Debug, Clone)]
struct Rule {
    needle: Option<String>,
    answer: Answer,
}

/// Serves raw files instead of simulating.
#[derive(Debug, Default)]
pub struct FakeRunner {
    rules: Vec<Rule>,
    requests: Mutex<Vec<RunRequest>>,
}

impl FakeRunner {
    /// Answers every run with the raw file at `path`.
    pub fn serving(path: impl Into<PathBuf>) -> FakeRunner {
        FakeRunner::default().otherwise(path)
    }

    /// Answers every run with `failure`.
    pub fn failing(failure: Failure) -> FakeRunner {
        FakeRunner {
            rules: vec![Rule {
                needle: None,
                answer: Answer::Fail(failure),
            }],
            ..FakeRunner::default()
        }
    }

    /// Decks containing `needle` get the raw file at `path`.
    pub fn when_deck_contains(
        mut self,
        needle: impl Into<String>,
        path: impl Into<PathBuf>,
    ) -> Self {
        self.rules.push(Rule {
            needle: Some(needle.into()),
            answer: Answer::Raw(path.into()),
        });
        self
    }

    /// Decks containing `needle` fail with `failure`.
    pub fn fail_when_deck_contains(mut self, needle: impl Into<String>, failure: Failure) -> Self {
        self.rules.push(Rule {
            needle: Some(needle.into()),
            answer: Answer::Fail(failure),
        });
        self
    }

    /// Decks containing `needle` time out.
    pub fn time_out_when_deck_contains(mut self, needle: impl Into<String>) -> Self {
        self.rules.push(Rule {
            needle: Some(needle.into()),
            answer: Answer::Timeout,
        });
        self
    }

    /// Decks no earlier rule matched get the raw file at `path`.
    pub fn otherwise(mut self, path: impl Into<PathBuf>) -> Self {
        self.rules.push(Rule {
            needle: None,
            answer: Answer::Raw(path.into()),
        });
        self
    }

    /// The requests seen so far, in order.
    pub fn requests(&self) -> Vec<RunRequest> {
        self.requests
            .lock()
            .map(|r| r.clone())
            .unwrap_or_else(|poisoned| poisoned.into_inner().clone())
    }
}

impl Runner for FakeRunner {
    fn run(&self, req: &RunRequest) -> Result<RunOutput, SpiceError> {
        match self.requests.lock() {
            Ok(mut r) => r.push(req.clone()),
            Err(poisoned) => poisoned.into_inner().push(req.clone()),
        }
        let rule = self.rules.iter().find(|r| {
            r.needle
                .as_ref()
                .is_none_or(|n| req.deck.contains(n.as_str()))
        });
        let context = |workdir: PathBuf, log: &str| {
            Box::new(RunContext {
                workdir,
                kept: true,
                log_tail: log.to_string(),
            })
        };
        let fake_dir = || PathBuf::from("<fake runner>");
        match rule.map(|r| &r.answer) {
            None => Err(SpiceError::MissingRaw {
                context: context(fake_dir(), "fake runner: no rule matches this deck"),
            }),
            Some(Answer::Fail(failure)) => Err(SpiceError::Failed {
                failure: failure.clone(),
                context: context(fake_dir(), "fake runner: canned failure"),
            }),
            Some(Answer::Timeout) => Err(SpiceError::Timeout {
                limit: req.timeout,
                context: context(fake_dir(), "fake runner: canned timeout"),
            }),
            Some(Answer::Raw(path)) => {
                let log = format!("fake runner: served {}\n", path.display());
                let dir = path.parent().map(PathBuf::from).unwrap_or_else(fake_dir);
                let raw = RawFile::read(path).map_err(|source| SpiceError::BadRaw {
                    source,
                    context: context(dir.clone(), &log),
                })?;
                let warnings = raw.warnings.iter().map(ToString::to_string).collect();
                Ok(RunOutput {
                    raw,
                    log,
                    version: Some("fake".into()),
                    elapsed: Duration::ZERO,
                    workdir: None,
                    warnings,
                })
            }
        }
    }
}

#[cfg(test)]
#[path = "fake_tests.rs"]
mod tests;
