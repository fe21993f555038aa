//! A sweep's files in a directory, as `chatterspice sweep --out DIR`
//! writes them (and the Python package's `sweep(out=DIR)`): `sweep.csv`
//! written row by row while the sweep runs, then `summary.json`,
//! `sweep.svg`, `sweep.png` and `sweep.meta.json` (a shard writes its
//! CSV and its identity file alone).
//!
//! The CSV is written under its partial name (`sweep.csv.partial`, with
//! `sweep.meta.json.partial` beside it) and renamed into place at the end.
//! A stop keeps the finished rows whole in `sweep.csv`, with
//! `sweep.meta.json` marked incomplete, for a resume: at a signal (a
//! finisher of [`crate::interrupt`]) and when the caller's
//! [`Progress::stopped`] says so (an embedding that goes on running).
//! Existing files of a sweep are an error unless `force`; the same
//! files are the place a resume continues from.

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::output::{OutputLock, Staged, WriteError, check_target, write_bundle};
use crate::scenario::Scenario;

use super::error::SweepError;
use super::record::Shard;
use super::resume::{self, Identity, Meta, ResumeError};
use super::run::{Progress, SweepMode, SweepOptions};
use super::sample::Sampler;
use super::summary::Summary;

/// Where a sweep writes its files, and what it may do to those there.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Destination {
    /// The directory (created if needed).
    pub dir: PathBuf,
    /// Continue the interrupted sweep whose files are in `dir`.
    pub resume: bool,
    /// Replace a sweep's files that exist in `dir`.
    pub force: bool,
    /// The slice of the sweep asked for, which names the files
    /// (`sweep.K-of-N.csv`, even for `1/N`); the sweep's options run the
    /// same slice.
    pub shard: Option<Shard>,
}

/// What a front end is told while a sweep writes its files.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Note {
    /// A new sweep replaces the rows an interrupted one left.
    ReplacingPartial {
        /// The interrupted sweep's partial CSV.
        partial: PathBuf,
        /// The directory.
        dir: PathBuf,
    },
    /// A resumed sweep starts from the rows it found.
    Resuming {
        /// The CSV the rows were read from.
        from: PathBuf,
        /// Samples already done.
        done: u64,
        /// Samples of the shard.
        total: u64,
    },
    /// A stopped sweep kept its finished rows.
    Kept {
        /// Rows kept.
        rows: u64,
        /// The CSV that holds them.
        csv: PathBuf,
    },
}

impl std::fmt::Display for Note {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Note::ReplacingPartial { partial, dir } => write!(
                f,
                "note: {} holds the rows of an interrupted sweep; this new sweep replaces it \
                 (--resume {} would have continued it)",
                partial.display(),
                dir.display()
            ),
            Note::Resuming { from, done, total } => write!(
                f,
                "resuming {}: {done} of {total} samples done",
                from.display()
            ),
            Note::Kept { rows, csv } => write!(
                f,
                "sweep interrupted: {rows} finished rows kept in {}; continue with --resume {}",
                csv.display(),
                csv.parent().unwrap_or(Path::new(".")).display()
            ),
        }
    }
}

/// Why a sweep's files could not be written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FilesError {
    /// The sweep's CSV exists and neither `force` nor `resume` was given.
    #[error(
        "{}: already exists; pass --force to overwrite the sweep's files, --resume {} to \
         continue an interrupted sweep, or choose another --out",
        path.display(),
        dir.display()
    )]
    Exists {
        /// The CSV.
        path: PathBuf,
        /// Its directory.
        dir: PathBuf,
    },
    /// An output could not be written, or is in the way.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// The interrupted sweep cannot be continued.
    #[error(transparent)]
    Resume(#[from] ResumeError),
    /// The sweep cannot run.
    #[error(transparent)]
    Sweep(#[from] SweepError),
    /// The sweep stopped while it ran (its rows could not be written, or
    /// the caller stopped it).
    #[error("{}: the sweep stopped", path.display())]
    Stopped {
        /// The CSV.
        path: PathBuf,
        /// Why.
        #[source]
        source: Box<SweepError>,
    },
    /// The plot could not be rendered as PNG.
    #[cfg(feature = "png")]
    #[error(transparent)]
    Png(#[from] crate::report::png::PngError),
}

/// What a sweep wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Written {
    /// The summary (`summary.json`).
    pub summary: Summary,
    /// Rows in the CSV.
    pub rows: u64,
    /// The files, the CSV first (its identity file not among them).
    pub files: Vec<PathBuf>,
}

/// The sweep's file names in its directory: a shard writes its CSV alone.
pub fn file_names(shard: Option<Shard>) -> Vec<String> {
    match shard {
        Some(s) => vec![format!("sweep.{}-of-{}.csv", s.index, s.count)],
        None => {
            let mut names = vec![
                "sweep.csv".to_owned(),
                "summary.json".to_owned(),
                "sweep.svg".to_owned(),
            ];
            if cfg!(feature = "png") {
                names.push("sweep.png".to_owned());
            }
            names
        }
    }
}

/// Which sweep this is, for `sweep.meta.json` and a resume: `text` is the
/// scenario's whole TOML text.
pub fn identity(
    scenario: &Scenario,
    text: &str,
    sampler: &Sampler,
    options: &SweepOptions<'_>,
    shard: Option<Shard>,
) -> Identity {
    let netlist_text = match scenario.netlist() {
        Some(Ok((_, netlist))) => netlist,
        _ => String::new(),
    };
    let circuit = matches!(options.mode, SweepMode::Circuit(_));
    Identity {
        tool: format!("chatterspice {}", env!("CARGO_PKG_VERSION")),
        scenario_digest: resume::digest(&[text.as_bytes(), netlist_text.as_bytes()]),
        seed: sampler.seed(),
        samples: sampler.count(),
        shard: shard.map(|s| s.to_string()),
        mode: if circuit { "circuit" } else { "mechanics" }.to_owned(),
        ideal: options.run.compare_ideal && circuit,
    }
}

/// Runs `scenario`'s sweep into `to.dir`: the CSV row by row, then the
/// summary, the plots and the identity file. `text` is the scenario's
/// whole TOML text (its digest identifies the sweep). `note` is told what
/// a person would want to know (also from a signal's thread).
pub fn write(
    scenario: &Scenario,
    text: &str,
    sampler: &Sampler,
    options: &SweepOptions<'_>,
    to: &Destination,
    progress: &dyn Progress,
    note: fn(&Note),
) -> Result<Written, FilesError> {
    let dir = &to.dir;
    let shard = to.shard;
    let names = file_names(shard);
    let csv_path = dir.join(&names[0]);
    let meta_path = resume::meta_path(&csv_path);
    let _lock = OutputLock::acquire(dir, &names[0])?;
    if !to.resume {
        refuse_existing(dir, &names, &meta_path, to.force)?;
    }
    let identity = identity(scenario, text, sampler, options, shard);
    let (partial_csv, partial_meta) = (resume::partial(&csv_path), resume::partial(&meta_path));
    // What a run killed outright left, else what a signal left.
    let (from_csv, from_meta) = if partial_csv.exists() && partial_meta.exists() {
        (partial_csv.clone(), partial_meta.clone())
    } else {
        (csv_path.clone(), meta_path.clone())
    };
    let kept = if to.resume {
        resume::check_meta(&from_meta, &identity)?;
        let (header, signals, columns) = super::run::layout(scenario, sampler, options)?;
        let mut done = super::summary::Collected::new(sampler.keys().to_vec(), signals.clone());
        let end = resume::finished_rows(
            &from_csv,
            &header,
            sampler.keys().len(),
            signals.len(),
            columns,
            options.shard,
            |record| done.add(&record).map_err(FilesError::from),
        )?;
        Some((end, done))
    } else {
        if partial_csv.exists() {
            note(&Note::ReplacingPartial {
                partial: partial_csv.clone(),
                dir: dir.clone(),
            });
        }
        None
    };
    // Resuming from the partial CSV continues it in place; from a CSV
    // elsewhere, its finished rows are copied first (below).
    let in_place = kept
        .as_ref()
        .filter(|_| from_csv == partial_csv)
        .map(|k| k.0);
    let mut staged = match in_place {
        Some(end) => Staged::continuing(&csv_path, &partial_csv, end, true)?,
        None => Staged::with_name(&csv_path, &partial_csv, to.force || to.resume)?,
    };
    let partial_meta_text = Meta {
        identity: identity.clone(),
        complete: false,
        rows: 0,
    }
    .to_json();
    let cannot_write = |path: &Path| {
        let path = path.to_path_buf();
        move |source| WriteError::Io { path, source }
    };
    std::fs::write(&partial_meta, partial_meta_text).map_err(cannot_write(&partial_meta))?;
    // Gone with the partial CSV when the sweep fails; kept beside it when
    // the process is killed.
    let _partial_meta =
        tempfile::TempPath::try_from_path(&partial_meta).map_err(cannot_write(&partial_meta))?;
    let done = match kept {
        Some((end, done)) => {
            if in_place.is_none() {
                copy_finished_rows(&from_csv, end, staged.file(), &partial_csv)?;
            }
            note(&Note::Resuming {
                from: from_csv.clone(),
                done: done.len() as u64,
                total: options.shard.len(sampler.count()),
            });
            Some(done)
        }
        None => None,
    };
    let stop = Stop {
        partial_csv: partial_csv.clone(),
        csv: csv_path.clone(),
        meta: meta_path.clone(),
        partial_meta: partial_meta.clone(),
        identity: identity.clone(),
        note,
    };
    let at_stop = {
        let stop = stop.clone();
        crate::interrupt::finish_at_stop(move || stop.keep_rows())
    };
    let collected =
        match super::run::run_from(scenario, sampler, options, staged.file(), progress, done) {
            Ok(c) if !progress.stopped() => c,
            outcome => {
                drop(at_stop);
                if progress.stopped() {
                    stop.keep_rows();
                }
                return Err(FilesError::Stopped {
                    path: csv_path,
                    source: Box::new(outcome.err().unwrap_or(SweepError::Stopped)),
                });
            }
        };
    let summary = collected.summary(sampler)?;
    let rows = collected.len() as u64;
    let mut files = Vec::new();
    if shard.is_none() {
        let svg = super::plot::render(&collected, sampler)?;
        files.push((names[1].clone(), summary.to_json().into_bytes()));
        #[cfg(feature = "png")]
        let png = crate::report::png::render(&svg)?;
        files.push((names[2].clone(), svg.into_bytes()));
        #[cfg(feature = "png")]
        files.push((names[3].clone(), png.bytes));
    }
    let meta = Meta {
        identity,
        complete: true,
        rows,
    };
    let meta_name = meta_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    files.push((meta_name, meta.to_json().into_bytes()));
    drop(at_stop);
    staged.commit()?;
    write_bundle(dir, &files, true)?;
    Ok(Written {
        summary,
        rows,
        files: names.iter().map(|n| dir.join(n)).collect(),
    })
}

/// Copy the header and the finished rows of `from` (its first `end`
/// bytes) into the staged CSV `to` (at `staged`), as they are: a file cut
/// short of `end` is an error naming it.
fn copy_finished_rows(
    from: &Path,
    end: u64,
    to: &mut std::fs::File,
    staged: &Path,
) -> Result<(), FilesError> {
    let cannot_write = |source| {
        FilesError::from(WriteError::Io {
            path: staged.to_path_buf(),
            source,
        })
    };
    let copied = crate::input::open_regular(from)
        .and_then(|file| std::io::copy(&mut std::io::Read::take(file, end), to));
    match copied {
        Ok(n) if n == end => Ok(()),
        Ok(_) => Err(cannot_write(std::io::Error::new(
            std::io::ErrorKind::UnexpectedEof,
            format!("{} was cut while it was copied", from.display()),
        ))),
        Err(e) => Err(cannot_write(e)),
    }
}

/// Fail before any work if the sweep's files exist (unless `force`), or
/// something is in the way of one.
fn refuse_existing(
    dir: &Path,
    names: &[String],
    meta_path: &Path,
    force: bool,
) -> Result<(), FilesError> {
    let csv_path = dir.join(&names[0]);
    for path in names
        .iter()
        .map(|n| dir.join(n))
        .chain([meta_path.to_path_buf()])
    {
        if let Err(e) = check_target(&path, force) {
            if matches!(e, WriteError::Exists { .. }) && path == csv_path {
                return Err(FilesError::Exists {
                    path,
                    dir: dir.to_path_buf(),
                });
            }
            return Err(e.into());
        }
    }
    Ok(())
}

/// What a stop keeps: the rows written so far into the partial CSV,
/// whole, moved to the CSV, and the identity file saying they are
/// incomplete, where a resume finds them.
#[derive(Clone)]
struct Stop {
    partial_csv: PathBuf,
    csv: PathBuf,
    meta: PathBuf,
    partial_meta: PathBuf,
    identity: Identity,
    note: fn(&Note),
}

impl Stop {
    fn keep_rows(&self) {
        if resume::truncate_to_whole_lines(&self.partial_csv).is_err() {
            return;
        }
        let rows = std::fs::read(&self.partial_csv).map_or(0, |b| resume::row_count(&b));
        if std::fs::rename(&self.partial_csv, &self.csv).is_ok() {
            let record = Meta {
                identity: self.identity.clone(),
                complete: false,
                rows,
            };
            if std::fs::write(&self.meta, record.to_json()).is_ok() {
                let _ = std::fs::remove_file(&self.partial_meta);
            }
            (self.note)(&Note::Kept {
                rows,
                csv: self.csv.clone(),
            });
        }
    }
}
