//! The netlist stage against real ngspice: every contact element parses
//! and runs, a pull-up switched by the contact shows exactly the
//! waveform's edges, the split PWL carries the same conductance as one
//! source; and the deck builder's checks on the netlists in
//! `tests/data/netlists/`.
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use std::path::{Path, PathBuf};

use chatterspice::chatter::{ContactState, Interval};
use chatterspice::netlist::{
    ContactElement, ContactInclude, Deck, DeckRequest, DeckWarning, NetlistError, contact_include,
    contact_include_split, prepare_deck,
};
use chatterspice::rawfile::Plot;
use chatterspice::spice::{Ngspice, RunRequest, Runner};
use chatterspice::waveform::{ContactModel, Waveform};

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/netlists")
        .join(rel)
}

const MODEL: ContactModel = ContactModel {
    r_closed: 0.05,
    r_open: 1e9,
    edge_time: 1e-8,
};

/// A closing at 100 µs, then `spans` as (closed, open) durations, then
/// closed for 100 µs.
fn chatter(spans: &[(f64, f64)], model: &ContactModel) -> Waveform {
    let mut ivs = Vec::new();
    let mut t = 1e-4;
    ivs.push(Interval {
        state: ContactState::Open,
        start: 0.0,
        end: t,
    });
    for &(closed, open) in spans {
        for (state, d) in [(ContactState::Closed, closed), (ContactState::Open, open)] {
            ivs.push(Interval {
                state,
                start: t,
                end: t + d,
            });
            t += d;
        }
    }
    ivs.push(Interval {
        state: ContactState::Closed,
        start: t,
        end: t + 1e-4,
    });
    Waveform::from_intervals(&ivs, model).unwrap()
}

/// Bounces that shrink from 40 µs to 0.2 µs, like a real closing; ends
/// at 0.4 ms.
fn realistic(model: &ContactModel) -> Waveform {
    let spans: Vec<(f64, f64)> = [40e-6, 20e-6, 8e-6, 3e-6, 1e-6, 0.4e-6, 0.2e-6]
        .iter()
        .map(|&d| (d, d / 2.0))
        .collect();
    chatter(&spans, model)
}

/// Schmitt edges of `v` with thresholds `low` < `high`.
fn edges(v: &[f64], low: f64, high: f64) -> usize {
    let mut high_state = v[0] > (low + high) / 2.0;
    let mut n = 0;
    for &x in v {
        if high_state && x < low {
            high_state = false;
            n += 1;
        } else if !high_state && x > high {
            high_state = true;
            n += 1;
        }
    }
    n
}

fn tran_plot(out: &chatterspice::spice::RunOutput) -> &Plot {
    out.raw
        .plot_named("transient analysis")
        .expect("a transient plot")
}

/// The pull-up deck around `inc`, run; the transient plot's owner.
fn run_pullup(
    ng: &Ngspice,
    inc: &ContactInclude,
    netlist: &Path,
    stop: f64,
) -> (chatterspice::spice::RunOutput, Deck) {
    let text = std::fs::read_to_string(netlist).unwrap();
    let deck = prepare_deck(&DeckRequest {
        netlist_text: &text,
        netlist_path: netlist,
        include_file_name: "contact.inc",
        subckt: &inc.subckt,
        coil: None,
        probes: &["v(in)"],
        chatter_end: stop,
        stop_at_least: stop,
        options: &[],
    })
    .unwrap();
    let mut req = RunRequest::new(deck.text.clone());
    req.includes.push(("contact.inc".into(), inc.text.clone()));
    req.includes.extend(inc.data_files.iter().cloned());
    let out = ng
        .run(&req)
        .unwrap_or_else(|e| panic!("{} failed: {e}\n{}", inc.element, deck.text));
    (out, deck)
}

/// The includes of a small waveform, against committed golden files (and
/// so across runs, days and machines). `UPDATE_GOLDEN=1` rewrites them.
#[test]
fn includes_are_byte_identical_for_the_same_input() {
    let w = chatter(&[(2e-5, 1e-5), (5e-6, 2e-6)], &MODEL);
    let update = std::env::var("UPDATE_GOLDEN").as_deref() == Ok("1");
    for element in ContactElement::ALL {
        let a = contact_include(&w, "CONTACT", element).unwrap();
        let b = contact_include(&w.clone(), "CONTACT", element).unwrap();
        assert_eq!(a, b, "{element}");
        let mut files = vec![(format!("contact_{element}.inc"), a.text.clone())];
        files.extend(a.data_files.iter().cloned());
        if element == ContactElement::Pwl {
            let split = contact_include_split(&w, "CONTACT", element, 4).unwrap();
            assert_eq!(split.pwl_sources, 3);
            files.push(("contact_pwl_split.inc".into(), split.text));
        }
        for (name, text) in files {
            let path = data("golden").join(&name);
            if update {
                std::fs::create_dir_all(path.parent().unwrap()).unwrap();
                std::fs::write(&path, &text).unwrap();
            }
            let golden = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("{}: {e} (UPDATE_GOLDEN=1 writes it)", path.display()));
            assert_eq!(
                text, golden,
                "{element}: {name} differs from the golden file"
            );
        }
    }
    // A different waveform gives a different file.
    let other = chatter(&[(1e-5, 1e-5)], &MODEL);
    assert_ne!(
        contact_include(&w, "CONTACT", ContactElement::Pwl)
            .unwrap()
            .text,
        contact_include(&other, "CONTACT", ContactElement::Pwl)
            .unwrap()
            .text
    );
}

/// Every time list the include emits (PWL sources, data files) strictly
/// increases, so no two times collide once printed.
#[test]
fn emitted_times_never_collide() {
    // Times far from zero with 1 ns edges: neighbours differ in the 7th digit.
    let model = ContactModel {
        edge_time: 1e-9,
        ..MODEL
    };
    let spans: Vec<(f64, f64)> = (0..300)
        .map(|i| (3e-9 + i as f64 * 1e-12, 2.5e-9))
        .collect();
    let w = chatter(&spans, &model);
    for element in ContactElement::ALL {
        let inc = contact_include_split(&w, "CONTACT", element, 64).unwrap();
        let mut lists: Vec<Vec<f64>> = Vec::new();
        let mut current: Option<Vec<f64>> = None;
        for line in inc.text.lines() {
            if line.ends_with("PWL(") {
                current = Some(Vec::new());
            } else if let (Some(rest), Some(list)) = (line.strip_prefix('+'), current.as_mut()) {
                let numbers: Vec<f64> = rest
                    .split_whitespace()
                    .filter_map(|x| x.parse().ok())
                    .collect();
                list.extend(numbers.iter().step_by(2));
                if rest.ends_with(')') {
                    lists.push(current.take().unwrap());
                }
            }
        }
        for (_, contents) in &inc.data_files {
            lists.push(
                contents
                    .lines()
                    .filter_map(|l| l.split_whitespace().next()?.parse().ok())
                    .collect(),
            );
        }
        if element != ContactElement::Switch || !lists.is_empty() {
            assert!(!lists.is_empty(), "{element}: no time list found");
        }
        for list in &lists {
            for pair in list.windows(2) {
                assert!(pair[1] > pair[0], "{element}: {} then {}", pair[0], pair[1]);
            }
        }
        if element == ContactElement::Pwl {
            assert!(inc.pwl_sources > 1, "the split is exercised");
            let total: usize = lists.iter().map(Vec::len).sum();
            // Window ends are shared: each split adds one point.
            assert_eq!(total, inc.points + inc.pwl_sources - 1);
        }
    }
}

#[test]
fn every_element_shows_exactly_the_waveforms_edges() {
    let ng = ngspice_or_skip!();
    let w = realistic(&MODEL);
    let want = w.edge_count();
    assert_eq!(want, 15);
    for element in ContactElement::ALL {
        let inc = contact_include(&w, "CONTACT", element).unwrap();
        let (out, deck) = run_pullup(&ng, &inc, &data("pullup.cir"), 1e-3);
        let v = tran_plot(&out).real("v(in)").unwrap();
        if std::env::var("DEBUG_EDGES").is_ok() {
            let t = tran_plot(&out).real("time").unwrap();
            for (t, v) in t.iter().zip(v) {
                eprintln!("{element} {t:e} {v}");
            }
        }
        assert_eq!(
            edges(v, 0.99, 2.31),
            want,
            "{element}: edges of v(in)\n{}",
            deck.text
        );
        // Open at the start, closed at the end.
        assert!(v[0] > 3.2 && v[v.len() - 1] < 0.01, "{element}");
        assert!(deck.warnings.is_empty(), "{element}: {:?}", deck.warnings);
    }
}

/// The contact from 1 mΩ to 1 GΩ: no "timestep too small" with any element.
#[test]
fn extreme_resistances_run() {
    let ng = ngspice_or_skip!();
    for (r_closed, r_open) in [(1e-3, 1e9), (0.05, 1e9), (1.0, 1e6)] {
        let model = ContactModel {
            r_closed,
            r_open,
            ..MODEL
        };
        let w = realistic(&model);
        for element in ContactElement::ALL {
            let inc = contact_include(&w, "CONTACT", element).unwrap();
            let (out, _) = run_pullup(&ng, &inc, &data("pullup.cir"), 1e-3);
            let v = tran_plot(&out).real("v(in)").unwrap();
            assert_eq!(
                edges(v, 0.99, 2.31),
                w.edge_count(),
                "{element} at {r_closed} / {r_open} Ω"
            );
        }
    }
}

/// V(g) of the split PWL and of one source both equal the waveform at
/// every time point ngspice computed.
#[test]
fn split_pwl_carries_the_same_conductance() {
    let ng = ngspice_or_skip!();
    let spans: Vec<(f64, f64)> = (0..60).map(|i| (4e-6 + i as f64 * 1e-7, 3e-6)).collect();
    let w = chatter(&spans, &MODEL);
    let one = contact_include_split(&w, "CONTACT", ContactElement::Pwl, usize::MAX).unwrap();
    let split = contact_include_split(&w, "CONTACT", ContactElement::Pwl, 32).unwrap();
    assert_eq!(one.pwl_sources, 1);
    assert!(split.pwl_sources >= 7, "{}", split.pwl_sources);
    let g_closed = MODEL.g_closed();
    for inc in [&one, &split] {
        let (out, _) = run_pullup(&ng, inc, &data("pullup.cir"), 1e-3);
        let plot = tran_plot(&out);
        let time = plot.real("time").unwrap();
        let g = plot.real("v(x1.g)").unwrap();
        let mut corners_hit = 0;
        for (&t, &g) in time.iter().zip(g) {
            let want = w.conductance_at(t);
            assert!(
                (g - want).abs() <= 1e-9 * g_closed,
                "{} sources: G({t:e}) = {g:e}, waveform {want:e}",
                inc.pwl_sources
            );
            assert!(g > 0.0);
            if w.points().iter().any(|p| (p.time - t).abs() <= 1e-12 * t) {
                corners_hit += 1;
            }
        }
        // Breakpoints: ngspice lands on (nearly) every corner exactly.
        assert!(
            corners_hit + 2 >= w.points().len(),
            "{} sources: {corners_hit} of {} corners are time points",
            inc.pwl_sources,
            w.points().len()
        );
    }
}

#[test]
fn kicad_netlist_runs_and_is_not_modified() {
    let ng = ngspice_or_skip!();
    let path = data("kicad.cir");
    let before = std::fs::read(&path).unwrap();
    assert!(before.windows(2).any(|w| w == b"\r\n"), "the file has CRLF");
    let w = realistic(&MODEL);
    let inc = contact_include(&w, "CONTACT", ContactElement::Pwl).unwrap();
    let (out, deck) = run_pullup(&ng, &inc, &path, 1e-3);
    assert!(
        deck.text.starts_with(".title KiCad schematic\n"),
        "{}",
        deck.text
    );
    let lib = data("models/input_stage.lib");
    assert_inlined(&deck.text, &lib, ".subckt input_stage vdd in");
    assert!(!deck.text.contains('\r'));
    assert!(deck.text.ends_with(".save v(in)\n.end\n"), "{}", deck.text);
    let v = tran_plot(&out).real("v(/in)").unwrap();
    assert_eq!(edges(v, 0.99, 2.31), w.edge_count());
    assert_eq!(std::fs::read(&path).unwrap(), before);
}

#[test]
fn control_block_is_left_out_and_probes_are_saved() {
    let ng = ngspice_or_skip!();
    let path = data("with_control.cir");
    let before = std::fs::read(&path).unwrap();
    let w = realistic(&MODEL);
    let inc = contact_include(&w, "CONTACT", ContactElement::Pwl).unwrap();
    let (out, deck) = run_pullup(&ng, &inc, &path, 1e-3);
    assert!(matches!(
        deck.warnings[..],
        [DeckWarning::ControlRemoved {
            first: 9,
            last: 13,
            ..
        }]
    ));
    let plot = tran_plot(&out);
    // The user's `.save v(vdd)` restricts what is saved; the probe was added.
    assert!(plot.real("v(vdd)").is_some());
    let v = plot.real("v(in)").expect("the probe is saved");
    assert_eq!(edges(v, 0.99, 2.31), w.edge_count());
    assert_eq!(std::fs::read(&path).unwrap(), before);
}

fn deck_error(file: &str) -> NetlistError {
    let path = data(file);
    let text = std::fs::read_to_string(&path).unwrap();
    prepare_deck(&DeckRequest {
        netlist_text: &text,
        netlist_path: &path,
        include_file_name: "contact.inc",
        subckt: "CONTACT",
        coil: None,
        probes: &["v(in)"],
        chatter_end: 4e-4,
        stop_at_least: 6e-4,
        options: &[],
    })
    .unwrap_err()
}

#[test]
fn deck_errors_name_the_file_the_line_and_the_fix() {
    let file = |name: &str| data(name).display().to_string();

    let e = deck_error("no_instance.cir");
    assert!(matches!(e, NetlistError::NoContactInstance { .. }), "{e}");
    assert_eq!(
        e.to_string(),
        format!(
            "{}: no `X` line instantiates the contact subcircuit `CONTACT`: add one between \
             the contact's two nodes, e.g. `X1 a b CONTACT`",
            file("no_instance.cir")
        )
    );

    let e = deck_error("no_tran.cir");
    assert!(matches!(e, NetlistError::NoTran { .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.starts_with(&file("no_tran.cir")), "{msg}");
    assert!(msg.contains("add a line such as `.tran 1u 6e-4`"), "{msg}");

    let e = deck_error("short_tran.cir");
    assert!(
        matches!(e, NetlistError::TranTooShort { line: 5, tstop, .. } if tstop == 2e-4),
        "{e}"
    );
    assert_eq!(
        e.to_string(),
        format!(
            "{}: line 5: `.tran` stops at 2e-4 s, before the chatter ends at 4e-4 s: set its \
             stop time to at least 6e-4 s, e.g. `.tran 1e-6 6e-4`",
            file("short_tran.cir")
        )
    );

    let e = deck_error("missing_include.cir");
    assert!(
        matches!(e, NetlistError::MissingInclude { line: 2, .. }),
        "{e}"
    );
    assert_eq!(
        e.to_string(),
        format!(
            "{}: line 2: `.include models/not_there.lib` names {}, which does not exist: fix \
             the path (a relative path is read from the netlist's directory)",
            file("missing_include.cir"),
            data("models/not_there.lib").display()
        )
    );
}

/// An `X` line inside an included file counts as the instance.
#[test]
fn instance_in_an_included_file_counts() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("board.inc"),
        "* the board\nR1 vdd in 10k\nXK1 in 0\n+ CONTACT\n",
    )
    .unwrap();
    let path = dir.path().join("top.cir");
    let text = "Top\n.inc board.inc\nV1 vdd 0 3.3\n.tran 1u 1m\n.end\n";
    let deck = prepare_deck(&DeckRequest {
        netlist_text: text,
        netlist_path: &path,
        include_file_name: "contact.inc",
        subckt: "CONTACT",
        coil: None,
        probes: &[],
        chatter_end: 4e-4,
        stop_at_least: 6e-4,
        options: &[],
    })
    .unwrap();
    assert_inlined(
        &deck.text,
        &dir.path().join("board.inc"),
        "XK1 in 0\n+ CONTACT\n",
    );
}

/// The deck holds `file`'s text (`line`) between markers naming its
/// absolute path, and no card that would make ngspice read a file itself.
fn assert_inlined(deck: &str, file: &Path, line: &str) {
    assert!(file.is_absolute());
    let begin = format!("* chatterspice: begin \"{}\"", file.display());
    let start = deck
        .find(&begin)
        .unwrap_or_else(|| panic!("no {begin} in\n{deck}"));
    let end = deck
        .find(&format!("* chatterspice: end \"{}\"", file.display()))
        .unwrap();
    assert!(deck[start..end].contains(line), "{deck}");
    for card in deck.lines() {
        let word = card
            .split_whitespace()
            .next()
            .unwrap_or("")
            .to_ascii_lowercase();
        assert!(
            !(word.starts_with(".inc") || word.starts_with(".lib")) || card.contains("contact.inc"),
            "{card} in\n{deck}"
        );
    }
}

/// A netlist named by a relative path still gets absolute include paths.
#[test]
fn relative_netlist_path_gives_absolute_includes() {
    let rel = Path::new("tests/data/netlists/kicad.cir");
    let text = std::fs::read_to_string(rel).unwrap();
    let deck = prepare_deck(&DeckRequest {
        netlist_text: &text,
        netlist_path: rel,
        include_file_name: "contact.inc",
        subckt: "CONTACT",
        coil: None,
        probes: &[],
        chatter_end: 4e-4,
        stop_at_least: 6e-4,
        options: &[],
    })
    .unwrap();
    let lib = std::env::current_dir()
        .unwrap()
        .join("tests/data/netlists/models/input_stage.lib");
    assert_inlined(&deck.text, &lib, ".subckt input_stage vdd in");
}
