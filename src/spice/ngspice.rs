//! The real runner: ngspice in batch mode, one process and one work
//! directory per run.
//!
//! Which binary: an explicit path, else `CHATTERSPICE_NGSPICE`, else
//! `ngspice` on `PATH`. [`Ngspice::locate`] probes it once (`ngspice -v`)
//! for its version, so a missing install fails before any run with the
//! command that fixes it.
//!
//! A run writes `deck.cir` and the includes into a fresh temporary
//! directory (under the system temp dir unless told otherwise — never the
//! user's directories), runs `ngspice -b -r out.raw -D norefvalue deck.cir` there
//! without a shell, and collects stdout and stderr line by line on two
//! threads into one log, in arrival order. The main thread waits for the
//! child with a deadline; at the deadline it kills (SIGKILL) and reaps it.
//!
//! Many decks at once ([`Runner::run_many`]) share one process: each deck
//! and its includes go into a directory of their own, and a control script
//! sources them in turn (`cd`, `source`, `run`, `write`, `destroy`,
//! `remcirc`), which saves ngspice's start-up on every deck but the first.
//! A deck's result is taken from the batch only when it is certain: the
//! batch's log shows no failure, the deck got to its end marker, and its
//! raw file reads whole with a transient plot that reaches the deck's
//! `.tran` stop time. Any other deck (a failure, a deck with its own
//! `.control` block or with analyses besides one `.tran`, a kept work
//! directory) runs on its own, so its result and any error are exactly
//! those of [`Runner::run`].

use std::collections::VecDeque;
use std::ffi::OsStr;
use std::io::{self, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use super::classify::{self, Exit};
use super::error::{RunContext, SpiceError, log_tail};
use super::run::{RunOutput, RunRequest, Runner};
use crate::rawfile::{RawFile, RawWarning};

/// The environment variable naming the ngspice binary.
pub const ENV_VAR: &str = "CHATTERSPICE_NGSPICE";
/// The deck's file name inside the work directory.
pub const DECK_NAME: &str = "deck.cir";
/// The raw file's name inside the work directory.
pub const RAW_NAME: &str = "out.raw";

/// ngspice, located and probed.
#[derive(Debug, Clone)]
pub struct Ngspice {
    program: PathBuf,
    version: Option<String>,
    workdir_parent: Option<PathBuf>,
    skip_user_init: bool,
}

impl Ngspice {
    /// Finds ngspice: `explicit`, else `$CHATTERSPICE_NGSPICE`, else `PATH`;
    /// then asks it for its version.
    pub fn locate(explicit: Option<&Path>) -> Result<Ngspice, SpiceError> {
        Ngspice::locate_within(explicit, VERSION_TIMEOUT)
    }

    /// [`Ngspice::locate`], its version check killed after `timeout` (a
    /// wrapper script that hangs fails here, not after minutes).
    pub fn locate_within(
        explicit: Option<&Path>,
        timeout: Duration,
    ) -> Result<Ngspice, SpiceError> {
        let requested = match explicit {
            Some(p) => p.to_path_buf(),
            None => match std::env::var_os(ENV_VAR) {
                Some(p) if !p.is_empty() => PathBuf::from(p),
                _ => PathBuf::from("ngspice"),
            },
        };
        let program = resolve(&requested)?;
        let version = probe_version(&program, timeout)?;
        Ok(Ngspice {
            program,
            version,
            workdir_parent: None,
            skip_user_init: false,
        })
    }

    /// [`Ngspice::locate`] with no explicit path.
    pub fn find() -> Result<Ngspice, SpiceError> {
        Ngspice::locate(None)
    }

    /// Create work directories under `dir` instead of the system temp dir.
    pub fn workdir_parent(mut self, dir: impl Into<PathBuf>) -> Ngspice {
        self.workdir_parent = Some(dir.into());
        self
    }

    /// Skip the user's own ngspice start-up files (`~/.spiceinit`, and a
    /// `.spiceinit` in the run's directory, which holds none): ngspice is
    /// started with `-n`. The system `spinit`, which loads the XSPICE code
    /// models, is read either way.
    pub fn skip_user_init(mut self, skip: bool) -> Ngspice {
        self.skip_user_init = skip;
        self
    }

    /// The ngspice binary found.
    pub fn program(&self) -> &Path {
        &self.program
    }

    /// e.g. `"39"`; `None` if `-v` printed no `ngspice-N` banner.
    pub fn version(&self) -> Option<&str> {
        self.version.as_deref()
    }
}

/// A bare name is looked up on `PATH` here, so "not found" is decided (and
/// reported) before any work directory exists. A relative path (`./x.sh`)
/// is made absolute against the current directory: runs start ngspice in
/// a work directory of their own.
fn resolve(program: &Path) -> Result<PathBuf, SpiceError> {
    if program.components().count() > 1 || program.is_absolute() {
        let absolute = std::path::absolute(program).unwrap_or_else(|_| program.to_path_buf());
        return if absolute.is_file() {
            Ok(absolute)
        } else {
            Err(SpiceError::NotFound {
                program: program.to_path_buf(),
                source: io::Error::new(io::ErrorKind::NotFound, "no such file"),
            })
        };
    }
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .map(|dir| dir.join(program))
        .find(|candidate| candidate.is_file())
        .ok_or_else(|| SpiceError::NotFound {
            program: program.to_path_buf(),
            source: io::Error::new(io::ErrorKind::NotFound, "not on PATH"),
        })
}

/// How long [`Ngspice::locate`] waits for `ngspice -v`.
pub const VERSION_TIMEOUT: Duration = Duration::from_secs(20);

fn probe_version(program: &Path, timeout: Duration) -> Result<Option<String>, SpiceError> {
    let mut cmd = Command::new(program);
    cmd.arg("-v");
    let finished = run_child(cmd, timeout).map_err(|source| SpiceError::NotFound {
        program: program.to_path_buf(),
        source,
    })?;
    if finished.status.is_none() {
        return Err(SpiceError::NotFound {
            program: program.to_path_buf(),
            source: io::Error::new(
                io::ErrorKind::TimedOut,
                format!(
                    "`{} -v` did not finish within {:.3} s (--timeout) and was killed",
                    program.display(),
                    timeout.as_secs_f64()
                ),
            ),
        });
    }
    Ok(parse_version(&finished.log))
}

/// `** ngspice-39 : Circuit level ...` → `39`.
pub fn parse_version(banner: &str) -> Option<String> {
    let i = banner.find("ngspice-")?;
    let v: String = banner[i + "ngspice-".len()..]
        .chars()
        .take_while(|c| !c.is_whitespace())
        .collect();
    (!v.is_empty()).then_some(v)
}

impl Runner for Ngspice {
    fn lock_step(&self) -> bool {
        true
    }

    fn run(&self, req: &RunRequest) -> Result<RunOutput, SpiceError> {
        for (name, _) in &req.includes {
            if !is_plain_name(name) {
                return Err(SpiceError::IncludeName { name: name.clone() });
            }
        }
        let dir = self.workdir("chatterspice-")?;
        let _remove_at_stop = crate::interrupt::remove_at_stop(dir.path());
        let write = |name: &str, text: &str| {
            let path = dir.path().join(name);
            std::fs::write(&path, text).map_err(|source| SpiceError::Write { path, source })
        };
        write(DECK_NAME, &req.deck)?;
        for (name, text) in &req.includes {
            write(name, text)?;
        }

        let cmd = self.command(dir.path(), &["-b", "-r", RAW_NAME], DECK_NAME);
        let started = Instant::now();
        let result = run_child(cmd, req.timeout);
        let elapsed = started.elapsed();

        let workdir = dir.path().to_path_buf();
        let kept = req.keep_workdir;
        // Keep or remove the directory now, so every error below says which.
        let dir_guard = if kept {
            let _ = dir.keep();
            None
        } else {
            Some(dir)
        };
        let context = |log: &str| {
            Box::new(RunContext {
                workdir: workdir.clone(),
                kept,
                log_tail: log_tail(log),
            })
        };

        let finished = result.map_err(|source| SpiceError::Process {
            program: self.program.clone(),
            source,
            context: context(""),
        })?;
        let exit = finished.status.map(exit_of);
        let out = read_run(&workdir, kept, finished.log, exit, req.timeout)?;
        drop(dir_guard);
        Ok(RunOutput {
            version: self.version.clone(),
            elapsed,
            ..out
        })
    }

    fn run_many(&self, reqs: &[RunRequest]) -> Vec<Result<RunOutput, SpiceError>> {
        let batched: Vec<(usize, f64)> = (0..reqs.len())
            .filter_map(|i| batchable(&reqs[i]).map(|stop| (i, stop)))
            .collect();
        let mut out: Vec<Option<Result<RunOutput, SpiceError>>> =
            reqs.iter().map(|_| None).collect();
        if batched.len() > 1
            && let Ok(done) = self.batch(reqs, &batched)
        {
            for (i, output) in done {
                out[i] = Some(Ok(output));
            }
        }
        out.into_iter()
            .zip(reqs)
            .map(|(done, req)| done.unwrap_or_else(|| self.run(req)))
            .collect()
    }
}

/// The first line of a batch's log for each deck, then its number.
const DECK_MARK: &str = "@@chatterspice-deck";
/// The line after a deck's raw file is written, then its number.
const DONE_MARK: &str = "@@chatterspice-done";

/// The `.tran` stop time of a deck a batch can run: no `.control` block,
/// one `.tran` with a plain stop time and no other analysis, includes by
/// plain name, and no kept work directory.
fn batchable(req: &RunRequest) -> Option<f64> {
    if req.keep_workdir || !req.includes.iter().all(|(name, _)| is_plain_name(name)) {
        return None;
    }
    const OTHERS: [&str; 11] = [
        ".control", ".op", ".ac", ".dc", ".noise", ".tf", ".sens", ".disto", ".pz", ".pss", ".sp",
    ];
    let mut stop = None;
    for line in req.deck.lines().skip(1) {
        let card = line.trim_start().to_ascii_lowercase();
        let word = card.split_whitespace().next().unwrap_or_default();
        if OTHERS.contains(&word) {
            return None;
        }
        if word == ".tran" {
            if stop.is_some() {
                return None;
            }
            let value = card.split_whitespace().nth(2)?;
            stop = Some(crate::netlist::number::parse_number(value)?);
        }
    }
    stop.filter(|t| *t > 0.0)
}

impl Ngspice {
    /// A fresh work directory whose name starts with `prefix`, under the
    /// configured parent or the system's temporary directory.
    fn workdir(&self, prefix: &str) -> Result<tempfile::TempDir, SpiceError> {
        let parent = self
            .workdir_parent
            .clone()
            .unwrap_or_else(std::env::temp_dir);
        tempfile::Builder::new()
            .prefix(prefix)
            .tempdir_in(&parent)
            .map_err(|source| SpiceError::WorkDir { parent, source })
    }

    /// ngspice on `file` with `args` in `dir` (after `-n` when the user's
    /// start-up file is skipped). Every run sets `norefvalue`: no progress
    /// line, and no clock read at every time point to decide when to print
    /// one (a fifth of a short run's time).
    fn command(&self, dir: &Path, args: &[&str], file: &str) -> Command {
        let mut cmd = Command::new(&self.program);
        if self.skip_user_init {
            cmd.arg("-n");
        }
        cmd.args(args)
            .args(["-D", "norefvalue", file])
            .current_dir(dir);
        // ngspice 39 crashes (SIGSEGV) looking for `~/.spiceinit` when HOME
        // is unset; the work directory is a home with no start-up file.
        if std::env::var_os("HOME").is_none_or(|h| h.is_empty()) {
            cmd.env("HOME", dir);
        }
        cmd
    }

    /// Runs the decks `which` of `reqs` (each with its `.tran` stop time)
    /// in one ngspice process: the outputs of those whose results are
    /// certain (see the module's docs). `Err` when the batch could not even
    /// be set up or started.
    fn batch(
        &self,
        reqs: &[RunRequest],
        which: &[(usize, f64)],
    ) -> Result<Vec<(usize, RunOutput)>, SpiceError> {
        let dir = self.workdir("chatterspice-batch-")?;
        let _remove_at_stop = crate::interrupt::remove_at_stop(dir.path());
        let write = |path: PathBuf, text: &str| {
            std::fs::write(&path, text).map_err(|source| SpiceError::Write { path, source })
        };
        let mut script = format!("* chatterspice: {} decks in turn\n.control\n", which.len());
        for (k, &(i, _)) in which.iter().enumerate() {
            let sub = dir.path().join(k.to_string());
            std::fs::create_dir(&sub).map_err(|source| SpiceError::WorkDir {
                parent: dir.path().to_path_buf(),
                source,
            })?;
            write(sub.join(DECK_NAME), &reqs[i].deck)?;
            for (name, text) in &reqs[i].includes {
                write(sub.join(name), text)?;
            }
            script.push_str(&format!(
                "echo {DECK_MARK} {k}\ncd {k}\nsource {DECK_NAME}\nrun\nwrite {RAW_NAME}\n\
                 destroy all\nremcirc\ncd ..\necho {DONE_MARK} {k}\n"
            ));
        }
        script.push_str("quit 0\n.endc\n.end\n");
        write(dir.path().join("batch.cir"), &script)?;

        let cmd = self.command(dir.path(), &["-b"], "batch.cir");
        let timeout = which.iter().map(|&(i, _)| reqs[i].timeout).sum();
        let started = Instant::now();
        let finished = run_child(cmd, timeout).map_err(|source| SpiceError::Process {
            program: self.program.clone(),
            source,
            context: Box::new(RunContext {
                workdir: dir.path().to_path_buf(),
                kept: false,
                log_tail: String::new(),
            }),
        })?;
        let share = started.elapsed() / which.len() as u32;
        // A failure anywhere, or a batch that did not end by itself, makes
        // every deck run again on its own: a log's lines cannot be told
        // apart by deck with certainty (stdout and stderr are two pipes).
        let clean = finished.status.is_some_and(|s| s.success())
            && classify::classify(Exit::Code(0), &finished.log).is_none();
        if !clean {
            return Ok(Vec::new());
        }
        let segments = split_log(&finished.log);
        let mut done = Vec::new();
        for (k, &(i, stop)) in which.iter().enumerate() {
            let Some(segment) = segments.get(&k).filter(|s| s.finished) else {
                continue;
            };
            let path = dir.path().join(k.to_string()).join(RAW_NAME);
            let Ok(bytes) = std::fs::read(&path) else {
                continue;
            };
            let Ok(raw) = RawFile::parse(&bytes) else {
                continue;
            };
            let reached = raw
                .last_transient()
                .and_then(|plot| plot.real("time"))
                .and_then(|t| t.last().copied());
            if !raw.warnings.is_empty() || reached.is_none_or(|t| t < stop * (1.0 - 1e-9)) {
                continue;
            }
            let mut warnings = classify::warnings(&segment.log);
            warnings.extend(raw.warnings.iter().map(ToString::to_string));
            done.push((
                i,
                RunOutput {
                    raw,
                    log: segment.log.clone(),
                    version: self.version.clone(),
                    elapsed: share,
                    workdir: None,
                    warnings,
                },
            ));
        }
        Ok(done)
    }
}

/// What a finished run in `workdir` gave: its raw file read and checked,
/// or the failure its log (`log`) and its exit (`None`: stopped at the
/// time limit `timeout`) tell. The output's version and elapsed time are
/// the caller's to fill in.
pub(crate) fn read_run(
    workdir: &Path,
    kept: bool,
    log: String,
    exit: Option<Exit>,
    timeout: Duration,
) -> Result<RunOutput, SpiceError> {
    let context = |log: &str| {
        Box::new(RunContext {
            workdir: workdir.to_path_buf(),
            kept,
            log_tail: log_tail(log),
        })
    };
    if log.contains("rawfile write error") {
        return Err(SpiceError::RawWrite {
            dir: workdir.to_path_buf(),
            context: context(&log),
        });
    }
    let Some(exit) = exit else {
        return Err(SpiceError::Timeout {
            limit: timeout,
            context: context(&log),
        });
    };
    if let Some(failure) = classify::classify(exit, &log) {
        return Err(SpiceError::Failed {
            failure,
            context: context(&log),
        });
    }
    let raw_path = workdir.join(RAW_NAME);
    let bytes = match std::fs::read(&raw_path) {
        Ok(b) => b,
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(SpiceError::MissingRaw {
                context: context(&log),
            });
        }
        Err(source) => {
            return Err(SpiceError::BadRaw {
                source: crate::rawfile::RawError::Io {
                    path: raw_path,
                    source,
                },
                context: context(&log),
            });
        }
    };
    let raw = RawFile::parse(&bytes).map_err(|source| SpiceError::BadRaw {
        source,
        context: context(&log),
    })?;
    drop(bytes);
    if let Some(warning) = raw
        .warnings
        .iter()
        .find(|w| matches!(w, RawWarning::Truncated { .. }))
    {
        // ngspice exited cleanly, so a cut file means a write failure
        // (disk full?), not a result to analyse.
        return Err(SpiceError::TruncatedRaw {
            warning: warning.clone(),
            context: context(&log),
        });
    }
    let mut warnings = classify::warnings(&log);
    warnings.extend(raw.warnings.iter().map(ToString::to_string));
    Ok(RunOutput {
        raw,
        log,
        version: None,
        elapsed: Duration::ZERO,
        workdir: kept.then_some(workdir.to_path_buf()),
        warnings,
    })
}

/// One deck's part of a batch's log.
#[derive(Debug, Default)]
struct Segment {
    log: String,
    /// Its end marker was seen.
    finished: bool,
}

/// A batch's log cut at its deck markers, by deck.
fn split_log(log: &str) -> std::collections::BTreeMap<usize, Segment> {
    let mut segments = std::collections::BTreeMap::<usize, Segment>::new();
    let mut current: Option<usize> = None;
    let number = |rest: &str| rest.trim().parse::<usize>().ok();
    for line in log.lines() {
        let trimmed = line.trim();
        if let Some(k) = trimmed.strip_prefix(DECK_MARK).and_then(number) {
            current = Some(k);
            segments.entry(k).or_default();
            continue;
        }
        if let Some(k) = trimmed.strip_prefix(DONE_MARK).and_then(number) {
            segments.entry(k).or_default().finished = true;
            current = None;
            continue;
        }
        if let Some(segment) = current.and_then(|k| segments.get_mut(&k)) {
            segment.log.push_str(line);
            segment.log.push('\n');
        }
    }
    segments
}

fn is_plain_name(name: &str) -> bool {
    let p = Path::new(name);
    !name.is_empty()
        && p.file_name() == Some(OsStr::new(name))
        && name != DECK_NAME
        && name != RAW_NAME
}

#[cfg(unix)]
fn exit_of(status: ExitStatus) -> Exit {
    use std::os::unix::process::ExitStatusExt;
    match (status.code(), status.signal()) {
        (Some(c), _) => Exit::Code(c),
        (None, Some(s)) => Exit::Signal(s),
        (None, None) => Exit::Code(-1),
    }
}

#[cfg(not(unix))]
fn exit_of(status: ExitStatus) -> Exit {
    Exit::Code(status.code().unwrap_or(-1))
}

// ---------------------------------------------------------------------------
// Child process with concurrent output capture and a deadline

pub(crate) struct Finished {
    /// `None` when the deadline killed the child.
    pub status: Option<ExitStatus>,
    pub log: String,
}

/// `cmd.spawn()`, tried again a few times while the executable is busy
/// (ETXTBSY): a script written just before (a wrapper, a test's stand-in)
/// stays open for writing in any child another thread forks before that
/// child's exec closes it.
fn spawn_retrying_busy(cmd: &mut Command) -> io::Result<std::process::Child> {
    const TEXT_FILE_BUSY: i32 = 26;
    let mut tries = 0;
    loop {
        match cmd.spawn() {
            Err(e) if e.raw_os_error() == Some(TEXT_FILE_BUSY) && tries < 20 => {
                tries += 1;
                std::thread::sleep(Duration::from_millis(5));
            }
            result => return result,
        }
    }
}

/// Runs `cmd` (stdin closed), collecting stdout and stderr as one log,
/// killing and reaping it after `timeout`.
pub(crate) fn run_child(mut cmd: Command, timeout: Duration) -> io::Result<Finished> {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    // Its own process group, so that the deadline kills whatever it
    // started too (a wrapper script that does not `exec` ngspice).
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(&mut cmd, 0);
    let started = Instant::now();
    let (mut child, _registered) =
        crate::interrupt::spawn_registered(|| spawn_retrying_busy(&mut cmd), Child::id)?;
    // Bounded: a child that prints faster than the log takes it waits.
    let (tx, rx) = mpsc::sync_channel::<Option<String>>(1024);
    let mut open_streams = 0;
    if let Some(out) = child.stdout.take() {
        spawn_reader(out, tx.clone());
        open_streams += 1;
    }
    if let Some(err) = child.stderr.take() {
        spawn_reader(err, tx.clone());
        open_streams += 1;
    }
    drop(tx);

    let deadline = started + timeout;
    let mut log = LogBuffer::default();
    // Once both pipes have closed the child is almost always exiting: poll
    // for it quickly at first (a fixed 20 ms would add up to 20 ms to every
    // run, a fifth of a short one), backing off to 20 ms for a child that
    // closed its output and kept running.
    let mut exit_poll = Duration::from_micros(250);
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break Some(status);
        }
        let now = Instant::now();
        if now >= deadline {
            kill_and_reap(&mut child)?;
            break None;
        }
        let wait = (deadline - now).min(Duration::from_millis(20));
        match rx.recv_timeout(wait) {
            Ok(Some(line)) => log.push(line),
            Ok(None) => open_streams -= 1,
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                thread::sleep(wait.min(exit_poll));
                exit_poll = (exit_poll * 2).min(Duration::from_millis(20));
            }
        }
    };
    // The pipes close when the child is gone; a grandchild could hold them
    // open, so the drain has its own short deadline.
    let drain_until = Instant::now() + Duration::from_secs(2);
    while open_streams > 0 {
        let now = Instant::now();
        if now >= drain_until {
            break;
        }
        match rx.recv_timeout(drain_until - now) {
            Ok(Some(line)) => log.push(line),
            Ok(None) => open_streams -= 1,
            Err(_) => break,
        }
    }
    Ok(Finished {
        status,
        log: log.finish(),
    })
}

fn kill_and_reap(child: &mut Child) -> io::Result<()> {
    // The whole group: the child leads it (see `run_child`).
    #[cfg(unix)]
    if let Ok(pid) = i32::try_from(child.id()) {
        // SAFETY: kill(2) with a negative pid signals that process group;
        // it reads no memory of ours.
        unsafe {
            libc::kill(-pid, libc::SIGKILL);
        }
    }
    match child.kill() {
        Ok(()) => {}
        // Exited between try_wait and kill: still reap below.
        Err(e) if e.kind() == io::ErrorKind::InvalidInput => {}
        Err(e) => return Err(e),
    }
    child.wait().map(|_| ())
}

/// The longest line kept whole; longer output is split.
const MAX_LINE: usize = 16 * 1024;

/// Sends complete lines (split at `\n` or `\r`, progress lines dropped),
/// then `None` at end of stream.
fn spawn_reader(mut stream: impl Read + Send + 'static, tx: mpsc::SyncSender<Option<String>>) {
    thread::spawn(move || {
        let mut buf = [0u8; 8192];
        let mut pending: Vec<u8> = Vec::new();
        let send = |line: &[u8]| {
            let text = String::from_utf8_lossy(line);
            // ngspice's transient progress ("Reference value : 1.2e-06"),
            // thousands of `\r`-separated updates that say nothing.
            if text.trim_start().starts_with("Reference value") {
                return true;
            }
            tx.send(Some(text.into_owned())).is_ok()
        };
        loop {
            let n = match stream.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(_) => break,
            };
            for &b in &buf[..n] {
                if b == b'\n' || b == b'\r' {
                    if !send(&pending) {
                        return;
                    }
                    pending.clear();
                } else {
                    pending.push(b);
                    // Output without newlines is cut into lines.
                    if pending.len() >= MAX_LINE {
                        if !send(&pending) {
                            return;
                        }
                        pending.clear();
                    }
                }
            }
        }
        if !pending.is_empty() {
            send(&pending);
        }
        let _ = tx.send(None);
    });
}

/// The log, bounded: the first `HEAD` bytes (parse errors are there) and
/// the last `TAIL` bytes (analysis failures are there) of a run that talks
/// for hours.
#[derive(Default)]
struct LogBuffer {
    head: String,
    tail: VecDeque<String>,
    tail_bytes: usize,
    dropped: usize,
    /// Collapses the blank lines that `\r\n` endings and ngspice's spacing make.
    last_blank: bool,
}

impl LogBuffer {
    const HEAD: usize = 256 * 1024;
    const TAIL: usize = 256 * 1024;

    fn push(&mut self, line: String) {
        let blank = line.trim().is_empty();
        if blank && self.last_blank {
            return;
        }
        self.last_blank = blank;
        if self.tail.is_empty() && self.head.len() + line.len() < Self::HEAD {
            self.head.push_str(&line);
            self.head.push('\n');
            return;
        }
        self.tail_bytes += line.len() + 1;
        self.tail.push_back(line);
        while self.tail_bytes > Self::TAIL {
            match self.tail.pop_front() {
                Some(l) => {
                    self.tail_bytes -= l.len() + 1;
                    self.dropped += 1;
                }
                None => break,
            }
        }
    }

    fn finish(self) -> String {
        let mut log = self.head;
        if self.dropped > 0 {
            log.push_str(&format!("[... {} log lines dropped ...]\n", self.dropped));
        }
        for line in self.tail {
            log.push_str(&line);
            log.push('\n');
        }
        log
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version_from_banner() {
        let banner = "******\n** ngspice-39 : Circuit level simulation program\n";
        assert_eq!(parse_version(banner).as_deref(), Some("39"));
        assert_eq!(
            parse_version("** ngspice-44.2 : x").as_deref(),
            Some("44.2")
        );
        assert_eq!(parse_version("something else"), None);
    }

    #[test]
    fn include_names_must_be_plain() {
        assert!(is_plain_name("contact.inc"));
        for bad in ["", "../x", "/etc/passwd", "a/b", DECK_NAME, RAW_NAME, ".."] {
            assert!(!is_plain_name(bad), "{bad}");
        }
    }

    #[test]
    fn log_buffer_keeps_head_and_tail() {
        let mut log = LogBuffer::default();
        for i in 0..100_000 {
            log.push(format!("line {i} with some padding to make it longer"));
        }
        let text = log.finish();
        assert!(text.len() < LogBuffer::HEAD + LogBuffer::TAIL + 100);
        assert!(text.starts_with("line 0 "));
        assert!(text.ends_with("line 99999 with some padding to make it longer\n"));
        assert!(text.contains("log lines dropped"));
    }

    #[test]
    fn missing_program_says_how_to_install() {
        let err = Ngspice::locate(Some(Path::new("/nonexistent/ngspice"))).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("apt-get install -y ngspice"), "{msg}");
        assert!(msg.contains("CHATTERSPICE_NGSPICE"), "{msg}");
    }
}
