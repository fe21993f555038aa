//! The envelope's circuit runs gathered into rounds, so that one simulator
//! process serves many relays.
//!
//! Each relay of an envelope runs the same pipeline as a plain run, on a
//! thread of its own, and asks its runner for one circuit pass at a time.
//! [`Gather`] is that runner: a request waits until every relay thread
//! still working has asked too (or left), and then the whole round goes
//! to the real runner's [`Runner::run_many`], split into one share per
//! job, the shares at once. ngspice runs a share as one process that
//! sources its decks in turn, which saves its start-up on every deck but
//! the first; every relay still gets exactly the result, or the error, a
//! run of its own would give.

use std::collections::HashMap;
use std::io;
use std::path::PathBuf;
use std::sync::{Condvar, Mutex, MutexGuard};

use crate::spice::{RunContext, RunOutput, RunRequest, Runner, SpiceError};

/// A runner that gathers the requests of `active` relay threads into
/// rounds for `inner`, `jobs` processes at a time.
pub(crate) struct Gather<'a> {
    inner: &'a dyn Runner,
    jobs: usize,
    state: Mutex<State>,
    wake: Condvar,
}

/// What the relay threads share.
#[derive(Default)]
struct State {
    /// Relay threads that have not left.
    active: usize,
    /// Requests waiting for the next round, by ticket.
    queue: Vec<(usize, RunRequest)>,
    /// Results of finished rounds not yet taken, by ticket.
    results: HashMap<usize, Result<RunOutput, SpiceError>>,
    /// The next ticket.
    tickets: usize,
    /// A round is running.
    running: bool,
}

impl<'a> Gather<'a> {
    /// A gatherer for `active` relay threads, each of which calls
    /// [`Gather::leave`] (or drops its [`Gather::member`]) when it has no
    /// more requests.
    pub(crate) fn new(inner: &'a dyn Runner, jobs: usize, active: usize) -> Gather<'a> {
        Gather {
            inner,
            jobs: jobs.max(1),
            state: Mutex::new(State {
                active,
                ..State::default()
            }),
            wake: Condvar::new(),
        }
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// A relay thread is done: rounds no longer wait for it.
    pub(crate) fn leave(&self) {
        self.lock().active -= 1;
        self.wake.notify_all();
    }

    /// A relay thread's membership: it leaves when the value is dropped,
    /// however the thread ends.
    pub(crate) fn member(&self) -> Member<'_, 'a> {
        Member(self)
    }

    /// Runs one round: `round` split into up to `jobs` shares of
    /// consecutive requests, each share through `inner.run_many` at once.
    fn round(&self, round: &[(usize, RunRequest)]) -> Vec<(usize, Result<RunOutput, SpiceError>)> {
        let shares = self.jobs.min(round.len()).max(1);
        let size = round.len().div_ceil(shares);
        std::thread::scope(|scope| {
            let handles: Vec<_> = round
                .chunks(size)
                .map(|share| {
                    scope.spawn(move || {
                        let reqs: Vec<RunRequest> =
                            share.iter().map(|(_, req)| req.clone()).collect();
                        let outputs = self.inner.run_many(&reqs);
                        share
                            .iter()
                            .map(|(ticket, _)| *ticket)
                            .zip(outputs)
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            handles
                .into_iter()
                .zip(round.chunks(size))
                .flat_map(|(handle, share)| {
                    handle.join().unwrap_or_else(|_| {
                        share
                            .iter()
                            .map(|(ticket, _)| (*ticket, Err(panicked())))
                            .collect()
                    })
                })
                .collect()
        })
    }
}

/// A relay thread's membership of a [`Gather`]: dropping it leaves.
pub(crate) struct Member<'g, 'a>(&'g Gather<'a>);

impl Drop for Member<'_, '_> {
    fn drop(&mut self) {
        self.0.leave();
    }
}

/// The error of a request whose round's runner panicked.
fn panicked() -> SpiceError {
    SpiceError::Process {
        program: PathBuf::from("ngspice"),
        source: io::Error::other("the simulator's runner stopped (panicked) during the run"),
        context: Box::new(RunContext {
            workdir: PathBuf::new(),
            kept: false,
            log_tail: String::new(),
        }),
    }
}

impl Runner for Gather<'_> {
    fn run(&self, req: &RunRequest) -> Result<RunOutput, SpiceError> {
        let mut state = self.lock();
        let ticket = state.tickets;
        state.tickets += 1;
        state.queue.push((ticket, req.clone()));
        self.wake.notify_all();
        loop {
            if let Some(result) = state.results.remove(&ticket) {
                return result;
            }
            if !state.running && !state.queue.is_empty() && state.queue.len() >= state.active {
                let round = std::mem::take(&mut state.queue);
                state.running = true;
                drop(state);
                let results = self.round(&round);
                state = self.lock();
                state.results.extend(results);
                state.running = false;
                self.wake.notify_all();
                continue;
            }
            state = self.wake.wait(state).unwrap_or_else(|e| e.into_inner());
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicUsize, Ordering};

    use super::*;
    use crate::rawfile::RawFile;

    /// Counts the calls of `run_many` and the requests in each; answers
    /// every request with an error naming its deck.
    #[derive(Default)]
    struct Counting {
        calls: AtomicUsize,
        largest: AtomicUsize,
    }

    impl Runner for Counting {
        fn run(&self, req: &RunRequest) -> Result<RunOutput, SpiceError> {
            Ok(RunOutput {
                raw: RawFile {
                    plots: Vec::new(),
                    warnings: Vec::new(),
                },
                log: req.deck.clone(),
                version: None,
                elapsed: std::time::Duration::ZERO,
                workdir: None,
                warnings: Vec::new(),
            })
        }

        fn run_many(&self, reqs: &[RunRequest]) -> Vec<Result<RunOutput, SpiceError>> {
            self.calls.fetch_add(1, Ordering::SeqCst);
            self.largest.fetch_max(reqs.len(), Ordering::SeqCst);
            reqs.iter().map(|r| self.run(r)).collect()
        }
    }

    #[test]
    fn every_request_gets_its_own_result_in_rounds_of_all_waiting_threads() {
        let inner = Counting::default();
        let threads = 12;
        let gather = Gather::new(&inner, 2, threads);
        std::thread::scope(|scope| {
            for t in 0..threads {
                let gather = &gather;
                scope.spawn(move || {
                    // Some threads ask twice, one never asks.
                    let asks = if t == 0 { 0 } else { 1 + t % 2 };
                    for k in 0..asks {
                        let deck = format!("deck {t} {k}");
                        let out = gather.run(&RunRequest::new(deck.clone()));
                        assert_eq!(out.map(|o| o.log).ok(), Some(deck));
                    }
                    gather.leave();
                });
            }
        });
        // 17 requests: the first round takes every thread's first request
        // (11, in two shares), the second the 6 second ones.
        assert!(inner.largest.load(Ordering::SeqCst) >= 5);
        assert!(inner.calls.load(Ordering::SeqCst) <= 6);
    }

    #[test]
    fn a_thread_that_panics_leaves_and_no_round_waits_for_it() {
        let inner = Counting::default();
        let gather = Gather::new(&inner, 2, 3);
        let answered = AtomicUsize::new(0);
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            std::thread::scope(|scope| {
                for t in 0..3 {
                    let (gather, answered) = (&gather, &answered);
                    scope.spawn(move || {
                        let _member = gather.member();
                        if t == 0 {
                            panic!("a relay's analysis failed");
                        }
                        let deck = format!("deck {t}");
                        let out = gather.run(&RunRequest::new(deck.clone()));
                        assert_eq!(out.map(|o| o.log).ok(), Some(deck));
                        answered.fetch_add(1, Ordering::SeqCst);
                    });
                }
            });
        }));
        assert!(outcome.is_err(), "the panic reaches the scope");
        assert_eq!(
            answered.load(Ordering::SeqCst),
            2,
            "the others were answered"
        );
    }
}
