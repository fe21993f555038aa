//! The SPICE raw file reader: what ngspice (or LTspice) hands back after a
//! run.
//!
//! A raw file is one or more *plots* (one per analysis: `.op`, `.tran`,
//! `.ac`, ...) concatenated with no separator. Each plot is a text header
//! (`Title:`, `Date:`, `Command:`, `Plotname:`, `Flags:`, `No. Variables:`,
//! `No. Points:`, `Dimensions:`, `Option:`, `Variables:`) followed by either
//! `Binary:` (point-major little-endian `f64`; complex plots store every
//! value as a `(re, im)` pair) or `Values:` (ASCII: a point index, then one
//! value per line, `re,im` for complex plots).
//!
//! What this reader deliberately copes with, because real files do it:
//! - both ASCII layouts: the batch writer's (`0\t\t<v>` and no blank line)
//!   and the `.control` `write` command's (` 0\t<v>`, blank line after each
//!   point), extra `key=value` attributes after the type, separated by a tab
//!   (batch) or a space (`write`);
//! - the `Command: version 44` line of ngspice 44+ and any other
//!   `Command:`/`Option:`/`Dimensions:` lines;
//! - `Flags: ... unpadded` with vectors shorter than the plot (`dims=`);
//! - a killed run: the batch writer patches `No. Points:` only when the
//!   analysis ends, so a killed run leaves `0` there and the data cut at an
//!   arbitrary byte. The point count is derived from the data, read up to
//!   the last whole point, and a [`RawWarning`] says so;
//! - `.options interp` in ngspice 39: more points than `No. Points:`
//!   declares (read, up to the next plot's header, with a warning), and
//!   with UIC the data started over several times, the variables and
//!   `Binary:` written again after an all-zero point (the last start's
//!   points are kept, with a warning). Its time stamps also run slow
//!   where the simulator's step exceeds the `.tran` step, which no reader
//!   can undo: `run` leaves `interp` out of the deck;
//! - ngspice 39 leaves garbage in the imaginary part of the AC frequency
//!   axis, so a complex plot's `frequency` scale is stored as real.
//!
//! LTspice writes the same structure in a dialect of its own ([`Dialect`]),
//! read into the same types:
//! - the header in UTF-16 little-endian, with no byte order mark (one is
//!   skipped if there); for ASCII data the values too. Names (plots,
//!   vectors, the title) are kept exactly, beyond ASCII included
//!   (`Noise Spectral Density - (V/Hz½ or A/Hz½)`). A UTF-8 header is read
//!   as LTspice's when a `Command:` line names LTspice, or an `Offset:` or
//!   `Backannotation:` line, or a flag only LTspice writes, says so;
//! - binary values: the first vector (time, frequency, the swept source,
//!   an operating point's first value) an `f64`, every other an `f32`
//!   (stored as the `f64` it converts to exactly), unless `Flags:` says
//!   `double` (all `f64`); complex plots store every value, the frequency
//!   included, as an `(re, im)` pair of `f64`. Points follow one another,
//!   or with `Flags: ... fastaccess` each vector's values are contiguous;
//! - time stamps with their sign bit set (LTspice's waveform compression
//!   leaves some negative) are read as their absolute value;
//! - `.step` runs (`Flags: ... stepped`) are one plot holding every step:
//!   the reader splits it into one [`Plot`] per step, with [`Plot::step`]
//!   saying which (see [`Step`] for how steps are told apart);
//! - `Offset:`, `Backannotation:`, `Output:` and other `Key: value` lines
//!   are kept verbatim in [`Plot::other_header_lines`];
//! - bytes after the declared points that are not another plot's header
//!   (LTspice has been seen to leave an all-zero point there) are left
//!   unread, with a [`RawWarning::TrailingData`]; a file cut short keeps
//!   its whole points with a [`RawWarning::Truncated`], but FastAccess
//!   data cut short are an error ([`RawError::ShortFastAccess`]).
//!
//! Malformed input is an error naming the line (text) or byte offset
//! (binary; offsets count the file's bytes, in UTF-16 text too); the
//! reader never panics and never allocates more than the input can fill,
//! whatever the header claims. Values are stored once, one `Vec` per
//! vector, so memory is the size of the data (LTspice's `f32` values take
//! twice their size as `f64`).

mod data;
mod direct;
mod error;
pub mod export;
mod header;
mod locate;
mod ltspice;
mod read;
mod stream;
#[cfg(test)]
mod tests;
mod types;
mod write;

pub use error::{Position, RawError};
pub use stream::stream_csv;
pub use types::{
    Complex64, Dialect, Encoding, Flags, MAX_LOADED_BYTES, Plot, RawFile, RawWarning, Step,
    Variable, Vector,
};
pub use write::to_binary;
