//! ngspice's shared library, `libngspice.so.0` (what KiCad loads), bound
//! at run time: no C build step, and a machine without the library still
//! runs everything else.
//!
//! The library is the simulator of a lock-step run
//! ([`crate::pipeline::lockstep`]): a circuit source asks the caller for its
//! value at every Newton iteration (`V… n 0 external`), and a
//! synchronisation call before and after every time step lets the caller
//! shorten the next step.
//!
//! # Isolation
//! ngspice keeps one circuit and all its state in globals, leaks across
//! runs, and may end a run by `longjmp` or by calling its exit callback.
//! None of that may reach the caller, so every run happens in a process
//! of its own: [`Library::run_isolated`] forks, the child runs the
//! circuit and writes its answer to a pipe, then exits without unwinding
//! or flushing anything of the parent's. The library is loaded and
//! initialised once in the parent (45 ms, measured) and never runs a
//! circuit there, so each child starts from the same clean, initialised
//! state and nothing accumulates from one run to the next. A child that
//! crashes, hangs past its time limit, or is stopped is reaped and
//! reported; the caller is unaffected.
//!
//! ngspice's `SIGINT` handler, which `ngSpice_Init` installs, is undone in
//! the parent at once (the caller's own handling of Ctrl-C stays in
//! force). Children run in the C locale and in a process group of their
//! own, registered with [`crate::interrupt`] like the batch program.
//!
//! Facts about ngspice 39 this relies on, checked on the installed
//! library: a source written `V… n 0 external` works, where `dc 0
//! external` crashes the simulator; the synchronisation call comes before
//! each step's Newton iterations (location 0, where the step may be
//! shortened) and after its truncation check (location 1); the accepted
//! point's values come only after that, through the data callback; node
//! names of a subcircuit read `x2.psi`, and an external source inside
//! instance `x1` is asked for as `v.x1.<name>` in lower case.

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::io::{Read, Write};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use libloading::Library as Dl;

/// The file name the dynamic loader is asked for.
pub const LIBRARY_NAME: &str = "libngspice.so.0";

/// Environment variable naming another library file to load instead
/// (e.g. a build of ngspice under test); set to an empty string, no
/// library is loaded at all (the lock-step coupling is then unavailable).
pub const LIBRARY_ENV: &str = "CHATTERSPICE_LIBNGSPICE";

/// What a circuit run in the library tells its caller; implemented by the
/// lock-step coupling. Every method is called on the thread that runs the
/// circuit, in the child process.
pub trait Session {
    /// One line ngspice printed (`stdout …` / `stderr …` prefixes removed).
    fn print(&mut self, line: &str);
    /// The names of the vectors of the run, in the order of [`Session::data`].
    fn vectors(&mut self, names: &[String]);
    /// The values of an accepted time point, in the order of
    /// [`Session::vectors`].
    fn data(&mut self, values: &[f64]);
    /// The value of external source `name` (lower case, e.g. `v.x2.v_x`)
    /// at `time` (0 during the operating point).
    fn source(&mut self, name: &str, time: f64) -> f64;
    /// Before a step from `time` (`location` 0: `delta` may be shortened)
    /// and after it (`location` 1: `redo` when ngspice rejected it, time
    /// already back at its start). Returning `true` at location 1 of an
    /// accepted step makes ngspice redo it with `delta`.
    fn sync(&mut self, time: f64, delta: &mut f64, redo: bool, location: i32) -> bool;
}

type SendChar = unsafe extern "C" fn(*mut c_char, c_int, *mut c_void) -> c_int;
type ControlledExit = unsafe extern "C" fn(c_int, bool, bool, c_int, *mut c_void) -> c_int;
type SendData = unsafe extern "C" fn(*mut VecValuesAll, c_int, c_int, *mut c_void) -> c_int;
type SendInitData = unsafe extern "C" fn(*mut VecInfoAll, c_int, *mut c_void) -> c_int;
type BgThreadRunning = unsafe extern "C" fn(bool, c_int, *mut c_void) -> c_int;
type GetSourceData = unsafe extern "C" fn(*mut f64, f64, *mut c_char, c_int, *mut c_void) -> c_int;
type GetSyncData =
    unsafe extern "C" fn(f64, *mut f64, f64, c_int, c_int, c_int, *mut c_void) -> c_int;
type Init = unsafe extern "C" fn(
    Option<SendChar>,
    Option<SendChar>,
    Option<ControlledExit>,
    Option<SendData>,
    Option<SendInitData>,
    Option<BgThreadRunning>,
    *mut c_void,
) -> c_int;
type InitSync = unsafe extern "C" fn(
    Option<GetSourceData>,
    Option<GetSourceData>,
    Option<GetSyncData>,
    *mut c_int,
    *mut c_void,
) -> c_int;
type Command = unsafe extern "C" fn(*mut c_char) -> c_int;
type SetBkpt = unsafe extern "C" fn(f64) -> bool;

/// `vecvalues` of sharedspice.h.
#[repr(C)]
struct VecValues {
    name: *mut c_char,
    creal: f64,
    cimag: f64,
    is_scale: bool,
    is_complex: bool,
}

/// `vecvaluesall`.
#[repr(C)]
struct VecValuesAll {
    count: c_int,
    index: c_int,
    values: *mut *mut VecValues,
}

/// `vecinfo`.
#[repr(C)]
struct VecInfo {
    number: c_int,
    name: *mut c_char,
    is_real: bool,
    vector: *mut c_void,
    scale: *mut c_void,
}

/// `vecinfoall`.
#[repr(C)]
struct VecInfoAll {
    name: *mut c_char,
    title: *mut c_char,
    date: *mut c_char,
    kind: *mut c_char,
    count: c_int,
    vectors: *mut *mut VecInfo,
}

/// The loaded, initialised library.
pub struct Library {
    /// Kept loaded for the life of the process (ngspice is never unloaded
    /// under its own globals).
    _dl: Dl,
    command: Command,
    set_bkpt: SetBkpt,
    version: Option<String>,
}

static LIBRARY: OnceLock<Result<Library, String>> = OnceLock::new();

/// The library, loaded and initialised on first use; why not, if it
/// cannot be (the error names the file and what to install).
pub fn library() -> Result<&'static Library, &'static str> {
    LIBRARY.get_or_init(load).as_ref().map_err(String::as_str)
}

fn load() -> Result<Library, String> {
    let name = std::env::var(LIBRARY_ENV).unwrap_or_else(|_| LIBRARY_NAME.to_owned());
    if name.is_empty() {
        return Err(format!(
            "ngspice's shared library is switched off ({LIBRARY_ENV} is empty)"
        ));
    }
    // ngSpice_Init looks for `~/.spiceinit` through the password database
    // and dereferences what it gets: a user without an entry (a container
    // run under an arbitrary uid) would crash this process, not a child.
    // SAFETY: getpwuid reads the database; the pointer is only tested.
    if unsafe { libc::getpwuid(libc::getuid()) }.is_null() {
        return Err(format!(
            "ngspice's shared library is not loaded: user {} has no entry in the password \
             database, and the library's initialisation would crash on that",
            // SAFETY: a plain system call.
            unsafe { libc::getuid() }
        ));
    }
    // SAFETY: loading runs the library's initialisers, which set up its
    // own state only.
    let dl = unsafe { Dl::new(&name) }.map_err(|e| {
        format!("cannot load ngspice's shared library {name} ({e}): apt-get install -y libngspice0")
    })?;
    // SAFETY: the prototypes of ngspice's sharedspice.h.
    let (init, init_sync, command, set_bkpt) = unsafe {
        let symbol = |s: &[u8]| -> Result<*mut c_void, String> {
            dl.get::<*mut c_void>(s).map(|f| *f).map_err(|e| {
                format!(
                    "{name} lacks {}: {e}",
                    String::from_utf8_lossy(&s[..s.len() - 1])
                )
            })
        };
        (
            std::mem::transmute::<*mut c_void, Init>(symbol(b"ngSpice_Init\0")?),
            std::mem::transmute::<*mut c_void, InitSync>(symbol(b"ngSpice_Init_Sync\0")?),
            std::mem::transmute::<*mut c_void, Command>(symbol(b"ngSpice_Command\0")?),
            std::mem::transmute::<*mut c_void, SetBkpt>(symbol(b"ngSpice_SetBkpt\0")?),
        )
    };
    // ngSpice_Init installs a SIGINT handler of its own: keep the caller's.
    let mut saved: libc::sigaction = unsafe { std::mem::zeroed() };
    // SAFETY: reading and restoring this process's SIGINT action, and the
    // library's documented initialisation with callbacks that live as long
    // as the program.
    let rc = unsafe {
        libc::sigaction(libc::SIGINT, std::ptr::null(), &mut saved);
        let rc = init(
            Some(send_char),
            Some(send_char),
            Some(controlled_exit),
            Some(send_data),
            Some(send_init_data),
            None,
            std::ptr::null_mut(),
        );
        let mut ident: c_int = 0;
        let rc_sync = init_sync(
            Some(get_vsrc_data),
            None,
            Some(get_sync_data),
            &mut ident,
            std::ptr::null_mut(),
        );
        libc::sigaction(libc::SIGINT, &saved, std::ptr::null_mut());
        rc.max(rc_sync)
    };
    if rc != 0 {
        return Err(format!("{name}: ngSpice_Init returned {rc}"));
    }
    let banner = BANNER
        .lock()
        .map(|lines| lines.join("\n"))
        .unwrap_or_default();
    Ok(Library {
        _dl: dl,
        command,
        set_bkpt,
        version: super::ngspice::parse_version(&banner),
    })
}

thread_local! {
    /// The session of the circuit running on this thread (in a child).
    static SESSION: std::cell::Cell<Option<*mut (dyn Session + 'static)>> =
        const { std::cell::Cell::new(None) };
}

/// Calls `f` with the running session; nothing (and `default`) when there
/// is none or when it panics (a panic must not unwind into C).
fn with_session<R>(default: R, f: impl FnOnce(&mut dyn Session) -> R) -> R {
    let Some(session) = SESSION.with(|s| s.get()) else {
        return default;
    };
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        // SAFETY: set by `Library::run_circuit` for the duration of the
        // (synchronous) run on this thread, which is the only one.
        f(unsafe { &mut *session })
    }))
    .unwrap_or(default)
}

/// A C string ngspice passes, as text.
///
/// # Safety
/// `text` is null or NUL-terminated and alive for the call.
unsafe fn text_of(text: *const c_char) -> String {
    if text.is_null() {
        String::new()
    } else {
        // SAFETY: as the caller promises.
        unsafe { CStr::from_ptr(text) }
            .to_string_lossy()
            .into_owned()
    }
}

unsafe extern "C" fn send_char(text: *mut c_char, _id: c_int, _user: *mut c_void) -> c_int {
    // SAFETY: ngspice passes a NUL-terminated string alive for the call.
    let line = unsafe { text_of(text) };
    let line = line
        .strip_prefix("stdout ")
        .or_else(|| line.strip_prefix("stderr "))
        .unwrap_or(&line)
        .to_owned();
    if SESSION.with(|s| s.get()).is_none() {
        // Printed outside a run: the banner at initialisation.
        if let Ok(mut banner) = BANNER.lock() {
            if banner.len() < 64 {
                banner.push(line);
            }
        }
        return 0;
    }
    with_session((), |s| s.print(&line));
    0
}

/// What the library printed outside a run (its banner, at
/// initialisation).
static BANNER: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

unsafe extern "C" fn controlled_exit(
    status: c_int,
    _unload: bool,
    _quit: bool,
    _id: c_int,
    _user: *mut c_void,
) -> c_int {
    // ngspice cannot go on after this: the child reports and ends here.
    with_session((), |s| {
        s.print(&format!("ngspice exited with status {status}"));
    });
    EXITED.with(|e| e.set(Some(status)));
    0
}

thread_local! {
    /// ngspice's exit status, once it has called its exit callback.
    static EXITED: std::cell::Cell<Option<c_int>> = const { std::cell::Cell::new(None) };
}

unsafe extern "C" fn send_init_data(
    info: *mut VecInfoAll,
    _id: c_int,
    _user: *mut c_void,
) -> c_int {
    if info.is_null() {
        return 0;
    }
    // SAFETY: ngspice passes its vector table, alive for the call.
    let names: Vec<String> = unsafe {
        let info = &*info;
        (0..usize::try_from(info.count).unwrap_or(0))
            .map(|k| {
                let v = *info.vectors.add(k);
                if v.is_null() {
                    String::new()
                } else {
                    text_of((*v).name)
                }
            })
            .collect()
    };
    with_session((), |s| s.vectors(&names));
    0
}

unsafe extern "C" fn send_data(
    values: *mut VecValuesAll,
    _count: c_int,
    _id: c_int,
    _user: *mut c_void,
) -> c_int {
    if values.is_null() {
        return 0;
    }
    // SAFETY: ngspice passes the accepted point's values, alive for the
    // call.
    let row: Vec<f64> = unsafe {
        let all = &*values;
        (0..usize::try_from(all.count).unwrap_or(0))
            .map(|k| {
                let v = *all.values.add(k);
                if v.is_null() { f64::NAN } else { (*v).creal }
            })
            .collect()
    };
    with_session((), |s| s.data(&row));
    0
}

unsafe extern "C" fn get_vsrc_data(
    value: *mut f64,
    time: f64,
    name: *mut c_char,
    _id: c_int,
    _user: *mut c_void,
) -> c_int {
    // SAFETY: the source's name, alive for the call.
    let name = unsafe { text_of(name) }.to_ascii_lowercase();
    let v = with_session(0.0, |s| s.source(&name, time));
    if !value.is_null() {
        // SAFETY: ngspice's output slot for the value.
        unsafe { *value = v };
    }
    0
}

unsafe extern "C" fn get_sync_data(
    time: f64,
    delta: *mut f64,
    _old_delta: f64,
    redo: c_int,
    _id: c_int,
    location: c_int,
    _user: *mut c_void,
) -> c_int {
    if delta.is_null() {
        return 0;
    }
    // SAFETY: ngspice's step, which the caller may shorten.
    let d = unsafe { &mut *delta };
    let mut step = *d;
    let again = with_session(false, |s| s.sync(time, &mut step, redo != 0, location));
    if step.is_finite() && step > 0.0 && step <= *d {
        *d = step;
    }
    c_int::from(again)
}

/// How an isolated run ended without an answer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Isolated {
    /// The child was killed at the time limit.
    Timeout(Duration),
    /// The child died (a crash in ngspice), with the signal or status.
    Died(String),
    /// A stop (Ctrl-C, SIGTERM) is under way: nothing was started.
    Stopping,
    /// fork or pipe failed.
    System(String),
}

impl std::fmt::Display for Isolated {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Isolated::Timeout(limit) => write!(
                f,
                "the run did not finish within {:.0} s and was stopped",
                limit.as_secs_f64()
            ),
            Isolated::Died(how) => write!(f, "ngspice's process died ({how})"),
            Isolated::Stopping => write!(f, "the run is being stopped by a signal"),
            Isolated::System(what) => write!(f, "{what}"),
        }
    }
}

impl Library {
    /// ngspice's version, e.g. `"39"`, from the library's banner.
    pub fn version(&self) -> Option<&str> {
        self.version.as_deref()
    }

    /// Runs an ngspice command in this (child) process; ngspice's return
    /// code says little (0 even when it refuses a command): its printed
    /// lines are the verdict.
    pub fn command(&self, command: &str) -> i32 {
        let Ok(text) = CString::new(command) else {
            return 1;
        };
        let mut bytes = text.into_bytes_with_nul();
        // SAFETY: a NUL-terminated buffer ngspice may read (and, as its
        // prototype allows, write) during the call.
        unsafe { (self.command)(bytes.as_mut_ptr().cast()) }
    }

    /// Makes ngspice land on `time` (not in the past) and restart there
    /// with a small step.
    pub fn breakpoint(&self, time: f64) -> bool {
        // SAFETY: a plain call of the library.
        unsafe { (self.set_bkpt)(time) }
    }

    /// Runs `commands` (e.g. `source deck.cir`, `run`) with `session`
    /// answering ngspice's callbacks; `false` when ngspice called its exit
    /// callback. Only in a child of [`Library::run_isolated`].
    pub fn run_circuit(&self, session: &mut dyn Session, commands: &[&str]) -> bool {
        // SAFETY: the session outlives the synchronous commands; the
        // pointer is cleared before this returns.
        let erased: *mut (dyn Session + 'static) =
            unsafe { std::mem::transmute::<*mut dyn Session, _>(session as *mut dyn Session) };
        SESSION.with(|s| s.set(Some(erased)));
        for command in commands {
            self.command(command);
            if EXITED.with(|e| e.get()).is_some() {
                break;
            }
        }
        SESSION.with(|s| s.set(None));
        EXITED.with(|e| e.get()).is_none()
    }

    /// Runs `child` in a forked process with this library and returns the
    /// bytes it answered, within `timeout`. The child must not touch the
    /// parent's locks (no printing, no logging); it runs in the C locale,
    /// with every inherited file descriptor but its answer's closed.
    pub fn run_isolated(
        &'static self,
        timeout: Duration,
        child: impl FnOnce(&'static Library) -> Vec<u8>,
    ) -> Result<Vec<u8>, Isolated> {
        let mut fds = [0 as c_int; 2];
        // SAFETY: a fresh pipe, closed on exec.
        if unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) } != 0 {
            return Err(Isolated::System(format!(
                "pipe: {}",
                std::io::Error::last_os_error()
            )));
        }
        // SAFETY: both ends are ours from here on.
        let (read_end, write_end) =
            unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) };
        let spawned = crate::interrupt::spawn_registered(
            || {
                // SAFETY: the child runs only `child`, then `_exit`s.
                let pid = unsafe { libc::fork() };
                if pid < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                if pid == 0 {
                    // In the child: never returns.
                    child_main(self, write_end.as_raw_fd(), child);
                }
                // SAFETY: the child leads a group of its own (both sides
                // set it, so no signal to the group can come first).
                unsafe { libc::setpgid(pid, pid) };
                Ok(pid)
            },
            |&pid| u32::try_from(pid).unwrap_or(0),
        );
        drop(write_end);
        let (pid, registered) = match spawned {
            Ok(spawned) => spawned,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {
                return Err(Isolated::Stopping);
            }
            Err(e) => return Err(Isolated::System(format!("fork: {e}"))),
        };
        let answer = read_until(read_end, timeout);
        if answer.is_err() {
            // SAFETY: our own child, not yet reaped.
            unsafe { libc::kill(pid, libc::SIGKILL) };
        }
        let mut status: c_int = 0;
        // SAFETY: reaping our own child.
        unsafe { libc::waitpid(pid, &mut status, 0) };
        drop(registered);
        let answer = answer.map_err(|()| Isolated::Timeout(timeout))?;
        if libc::WIFSIGNALED(status) {
            return Err(Isolated::Died(format!("signal {}", libc::WTERMSIG(status))));
        }
        if !libc::WIFEXITED(status) || libc::WEXITSTATUS(status) != 0 || answer.is_empty() {
            return Err(Isolated::Died(format!(
                "exit status {}",
                libc::WEXITSTATUS(status)
            )));
        }
        Ok(answer)
    }
}

/// The child's side of [`Library::run_isolated`].
fn child_main(
    library: &'static Library,
    answer: c_int,
    child: impl FnOnce(&'static Library) -> Vec<u8>,
) -> ! {
    // SAFETY: this process is the fork's single thread; it only closes
    // inherited descriptors, sets its own group and locale, and ends with
    // `_exit`, never returning into the parent's code.
    unsafe {
        libc::setpgid(0, 0);
        let below = libc::syscall(libc::SYS_close_range, 3u32, (answer - 1) as u32, 0u32);
        let above = libc::syscall(libc::SYS_close_range, (answer + 1) as u32, u32::MAX, 0u32);
        if below != 0 || above != 0 {
            let max = libc::sysconf(libc::_SC_OPEN_MAX).clamp(256, 65_536) as c_int;
            for fd in (3..max).filter(|&fd| fd != answer) {
                libc::close(fd);
            }
        }
        libc::setlocale(libc::LC_ALL, c"C".as_ptr());
        // ngspice's prints go through its callback; its own stdout and
        // stderr are the parent's terminal: silence them.
        let null = libc::open(c"/dev/null".as_ptr(), libc::O_RDWR);
        if null >= 0 {
            libc::dup2(null, 0);
            libc::dup2(null, 1);
            libc::dup2(null, 2);
        }
    }
    let bytes = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| child(library)))
        .unwrap_or_default();
    // SAFETY: the answer's write end, ours; then the end of the child.
    unsafe {
        let mut out = std::fs::File::from_raw_fd(answer);
        let ok = out.write_all(&bytes).is_ok();
        std::mem::forget(out);
        libc::_exit(if ok && !bytes.is_empty() { 0 } else { 1 });
    }
}

/// Everything `fd` gives until its writer closes it, within `limit`.
fn read_until(fd: OwnedFd, limit: Duration) -> Result<Vec<u8>, ()> {
    let start = Instant::now();
    let mut file = std::fs::File::from(fd);
    let mut out = Vec::new();
    let mut buf = [0u8; 65_536];
    loop {
        let left = limit.saturating_sub(start.elapsed());
        if left.is_zero() {
            return Err(());
        }
        let mut poll = libc::pollfd {
            fd: file.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        let ms = c_int::try_from(left.as_millis().max(1)).unwrap_or(c_int::MAX);
        // SAFETY: one descriptor we own.
        let ready = unsafe { libc::poll(&mut poll, 1, ms.min(200)) };
        if ready < 0 {
            if std::io::Error::last_os_error().kind() == std::io::ErrorKind::Interrupted {
                continue;
            }
            return Err(());
        }
        if ready == 0 {
            continue;
        }
        match file.read(&mut buf) {
            Ok(0) => return Ok(out),
            Ok(n) => out.extend_from_slice(&buf[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(_) => return Ok(out),
        }
    }
}
