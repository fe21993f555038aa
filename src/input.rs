//! Reading the user's files without blocking and without surprises.
//!
//! Every file the tool reads on the user's behalf (scenario, netlist and
//! the files it includes, scope captures, measured records, raw files)
//! goes through [`open_regular`]: the path is opened non-blocking and the
//! opened file (not the path, which could change in between) must be a
//! regular file. A FIFO would otherwise block the tool forever waiting for
//! a writer, and a device such as `/dev/zero` would never end; both are
//! refused at once with [`NotRegular`] as the error's inner value.
//! [`read`] also bounds the size read.

use std::fmt;
use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// The largest text input read whole: far above any netlist, scenario or
/// capture export, far below what would exhaust memory.
pub const MAX_TEXT_BYTES: u64 = 512 * 1024 * 1024;

/// What a path that is not a regular file turned out to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NotRegular {
    /// A directory.
    Directory,
    /// A FIFO (named pipe): reading it would wait for a writer.
    Fifo,
    /// A Unix domain socket.
    Socket,
    /// A character device, such as `/dev/zero`, which may never end.
    CharDevice,
    /// A block device, such as a disk.
    BlockDevice,
    /// Anything else that is not a regular file.
    Other,
}

impl fmt::Display for NotRegular {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match self {
            NotRegular::Directory => "a directory",
            NotRegular::Fifo => "a FIFO (named pipe)",
            NotRegular::Socket => "a socket",
            NotRegular::CharDevice => "a character device",
            NotRegular::BlockDevice => "a block device",
            NotRegular::Other => "not a regular file",
        };
        write!(f, "{what}, not a regular file: give the path of a file")
    }
}

impl std::error::Error for NotRegular {}

/// Opens `path` for reading without blocking (a FIFO with no writer would
/// block `open` itself) and refuses anything but a regular file.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let kind = file.metadata()?.file_type();
    if kind.is_file() {
        return Ok(file);
    }
    Err(io::Error::new(io::ErrorKind::InvalidInput, kind_of(kind)))
}

fn kind_of(kind: std::fs::FileType) -> NotRegular {
    if kind.is_dir() {
        return NotRegular::Directory;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return NotRegular::Fifo;
        }
        if kind.is_socket() {
            return NotRegular::Socket;
        }
        if kind.is_char_device() {
            return NotRegular::CharDevice;
        }
        if kind.is_block_device() {
            return NotRegular::BlockDevice;
        }
    }
    NotRegular::Other
}

/// The bytes of the regular file at `path`, at most [`MAX_TEXT_BYTES`].
pub fn read(path: &Path) -> io::Result<Vec<u8>> {
    read_limited(path, MAX_TEXT_BYTES)
}

/// The bytes of the regular file at `path`; a file of more than `limit`
/// bytes is an error.
pub fn read_limited(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    let file = open_regular(path)?;
    let len = file.metadata()?.len();
    if len > limit {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{len} bytes is more than the {limit} bytes read whole: is this the right file?"
            ),
        ));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    // A file that grows while it is read is cut at the limit too.
    file.take(limit).read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// [`read`] as UTF-8 text.
pub fn read_to_string(path: &Path) -> io::Result<String> {
    String::from_utf8(read(path)?).map_err(|e| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "not UTF-8 text (byte {} is invalid): save it as UTF-8",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fifo_is_refused_at_once_and_a_file_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        let c = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: mkfifo reads the NUL-terminated path only.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let err = read(&fifo).unwrap_err();
        assert!(err.to_string().contains("FIFO"), "{err}");
        let err = read(dir.path()).unwrap_err();
        assert!(err.to_string().contains("directory"), "{err}");
        let err = read(Path::new("/dev/zero")).unwrap_err();
        assert!(err.to_string().contains("character device"), "{err}");
        let file = dir.path().join("f.txt");
        std::fs::write(&file, "hello").unwrap();
        assert_eq!(read_to_string(&file).unwrap(), "hello");
    }
}
