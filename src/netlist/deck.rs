//! The run deck: the user's netlist, read and never written, with what the
//! run needs around it.
//!
//! ngspice reads a deck as *cards*: the first line is always the title
//! (whatever it says: a `.include` there is silently lost), a line starting
//! with `+` continues the card before it (comment and blank lines in
//! between do not interrupt it), `*` starts a comment line, `;` and a `$`
//! after whitespace start an inline comment, and names and keywords are
//! case-insensitive. CRLF endings and tabs are accepted.
//!
//! [`prepare_deck`] copies the netlist line by line and changes only this:
//! - `.include <contact include>` right after the title;
//! - each `.include`/`.inc…`/`.lib FILE [SECTION]` card is replaced by the
//!   file's (or the section's) text, read and checked by
//!   [`super::inline`]; a relative path is resolved against the netlist's
//!   directory, and a missing file is an error naming the line;
//! - `.control` … `.endc` blocks (matched by prefix, as ngspice does) and
//!   `*#` lines are left out, with a warning; a `*ng_script` title is
//!   refused. ngspice runs these as commands. In batch mode
//!   (`ngspice -b -r out.raw`) the runner owns the analysis and the raw
//!   file; a control block would run its own `tran` a second time, `write`
//!   elsewhere, or `quit` before the raw file exists;
//! - when the netlist has `.save` lines (then ngspice saves only what they
//!   name), a `.save` for each probe's vectors;
//! - `.end` and anything after it are dropped, and one `.end` closes the deck.
//!
//! It checks that some `X` card instantiates the contact subcircuit (in the
//! netlist or, failing that, in the files it includes), that the netlist
//! does not define a subcircuit of that name itself, and that there is one
//! `.tran` whose stop time covers the chatter.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

pub use super::error::DeckWarning;
use super::error::NetlistError;
use super::inline::{Command, IncludeRef, Inliner, SourceLine, command_line, is_script_title};
use super::lexical::{physical_lines, resolve, split_path, strip_comment};
use super::number::parse_number;
use crate::waveform::format_time;

/// How deep [`prepare_deck`] follows `.include`s looking for the contact's
/// `X` line: enough for any real project, and a guard against cycles.
const MAX_INCLUDE_DEPTH: usize = 8;

/// What to build a run deck from.
#[derive(Debug, Clone, Copy)]
pub struct DeckRequest<'a> {
    /// The netlist's text.
    pub netlist_text: &'a str,
    /// Where it was read from: the base of relative include paths, and the
    /// name in messages.
    pub netlist_path: &'a Path,
    /// The contact include's plain file name, written next to the deck.
    pub include_file_name: &'a str,
    /// The contact subcircuit's name, e.g. `CONTACT`.
    pub subckt: &'a str,
    /// For a coil-driven relay: the coil include's plain file name and the
    /// coil subcircuit's name (e.g. `COIL`), which the netlist must
    /// instantiate too.
    pub coil: Option<(&'a str, &'a str)>,
    /// ngspice vector names to measure: `v(node)`, `v(a,b)`, `i(vsource)`.
    pub probes: &'a [&'a str],
    /// s, when the chatter ends: a `.tran` that stops earlier is an error.
    pub chatter_end: f64,
    /// s, the stop time the caller wants (chatter end plus a margin): a
    /// `.tran` that stops earlier is a warning.
    pub stop_at_least: f64,
    /// Option lines the deck carries right after the includes (before the
    /// netlist's own, so that a later `.options` of the netlist wins),
    /// e.g. the arc's integration method.
    pub options: &'a [&'a str],
}

/// The run deck and what was noticed on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct Deck {
    /// Title line first, `.end` last, `\n` line endings.
    pub text: String,
    /// For each line of `text`, the file (an index into `files`) and
    /// 1-based line it came from; `None` for a line chatterspice added.
    pub source_lines: Vec<Option<SourceLine>>,
    /// Every file the deck holds text of: the user's netlist first, then
    /// each included file in the order it was inlined (a file included
    /// twice is listed twice).
    pub files: Vec<PathBuf>,
    /// What the deck left out or the user may want to change, in the
    /// order noticed.
    pub warnings: Vec<DeckWarning>,
    /// The analysis the deck runs, as it is in the deck.
    pub tran: Tran,
}

impl Deck {
    /// The file and line (1-based) behind line `deck_line` (1-based, the
    /// title being line 1, as ngspice counts) of the deck, when it has one:
    /// the user's netlist or a file it includes.
    pub fn source_line(&self, deck_line: usize) -> Option<(&Path, usize)> {
        let origin = deck_line
            .checked_sub(1)
            .and_then(|i| self.source_lines.get(i).copied().flatten())?;
        Some((self.files.get(origin.file)?.as_path(), origin.line))
    }
}

/// A `.tran tstep tstop [tstart [tmax]] [uic]` card. SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tran {
    /// s
    pub tstep: f64,
    /// s
    pub tstop: f64,
    /// s, 0 when not given.
    pub tstart: f64,
    /// s, when given.
    pub tmax: Option<f64>,
    /// `uic`: start from the initial conditions, skipping the operating
    /// point.
    pub uic: bool,
    /// 1-based line in the netlist.
    pub line: usize,
}

impl Tran {
    /// The same card with its stop time set to `stop` (s): the step,
    /// TSTART, TMAX and `uic` kept as the user wrote them, so that a
    /// suggestion changes nothing but the stop.
    pub fn with_stop(&self, stop: f64) -> String {
        let mut card = format!(
            ".tran {} {}",
            crate::waveform::format_time(self.tstep),
            crate::waveform::format_time(stop)
        );
        if self.tstart != 0.0 || self.tmax.is_some() {
            if self.tstart == 0.0 {
                card += " 0";
            } else {
                card += &format!(" {}", crate::waveform::format_time(self.tstart));
            }
        }
        if let Some(tmax) = self.tmax {
            card += &format!(" {}", crate::waveform::format_time(tmax));
        }
        if self.uic {
            card += " uic";
        }
        card
    }

    /// s, the largest step ngspice takes: TMAX, or by default
    /// min(tstep, (tstop − tstart)/50).
    pub fn effective_max_step(&self) -> f64 {
        self.tmax
            .unwrap_or_else(|| self.tstep.min((self.tstop - self.tstart) / 50.0))
    }
}

/// One card: its physical lines and its text with continuations joined
/// and comments removed.
pub(super) struct Card {
    /// 0-based index of the first physical line.
    first: usize,
    /// 0-based index of the last physical line.
    last: usize,
    /// The card's text, continuations joined, comments removed.
    pub(super) text: String,
}

impl Card {
    fn line(&self) -> usize {
        self.first + 1
    }

    fn keyword(&self) -> String {
        self.text
            .split_whitespace()
            .next()
            .unwrap_or("")
            .to_ascii_lowercase()
    }
}

/// What happens to a physical line of the netlist in the deck.
enum Fate {
    Keep,
    Drop,
    Replace(String),
    /// An include card: the file (or its section) is inlined.
    Inline {
        path: PathBuf,
        section: Option<String>,
        card: String,
    },
}

/// Build the run deck around the user's netlist (see the module overview).
pub fn prepare_deck(req: &DeckRequest<'_>) -> Result<Deck, NetlistError> {
    prepare_deck_with_params(req, &[])
}

/// [`prepare_deck`], with values for the netlist's own `.param` names
/// (`[circuit.params]`): each must be defined by a top-level `.param` of
/// the netlist or of a file it includes, and is set again at the end of
/// the deck. ngspice lets the last definition win everywhere, expressions
/// that use the name included (measured with ngspice 39), so the user's
/// file stays as it is.
pub fn prepare_deck_with_params(
    req: &DeckRequest<'_>,
    params: &[(&str, f64)],
) -> Result<Deck, NetlistError> {
    let netlist = req.netlist_path;
    let mut save_lines: Vec<String> = Vec::new();
    for probe in req.probes {
        save_lines.extend(save_names(probe)?);
    }
    let lines = physical_lines(req.netlist_text);
    let mut warnings = Vec::new();
    check_title(&lines, netlist, &mut warnings)?;
    let (mut fates, control_line) = leave_out_commands(&lines, netlist, &mut warnings)?;
    let scan = scan_cards(req, &lines, &mut fates, &mut warnings)?;
    check_instances(req, &scan)?;
    check_params(req, params, &scan)?;
    let tran = check_tran(req, scan.tran, control_line, &mut warnings)?;
    let deck = Written {
        lines: &lines,
        fates: &fates,
        params,
        save: if scan.has_save { &save_lines } else { &[] },
        tran,
    };
    write_deck(req, &deck, warnings)
}

/// The title line: never a `*ng_script`, and a warning when it looks like
/// a card (ngspice ignores it as the title).
fn check_title(
    lines: &[&str],
    netlist: &Path,
    warnings: &mut Vec<DeckWarning>,
) -> Result<(), NetlistError> {
    let netlist = netlist.to_path_buf();
    if lines.iter().all(|l| l.trim().is_empty()) {
        return Err(NetlistError::EmptyNetlist { netlist });
    }
    let title = lines[0];
    if is_script_title(title) {
        return Err(NetlistError::ScriptTitle { netlist });
    }
    let title_word = title.split_whitespace().next().unwrap_or("");
    if title_word.starts_with('.') && !title_word.eq_ignore_ascii_case(".title") {
        warnings.push(DeckWarning::TitleIsCard {
            netlist,
            text: title.trim().to_owned(),
        });
    }
    Ok(())
}

/// Each line's fate after the command lines (`.control` blocks, `*#`) and
/// everything from `.end` on are left out, and the first line of a
/// `.control` block, if any.
fn leave_out_commands(
    lines: &[&str],
    netlist: &Path,
    warnings: &mut Vec<DeckWarning>,
) -> Result<(Vec<Fate>, Option<usize>), NetlistError> {
    let netlist = netlist.to_path_buf();
    let mut fates: Vec<Fate> = (0..lines.len()).map(|_| Fate::Keep).collect();
    let mut control_line = None;
    let mut i = 1;
    while i < lines.len() {
        let word = first_word(lines[i]);
        let command = command_line(lines[i]);
        if command == Some(Command::Hash) {
            fates[i] = Fate::Drop;
            warnings.push(DeckWarning::CommandCommentRemoved {
                netlist: netlist.clone(),
                line: i + 1,
            });
            i += 1;
            continue;
        }
        if command == Some(Command::ControlStart) {
            let start = i;
            let end = (i + 1..lines.len())
                .find(|&j| command_line(lines[j]) == Some(Command::ControlEnd))
                .ok_or(NetlistError::UnclosedControl {
                    netlist: netlist.clone(),
                    line: start + 1,
                })?;
            fates[start..=end].fill_with(|| Fate::Drop);
            control_line.get_or_insert(start + 1);
            warnings.push(DeckWarning::ControlRemoved {
                netlist: netlist.clone(),
                first: start + 1,
                last: end + 1,
            });
            i = end + 1;
            continue;
        }
        if word == ".end" {
            fates[i..].fill_with(|| Fate::Drop);
            if let Some(j) = (i + 1..lines.len()).find(|&j| !is_blank_or_comment(lines[j])) {
                warnings.push(DeckWarning::IgnoredAfterEnd {
                    netlist: netlist.clone(),
                    line: j + 1,
                });
            }
            break;
        }
        i += 1;
    }

    Ok((fates, control_line))
}

/// What the netlist's own cards hold.
struct Scan {
    instances: usize,
    coil_instances: usize,
    has_save: bool,
    tran: Option<Tran>,
    /// The include cards: line and file.
    includes: Vec<(usize, PathBuf)>,
    /// Top-level `.param` names, lower case.
    defined: HashSet<String>,
}

/// Reads the cards of the lines `fates` keeps: include cards become
/// [`Fate::Inline`], `.options interp` is left out, and the rest is
/// recorded in a [`Scan`].
fn scan_cards(
    req: &DeckRequest<'_>,
    lines: &[&str],
    fates: &mut [Fate],
    warnings: &mut Vec<DeckWarning>,
) -> Result<Scan, NetlistError> {
    let netlist = req.netlist_path.to_path_buf();
    let base = req
        .netlist_path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    // Cards are only read outside the lines left out, and not the title.
    let live: Vec<bool> = fates
        .iter()
        .enumerate()
        .map(|(i, f)| i > 0 && !matches!(f, Fate::Drop))
        .collect();
    let cards = cards(lines, &live);
    let mut instances = 0;
    let mut coil_instances = 0;
    let mut has_save = false;
    let mut tran: Option<Tran> = None;
    let mut includes: Vec<(usize, PathBuf)> = Vec::new();
    // `.subckt` nesting: a `.param` inside one is local to it.
    let mut depth = 0usize;
    let mut defined: HashSet<String> = HashSet::new();
    for card in &cards {
        let keyword = card.keyword();
        match keyword.as_str() {
            k if k.starts_with(".inc") || k.starts_with(".lib") => {
                if let Some((path, section)) = resolve_include(card, k, &base, &netlist)? {
                    fates[card.first] = Fate::Inline {
                        path: path.clone(),
                        section,
                        card: card.text.clone(),
                    };
                    for fate in &mut fates[card.first + 1..=card.last] {
                        *fate = Fate::Drop;
                    }
                    includes.push((card.line(), path));
                }
            }
            ".save" => has_save = true,
            ".options" | ".option" | ".opt" => {
                let words: Vec<&str> = card.text.split_whitespace().collect();
                let is_interp = |w: &&str| w.eq_ignore_ascii_case("interp");
                if words.iter().any(is_interp) {
                    let kept: Vec<&str> = words.into_iter().filter(|w| !is_interp(w)).collect();
                    let text = if kept.len() > 1 {
                        kept.join(" ")
                    } else {
                        "* chatterspice: `.options interp` left out".to_owned()
                    };
                    replace(fates, card, text);
                    warnings.push(DeckWarning::InterpRemoved {
                        netlist: netlist.clone(),
                        line: card.line(),
                    });
                }
            }
            ".param" if depth == 0 => {
                defined.extend(param_names(&card.text));
            }
            ".ends" => depth = depth.saturating_sub(1),
            ".subckt" => {
                depth += 1;
                let name = card.text.split_whitespace().nth(1).unwrap_or("");
                if name.eq_ignore_ascii_case(req.subckt) {
                    return Err(NetlistError::SubcktConflict {
                        netlist,
                        line: card.line(),
                        subckt: req.subckt.to_owned(),
                    });
                }
            }
            ".tran" => {
                if let Some(first) = &tran {
                    return Err(NetlistError::TwoTran {
                        netlist,
                        first: first.line,
                        second: card.line(),
                    });
                }
                tran = Some(parse_tran(card, &netlist)?);
            }
            _ => {
                if instantiates(&card.text, req.subckt) {
                    instances += 1;
                }
                if req
                    .coil
                    .is_some_and(|(_, coil)| instantiates(&card.text, coil))
                {
                    coil_instances += 1;
                }
            }
        }
    }

    Ok(Scan {
        instances,
        coil_instances,
        has_save,
        tran,
        includes,
        defined,
    })
}

/// Some `X` card, in the netlist or a file it includes, uses the contact
/// (and the coil, for a coil-driven relay).
fn check_instances(req: &DeckRequest<'_>, scan: &Scan) -> Result<(), NetlistError> {
    let netlist = req.netlist_path.to_path_buf();
    let (instances, coil_instances, includes) =
        (scan.instances, scan.coil_instances, &scan.includes);
    if instances == 0 {
        let mut seen = HashSet::new();
        let found = includes.iter().try_fold(false, |found, (line, path)| {
            if found {
                return Ok(true);
            }
            include_instantiates(path, req.subckt, &netlist, *line, 1, &mut seen)
        })?;
        if !found {
            return Err(NetlistError::NoContactInstance {
                netlist,
                subckt: req.subckt.to_owned(),
            });
        }
    }
    if let Some((_, coil)) = req.coil {
        let mut seen = HashSet::new();
        let mut found = coil_instances > 0;
        for (line, path) in includes {
            if found {
                break;
            }
            found = include_instantiates(path, coil, &netlist, *line, 1, &mut seen)?;
        }
        if !found {
            return Err(NetlistError::NoCoilInstance {
                netlist,
                subckt: coil.to_owned(),
            });
        }
    }

    Ok(())
}

/// Every `[circuit.params]` name is a top-level `.param` of the netlist
/// or of a file it includes.
fn check_params(
    req: &DeckRequest<'_>,
    params: &[(&str, f64)],
    scan: &Scan,
) -> Result<(), NetlistError> {
    let netlist = req.netlist_path.to_path_buf();
    let mut defined = scan.defined.clone();
    let includes = &scan.includes;
    if !params.is_empty() {
        let mut seen = HashSet::new();
        for (_, path) in includes {
            include_params(path, 1, &mut seen, &mut defined);
        }
        if let Some((name, _)) = params
            .iter()
            .find(|(name, _)| !defined.contains(&name.to_ascii_lowercase()))
        {
            return Err(NetlistError::UnknownParam {
                netlist,
                name: (*name).to_owned(),
                defined: {
                    let mut names: Vec<&str> = defined.iter().map(String::as_str).collect();
                    names.sort_unstable();
                    names.join(", ")
                },
            });
        }
    }

    Ok(())
}

/// The one `.tran`, long enough for the chatter (an error) and for the
/// circuit to settle after it (a warning).
fn check_tran(
    req: &DeckRequest<'_>,
    tran: Option<Tran>,
    control_line: Option<usize>,
    warnings: &mut Vec<DeckWarning>,
) -> Result<Tran, NetlistError> {
    let netlist = req.netlist_path.to_path_buf();
    let Some(tran) = tran else {
        return Err(NetlistError::NoTran {
            netlist,
            stop: req.stop_at_least,
            control_line,
        });
    };
    if tran.tstop < req.chatter_end {
        let stop = round_up_2(req.stop_at_least.max(req.chatter_end));
        return Err(NetlistError::TranTooShort {
            netlist,
            line: tran.line,
            tstop: tran.tstop,
            tstep: tran.tstep,
            chatter_end: req.chatter_end,
            stop,
            card: tran.with_stop(stop),
        });
    }
    if tran.tstop < req.stop_at_least {
        let wanted = round_up_2(req.stop_at_least);
        warnings.push(DeckWarning::StopShort {
            netlist: netlist.clone(),
            line: tran.line,
            tstop: tran.tstop,
            tstep: tran.tstep,
            wanted,
            card: tran.with_stop(wanted),
        });
    }
    Ok(tran)
}

/// What [`write_deck`] writes.
struct Written<'a> {
    lines: &'a [&'a str],
    fates: &'a [Fate],
    params: &'a [(&'a str, f64)],
    /// The probes' `.save` vectors, when the netlist saves its own.
    save: &'a [String],
    tran: Tran,
}

/// The deck: title, the contact (and coil) includes, the netlist's lines
/// by their fates with included files written in, the scenario's
/// parameters, the probes' saves, `.end`.
fn write_deck(
    req: &DeckRequest<'_>,
    deck: &Written<'_>,
    mut warnings: Vec<DeckWarning>,
) -> Result<Deck, NetlistError> {
    let Written {
        lines,
        fates,
        params,
        save,
        tran,
    } = *deck;
    let title = lines[0];
    let mut inliner = Inliner::new(req.netlist_path, &mut warnings);
    let own = |line: usize| Some(SourceLine { file: 0, line });
    inliner.push(title.to_owned(), own(1));
    inliner.push(
        format!(
            "* chatterspice run deck for {}; that file is not modified",
            req.netlist_path.display()
        ),
        None,
    );
    inliner.push(
        format!(".include {}", quote_if_needed(req.include_file_name)),
        None,
    );
    if let Some((coil_include, _)) = req.coil {
        inliner.push(format!(".include {}", quote_if_needed(coil_include)), None);
    }
    for option in req.options {
        inliner.push((*option).to_owned(), None);
    }
    for (index, (line, fate)) in lines.iter().zip(fates).enumerate().skip(1) {
        match fate {
            Fate::Keep => inliner.push((*line).to_owned(), own(index + 1)),
            Fate::Drop => {}
            Fate::Replace(new) => inliner.push(new.clone(), own(index + 1)),
            Fate::Inline {
                path,
                section,
                card,
            } => inliner.include(&IncludeRef {
                path,
                section: section.as_deref(),
                card,
                from: SourceLine {
                    file: 0,
                    line: index + 1,
                },
            })?,
        }
    }
    if !params.is_empty() {
        inliner.push(
            "* chatterspice: the scenario's [circuit.params]".to_owned(),
            None,
        );
        for (name, value) in params {
            inliner.push(format!(".param {name}={}", format_time(*value)), None);
        }
    }
    if !save.is_empty() {
        inliner.push("* chatterspice: the probes".to_owned(), None);
        inliner.push(format!(".save {}", save.join(" ")), None);
    }
    inliner.push(".end".to_owned(), None);
    let files = std::mem::take(&mut inliner.files);
    let mut text = String::new();
    let mut source_lines = Vec::with_capacity(inliner.lines.len());
    for (line, origin) in inliner.lines {
        text.push_str(&line);
        text.push('\n');
        source_lines.push(origin);
    }
    Ok(Deck {
        text,
        source_lines,
        files,
        warnings,
        tran,
    })
}

/// The value the netlist's own top-level `.param name=value` gives `name`
/// (the last such definition), when that value is a plain number
/// (`8.2n`, `{47e-9}`); `None` for an expression or no definition.
pub fn param_value(netlist_text: &str, name: &str) -> Option<f64> {
    let lines = physical_lines(netlist_text);
    let mut live = vec![true; lines.len()];
    if let Some(title) = live.first_mut() {
        *title = false;
    }
    let mut nesting = 0usize;
    let mut found = None;
    for card in cards(&lines, &live) {
        match card.keyword().as_str() {
            ".subckt" => nesting += 1,
            ".ends" => nesting = nesting.saturating_sub(1),
            ".param" if nesting == 0 => {
                let body = card.text.trim_start().get(".param".len()..).unwrap_or("");
                // `a = 1 b={2}`: split at each `=`, the name is the last
                // word before it, the value the first word after it.
                let parts: Vec<&str> = body.split('=').collect();
                for k in 0..parts.len().saturating_sub(1) {
                    let before = parts[k].split_whitespace().last().unwrap_or("");
                    if before.eq_ignore_ascii_case(name) {
                        let after = parts[k + 1].split_whitespace().next().unwrap_or("");
                        let plain = after.trim_start_matches('{').trim_end_matches('}');
                        found = parse_number(plain);
                    }
                }
            }
            _ => {}
        }
    }
    found
}

/// The names a `.param` card assigns (`.param a=1 b = {a*2}`), lower
/// case: each word before an `=`.
fn param_names(card: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut rest = card.trim_start().get(".param".len()..).unwrap_or("");
    while let Some(eq) = rest.find('=') {
        let before = rest[..eq].trim_end();
        let name = before
            .rsplit(|c: char| c.is_whitespace() || c == '}' || c == ',')
            .next()
            .unwrap_or("");
        if !name.is_empty() && name.chars().all(|c| c.is_alphanumeric() || c == '_') {
            names.push(name.to_ascii_lowercase());
        }
        rest = &rest[eq + 1..];
    }
    names
}

/// Adds the top-level `.param` names of included file `path` (and of the
/// files it includes) to `defined`. Unreadable files add nothing: the
/// instance search reports them.
fn include_params(
    path: &Path,
    depth: usize,
    seen: &mut HashSet<PathBuf>,
    defined: &mut HashSet<String>,
) {
    if depth > MAX_INCLUDE_DEPTH || !seen.insert(path.to_path_buf()) {
        return;
    }
    let Ok(text) = crate::input::read_to_string(path) else {
        return;
    };
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let lines = physical_lines(&text);
    // An included file has no title line: every line is live.
    let live = vec![true; lines.len()];
    let mut nesting = 0usize;
    for card in cards(&lines, &live) {
        match card.keyword().as_str() {
            ".subckt" => nesting += 1,
            ".ends" => nesting = nesting.saturating_sub(1),
            ".param" if nesting == 0 => defined.extend(param_names(&card.text)),
            ".include" | ".inc" | ".lib" => {
                let rest = card.text.trim_start();
                let rest = rest.split_once(char::is_whitespace).map_or("", |(_, r)| r);
                let (written, _) = split_path(rest.trim());
                if !written.is_empty() {
                    include_params(&resolve(written, &base), depth + 1, seen, defined);
                }
            }
            _ => {}
        }
    }
}

/// `t` rounded up to two significant digits (1.4779e-3 → 1.5e-3): a stop
/// time to suggest, which a person can type.
fn round_up_2(t: f64) -> f64 {
    if !(t.is_finite() && t > 0.0) {
        return t;
    }
    let scale = 10f64.powi(t.log10().floor() as i32 - 1);
    let rounded = (t / scale).ceil() * scale;
    // Back to the shortest decimal form: 1.5e-3, not 1.5000000000000002e-3.
    let text = format!("{rounded:.1e}");
    text.parse::<f64>().map_or(rounded, |r| r.max(t))
}

/// The vectors a probe needs saved: `v(a,b)` needs both nodes (ground
/// needs none).
pub fn save_names(signal: &str) -> Result<Vec<String>, NetlistError> {
    let bad = || NetlistError::BadProbe {
        signal: signal.to_owned(),
    };
    let s = signal.trim();
    let open = s.find('(').ok_or_else(bad)?;
    let kind = s[..open].trim().to_ascii_lowercase();
    let inner = s[open + 1..].strip_suffix(')').ok_or_else(bad)?;
    let args: Vec<&str> = inner.split(',').map(str::trim).collect();
    if args
        .iter()
        .any(|a| a.is_empty() || a.contains(|c: char| c.is_whitespace() || "()".contains(c)))
    {
        return Err(bad());
    }
    match (kind.as_str(), args.len()) {
        ("v", 1 | 2) => Ok(args
            .iter()
            .filter(|a| !matches!(a.to_ascii_lowercase().as_str(), "0" | "gnd"))
            .map(|a| format!("v({a})"))
            .collect()),
        ("i", 1) => Ok(vec![format!("i({})", args[0])]),
        _ => Err(bad()),
    }
}

fn first_word(line: &str) -> String {
    strip_comment(line)
        .split_whitespace()
        .next()
        .unwrap_or("")
        .to_ascii_lowercase()
}

fn is_blank_or_comment(line: &str) -> bool {
    let t = line.trim_start();
    t.is_empty() || t.starts_with('*')
}

/// The cards among the live lines: `+` lines join the card before them,
/// across comment and blank lines.
pub(super) fn cards(lines: &[&str], live: &[bool]) -> Vec<Card> {
    let mut out: Vec<Card> = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        if !live[i] || is_blank_or_comment(line) {
            continue;
        }
        let text = strip_comment(line).trim();
        if let Some(rest) = text.strip_prefix('+') {
            if let Some(card) = out.last_mut() {
                card.text.push(' ');
                card.text.push_str(rest.trim());
                card.last = i;
                continue;
            }
        }
        if !text.is_empty() {
            out.push(Card {
                first: i,
                last: i,
                text: text.to_owned(),
            });
        }
    }
    out
}

fn replace(fates: &mut [Fate], card: &Card, text: String) {
    fates[card.first] = Fate::Replace(text);
    for fate in &mut fates[card.first + 1..=card.last] {
        *fate = Fate::Drop;
    }
}

/// The instance names (lowercased, as ngspice names them in vectors, e.g.
/// `x2`) of the `X` cards of `netlist_text` that use `subckt`, in order.
/// Only the netlist itself is read, not its includes.
pub fn instances_of(netlist_text: &str, subckt: &str) -> Vec<String> {
    cards_using(netlist_text, subckt)
        .iter()
        .filter_map(|c| c.split_whitespace().next())
        .map(str::to_ascii_lowercase)
        .collect()
}

/// The text of each `X` card of `netlist_text` (not its includes) that
/// uses `subckt`, in order.
fn cards_using(netlist_text: &str, subckt: &str) -> Vec<String> {
    let lines = physical_lines(netlist_text);
    if lines.is_empty() {
        return Vec::new();
    }
    let mut live = vec![true; lines.len()];
    live[0] = false;
    cards(&lines, &live)
        .into_iter()
        .filter(|c| instantiates(&c.text, subckt))
        .map(|c| c.text)
        .collect()
}

/// The first two nodes (lowercased) of each `X` card of `netlist_text`
/// that uses `subckt`, in order: the contact's terminals a and b.
pub fn instance_nodes_of(netlist_text: &str, subckt: &str) -> Vec<(String, String)> {
    cards_using(netlist_text, subckt)
        .iter()
        .filter_map(|c| {
            let mut tokens = c.split_whitespace().skip(1);
            Some((
                tokens.next()?.to_ascii_lowercase(),
                tokens.next()?.to_ascii_lowercase(),
            ))
        })
        .collect()
}

/// Whether an `X` card's subcircuit is `subckt`: the last token that is
/// not a `name=value` parameter (nor `params:`).
fn instantiates(card: &str, subckt: &str) -> bool {
    subckt_of(card).is_some_and(|m| m.eq_ignore_ascii_case(subckt))
}

/// The subcircuit an `X` card instantiates (the last word before its
/// parameters), as written; `None` for any other card.
pub(super) fn subckt_of(card: &str) -> Option<String> {
    let mut tokens = card.split_whitespace();
    if !tokens
        .next()
        .is_some_and(|t| t.starts_with('x') || t.starts_with('X'))
    {
        return None;
    }
    // `w = 1` and `w=1` alike: glue the `=` to its neighbours first.
    let glued = card.replace(" =", "=").replace("= ", "=");
    glued
        .split_whitespace()
        .skip(1)
        .filter(|t| !t.contains('=') && !t.eq_ignore_ascii_case("params:"))
        .last()
        .map(str::to_owned)
}

/// The file an include card names and, for `.lib FILE SECTION`, the
/// section; `None` when the card is left as it is (a `.lib` section
/// header).
fn resolve_include(
    card: &Card,
    keyword: &str,
    base: &Path,
    netlist: &Path,
) -> Result<Option<(PathBuf, Option<String>)>, NetlistError> {
    let original = card.text.split_whitespace().next().unwrap_or(keyword);
    let rest = card.text[original.len()..].trim();
    let (written, after) = split_path(rest);
    if written.is_empty() {
        return Ok(None);
    }
    let resolved = resolve(written, base);
    let is_lib = keyword.starts_with(".lib");
    // `.lib name` alone is a section header inside a library file; with a
    // file behind it, PSpice-style, it includes the whole file.
    if is_lib && after.is_empty() && !resolved.is_file() {
        return Ok(None);
    }
    if !resolved.exists() {
        return Err(NetlistError::MissingInclude {
            netlist: netlist.to_path_buf(),
            line: card.line(),
            card: card.text.clone(),
            resolved,
        });
    }
    let section = after
        .split_whitespace()
        .next()
        .filter(|_| is_lib)
        .map(str::to_owned);
    Ok(Some((resolved, section)))
}

/// Whether an included file (or one it includes) has an `X` card for
/// `subckt`.
fn include_instantiates(
    path: &Path,
    subckt: &str,
    netlist: &Path,
    line: usize,
    depth: usize,
    seen: &mut HashSet<PathBuf>,
) -> Result<bool, NetlistError> {
    if depth > MAX_INCLUDE_DEPTH || !seen.insert(path.to_path_buf()) {
        return Ok(false);
    }
    let bytes = crate::input::read(path).map_err(|source| NetlistError::ReadInclude {
        netlist: netlist.to_path_buf(),
        line,
        included: path.to_path_buf(),
        source,
    })?;
    let text = String::from_utf8_lossy(&bytes);
    let lines = physical_lines(&text);
    // An included file has no title line.
    let live = vec![true; lines.len()];
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    for card in cards(&lines, &live) {
        let keyword = card.keyword();
        if instantiates(&card.text, subckt) {
            return Ok(true);
        }
        if matches!(keyword.as_str(), ".include" | ".inc" | ".lib") {
            let (written, _) = split_path(card.text[keyword.len()..].trim());
            let inner = resolve(written, &base);
            if inner.is_file()
                && include_instantiates(&inner, subckt, netlist, line, depth + 1, seen)?
            {
                return Ok(true);
            }
        }
    }
    Ok(false)
}

fn parse_tran(card: &Card, netlist: &Path) -> Result<Tran, NetlistError> {
    let bad = |problem: String| NetlistError::BadTran {
        netlist: netlist.to_path_buf(),
        line: card.line(),
        card: card.text.clone(),
        problem,
    };
    let mut numbers = Vec::new();
    let mut uic = false;
    for token in card.text.split_whitespace().skip(1) {
        if token.eq_ignore_ascii_case("uic") {
            uic = true;
        } else if let Some(x) = parse_number(token) {
            if uic || numbers.len() == 4 {
                return Err(bad(format!(
                    "unexpected `{token}`: the form is `.tran tstep tstop [tstart [tmax]] [uic]`"
                )));
            }
            numbers.push(x);
        } else {
            return Err(bad(format!(
                "`{token}` is not a number chatterspice can read (it checks the stop time \
                 against the chatter): write plain numbers such as `1u` and `20m`"
            )));
        }
    }
    if numbers.len() < 2 {
        return Err(bad(
            "needs at least a step and a stop time, e.g. `.tran 1u 20m`".to_owned(),
        ));
    }
    let tran = Tran {
        tstep: numbers[0],
        tstop: numbers[1],
        tstart: numbers.get(2).copied().unwrap_or(0.0),
        tmax: numbers.get(3).copied(),
        uic,
        line: card.line(),
    };
    if !(tran.tstep > 0.0 && tran.tstop > tran.tstart && tran.tstart >= 0.0) {
        return Err(bad(
            "needs tstep > 0 and tstop > tstart >= 0, e.g. `.tran 1u 20m`".to_owned(),
        ));
    }
    if tran.tmax.is_some_and(|m| m <= 0.0) {
        return Err(bad("TMAX must be > 0".to_owned()));
    }
    Ok(tran)
}

fn quote_if_needed(name: &str) -> String {
    if name.contains(char::is_whitespace) {
        format!("\"{name}\"")
    } else {
        name.to_owned()
    }
}

#[cfg(test)]
#[path = "deck_tests.rs"]
mod tests;
