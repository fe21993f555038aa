//! The tests of `direct.rs`: in a file of their own, so that the
//! checkout's test data they name stays out of the module's code.

use super::*;
use crate::rawfile::export::plot_csv;
use crate::rawfile::{RawError, Vector, stream_csv};
use proptest::prelude::*;
use std::io::{Seek, Write};
use std::path::PathBuf;

fn stored(dir: &str) -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(dir);
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "raw"))
        .collect();
    files.sort();
    files
}

/// `bytes` as a file read by this module: `None` when it hands the
/// file to the parser.
fn direct(file: &mut File, bytes: &[u8]) -> Option<RawFile> {
    file.set_len(0).unwrap();
    file.rewind().unwrap();
    file.write_all(bytes).unwrap();
    read(file, bytes.len() as u64).unwrap()
}

/// What [`RawFile::read`] gives for `bytes` on disk and what
/// [`RawFile::parse`] gives for them, errors as their text (the path
/// taken off).
fn both(bytes: &[u8]) -> (Result<RawFile, String>, Result<RawFile, String>) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.raw");
    std::fs::write(&path, bytes).unwrap();
    let read = RawFile::read(&path).map_err(|e| match e {
        RawError::InFile { error, .. } => error.to_string(),
        e => e.to_string(),
    });
    (read, RawFile::parse(bytes).map_err(|e| e.to_string()))
}

#[test]
fn every_stored_ngspice_binary_file_is_read_direct_as_the_parser_reads_it() {
    let mut file = tempfile::tempfile().unwrap();
    let mut direct_reads = 0;
    for path in stored("raw").into_iter().chain(stored("ltspice")) {
        let bytes = std::fs::read(&path).unwrap();
        let parsed = RawFile::parse(&bytes).unwrap();
        let ngspice_binary =
            path.parent().unwrap().ends_with("raw") && bytes.windows(8).any(|w| w == b"Binary:\n");
        match direct(&mut file, &bytes) {
            Some(raw) => {
                assert!(ngspice_binary, "{}: read direct", path.display());
                assert_eq!(raw, parsed, "{}", path.display());
                direct_reads += 1;
            }
            None => assert!(!ngspice_binary, "{}: not read direct", path.display()),
        }
    }
    assert_eq!(direct_reads, 6);
}

#[test]
fn a_file_cut_anywhere_is_read_as_the_parser_reads_it() {
    // Two plots (an operating point, then a transient) and a complex
    // one: every cut, in the header, between the plots, mid-point.
    let mut file = tempfile::tempfile().unwrap();
    for name in ["divider_op_tran.raw", "rc_ac.raw"] {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/raw")
            .join(name);
        let bytes = std::fs::read(path).unwrap();
        for cut in 0..=bytes.len() {
            let part = &bytes[..cut];
            let parsed = RawFile::parse(part);
            match direct(&mut file, part) {
                Some(raw) => assert_eq!(Ok(raw), parsed.map_err(|e| e.to_string())),
                // Only a cut the parser rejects (inside a header) is
                // left to it, to say what is wrong.
                None => assert!(parsed.is_err(), "{name} cut at {cut}: not read direct"),
            }
        }
    }
}

fn plot(name: &str, points: usize, values: &[f64]) -> Vec<u8> {
    let mut f = format!(
        "Title: t\nDate: d\nPlotname: {name}\nFlags: real\nNo. Variables: 2\n\
             No. Points: {points}\nVariables:\n\t0\ttime\ttime\n\t1\tv(out)\tvoltage\nBinary:\n"
    )
    .into_bytes();
    f.extend(values.iter().flat_map(|v| v.to_le_bytes()));
    f
}

#[test]
fn a_plot_with_no_points_before_another_is_empty_in_memory_on_disk_and_in_csv() {
    let mut bytes = plot("Operating Point", 0, &[]);
    bytes.extend(plot("Transient Analysis", 2, &[0.0, 1.5, 1e-3, 2.5]));
    let mut file = tempfile::tempfile().unwrap();
    let raw = direct(&mut file, &bytes).expect("read direct");
    assert_eq!(raw, RawFile::parse(&bytes).unwrap());
    assert_eq!(raw.plots.len(), 2);
    assert_eq!(raw.plots[0].points(), 0);
    assert_eq!(raw.plots[1].real("v(out)"), Some(&[1.5, 2.5][..]));
    assert!(raw.warnings.is_empty());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.raw");
    std::fs::write(&path, &bytes).unwrap();
    for (index, p) in raw.plots.iter().enumerate() {
        let (mut streamed, mut whole) = (Vec::new(), Vec::new());
        let warnings = stream_csv(&path, Some(index), &mut streamed).unwrap();
        assert_eq!(warnings, Some(Vec::new()));
        plot_csv(p, &mut whole).unwrap();
        assert_eq!(streamed, whole, "plot {index}");
    }
}

#[test]
fn files_it_hands_to_the_parser_read_alike() {
    let two = plot("Transient Analysis", 2, &[0.0, 1.5, 1e-3, 2.5]);
    // Real values flagged complex: the parser says the flag is wrong.
    let at = two.windows(10).position(|w| w == b"Flags: rea").unwrap();
    let mut flagged = two[..at].to_vec();
    flagged.extend(b"Flags: complex");
    flagged.extend(&two[at + "Flags: real".len()..]);
    let (read, parsed) = both(&flagged);
    assert!(
        parsed.as_ref().is_err_and(|e| e.contains("Flags: real")),
        "{parsed:?}"
    );
    assert_eq!(read, parsed);
    // A blank line between two plots, and bytes after the last.
    for tail in [&b"\nTitle: u\n"[..], b"\x01\x02\x03"] {
        let mut bytes = two.clone();
        bytes.extend(tail);
        let (read, parsed) = both(&bytes);
        assert_eq!(read, parsed);
    }
}

#[test]
fn points_across_many_blocks_land_in_order() {
    // Rows of 3 real or complex values, over three and a half blocks,
    // whole and cut mid-point: every value is told by its place.
    let mut file = tempfile::tempfile().unwrap();
    for flags in ["real", "complex"] {
        let width = if flags == "real" { 8 } else { 16 };
        let points = 7 * crate::rawfile::locate::BLOCK_BYTES / (2 * 3 * width) + 5;
        let mut bytes = format!(
            "Title: t\nDate: d\nPlotname: Transient Analysis\nFlags: {flags}\n\
                 No. Variables: 3\nNo. Points: {points}\nVariables:\n\t0\ttime\ttime\n\
                 \t1\tv(a)\tvoltage\n\t2\ti(v1)\tcurrent\nBinary:\n"
        )
        .into_bytes();
        for p in 0..points {
            for v in 0..3 {
                for part in 0..width / 8 {
                    let x = (p * 10 + v) as f64 + 0.5 * part as f64;
                    bytes.extend(x.to_le_bytes());
                }
            }
        }
        for cut in [0, 13] {
            let part = &bytes[..bytes.len() - cut];
            let raw = direct(&mut file, part).expect("read direct");
            assert_eq!(raw, RawFile::parse(part).unwrap());
            let n = if cut == 0 { points } else { points - 1 };
            let p = &raw.plots[0];
            assert_eq!(p.points(), n);
            let last = (n - 1) as f64 * 10.0;
            match p.vector(2).unwrap() {
                Vector::Real(v) => assert_eq!(v[n - 1], last + 2.0),
                Vector::Complex(v) => {
                    assert_eq!(v[n - 1], Complex64::new(last + 2.0, last + 2.5))
                }
            }
        }
    }
}

#[test]
fn points_shared_between_threads_land_in_order() {
    // A killed run (every vector its whole points) and a plot whose
    // `dims=` make one vector shorter than the others, in 1 to 5
    // threads, the shares ending mid-tile and mid-block.
    let per_block = crate::rawfile::locate::BLOCK_BYTES / 24;
    let points = 3 * per_block + 7;
    let vars = "\t0\ttime\ttime\n\t1\tv(a)\tvoltage\n\t2\ti(v1)\tcurrent\n";
    let short = "\t0\ttime\ttime\n\t1\tv(a)\tvoltage dims=1001\n\t2\ti(v1)\tcurrent\n";
    for (declared, vars) in [(0, vars), (points, short)] {
        let mut bytes = format!(
            "Title: t\nDate: d\nPlotname: Transient Analysis\nFlags: real\n\
                 No. Variables: 3\nNo. Points: {declared}\nVariables:\n{vars}Binary:\n"
        )
        .into_bytes();
        for p in 0..points {
            for v in 0..3 {
                bytes.extend(((p * 10 + v) as f64).to_le_bytes());
            }
        }
        if declared == 0 {
            // Cut mid-point.
            bytes.extend([1, 2, 3]);
        }
        let mut file = tempfile::tempfile().unwrap();
        file.write_all(&bytes).unwrap();
        let parsed = RawFile::parse(&bytes).unwrap();
        let place = locate(&mut file, bytes.len() as u64)
            .unwrap()
            .unwrap()
            .remove(0);
        let lens: Vec<usize> = parsed.plots[0].columns.iter().map(Column::len).collect();
        for threads in 1..=5 {
            let columns = read_real(&file, &place, &lens, threads).unwrap();
            assert_eq!(columns, parsed.plots[0].columns, "{threads} threads");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Edited, cut and spliced ngspice files: the reader from disk
    /// gives what the parser gives, values, warnings and errors alike.
    #[test]
    fn edited_files_read_from_disk_as_parsed(
        first in prop::sample::select(vec!["rc_tran.raw", "divider_op_tran.raw", "rc_ac.raw", "killed_binary.raw"]),
        second in prop::option::of(prop::sample::select(vec!["rc_tran.raw", "rc_ac.raw", "killed_binary.raw"])),
        blanks in prop::sample::select(vec!["", "\n", " \n"]),
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..4),
        cut in prop::option::of(any::<prop::sample::Index>()),
    ) {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/raw");
        let mut bytes = std::fs::read(dir.join(first)).unwrap();
        if let Some(second) = second {
            bytes.extend(blanks.bytes());
            bytes.extend(std::fs::read(dir.join(second)).unwrap());
        }
        for (at, byte) in edits {
            let i = at.index(bytes.len());
            bytes[i] = byte;
        }
        if let Some(cut) = cut {
            bytes.truncate(cut.index(bytes.len() + 1));
        }
        let (read, parsed) = both(&bytes);
        prop_assert_eq!(read, parsed);
    }
}
