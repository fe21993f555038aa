//! The one way files reach the disk: outputs never harm inputs, and a
//! failed or interrupted write leaves the earlier file or nothing.
//!
//! - **Inputs are protected.** Every file a command reads is marked with
//!   [`protect_input`]; an output path that resolves to one of them
//!   (through `..`, a relative path or symbolic links) is refused, with
//!   `--force` too ([`WriteError::IsInput`]).
//! - **Writes are atomic.** A file is written to a temporary name in its
//!   own directory and renamed into place ([`Staged`]): a reader sees the
//!   old file or the new one, never half of one. A symbolic link in the
//!   way is replaced by the file, never written through.
//! - **Nothing in the way is removed.** Without `--force` an existing
//!   path is an error ([`WriteError::Exists`]); with it, only a regular
//!   file or a link is replaced: a directory (or a FIFO, a socket) in the
//!   way is an error ([`WriteError::InTheWay`]).
//! - **Bundles are all or nothing.** [`write_bundle`] checks every target,
//!   stages every file, and only then renames them in: a bundle that
//!   fails leaves the previous bundle (or nothing), never a partial one.
//! - **One run at a time per output.** [`OutputLock`] holds an advisory
//!   lock (`flock`) on a lock file beside the outputs for the length of a
//!   run; a second run into the same outputs is refused
//!   ([`WriteError::Busy`]). The lock file is removed when the run ends,
//!   also at a signal; one left by a killed process (SIGKILL) holds no
//!   lock and blocks nothing.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// Why an output could not be written.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum WriteError {
    /// The output exists and `--force` was not given.
    #[error("{}: already exists; it was left untouched (pass --force to replace it)", path.display())]
    Exists {
        /// The output path.
        path: PathBuf,
    },
    /// The output resolves to a file the run reads.
    #[error(
        "{}: this is an input of the run (the scenario, its netlist, a file it includes or a \
         record); --force overwrites earlier outputs, never inputs: choose another output",
        path.display()
    )]
    IsInput {
        /// The output path, as given.
        path: PathBuf,
    },
    /// With `--force`, the output path holds something other than a
    /// regular file or a symbolic link.
    #[error(
        "{}: {what} is in the way of an output and is left alone: move it, or choose another \
         output",
        path.display()
    )]
    InTheWay {
        /// The output path.
        path: PathBuf,
        /// What is there: `"a directory"` or `"a special file"`.
        what: &'static str,
    },
    /// Another process holds the output's lock.
    #[error(
        "{}: another chatterspice run is writing these outputs now (it holds {}): wait for it, \
         or choose another output",
        dir.display(), lock.display()
    )]
    Busy {
        /// The directory of the outputs.
        dir: PathBuf,
        /// The lock file held.
        lock: PathBuf,
    },
    /// The file system refused an operation on an output or its directory
    /// (creating, writing, renaming, locking).
    #[error("{}: cannot write it", path.display())]
    Io {
        /// The file or directory the operation was on.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
}

fn io_error(path: &Path) -> impl Fn(std::io::Error) -> WriteError + '_ {
    move |source| WriteError::Io {
        path: path.to_owned(),
        source,
    }
}

/// The files this process read as inputs.
static INPUTS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Mark `path` as an input: no output is ever written over it.
pub fn protect_input(path: &Path) {
    if let Some(id) = identity(path) {
        let mut inputs = INPUTS.lock().unwrap_or_else(|e| e.into_inner());
        if !inputs.contains(&id) {
            inputs.push(id);
        }
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

/// The canonical path of `path` (symbolic links followed), or of its
/// directory joined with its name when the file does not exist yet.
fn identity(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = path.canonicalize() {
        return Some(p);
    }
    let name = path.file_name()?;
    dir_of(path).canonicalize().ok().map(|d| d.join(name))
}

fn dir_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Checks that `path` may be written: not an input, not in the way, and
/// (unless `overwrite`) not there at all.
pub fn check_target(path: &Path, overwrite: bool) -> Result<(), WriteError> {
    if is_input(path) {
        return Err(WriteError::IsInput {
            path: path.to_owned(),
        });
    }
    let Ok(meta) = path.symlink_metadata() else {
        return Ok(());
    };
    if !overwrite {
        return Err(WriteError::Exists {
            path: path.to_owned(),
        });
    }
    let kind = meta.file_type();
    if kind.is_file() || kind.is_symlink() {
        return Ok(());
    }
    Err(WriteError::InTheWay {
        path: path.to_owned(),
        what: if kind.is_dir() {
            "a directory"
        } else {
            "a special file"
        },
    })
}

/// A file being written under a temporary name beside its target, put in
/// place by [`Staged::commit`]; dropped uncommitted, it is removed.
#[derive(Debug)]
pub struct Staged {
    tmp: tempfile::NamedTempFile,
    target: PathBuf,
    overwrite: bool,
}

impl Staged {
    /// Checks `target` ([`check_target`]) and creates the temporary file.
    pub fn new(target: &Path, overwrite: bool) -> Result<Staged, WriteError> {
        check_target(target, overwrite)?;
        let tmp = tempfile::Builder::new()
            .prefix(".chatterspice-")
            .suffix(".tmp")
            .tempfile_in(dir_of(target))
            .map_err(io_error(target))?;
        Ok(Staged {
            tmp,
            target: target.to_owned(),
            overwrite,
        })
    }

    /// [`Staged::new`] at a known temporary path `partial` (created, or
    /// emptied): for an output written over a long run, which a later run
    /// may continue from if this one is killed.
    pub fn with_name(target: &Path, partial: &Path, overwrite: bool) -> Result<Staged, WriteError> {
        check_target(target, overwrite)?;
        check_target(partial, true)?;
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(partial)
            .map_err(io_error(partial))?;
        let path = tempfile::TempPath::try_from_path(partial).map_err(io_error(partial))?;
        Ok(Staged {
            tmp: tempfile::NamedTempFile::from_parts(file, path),
            target: target.to_owned(),
            overwrite,
        })
    }

    /// [`Staged::with_name`] continuing the temporary file `partial` that
    /// a stopped run left: its first `keep` bytes stay, the rest is cut,
    /// and writing goes on after them.
    pub fn continuing(
        target: &Path,
        partial: &Path,
        keep: u64,
        overwrite: bool,
    ) -> Result<Staged, WriteError> {
        check_target(target, overwrite)?;
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(partial)
            .map_err(io_error(partial))?;
        file.set_len(keep)
            .and_then(|()| std::io::Seek::seek(&mut file, std::io::SeekFrom::End(0)))
            .map_err(io_error(partial))?;
        let path = tempfile::TempPath::try_from_path(partial).map_err(io_error(partial))?;
        Ok(Staged {
            tmp: tempfile::NamedTempFile::from_parts(file, path),
            target: target.to_owned(),
            overwrite,
        })
    }

    /// The file to write to.
    pub fn file(&mut self) -> &mut File {
        self.tmp.as_file_mut()
    }

    /// The temporary file's path (for a finisher that must reach it).
    pub fn temporary_path(&self) -> &Path {
        self.tmp.path()
    }

    /// The path the file goes to.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Flushes the file to disk and renames it to its target, after
    /// checking the target once more (it may have appeared meanwhile).
    pub fn commit(self) -> Result<(), WriteError> {
        let target = self.target;
        let io = io_error(&target);
        check_target(&target, self.overwrite)?;
        // A temporary file is private (0600); an output is an ordinary
        // file, or keeps the mode of the file it replaces.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = match std::fs::metadata(&target) {
                Ok(existing) if self.overwrite && existing.is_file() => {
                    existing.permissions().mode()
                }
                _ => 0o644,
            };
            self.tmp
                .as_file()
                .set_permissions(std::fs::Permissions::from_mode(mode))
                .map_err(&io)?;
        }
        self.tmp.as_file().sync_all().map_err(&io)?;
        let persisted = if self.overwrite {
            self.tmp.persist(&target)
        } else {
            self.tmp.persist_noclobber(&target)
        };
        // On failure the temporary file is dropped with the error, removing it.
        persisted.map(drop).map_err(|e| {
            if e.error.kind() == std::io::ErrorKind::AlreadyExists {
                WriteError::Exists {
                    path: target.clone(),
                }
            } else {
                io(e.error)
            }
        })
    }
}

/// Writes `contents` to `path` atomically (see the module overview).
pub fn write_new_file(path: &Path, contents: &[u8], overwrite: bool) -> Result<(), WriteError> {
    let mut staged = Staged::new(path, overwrite)?;
    staged.file().write_all(contents).map_err(io_error(path))?;
    staged.commit()
}

/// Writes several files into `dir` (created if needed), all or nothing:
/// every target is checked and every file staged before the first is
/// renamed into place. Unless `overwrite`, nothing is written when any
/// file exists already; the error names the first.
pub fn write_bundle(
    dir: &Path,
    files: &[(String, Vec<u8>)],
    overwrite: bool,
) -> Result<(), WriteError> {
    std::fs::create_dir_all(dir).map_err(io_error(dir))?;
    for (name, _) in files {
        check_target(&dir.join(name), overwrite)?;
    }
    let mut staged = Vec::with_capacity(files.len());
    for (name, contents) in files {
        let path = dir.join(name);
        let mut file = Staged::new(&path, overwrite)?;
        file.file().write_all(contents).map_err(io_error(&path))?;
        staged.push(file);
    }
    for file in staged {
        file.commit()?;
    }
    Ok(())
}

/// An exclusive hold on a set of outputs for the length of a run: a lock
/// file `.<name>.chatterspice-lock` in `dir`, locked with `flock`, and
/// removed on drop (and at a signal).
#[derive(Debug)]
pub struct OutputLock {
    path: PathBuf,
    _file: File,
    _at_stop: crate::interrupt::Registered,
}

impl OutputLock {
    /// Locks the outputs named `name` in `dir` (created if needed), or
    /// fails with [`WriteError::Busy`] when another run holds them.
    pub fn acquire(dir: &Path, name: &str) -> Result<OutputLock, WriteError> {
        std::fs::create_dir_all(dir).map_err(io_error(dir))?;
        let path = dir.join(format!(".{name}.chatterspice-lock"));
        loop {
            let file = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io_error(&path))?;
            if !try_lock(&file).map_err(io_error(&path))? {
                return Err(WriteError::Busy {
                    dir: dir.to_owned(),
                    lock: path,
                });
            }
            // The holder before us may have removed the file between our
            // open and our lock: then the lock is on a file nobody else
            // sees, so take the one at the path now.
            if same_file(&file, &path) {
                let at_stop = crate::interrupt::remove_at_stop(&path);
                return Ok(OutputLock {
                    path,
                    _file: file,
                    _at_stop: at_stop,
                });
            }
        }
    }
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        // Removed while still locked, so that no other run can lock this
        // file and then lose it.
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(unix)]
fn try_lock(file: &File) -> std::io::Result<bool> {
    use std::os::unix::io::AsRawFd;
    // SAFETY: flock(2) on a descriptor we own; it reads no memory.
    let r = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if r == 0 {
        return Ok(true);
    }
    let err = std::io::Error::last_os_error();
    if err.raw_os_error() == Some(libc::EWOULDBLOCK) {
        Ok(false)
    } else {
        Err(err)
    }
}

#[cfg(not(unix))]
fn try_lock(_file: &File) -> std::io::Result<bool> {
    Ok(true)
}

#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_file: &File, path: &Path) -> bool {
    path.exists()
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

    /// A directory where the last file of a bundle goes: with --force the
    /// bundle fails as a whole, the earlier bundle stays, the directory
    /// and what it holds stay, and no temporary file is left.
    #[test]
    fn a_directory_in_the_way_fails_the_bundle_and_is_left_alone() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path();
        let first = [
            ("report.json".to_owned(), b"old".to_vec()),
            ("plot.svg".to_owned(), b"old".to_vec()),
        ];
        write_bundle(out, &first, false).unwrap();
        std::fs::create_dir(out.join("plot.png")).unwrap();
        std::fs::write(out.join("plot.png/mine.txt"), "mine").unwrap();
        let second = [
            ("report.json".to_owned(), b"new".to_vec()),
            ("plot.svg".to_owned(), b"new".to_vec()),
            ("plot.png".to_owned(), b"new".to_vec()),
        ];
        let err = write_bundle(out, &second, true).unwrap_err();
        assert!(matches!(err, WriteError::InTheWay { .. }), "{err:?}");
        assert_eq!(std::fs::read(out.join("report.json")).unwrap(), b"old");
        assert_eq!(
            std::fs::read(out.join("plot.png/mine.txt")).unwrap(),
            b"mine"
        );
        let names: Vec<String> = std::fs::read_dir(out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names.len(), 3, "{names:?}");
    }

    /// A link in the way to an input is refused; a link elsewhere is
    /// replaced by the file, and what it pointed to is untouched.
    #[cfg(unix)]
    #[test]
    fn links_are_never_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("netlist.cir"), "input").unwrap();
        std::fs::write(d.join("other.txt"), "other").unwrap();
        protect_input(&d.join("netlist.cir"));
        std::os::unix::fs::symlink(d.join("netlist.cir"), d.join("sweep.csv")).unwrap();
        std::os::unix::fs::symlink(d.join("other.txt"), d.join("plot.svg")).unwrap();
        let err = write_new_file(&d.join("sweep.csv"), b"rows", true).unwrap_err();
        assert!(matches!(err, WriteError::IsInput { .. }), "{err:?}");
        write_new_file(&d.join("plot.svg"), b"<svg/>", true).unwrap();
        assert_eq!(std::fs::read(d.join("netlist.cir")).unwrap(), b"input");
        assert_eq!(std::fs::read(d.join("other.txt")).unwrap(), b"other");
        assert_eq!(std::fs::read(d.join("plot.svg")).unwrap(), b"<svg/>");
    }

    #[test]
    fn a_missing_directory_is_an_io_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no/such/dir/out.txt");
        let err = write_new_file(&path, b"x", false).unwrap_err();
        assert!(matches!(err, WriteError::Io { .. }), "{err:?}");
        assert!(err.to_string().contains("out.txt"), "{err}");
    }

    #[test]
    fn a_lock_is_exclusive_and_leaves_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        let lock = OutputLock::acquire(dir.path(), "sweep.csv").unwrap();
        let err = OutputLock::acquire(dir.path(), "sweep.csv").unwrap_err();
        assert!(matches!(err, WriteError::Busy { .. }), "{err:?}");
        // Other outputs in the same directory are not held.
        drop(OutputLock::acquire(dir.path(), "sweep.2-of-4.csv").unwrap());
        drop(lock);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        // A lock file left by a killed run holds no lock.
        std::fs::write(dir.path().join(".sweep.csv.chatterspice-lock"), "").unwrap();
        drop(OutputLock::acquire(dir.path(), "sweep.csv").unwrap());
    }
}
