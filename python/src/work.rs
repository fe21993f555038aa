//! Long calls as Python expects them: the work runs on a thread of its
//! own with the GIL released, while the calling thread waits in short
//! slices, and between slices runs Python's signal handlers and the
//! caller's progress callback.
//!
//! A Ctrl-C (KeyboardInterrupt), a SIGTERM or an exception from the
//! callback cancels the work: every ngspice process of the process is
//! killed and no new one starts until the work has unwound (its work
//! directories are removed as it does), a sweep stops writing rows, and
//! the exception is raised within [`POLL`] plus [`UNWIND`] of the
//! signal. Work that cannot be stopped (the mechanics of a long
//! simulation) finishes on its thread, unseen.
//!
//! Python runs signal handlers only on the main thread, so a call made
//! from another thread is interrupted only by a callback's exception.
//! During a call from the main thread a SIGTERM whose handler is
//! Python's default (the process ends) raises `SystemExit(143)` instead,
//! so that the work is stopped and cleaned up before the process ends.

use std::io;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use pyo3::exceptions::PySystemExit;
use pyo3::prelude::*;

use crate::error::Failure;

/// How long the calling thread waits between two looks at signals and
/// progress.
const POLL: Duration = Duration::from_millis(20);
/// How long a cancelled call waits for its work to unwind before it
/// raises anyway.
const UNWIND: Duration = Duration::from_millis(300);
/// SIGTERM's number, as Linux and macOS give it.
const SIGTERM: i32 = 15;

/// What the work and the calling thread share: the progress counts and
/// the cancellation.
#[derive(Debug, Default)]
pub struct Ticker {
    done: AtomicU64,
    total: AtomicU64,
    cancelled: AtomicBool,
}

impl Ticker {
    /// Whether the call has been cancelled.
    pub fn cancelled(&self) -> bool {
        self.cancelled.load(Ordering::SeqCst)
    }

    /// The work has `total` steps.
    pub fn start(&self, total: u64) {
        self.total.store(total, Ordering::SeqCst);
    }

    /// `n` more steps are done.
    pub fn advance(&self, n: u64) {
        self.done.fetch_add(n, Ordering::SeqCst);
    }

    fn counts(&self) -> (u64, u64) {
        (
            self.done.load(Ordering::SeqCst),
            self.total.load(Ordering::SeqCst),
        )
    }
}

impl chatterspice::sweep::Progress for Ticker {
    fn start(&self, total: u64) {
        Ticker::start(self, total);
    }

    fn advance(&self, done: u64) {
        Ticker::advance(self, done);
    }

    fn stopped(&self) -> bool {
        self.cancelled()
    }
}

/// A byte sink that refuses writes once the call is cancelled, so that a
/// sweep writing its rows to it stops.
pub struct Sink {
    pub bytes: Vec<u8>,
    ticker: Arc<Ticker>,
}

impl Sink {
    pub fn new(ticker: Arc<Ticker>) -> Sink {
        Sink {
            bytes: Vec::new(),
            ticker,
        }
    }
}

impl io::Write for Sink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if self.ticker.cancelled() {
            // Not `Interrupted`, which `write_all` takes as "try again".
            return Err(io::Error::other("the call was cancelled"));
        }
        self.bytes.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Runs `work` on a thread of its own and waits for it, the GIL
/// released, looking at signals and calling `progress(done, total)`
/// (when given, and the counts have changed) every [`POLL`].
pub fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(Arc<Ticker>) -> Result<T, Failure> + Send + 'static,
) -> PyResult<T> {
    let ticker = Arc::new(Ticker::default());
    let (tx, rx) = mpsc::sync_channel(1);
    // Shared with the waits below, which may run on any thread.
    let rx = Mutex::new(rx);
    let shared = Arc::clone(&ticker);
    let handle = std::thread::Builder::new()
        .name("chatterspice-call".to_owned())
        .spawn(move || {
            let _ = tx.send(work(shared));
        })
        .map_err(|e| Failure::simulation(format!("cannot start a thread for the call: {e}")))?;
    let terminate = TermHandler::install(py)?;
    let mut shown = (0, 0);
    let outcome = loop {
        match py.detach(|| lock(&rx).recv_timeout(POLL)) {
            Ok(result) => break Ok(result),
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                break Ok(Err(Failure::simulation(
                    "the call's work stopped without a result (a panic in the library)",
                )));
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
        }
        let tick = py.check_signals().and_then(|()| {
            let counts = ticker.counts();
            match progress {
                Some(callback) if counts != shown => {
                    shown = counts;
                    callback.call1(counts).map(drop)
                }
                _ => Ok(()),
            }
        });
        if let Err(e) = tick {
            break Err(e);
        }
    };
    let outcome = match outcome {
        Ok(result) => {
            let _ = handle.join();
            result.map_err(PyErr::from)
        }
        Err(e) => {
            cancel(py, &ticker, handle, &rx);
            Err(e)
        }
    };
    // Only now, with the work stopped: a second SIGTERM would end the
    // process at once.
    terminate.restore(py)?;
    let result = outcome?;
    // The last counts, so that a callback sees the work whole.
    if let Some(callback) = progress {
        let counts = ticker.counts();
        if counts != shown && counts.1 > 0 {
            callback.call1(counts)?;
        }
    }
    Ok(result)
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Stops the work: ngspice killed and refused, the ticker cancelled; waits
/// up to [`UNWIND`] for the work, then leaves it to finish on its own.
fn cancel<T: Send + 'static>(
    py: Python<'_>,
    ticker: &Ticker,
    handle: std::thread::JoinHandle<()>,
    rx: &Mutex<mpsc::Receiver<T>>,
) {
    ticker.cancelled.store(true, Ordering::SeqCst);
    let refusing = chatterspice::interrupt::cancel();
    let until = Instant::now() + UNWIND;
    let finished = py.detach(|| {
        lock(rx)
            .recv_timeout(until.saturating_duration_since(Instant::now()))
            .is_ok()
    });
    if finished || handle.is_finished() {
        let _ = handle.join();
        drop(refusing);
    } else {
        // ngspice stays refused until the work has unwound.
        let _ = std::thread::Builder::new()
            .name("chatterspice-unwind".to_owned())
            .spawn(move || {
                let _ = handle.join();
                drop(refusing);
            });
    }
}

/// Python's handler of SIGTERM while a call runs on the main thread, and
/// the handler it replaced.
struct TermHandler {
    previous: Option<Py<PyAny>>,
}

impl TermHandler {
    /// Replaces SIGTERM's default action (the process ends, leaving
    /// ngspice and work directories behind) by `SystemExit(143)`, raised
    /// where the call waits; nothing when called off the main thread or
    /// when the program handles SIGTERM itself.
    fn install(py: Python<'_>) -> PyResult<TermHandler> {
        let threading = py.import("threading")?;
        let main = threading.call_method0("main_thread")?;
        if !threading.call_method0("current_thread")?.is(&main) {
            return Ok(TermHandler { previous: None });
        }
        let signal = py.import("signal")?;
        let current = signal.call_method1("getsignal", (SIGTERM,))?;
        if !current.is(signal.getattr("SIG_DFL")?) {
            return Ok(TermHandler { previous: None });
        }
        let handler = wrap_pyfunction!(on_sigterm, py)?;
        signal.call_method1("signal", (SIGTERM, handler))?;
        Ok(TermHandler {
            previous: Some(current.unbind()),
        })
    }

    fn restore(self, py: Python<'_>) -> PyResult<()> {
        if let Some(previous) = self.previous {
            py.import("signal")?
                .call_method1("signal", (SIGTERM, previous))?;
        }
        Ok(())
    }
}

/// SIGTERM during a call: end the process as its default action would,
/// once the call has stopped its work.
#[pyfunction]
fn on_sigterm(signum: i32, frame: Bound<'_, PyAny>) -> PyResult<()> {
    let _ = frame;
    Err(PySystemExit::new_err(128 + signum))
}
