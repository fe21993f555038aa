//! Soak test of the lock-step runner's isolation: many runs of a small
//! circuit with an external source through ngspice's shared library, each
//! in a process of its own, from a pool of worker threads; the caller's
//! memory is sampled as it goes and no process may be left behind.
//!
//! ```text
//! cargo run --release --example lockstep_soak -- RUNS JOBS
//! ```
//!
//! Prints the caller's resident memory after the first 1000 runs and at
//! the end, their ratio, and the number of child processes left; exits 1
//! if memory grew by more than 10 % or a process is left.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use chatterspice::spice::shared::{Session, library};

/// Answers the external source with a square wave and counts the points.
#[derive(Default)]
struct Square {
    points: usize,
    last: f64,
}

impl Session for Square {
    fn print(&mut self, _line: &str) {}
    fn vectors(&mut self, _names: &[String]) {}
    fn data(&mut self, values: &[f64]) {
        self.points += 1;
        self.last = values.first().copied().unwrap_or(0.0);
    }
    fn source(&mut self, _name: &str, time: f64) -> f64 {
        if (time * 1e4) as u64 % 2 == 0 {
            0.0
        } else {
            1.0
        }
    }
    fn sync(&mut self, _time: f64, _delta: &mut f64, _redo: bool, _location: i32) -> bool {
        false
    }
}

const DECK: &str = "soak\n\
V1 g 0 external\n\
R1 g out 1k\n\
C1 out 0 10n\n\
.tran 1u 1m\n\
.end\n";

/// kB of resident memory of this process.
fn rss_kb() -> usize {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

/// Child processes of this process still present.
fn children() -> usize {
    let me = std::process::id().to_string();
    std::fs::read_dir("/proc")
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| std::fs::read_to_string(e.path().join("stat")).ok())
        .filter(|stat| {
            // pid (comm) state ppid ...
            stat.rsplit_once(')')
                .and_then(|(_, rest)| rest.split_whitespace().nth(1).map(|p| p == me))
                .unwrap_or(false)
        })
        .count()
}

fn main() {
    let mut args = std::env::args().skip(1);
    let runs: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(10_000);
    let jobs: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(2);
    let lib = match library() {
        Ok(lib) => lib,
        Err(why) => {
            eprintln!("{why}");
            std::process::exit(2);
        }
    };
    let dir = tempfile::tempdir().expect("a work directory");
    let deck = dir.path().join("soak.cir");
    std::fs::write(&deck, DECK).expect("the deck");
    let source = format!("source {}", deck.display());
    let done = AtomicUsize::new(0);
    let failed = AtomicUsize::new(0);
    let after_1000 = AtomicUsize::new(0);
    let started = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..jobs {
            scope.spawn(|| {
                loop {
                    let k = done.fetch_add(1, Ordering::SeqCst);
                    if k >= runs {
                        break;
                    }
                    let answer = lib.run_isolated(Duration::from_secs(30), |lib| {
                        let mut session = Square::default();
                        lib.run_circuit(&mut session, &[&source, "run", "destroy all"]);
                        session.points.to_le_bytes().to_vec()
                    });
                    match answer {
                        Ok(bytes) if bytes.len() == 8 => {}
                        _ => {
                            failed.fetch_add(1, Ordering::SeqCst);
                        }
                    }
                    if k + 1 == 1000 {
                        after_1000.store(rss_kb(), Ordering::SeqCst);
                    }
                }
            });
        }
    });
    let end = rss_kb();
    let first = after_1000.load(Ordering::SeqCst).max(1);
    let left = children();
    let ratio = end as f64 / first as f64;
    println!(
        "{runs} runs on {jobs} threads in {:.1} s ({:.2} ms each), {} failed; \
         resident memory after 1000 runs {first} kB, at the end {end} kB (ratio {ratio:.3}); \
         {left} child processes left",
        started.elapsed().as_secs_f64(),
        started.elapsed().as_secs_f64() * 1e3 / runs as f64,
        failed.load(Ordering::SeqCst),
    );
    if ratio > 1.10 || left > 0 || failed.load(Ordering::SeqCst) > 0 {
        std::process::exit(1);
    }
}
