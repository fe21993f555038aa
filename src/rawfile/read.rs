//! Reading a whole raw file: [`RawFile::read`] from disk (straight into
//! the columns when it can) and [`RawFile::parse`] from bytes in memory.

use std::path::Path;

use super::data::{read_ascii, read_binary};
use super::direct;
use super::error::RawError;
use super::header::{Cursor, DataKind, parse_header};
use super::ltspice;
use super::types::{Dialect, MAX_LOADED_BYTES, RawFile};

/// The metadata of `path`, which must be a regular file: a device or a
/// pipe could feed a reader without end.
pub(super) fn regular_file(path: &Path) -> Result<std::fs::Metadata, RawError> {
    let meta = std::fs::metadata(path).map_err(|source| RawError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    if !meta.is_file() {
        return Err(RawError::NotAFile {
            path: path.to_path_buf(),
        });
    }
    Ok(meta)
}

impl RawFile {
    /// Reads and parses a raw file; errors name the path. Only regular
    /// files of at most [`MAX_LOADED_BYTES`] are read (a device such as
    /// `/dev/zero` would never end).
    ///
    /// ngspice's binary files (whole, or cut short by a killed run) are
    /// read from the disk straight into the columns a block of points at a
    /// time, so memory is the size of the values plus a 256 KiB buffer; any
    /// other file (ASCII, LTspice's, `.options interp`, unpadded) is read
    /// whole and parsed as [`RawFile::parse`] does. Both give the same
    /// plots and warnings.
    pub fn read(path: impl AsRef<Path>) -> Result<RawFile, RawError> {
        let path = path.as_ref();
        let io = |source| RawError::Io {
            path: path.to_path_buf(),
            source,
        };
        let meta = regular_file(path)?;
        if meta.len() > MAX_LOADED_BYTES {
            return Err(RawError::TooLarge {
                path: path.to_path_buf(),
                size: meta.len(),
                limit: MAX_LOADED_BYTES,
            });
        }
        let mut file = crate::input::open_regular(path).map_err(io)?;
        let len = file.metadata().map_err(io)?.len();
        if let Some(raw) = direct::read(&mut file, len).map_err(io)? {
            return Ok(raw);
        }
        drop(file);
        let bytes = crate::input::read_limited(path, MAX_LOADED_BYTES).map_err(io)?;
        RawFile::parse(&bytes).map_err(|error| RawError::InFile {
            path: path.to_path_buf(),
            error: Box::new(error),
        })
    }

    /// Parses the bytes of a raw file.
    ///
    /// ```
    /// use chatterspice::rawfile::RawFile;
    ///
    /// let text = "Title: divider\nDate: today\nPlotname: Transient Analysis\n\
    ///             Flags: real\nNo. Variables: 2\nNo. Points: 2\nVariables:\n\
    ///             \t0\ttime\ttime\n\t1\tv(out)\tvoltage\nValues:\n\
    ///             0\t0.0\n\t1.5\n1\t1e-3\n\t1.65\n";
    /// let raw = RawFile::parse(text.as_bytes())?;
    /// let plot = raw.last_transient().expect("a transient plot");
    /// assert_eq!(plot.real("v(out)"), Some(&[1.5, 1.65][..]));
    /// # Ok::<(), chatterspice::rawfile::RawError>(())
    /// ```
    pub fn parse(bytes: &[u8]) -> Result<RawFile, RawError> {
        let mut cur = Cursor {
            bytes,
            pos: 0,
            line: Some(1),
        };
        let mut plots = Vec::new();
        let mut warnings = Vec::new();
        let mut title = String::new();
        let mut date = String::new();
        loop {
            ltspice::skip_blank(&mut cur);
            if cur.at_end() {
                break;
            }
            let index = plots.len();
            let (mut plot, warning) = match ltspice::utf16_start(cur.rest(), cur.at())? {
                Some(bom) => ltspice::read_utf16_plot(&mut cur, bom, &mut title, &mut date, index)?,
                None => {
                    let header = parse_header(&mut cur, &mut title, &mut date)?;
                    match (header.data, header.plot.dialect) {
                        (DataKind::Binary, Dialect::Ngspice) => {
                            read_binary(&mut cur, header, index)?
                        }
                        (DataKind::Binary, Dialect::Ltspice) => {
                            ltspice::read_binary(&mut cur, header, index)?
                        }
                        (DataKind::Ascii, _) => read_ascii(&mut cur, header, index)?,
                    }
                }
            };
            if plot.dialect == Dialect::Ltspice {
                ltspice::unsign_time(&mut plot);
            }
            let steps = ltspice::split_steps(plot);
            // A stepped plot's warnings are about where its data end: in
            // its last step.
            let last = index + steps.len().saturating_sub(1);
            warnings.extend(warning.into_iter().map(|w| w.in_plot(last)));
            plots.extend(steps);
        }
        if plots.is_empty() {
            return Err(RawError::Empty);
        }
        Ok(RawFile { plots, warnings })
    }
}
