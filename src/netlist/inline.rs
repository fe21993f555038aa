//! Included files, read and checked by chatterspice and written into the
//! deck, so that ngspice reads nothing the tool did not check.
//!
//! ngspice treats some lines of *any* file it reads as commands: a
//! `.control` … `.endc` block (recognised by prefix, case-insensitively,
//! so `.CONTROLS` opens one too) and a line starting `*#`. Commands can
//! run programs (`shell`), write files and source scripts. A vendor model
//! library or a colleague's subcircuit is data, so every file a netlist
//! reaches through `.include`/`.inc…` or `.lib FILE SECTION`, at any depth,
//! is inlined here with its command lines left out (with a warning naming
//! the file and lines). The run deck then names no user file at all.
//!
//! As in ngspice: a relative path is read from the including file's
//! directory (`~/` from the home directory); `.lib FILE SECTION` takes the
//! lines between `.lib SECTION` and `.endl` of FILE; `.lib FILE` alone
//! includes the whole file (PSpice style); a `.end` inside an included
//! file is ignored. A file that includes itself, directly or not, is an
//! error, as is nesting deeper than [`MAX_DEPTH`] or more than
//! [`MAX_INLINED_BYTES`] of inlined text.

use std::path::{Path, PathBuf};

use super::error::{DeckWarning, NetlistError};
use super::lexical::{physical_lines, resolve, split_path, strip_comment};

/// Nesting depth of includes: far beyond real projects.
pub const MAX_DEPTH: usize = 32;
/// Inlined text in all: vendor libraries of tens of megabytes pass.
pub const MAX_INLINED_BYTES: usize = 256 * 1024 * 1024;

/// Where a deck line came from: line `line` (1-based) of file `file`, an
/// index into the deck's list of files (0 being the user's netlist).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SourceLine {
    /// Index into the deck's files; 0 is the user's netlist.
    pub file: usize,
    /// 1-based line in that file.
    pub line: usize,
}

/// What a command line looks like to ngspice: `Some` for the start of a
/// `.control` block, a `.endc` or a `*#` command comment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Command {
    ControlStart,
    ControlEnd,
    Hash,
}

/// How ngspice classifies a physical line (it strips leading blanks and
/// compares prefixes without regard to case).
pub(super) fn command_line(line: &str) -> Option<Command> {
    let t = line.trim_start().as_bytes();
    let starts = |p: &[u8]| t.len() >= p.len() && t[..p.len()].eq_ignore_ascii_case(p);
    if starts(b".control") {
        Some(Command::ControlStart)
    } else if starts(b".endc") {
        Some(Command::ControlEnd)
    } else if starts(b"*#") {
        Some(Command::Hash)
    } else {
        None
    }
}

/// Whether `title` makes ngspice read the whole deck as a command script.
pub(super) fn is_script_title(title: &str) -> bool {
    let t = title.trim_start().as_bytes();
    t.len() >= 10 && t[..10].eq_ignore_ascii_case(b"*ng_script")
}

/// The inlined lines of a deck, with their origins.
pub(super) struct Inliner<'w> {
    pub lines: Vec<(String, Option<SourceLine>)>,
    /// Every file read; index 0 is the user's netlist.
    pub files: Vec<PathBuf>,
    pub warnings: &'w mut Vec<DeckWarning>,
    /// The files being inlined, outermost first (cycle detection).
    stack: Vec<PathBuf>,
    bytes: usize,
}

/// An include card, as the inliner needs it.
pub(super) struct IncludeRef<'a> {
    /// The file, resolved.
    pub path: &'a Path,
    /// `.lib FILE SECTION`'s section; `None` for the whole file.
    pub section: Option<&'a str>,
    /// The card that includes it.
    pub card: &'a str,
    /// Where that card is.
    pub from: SourceLine,
}

impl<'w> Inliner<'w> {
    pub fn new(netlist: &Path, warnings: &'w mut Vec<DeckWarning>) -> Inliner<'w> {
        Inliner {
            lines: Vec::new(),
            files: vec![netlist.to_path_buf()],
            warnings,
            stack: vec![identity(netlist)],
            bytes: 0,
        }
    }

    fn file_path(&self, index: usize) -> PathBuf {
        self.files[index].clone()
    }

    pub fn push(&mut self, line: String, origin: Option<SourceLine>) {
        self.lines.push((line, origin));
    }

    /// Inlines the file (or section) of `include`, between two comment
    /// lines that name it.
    pub fn include(&mut self, include: &IncludeRef<'_>) -> Result<(), NetlistError> {
        let includer = self.file_path(include.from.file);
        let id = identity(include.path);
        if self.stack.contains(&id) {
            return Err(NetlistError::IncludeCycle {
                netlist: includer,
                line: include.from.line,
                included: include.path.to_path_buf(),
            });
        }
        if self.stack.len() > MAX_DEPTH {
            return Err(NetlistError::IncludeTooDeep {
                netlist: includer,
                line: include.from.line,
                depth: MAX_DEPTH,
            });
        }
        let bytes =
            crate::input::read(include.path).map_err(|source| NetlistError::ReadInclude {
                netlist: includer.clone(),
                line: include.from.line,
                included: include.path.to_path_buf(),
                source,
            })?;
        self.bytes += bytes.len();
        if self.bytes > MAX_INLINED_BYTES {
            return Err(NetlistError::IncludeTooLarge {
                netlist: includer,
                line: include.from.line,
                limit: MAX_INLINED_BYTES,
            });
        }
        // An output of this process never replaces a file the run reads.
        crate::output::protect_input(include.path);
        let text = String::from_utf8_lossy(&bytes);
        let file = self.files.len();
        self.files.push(include.path.to_path_buf());
        let what = match include.section {
            Some(section) => format!("section {section} of \"{}\"", include.path.display()),
            None => format!("\"{}\"", include.path.display()),
        };
        self.push(
            format!(
                "* chatterspice: begin {what}, inlined for `{}`",
                include.card
            ),
            None,
        );
        self.stack.push(id);
        let result = self.lines_of(&text, file, include);
        self.stack.pop();
        result?;
        self.push(format!("* chatterspice: end {what}"), None);
        Ok(())
    }

    fn lines_of(
        &mut self,
        text: &str,
        file: usize,
        include: &IncludeRef<'_>,
    ) -> Result<(), NetlistError> {
        let path = include.path;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        // With a section: outside it until its `.lib SECTION`, inside until `.endl`.
        let mut inside = include.section.is_none();
        let mut found = include.section.is_none();
        let mut control: Option<usize> = None;
        for (index, raw) in physical_lines(text).into_iter().enumerate() {
            let line = index + 1;
            let origin = Some(SourceLine { file, line });
            if let Some(section) = include.section {
                let words: Vec<&str> = raw.split_whitespace().collect();
                let keyword = words.first().map(|w| w.to_ascii_lowercase());
                match keyword.as_deref() {
                    Some(k) if !inside && k.starts_with(".lib") && words.len() == 2 => {
                        if words[1].eq_ignore_ascii_case(section) {
                            inside = true;
                            found = true;
                        }
                        continue;
                    }
                    Some(k) if inside && k.starts_with(".endl") => {
                        inside = false;
                        continue;
                    }
                    _ => {}
                }
                if !inside {
                    continue;
                }
            }
            match (control, command_line(raw)) {
                (Some(first), Some(Command::ControlEnd)) => {
                    self.warnings.push(DeckWarning::ControlRemoved {
                        netlist: path.to_path_buf(),
                        first,
                        last: line,
                    });
                    control = None;
                    continue;
                }
                (Some(_), _) => continue,
                (None, Some(Command::ControlStart)) => {
                    control = Some(line);
                    continue;
                }
                (None, Some(Command::Hash)) => {
                    self.warnings.push(DeckWarning::CommandCommentRemoved {
                        netlist: path.to_path_buf(),
                        line,
                    });
                    continue;
                }
                // A stray `.endc` ends nothing; ngspice ignores it too.
                (None, Some(Command::ControlEnd)) => {
                    self.push(format!("* {raw}"), origin);
                    continue;
                }
                (None, None) => {}
            }
            let trimmed = raw.trim_start();
            let keyword = trimmed
                .split_whitespace()
                .next()
                .unwrap_or("")
                .to_ascii_lowercase();
            if keyword == ".end" {
                self.push(format!("* {trimmed}"), origin);
                continue;
            }
            let is_inc = keyword.starts_with(".inc");
            let is_lib = keyword.starts_with(".lib");
            if is_inc || is_lib {
                let rest = trimmed[keyword.len()..].trim();
                let rest = strip_comment(rest).trim();
                let (written, after) = split_path(rest);
                if written.is_empty() {
                    self.push(raw.to_owned(), origin);
                    continue;
                }
                let resolved = resolve(written, &base);
                let section = after.split_whitespace().next();
                if is_lib && section.is_none() && !resolved.is_file() {
                    // `.lib NAME`: a section header of this file.
                    self.push(raw.to_owned(), origin);
                    continue;
                }
                if !resolved.is_file() && !resolved.exists() {
                    return Err(NetlistError::MissingInclude {
                        netlist: path.to_path_buf(),
                        line,
                        card: trimmed.to_owned(),
                        resolved,
                    });
                }
                self.include(&IncludeRef {
                    path: &resolved,
                    section: if is_lib { section } else { None },
                    card: trimmed,
                    from: SourceLine { file, line },
                })?;
                continue;
            }
            self.push(raw.to_owned(), origin);
        }
        if let Some(first) = control {
            return Err(NetlistError::UnclosedControl {
                netlist: path.to_path_buf(),
                line: first,
            });
        }
        if !found {
            return Err(NetlistError::MissingLibSection {
                netlist: self.file_path(include.from.file),
                line: include.from.line,
                library: path.to_path_buf(),
                section: include.section.unwrap_or_default().to_owned(),
            });
        }
        Ok(())
    }
}

/// The path as a cycle check compares it: canonical when it exists.
fn identity(path: &Path) -> PathBuf {
    path.canonicalize().unwrap_or_else(|_| path.to_path_buf())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn command_lines_are_recognised_as_ngspice_does() {
        for (line, want) in [
            (".control", Some(Command::ControlStart)),
            ("  .CONTROLS", Some(Command::ControlStart)),
            ("\t.Endc", Some(Command::ControlEnd)),
            ("*# shell touch x", Some(Command::Hash)),
            (" *#echo", Some(Command::Hash)),
            ("* # a comment", None),
            ("+.control", None),
            ("R1 a b 1k", None),
        ] {
            assert_eq!(command_line(line), want, "{line:?}");
        }
        assert!(is_script_title("*ng_script"));
        assert!(is_script_title("*NG_SCRIPT_with_params"));
        assert!(!is_script_title("* ng_script"));
        assert!(!is_script_title("my circuit"));
    }
}
