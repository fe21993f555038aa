//! One circuit pass for a coil-driven relay: the mechanics advanced in
//! lock-step with ngspice's own time steps, through the simulator's shared
//! library ([`crate::spice::shared`]).
//!
//! The circuit sees the armature and the contacts as three external
//! sources (`V… n 0 external`), asked for their values at every Newton
//! iteration: the armature's position on the coil's node `xmm` (the coil
//! include is the one of the passes, with this source in place of the
//! path's PWL), and the conductance of the normally-open and the
//! normally-closed contact (`B… a b I = V(a,b) * V(g)`, as the PWL
//! element).
//!
//! Each step of ngspice from an accepted point `t_n`:
//! 1. **Plan** (before the step's Newton iterations): a speculation of the
//!    mechanics runs from the state at `t_n` to the step's end, under the
//!    coil's flux extrapolated linearly from the last two accepted points.
//!    If it meets an event (an impact, a release, the pole face, the rest
//!    stop) inside the step, the step is shortened to end on it and a
//!    breakpoint is set there and at the end of the contact's edge, so
//!    that no event is stepped over. The sources' values during the step
//!    are functions of time read from this plan, so a rejected step and
//!    its retry see the same values.
//! 2. **Commit** (when ngspice hands over the accepted point `t_{n+1}`
//!    and its flux ψ): the mechanics advances exactly from `t_n` under the
//!    flux interpolated linearly between the two points, the same pull
//!    the passes use, with the engine's own event location.
//!
//! The relay's results are then computed as the passes compute theirs:
//! the mechanics run once more over the whole record under the run's
//! flux ([`crate::mechanics::two_stage::driven_run`]); the largest move of
//! an event time between that run and the lock-step's own is reported as
//! the run's change.

use std::cell::RefCell;
use std::path::Path;
use std::sync::Mutex;
use std::time::Instant;

use crate::arc::ArcModel;
use crate::chatter::{ContactState, Interval};
use crate::coil::Coil;
use crate::mechanics::cycle::Stops;
use crate::mechanics::two_stage::TwoStage;
use crate::mechanics::two_stage::stepper::{Stepper, with_stepper};
use crate::mechanics::{Mechanics, Settings};
use crate::netlist::arc::with_arc_external;
use crate::netlist::{ContactElement, ContactInclude, NetlistError};
use crate::spice::classify::Exit;
use crate::spice::ngspice::{DECK_NAME, RAW_NAME, read_run};
use crate::spice::shared::{Isolated, Library, Session};
use crate::spice::{RunContext, RunOutput, RunRequest, Runner, SpiceError, log_tail};
use crate::waveform::ContactModel;

/// The external source of the armature's position (mm) in the coil
/// include.
pub const ARMATURE_SOURCE: &str = "V_X";
/// The external source of the normally-open contact's conductance (S).
pub const MAKE_SOURCE: &str = "V_LSNO";
/// The external source of the normally-closed contact's conductance (S).
pub const BREAK_SOURCE: &str = "V_LSNC";

/// s: an event closer than this to the start of a step is not landed on
/// exactly: the step is cut to this length and goes past it, and the
/// commit places the event where it happened. A landing falls short when
/// the flux over the step was not what the plan extrapolated; without
/// this, a slow event (the armature lifting off its rest stop as the pull
/// grows) recedes before each landing and the steps shrink without end.
/// 1 ns is a hundredth of the coupling's tolerance.
const LAND_MIN: f64 = 1e-9;

/// The contact subcircuit `subckt` whose conductance is the external
/// source `source` (siemens on node `g`); with `arc`, the arc element of
/// the passes wrapped around it, its gap's voltages external sources too
/// (the contact's gap at rest is `travel`, m).
pub fn contact_include(
    subckt: &str,
    source: &str,
    arc: Option<&ArcModel>,
    travel: f64,
) -> Result<String, NetlistError> {
    let text = format!(
        "* chatterspice lock-step contact: its conductance (S) is asked of the \
         mechanics at every time point.\n\
         .subckt {subckt} a b\n\
         {source} g 0 external\n\
         B1 a b I = V(a,b) * V(g)\n\
         .ends {subckt}\n"
    );
    let Some(arc) = arc else {
        return Ok(text);
    };
    let include = ContactInclude {
        element: ContactElement::Pwl,
        subckt: subckt.to_owned(),
        text,
        data_files: Vec::new(),
        points: 0,
        pwl_sources: 0,
    };
    Ok(with_arc_external(include, arc, travel)?.text)
}

/// What the lock-step run needs of the relay.
#[derive(Debug, Clone)]
pub struct Relay {
    /// The armature (its `force` unused: the coil drives it).
    pub mechanics: Mechanics,
    /// How it is built.
    pub build: TwoStage,
    /// The contact and the rest stop.
    pub stops: Stops,
    /// The engine's settings (`t_end` is the circuit's stop time).
    pub settings: Settings,
    /// The coil, for its pull ψ²/(2 μ0 N² A).
    pub coil: Coil,
    /// The contacts' resistances and edge.
    pub contact: ContactModel,
    /// The flux vector as ngspice's data callback names it, e.g. `x2.psi`.
    pub flux: String,
    /// The normally-open contact's arc, whose gap voltages the run answers
    /// (`Vvarc`, `Vvbd`, `Vlow` of the arc element).
    pub arc: Option<ArcModel>,
}

/// What one lock-step run did, beyond its raw file.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Stats {
    /// Accepted time points.
    pub points: usize,
    /// Steps shortened to land on an event.
    pub landed: usize,
    /// s: the normally-open contact's changes of state, then the
    /// normally-closed contact's, as the run itself found them.
    pub make_changes: Vec<f64>,
    /// s: the normally-closed contact's changes of state.
    pub break_changes: Vec<f64>,
    /// The mechanics failed during the run (the sources then held their
    /// values); the whole-record run reports why.
    pub mechanics_failed: Option<String>,
}

/// The child's answer.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
struct Answer {
    log: String,
    exited: Option<i32>,
    stats: Stats,
}

/// A [`Runner`] that runs a deck through the shared library with the
/// relay in lock-step (the deck must include the lock-step coil and
/// contacts). Each run is a process of its own.
pub struct LockStepRunner {
    library: &'static Library,
    relay: Relay,
    last: Mutex<Option<Stats>>,
}

impl LockStepRunner {
    /// A runner of `relay` through `library`.
    pub fn new(library: &'static Library, relay: Relay) -> LockStepRunner {
        LockStepRunner {
            library,
            relay,
            last: Mutex::new(None),
        }
    }

    /// What the last run did.
    pub fn last_stats(&self) -> Option<Stats> {
        self.last.lock().ok().and_then(|s| s.clone())
    }
}

impl Runner for LockStepRunner {
    fn run(&self, req: &RunRequest) -> Result<RunOutput, SpiceError> {
        let parent = std::env::temp_dir();
        let dir = tempfile::Builder::new()
            .prefix("chatterspice-lockstep-")
            .tempdir_in(&parent)
            .map_err(|source| SpiceError::WorkDir {
                parent: parent.clone(),
                source,
            })?;
        let _remove_at_stop = crate::interrupt::remove_at_stop(dir.path());
        let write = |name: &str, text: &str| {
            let path = dir.path().join(name);
            std::fs::write(&path, text).map_err(|source| SpiceError::Write { path, source })
        };
        write(DECK_NAME, &req.deck)?;
        for (name, text) in &req.includes {
            if name.contains('/') {
                return Err(SpiceError::IncludeName { name: name.clone() });
            }
            write(name, text)?;
        }
        let workdir = dir.path().to_path_buf();
        let started = Instant::now();
        let relay = &self.relay;
        let answer = self
            .library
            .run_isolated(req.timeout, |library| child(library, relay, &workdir));
        let elapsed = started.elapsed();
        let kept = req.keep_workdir;
        let guard = if kept {
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
        let answer: Answer = match answer {
            Ok(bytes) => serde_json::from_slice(&bytes).map_err(|e| SpiceError::Process {
                program: crate::spice::shared::LIBRARY_NAME.into(),
                source: std::io::Error::other(format!("an unreadable answer: {e}")),
                context: context(""),
            })?,
            Err(Isolated::Timeout(limit)) => {
                return Err(SpiceError::Timeout {
                    limit,
                    context: context(""),
                });
            }
            Err(other) => {
                return Err(SpiceError::Process {
                    program: crate::spice::shared::LIBRARY_NAME.into(),
                    source: std::io::Error::other(other.to_string()),
                    context: context(""),
                });
            }
        };
        if let Ok(mut last) = self.last.lock() {
            *last = Some(answer.stats.clone());
        }
        let exit = Exit::Code(answer.exited.unwrap_or(0));
        let out = read_run(&workdir, kept, answer.log, Some(exit), req.timeout)?;
        drop(guard);
        Ok(RunOutput {
            version: self.library.version().map(str::to_owned),
            elapsed,
            ..out
        })
    }
}

/// The flux linkage of the accepted points, linear between them and
/// extrapolated linearly beyond the last (a speculation's drive).
#[derive(Debug, Default)]
struct Flux {
    points: Vec<(f64, f64)>,
}

impl Flux {
    fn push(&mut self, t: f64, psi: f64) {
        match self.points.last_mut() {
            Some(last) if t <= last.0 => {
                // A repeated point (a breakpoint's): the later value.
                if t == last.0 {
                    last.1 = psi;
                }
            }
            _ => self.points.push((t, psi)),
        }
    }

    fn at(&self, t: f64) -> f64 {
        let p = &self.points;
        match p.len() {
            0 => 0.0,
            1 => p[0].1,
            n => {
                // The mechanics asks at or near the newest points (a
                // commit within the last step, a plan beyond it): try the
                // last segment before searching.
                let k = if t >= p[n - 2].0 {
                    n - 1
                } else {
                    p.partition_point(|&(s, _)| s <= t).clamp(1, n - 1)
                };
                let (a, b) = (p[k - 1], p[k]);
                if b.0 <= a.0 {
                    return b.1;
                }
                a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
            }
        }
    }
}

/// The child's side: runs the deck in `dir` with `relay` in lock-step and
/// answers with the log and what the run did.
fn child(library: &'static Library, relay: &Relay, dir: &Path) -> Vec<u8> {
    let mut answer = Answer::default();
    let Ok(c_dir) = std::ffi::CString::new(dir.as_os_str().as_encoded_bytes()) else {
        return Vec::new();
    };
    // SAFETY: this process's own working directory.
    if unsafe { libc::chdir(c_dir.as_ptr()) } != 0 {
        answer.log = format!("cannot enter the work directory {}", dir.display());
        answer.exited = Some(1);
        return serde_json::to_vec(&answer).unwrap_or_default();
    }
    let flux = RefCell::new(Flux::default());
    let coil = relay.coil;
    let pull = |t: f64, _x: f64| coil.force_from_flux(flux.borrow().at(t));
    let ran = with_stepper(
        &relay.mechanics,
        &relay.build,
        &relay.stops,
        &relay.settings,
        pull,
        |stepper| {
            let mut session = Lock {
                library,
                committed: stepper,
                plan: None,
                flux: &flux,
                relay,
                columns: None,
                log: String::new(),
                stats: Stats::default(),
                breakpoints: Vec::new(),
            };
            let finished = library.run_circuit(
                &mut session,
                &[
                    // As the batch runs: no progress reports, and no
                    // clock read at every time point to time them.
                    "set norefvalue",
                    &format!("source {DECK_NAME}"),
                    "run",
                    &format!("write {RAW_NAME}"),
                ],
            );
            session.stats.make_changes = changes(session.committed.intervals());
            session.stats.break_changes = changes(session.committed.back_intervals());
            (finished, session.log, session.stats)
        },
    );
    match ran {
        Ok((finished, log, stats)) => {
            answer.log = log;
            answer.exited = (!finished).then_some(1);
            answer.stats = stats;
        }
        Err(e) => {
            answer.log = format!("the relay cannot be run: {e}");
            answer.exited = Some(1);
        }
    }
    serde_json::to_vec(&answer).unwrap_or_default()
}

/// s: the times a contact changed state.
fn changes(intervals: &[Interval]) -> Vec<f64> {
    intervals.iter().skip(1).map(|iv| iv.start).collect()
}

/// The lock-step session of one run.
struct Lock<'s, 'a, F: Fn(f64, f64) -> f64> {
    library: &'static Library,
    committed: &'s mut Stepper<'a, F>,
    /// The speculation of the step under way: read for the sources'
    /// values within it.
    plan: Option<Stepper<'a, F>>,
    flux: &'s RefCell<Flux>,
    relay: &'s Relay,
    /// (time, flux) columns of the data callback.
    columns: Option<(usize, usize)>,
    log: String,
    stats: Stats,
    /// Breakpoints set so far (not set twice).
    breakpoints: Vec<f64>,
}

impl<F: Fn(f64, f64) -> f64> Lock<'_, '_, F> {
    fn breakpoint(&mut self, t: f64) {
        // Two breakpoints a hair apart make ngspice's next step a tenth of
        // their distance: one per neighbourhood. (An event that recedes
        // while it is landed on, as a lift-off under a pull that grows
        // slower than the plan's extrapolation, would otherwise leave a
        // trail of breakpoints ever closer together.)
        let near = |b: &f64| (b - t).abs() < 10.0 * LAND_MIN;
        if t.is_finite() && !self.breakpoints.iter().any(near) && t < self.relay.settings.t_end {
            self.breakpoints.push(t);
            self.library.breakpoint(t);
        }
    }

    /// The contact's conductance at `t` after the changes of `intervals`:
    /// each change ramps it linearly toward its new level over one edge
    /// (from wherever the last ramp left it).
    fn conductance(&self, intervals: &[Interval], t: f64) -> f64 {
        let c = &self.relay.contact;
        let (g_open, g_closed) = (1.0 / c.r_open, 1.0 / c.r_closed);
        let level = |state: ContactState| f64::from(u8::from(state == ContactState::Closed));
        let Some(first) = intervals.first() else {
            return g_open;
        };
        let mut s = level(first.state);
        let (mut since, mut target) = (first.start, s);
        let approach = |s: f64, target: f64, span: f64| {
            let d = (span / c.edge_time).max(0.0);
            if target > s {
                (s + d).min(target)
            } else {
                (s - d).max(target)
            }
        };
        for iv in &intervals[1..] {
            if iv.start > t {
                break;
            }
            s = approach(s, target, iv.start - since);
            since = iv.start;
            target = level(iv.state);
        }
        s = approach(s, target, t - since);
        g_open + s * (g_closed - g_open)
    }

    fn fail(&mut self, what: String) {
        if self.stats.mechanics_failed.is_none() {
            self.stats.mechanics_failed = Some(what);
        }
    }
}

impl<F: Fn(f64, f64) -> f64> Session for Lock<'_, '_, F> {
    fn print(&mut self, line: &str) {
        self.log.push_str(line);
        self.log.push('\n');
    }

    fn vectors(&mut self, names: &[String]) {
        let find = |wanted: &str| {
            names
                .iter()
                .position(|n| n.eq_ignore_ascii_case(wanted))
                .or_else(|| {
                    names
                        .iter()
                        .position(|n| n.eq_ignore_ascii_case(&format!("v({wanted})")))
                })
        };
        self.columns = find("time").zip(find(&self.relay.flux));
        if self.columns.is_none() {
            self.fail(format!(
                "the run has no vector `{}` (the coil's flux linkage) to drive the armature",
                self.relay.flux
            ));
        }
    }

    fn data(&mut self, values: &[f64]) {
        let Some((time, psi)) = self.columns else {
            return;
        };
        let (Some(&t), Some(&psi)) = (values.get(time), values.get(psi)) else {
            return;
        };
        self.flux.borrow_mut().push(t, psi);
        self.stats.points += 1;
        self.plan = None;
        if self.stats.mechanics_failed.is_none() && t > self.committed.time() {
            let before = (
                self.committed.intervals().len(),
                self.committed.back_intervals().len(),
            );
            if let Err(e) = self.committed.advance_to(t) {
                self.fail(e.to_string());
                return;
            }
            // A change committed in this step: its edge ends one edge on.
            let edge = self.relay.contact.edge_time;
            let ends: Vec<f64> = self.committed.intervals()[before.0..]
                .iter()
                .chain(&self.committed.back_intervals()[before.1..])
                .map(|iv| iv.start + edge)
                .filter(|&end| end > t)
                .collect();
            {
                for end in ends {
                    self.breakpoint(end);
                }
            }
        }
    }

    fn source(&mut self, name: &str, time: f64) -> f64 {
        let from: &Stepper<'_, F> = match &self.plan {
            Some(plan) if time >= self.committed.time() => plan,
            _ => self.committed,
        };
        let suffix = |source: &str| {
            name.len() > source.len()
                && name.ends_with(&source.to_ascii_lowercase())
                && name.as_bytes()[name.len() - source.len() - 1] == b'.'
        };
        if suffix(ARMATURE_SOURCE) {
            // mm: in metres the stroke is below ngspice's tolerance.
            from.armature(time) * 1e3
        } else if suffix(MAKE_SOURCE) {
            self.conductance(from.intervals(), time)
        } else if suffix(BREAK_SOURCE) {
            self.conductance(from.back_intervals(), time)
        } else if let Some(arc) = &self.relay.arc {
            // The gap as the passes' profile has it: the travel less the
            // armature's position.
            let gap = self.relay.mechanics.gap - from.armature(time);
            if suffix("Vvarc") {
                arc.arc_voltage(gap)
            } else if suffix("Vvbd") {
                arc.hold_voltage(gap)
            } else if suffix("Vlow") {
                arc.low_current_term(gap)
            } else {
                0.0
            }
        } else {
            0.0
        }
    }

    fn sync(&mut self, time: f64, delta: &mut f64, _redo: bool, location: i32) -> bool {
        if location != 0 || self.stats.mechanics_failed.is_some() {
            return false;
        }
        let t_n = self.committed.time().max(time);

        let horizon = time + *delta;
        let mut plan = self.committed.speculate();
        if let Err(e) = plan.advance_to(horizon) {
            // The speculation under an extrapolated pull may fail where
            // the real one will not: plan nothing, hold the present.
            self.log
                .push_str(&format!("note: the step's plan failed ({e})\n"));
            self.plan = None;
            return false;
        }
        if let Some(event) = plan.first_event_after(t_n)
            && event < horizon
        {
            if event - time > LAND_MIN {
                *delta = event - time;
                self.stats.landed += 1;
                self.breakpoint(event);
            } else {
                // Just ahead, where the last landing fell short: a step of
                // at most LAND_MIN goes past it, and the commit places it.
                *delta = delta.min(LAND_MIN);
            }
        }
        self.plan = Some(plan);
        false
    }
}
