//! Reports: the last stage of the pipeline, where a result becomes text.
//!
//! One small module per format, each a pure function from the result to a
//! `String`:
//! - [`json`]: the contract of docs/output.md, for scripts;
//! - [`csv`]: one row per impact, for spreadsheets and plotting;
//! - [`table`]: a summary and an aligned impact table, for a person at a
//!   terminal, in engineering units;
//! - [`svg`]: a plot of the contact and the probed signals over time;
//! - [`bundle`]: every file of a `run --out DIR`.
//!
//! Output is deterministic: the same result gives byte-identical text (no
//! timestamps, fixed field order, shortest round-trip floats).
//! [`write_new_file`] puts a report on disk without clobbering anything.

pub mod bundle;
pub mod csv;
pub mod json;
pub mod png;
pub mod svg;
pub mod table;
pub mod units;

use std::io::Write;
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::chatter::Chatter;
use crate::mechanics::Dimensionless;

/// The formats a chatter result can be rendered in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Json,
    Csv,
    Table,
}

/// Render `chatter` in `format`. `dimensionless` (the relay's groups) is
/// added to the JSON when given; the other formats show the sequence only.
pub fn render(format: Format, chatter: &Chatter, dimensionless: Option<&Dimensionless>) -> String {
    match format {
        Format::Json => json::render(chatter, dimensionless),
        Format::Csv => csv::render(chatter),
        Format::Table => table::render(chatter),
    }
}

/// Why a report could not be written.
#[derive(Debug, Error)]
pub enum WriteError {
    #[error("{}: already exists; it was left untouched", path.display())]
    Exists { path: PathBuf },
    #[error(
        "{}: this is an input of the run (the scenario, its netlist or a record); \
         --force overwrites earlier outputs, never inputs: choose another output",
        path.display()
    )]
    IsInput { path: PathBuf },
    #[error("{}: cannot write the report", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

/// The files this process read as inputs; [`write_new_file`] refuses to
/// write over any of them, even when told to overwrite.
static INPUTS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Mark `path` as an input: no report is ever written over it.
pub fn protect_input(path: &Path) {
    if let Some(id) = identity(path) {
        INPUTS.lock().unwrap_or_else(|e| e.into_inner()).push(id);
    }
}

/// Whether `path` names a file marked with [`protect_input`] (by another
/// name too: through `..`, a symbolic link or a relative path).
pub fn is_input(path: &Path) -> bool {
    identity(path).is_some_and(|id| {
        INPUTS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .contains(&id)
    })
}

/// The canonical path of `path`, or of its directory joined with its name
/// when the file does not exist yet.
fn identity(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = path.canonicalize() {
        return Some(p);
    }
    let name = path.file_name()?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    dir.canonicalize().ok().map(|d| d.join(name))
}

/// Write several report files into `dir`, creating it if needed. Unless
/// `overwrite`, nothing is written when any of the files already exists:
/// the error names the first, and the directory is left as it was (apart
/// from being created), so a second run never clobbers half of a first.
/// Each file is written with [`write_new_file`].
pub fn write_bundle(
    dir: &Path,
    files: &[(String, Vec<u8>)],
    overwrite: bool,
) -> Result<(), WriteError> {
    std::fs::create_dir_all(dir).map_err(|source| WriteError::Io {
        path: dir.to_owned(),
        source,
    })?;
    if let Some(path) = files
        .iter()
        .map(|(name, _)| dir.join(name))
        .find(|p| is_input(p))
    {
        return Err(WriteError::IsInput { path });
    }
    if !overwrite {
        if let Some(path) = files
            .iter()
            .map(|(name, _)| dir.join(name))
            .find(|p| p.symlink_metadata().is_ok())
        {
            return Err(WriteError::Exists { path });
        }
    }
    for (name, contents) in files {
        write_new_file(&dir.join(name), contents, overwrite)?;
    }
    Ok(())
}

/// Write `contents` to `path` all at once: into a temporary file in the
/// same directory, then renamed over `path`, so that a reader (or a crash)
/// never sees half a report. Unless `overwrite`, an existing `path` is an
/// error and stays untouched; the check is the rename itself, so a file
/// created meanwhile is not clobbered either.
pub fn write_new_file(path: &Path, contents: &[u8], overwrite: bool) -> Result<(), WriteError> {
    let io = |source| WriteError::Io {
        path: path.to_owned(),
        source,
    };
    if is_input(path) {
        return Err(WriteError::IsInput {
            path: path.to_owned(),
        });
    }
    // Checked up front too, so that an existing file is reported as such
    // even where the temporary file could not be created.
    if !overwrite && path.symlink_metadata().is_ok() {
        return Err(WriteError::Exists {
            path: path.to_owned(),
        });
    }
    let dir = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".chatterspice-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(io)?;
    tmp.write_all(contents).map_err(io)?;
    // A temporary file is private (0600); a report is an ordinary file.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = match std::fs::metadata(path) {
            Ok(existing) if overwrite => existing.permissions().mode(),
            _ => 0o644,
        };
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(mode))
            .map_err(io)?;
    }
    tmp.as_file().sync_all().map_err(io)?;
    let persisted = if overwrite {
        tmp.persist(path)
    } else {
        tmp.persist_noclobber(path)
    };
    // On failure the temporary file is dropped with the error, removing it.
    persisted.map(drop).map_err(|e| {
        if e.error.kind() == std::io::ErrorKind::AlreadyExists {
            WriteError::Exists {
                path: path.to_owned(),
            }
        } else {
            io(e.error)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_a_new_file_and_leaves_no_temporary_behind() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.json");
        write_new_file(&path, b"{}\n", false).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "{}\n");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn a_new_report_is_readable_by_others_like_any_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("report.json");
        write_new_file(&path, b"{}", false).unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o644);
    }

    #[test]
    fn refuses_to_overwrite_unless_asked() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        std::fs::write(&path, "precious").unwrap();
        let err = write_new_file(&path, b"new", false).unwrap_err();
        assert!(matches!(err, WriteError::Exists { .. }), "{err:?}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "precious");
        write_new_file(&path, b"new", true).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_bundle_is_all_or_nothing_when_a_file_exists() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("run");
        let files = [
            ("report.json".to_owned(), b"{}".to_vec()),
            ("plot.svg".to_owned(), b"<svg/>".to_vec()),
        ];
        write_bundle(&out, &files, false).unwrap();
        assert_eq!(std::fs::read(out.join("plot.svg")).unwrap(), b"<svg/>");

        std::fs::remove_file(out.join("report.json")).unwrap();
        std::fs::write(out.join("plot.svg"), "mine").unwrap();
        let err = write_bundle(&out, &files, false).unwrap_err();
        assert!(err.to_string().contains("plot.svg"), "{err}");
        assert!(
            !out.join("report.json").exists(),
            "wrote part of the bundle"
        );
        assert_eq!(
            std::fs::read_to_string(out.join("plot.svg")).unwrap(),
            "mine"
        );

        write_bundle(&out, &files, true).unwrap();
        assert_eq!(std::fs::read(out.join("report.json")).unwrap(), b"{}");
    }

    #[test]
    fn a_missing_directory_is_an_io_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no/such/dir/out.txt");
        let err = write_new_file(&path, b"x", false).unwrap_err();
        assert!(matches!(err, WriteError::Io { .. }), "{err:?}");
        assert!(err.to_string().contains("out.txt"), "{err}");
    }
}

/// Hand-built results for the renderers' tests: the engine is tested on
/// its own, and these pin down every shape a report must handle.
#[cfg(test)]
pub(crate) mod fixtures {
    use crate::chatter::{Chatter, ContactState, Impact, Interval, Outcome};

    fn interval(state: ContactState, start: f64, end: f64) -> Interval {
        Interval { state, start, end }
    }

    /// Two bounces, then stuck on the third impact (Kelvin–Voigt-like).
    pub fn stuck() -> Chatter {
        use ContactState::{Closed, Open};
        let bounce = |t: f64, v: f64, tr: f64, vr: f64, peak: f64, min: f64, gap: f64| Impact {
            impact_time: t,
            impact_velocity: v,
            release_time: Some(tr),
            release_velocity: Some(vr),
            restitution: Some(-vr / v),
            contact_time: Some(tr - t),
            peak_force: Some(peak),
            min_force: Some(min),
            max_gap_after: Some(gap),
        };
        Chatter {
            outcome: Outcome::Stuck,
            first_impact: Some(0.0012),
            settle_time: Some(0.0016),
            bounce_count: 2,
            impacts: vec![
                bounce(0.0012, 0.31, 0.00121, -0.26, 2.1, -0.1, 3.0e-6),
                bounce(0.0014, 0.2, 0.001405, -0.15, 1.25, -0.04, 1.0e-6),
                Impact {
                    impact_time: 0.0016,
                    impact_velocity: 0.05,
                    release_time: None,
                    release_velocity: None,
                    restitution: None,
                    contact_time: None,
                    peak_force: Some(0.6),
                    min_force: Some(0.36),
                    max_gap_after: None,
                },
            ],
            intervals: vec![
                interval(Open, 0.0, 0.0012),
                interval(Closed, 0.0012, 0.00121),
                interval(Open, 0.00121, 0.0014),
                interval(Closed, 0.0014, 0.001405),
                interval(Open, 0.001405, 0.0016),
                interval(Closed, 0.0016, 0.02),
            ],
            shortfall: None,
            accumulation_time: None,
            t_end: 0.02,
        }
    }

    /// The gap is beyond the overshoot: no impact at all.
    pub fn never_closes() -> Chatter {
        Chatter {
            outcome: Outcome::NeverCloses,
            first_impact: None,
            settle_time: None,
            bounce_count: 0,
            impacts: vec![],
            intervals: vec![interval(ContactState::Open, 0.0, 0.02)],
            shortfall: Some(2.5e-5),
            accumulation_time: None,
            t_end: 0.02,
        }
    }
}
