//! The lexical rules ngspice reads a netlist line by (comments, quoted
//! paths, where a relative path points), shared by the deck and the
//! inliner.

use std::path::{Path, PathBuf};

/// The line without its inline comment (`;` anywhere, `$` after
/// whitespace), and without a whole-line `*` comment.
pub(super) fn strip_comment(line: &str) -> &str {
    if line.trim_start().starts_with('*') {
        return "";
    }
    let mut prev_space = true;
    for (i, c) in line.char_indices() {
        if c == ';' || (c == '$' && prev_space) {
            return &line[..i];
        }
        prev_space = c.is_whitespace();
    }
    line
}

/// A possibly quoted path and the rest of the card.
pub(super) fn split_path(rest: &str) -> (&str, &str) {
    for quote in ['"', '\''] {
        if let Some(inner) = rest.strip_prefix(quote) {
            if let Some(end) = inner.find(quote) {
                return (&inner[..end], inner[end + 1..].trim());
            }
        }
    }
    match rest.find(char::is_whitespace) {
        Some(i) => (&rest[..i], rest[i..].trim()),
        None => (rest, ""),
    }
}

pub(super) fn resolve(written: &str, base: &Path) -> PathBuf {
    if let Some(home_rel) = written.strip_prefix("~/") {
        if let Some(home) = std::env::var_os("HOME") {
            return PathBuf::from(home).join(home_rel);
        }
    }
    let p = base.join(written);
    // A netlist given by a relative path has a relative directory; the
    // deck runs elsewhere, so the current directory is joined here.
    std::path::absolute(&p).unwrap_or(p)
}

/// Lines without their `\r`; a final newline does not make an extra line.
pub(super) fn physical_lines(text: &str) -> Vec<&str> {
    let mut lines: Vec<&str> = text
        .split('\n')
        .map(|l| l.strip_suffix('\r').unwrap_or(l))
        .collect();
    if lines.len() > 1 && lines[lines.len() - 1].is_empty() {
        lines.pop();
    }
    lines
}
