//! Clean stops: what the process has started or left half-done, so that
//! SIGINT or SIGTERM can undo it before the process exits.
//!
//! The library records, while it runs:
//! - every child process group it starts (ngspice runs in a group of its
//!   own, so a Ctrl-C at the terminal reaches only chatterspice, which then
//!   decides), registered under the same lock as the spawn itself, so no
//!   child can be started unseen while a stop is under way;
//! - every temporary work directory it creates;
//! - finishers: short actions that make a half-written output whole (a
//!   sweep puts its finished rows where `--resume` finds them).
//!
//! [`install`] (called by the binary, never implicitly by the library)
//! starts a thread that waits for SIGINT, SIGTERM or SIGHUP and then, with
//! the registry locked: kills every registered process group (SIGKILL),
//! removes every registered directory, runs the finishers, and exits with
//! 128 + the signal number (130 for SIGINT, 143 for SIGTERM).

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicI32, AtomicUsize, Ordering};

/// A finisher: run once, at a stop.
type Finisher = Box<dyn FnOnce() + Send>;

#[derive(Default)]
struct Registry {
    next: u64,
    children: Vec<(u64, i32)>,
    dirs: Vec<(u64, PathBuf)>,
    finishers: Vec<(u64, Finisher)>,
}

static REGISTRY: Mutex<Option<Registry>> = Mutex::new(None);
/// The signal that stopped the process, 0 while running.
static STOPPING: AtomicI32 = AtomicI32::new(0);

fn with<R>(f: impl FnOnce(&mut Registry) -> R) -> R {
    let mut guard = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    f(guard.get_or_insert_with(Registry::default))
}

fn key(registry: &mut Registry) -> u64 {
    registry.next += 1;
    registry.next
}

/// Cancellations in force (see [`cancel`]): while any is, no child is
/// started.
static CANCELLING: AtomicUsize = AtomicUsize::new(0);

/// The signal a stop is under way for, if one is.
pub fn stopping() -> Option<i32> {
    match STOPPING.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// A registration: dropping it removes the entry (the work is done, or
/// the caller cleans up itself).
#[derive(Debug)]
#[must_use = "the entry is removed when this is dropped"]
pub struct Registered(u64);

impl Drop for Registered {
    fn drop(&mut self) {
        let id = self.0;
        with(|r| {
            r.children.retain(|(k, _)| *k != id);
            r.dirs.retain(|(k, _)| *k != id);
            r.finishers.retain(|(k, _)| *k != id);
        });
    }
}

/// Spawns a child with `spawn` and registers its process group (the
/// child must lead a group of its own), atomically with respect to a stop:
/// once a stop has begun, nothing new is started.
pub fn spawn_registered<T>(
    spawn: impl FnOnce() -> std::io::Result<T>,
    pid_of: impl FnOnce(&T) -> u32,
) -> std::io::Result<(T, Registered)> {
    with(|r| {
        if stopping().is_some() || CANCELLING.load(Ordering::SeqCst) > 0 {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "the run is being stopped by a signal",
            ));
        }
        let child = spawn()?;
        let id = key(r);
        if let Ok(pid) = i32::try_from(pid_of(&child)) {
            r.children.push((id, pid));
        }
        Ok((child, Registered(id)))
    })
}

/// Removes `dir` (recursively; or the file of that name) at a stop.
pub fn remove_at_stop(dir: &Path) -> Registered {
    with(|r| {
        let id = key(r);
        r.dirs.push((id, dir.to_path_buf()));
        Registered(id)
    })
}

/// Runs `finish` at a stop (unless the returned registration is dropped
/// first).
pub fn finish_at_stop(finish: impl FnOnce() + Send + 'static) -> Registered {
    with(|r| {
        let id = key(r);
        r.finishers.push((id, Box::new(finish)));
        Registered(id)
    })
}

/// Runs `f` unless a stop is under way, excluding the stop while it runs:
/// a write that a finisher reads back (a sweep's rows) is then either
/// wholly before the finisher or never made. `f` must not register
/// anything itself. Blocks for good once a stop holds the registry, as
/// the process is about to exit.
pub fn unless_stopping<R>(f: impl FnOnce() -> R) -> Option<R> {
    let _guard = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    if stopping().is_some() {
        return None;
    }
    Some(f())
}

/// Stops everything registered, as the signal handler does, and returns
/// the exit code for `signal`; the caller exits with it.
pub fn stop(signal: i32) -> i32 {
    STOPPING.store(signal, Ordering::SeqCst);
    let mut guard = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    let registry = guard.get_or_insert_with(Registry::default);
    #[cfg(unix)]
    for (_, pid) in &registry.children {
        // SAFETY: kill(2) with a negative pid signals that process group;
        // it reads no memory of ours.
        unsafe {
            libc::kill(-pid, libc::SIGKILL);
        }
    }
    // Reap them (they are this process's children), so that none is
    // still running when the process exits; SIGKILL takes effect at once
    // unless a process is stuck in the kernel, hence the bound.
    #[cfg(unix)]
    {
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(1);
        for (_, pid) in &registry.children {
            loop {
                let mut status = 0;
                // SAFETY: waitpid writes the status it is given.
                let r = unsafe { libc::waitpid(*pid, &mut status, libc::WNOHANG) };
                if r != 0 || std::time::Instant::now() > deadline {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(2));
            }
        }
    }
    for (_, path) in &registry.dirs {
        if std::fs::remove_dir_all(path).is_err() {
            let _ = std::fs::remove_file(path);
        }
    }
    for (_, finish) in registry.finishers.drain(..) {
        finish();
    }
    // The lock stays held: nothing else starts before the exit.
    std::mem::forget(guard);
    128 + signal
}

/// Installs the handler for SIGINT, SIGTERM and SIGHUP: a thread that
/// [`stop`]s and exits. For binaries; call it once, early.
#[cfg(unix)]
pub fn install() -> std::io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new()
        .name("signals".to_owned())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let code = stop(signal);
                eprintln!(
                    "chatterspice: stopped by signal {signal}; ngspice runs and work directories \
                     removed"
                );
                std::process::exit(code);
            }
        })?;
    Ok(())
}

/// No signals to handle.
#[cfg(not(unix))]
pub fn install() -> std::io::Result<()> {
    Ok(())
}

/// A cancellation in force: until it is dropped, starting a child fails
/// as it does during a stop.
#[derive(Debug)]
#[must_use = "new children are refused only while this lives"]
pub struct Cancelling(());

impl Drop for Cancelling {
    fn drop(&mut self) {
        CANCELLING.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Stops the work under way without exiting, for an embedding that goes
/// on running (the Python package on Ctrl-C): refuses new children while
/// the returned guard lives and kills every registered process group now
/// (SIGKILL). The runs see their ngspice killed, fail, and reap it and
/// remove their work directories as they unwind; nothing is reaped here.
/// It reaches every run of the process, not one caller's.
pub fn cancel() -> Cancelling {
    with(|r| {
        CANCELLING.fetch_add(1, Ordering::SeqCst);
        #[cfg(unix)]
        for (_, pid) in &r.children {
            // SAFETY: kill(2) with a negative pid signals that process
            // group; it reads no memory of ours.
            unsafe {
                libc::kill(-pid, libc::SIGKILL);
            }
        }
        #[cfg(not(unix))]
        let _ = r;
        Cancelling(())
    })
}
