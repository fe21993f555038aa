//! The raw reader against files written by real ngspice 39
//! (`tests/data/raw/*.raw`, decks next to them), checked against values
//! computed here in closed form, plus hand-cut killed runs, a header as
//! ngspice 44+ writes it, and a bounded no-panic property on arbitrary and
//! mutated input.

use std::f64::consts::PI;
use std::path::PathBuf;

use chatterspice::rawfile::{Complex64, RawFile, RawWarning, Vector};
use proptest::prelude::*;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/raw")
        .join(name)
}

fn read(name: &str) -> RawFile {
    RawFile::read(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

const R: f64 = 1e3; // Ω
const C: f64 = 1e-6; // F
const TAU: f64 = R * C; // s
const RAMP: f64 = 1e-9; // s, the PWL source's rise to 1 V

/// Output of the RC low-pass driven by a 0→1 V ramp of length `RAMP`.
fn rc_step(t: f64) -> f64 {
    if t <= RAMP {
        (t - TAU * (1.0 - (-t / TAU).exp())) / RAMP
    } else {
        1.0 - (TAU / RAMP) * ((-(t - RAMP) / TAU).exp() - (-t / TAU).exp())
    }
}

/// ngspice's default RELTOL is 1e-3: its truncation-error control keeps
/// the transient within about that of the exact solution on a 1 V signal.
const TRAN_TOL: f64 = 1e-3;

fn check_rc_transient(raw: &RawFile, out_name: &str, t_end: f64) {
    assert_eq!(raw.plots.len(), 1);
    let p = &raw.plots[0];
    assert_eq!(p.name, "Transient Analysis");
    assert!(!p.is_complex());
    let t = p.real("time").unwrap();
    let out = p.real(out_name).unwrap();
    assert_eq!(t.len(), p.points());
    assert_eq!(t[0], 0.0);
    assert!((t[t.len() - 1] - t_end).abs() < 1e-15, "{}", t[t.len() - 1]);
    assert!(t.windows(2).all(|w| w[1] > w[0]), "time strictly increases");
    for (&ti, &vi) in t.iter().zip(out) {
        let exact = rc_step(ti);
        assert!(
            (vi - exact).abs() < TRAN_TOL,
            "t = {ti:e}: ngspice {vi} vs exact {exact}"
        );
    }
}

#[test]
fn binary_transient_matches_the_closed_form_rc_step() {
    let raw = read("rc_tran.raw");
    assert!(raw.warnings.is_empty());
    check_rc_transient(&raw, "v(out)", 5e-3);
    let p = &raw.plots[0];
    assert_eq!(p.declared_points, 128);
    // Kirchhoff at every point: the source current is −(v(in) − v(out))/R.
    let (vin, vout, i) = (
        p.real("v(in)").unwrap(),
        p.real("v(out)").unwrap(),
        p.real("i(v1)").unwrap(),
    );
    for k in 0..p.points() {
        let expect = -(vin[k] - vout[k]) / R;
        assert!(
            (i[k] - expect).abs() <= 1e-9 * expect.abs().max(1e-9),
            "point {k}"
        );
    }
}

#[test]
fn column_names_are_case_insensitive() {
    let raw = read("rc_tran.raw");
    let p = &raw.plots[0];
    assert_eq!(p.real("V(OUT)"), p.real("v(out)"));
    assert_eq!(p.index_of("I(V1)"), Some(3));
    assert!(p.column("v(nowhere)").is_none());
    assert!(
        p.complex("v(out)").is_none(),
        "a real vector is not complex"
    );
}

#[test]
fn ascii_transient_matches_the_closed_form_rc_step() {
    let raw = read("rc_tran_ascii.raw");
    check_rc_transient(&raw, "v(out)", 2e-3);
}

#[test]
fn ngspice_44_command_line_is_read_and_changes_nothing_else() {
    let old = read("rc_tran.raw");
    let new = read("rc_tran_ngspice44.raw");
    assert_eq!(new.plots[0].commands, vec!["version 44.2".to_string()]);
    assert!(old.plots[0].commands.is_empty());
    assert_eq!(new.plots[0].real("v(out)"), old.plots[0].real("v(out)"));
}

fn rc_lowpass(f: f64) -> Complex64 {
    Complex64::new(1.0, 0.0) / Complex64::new(1.0, 2.0 * PI * f * TAU)
}

#[test]
fn ac_magnitude_and_phase_match_the_rc_lowpass() {
    let raw = read("rc_ac.raw");
    let p = &raw.plots[0];
    assert_eq!(p.name, "AC Analysis");
    assert!(p.is_complex());
    // The axis is real even though ngspice 39 wrote garbage as its imaginary part.
    let f = p.real("frequency").expect("frequency is stored as real");
    assert_eq!(f.len(), 13);
    for (k, &fk) in f.iter().enumerate() {
        let decade = 10f64.powf(1.0 + k as f64 / 3.0);
        assert!((fk - decade).abs() < 1e-9 * decade, "{fk} vs {decade}");
    }
    let out = p.complex("v(out)").unwrap();
    for (&fk, &h) in f.iter().zip(out) {
        let exact = rc_lowpass(fk);
        // AC is one exact linear solve per frequency: no truncation error.
        assert!((h.norm() - exact.norm()).abs() < 1e-12, "|H({fk})|");
        assert!((h.arg() - exact.arg()).abs() < 1e-12, "arg H({fk})");
    }
    // At the corner 1/(2πRC) the magnitude is 1/√2: interpolate nothing,
    // check the closed form itself is what the points follow.
    assert!((rc_lowpass(1.0 / (2.0 * PI * TAU)).norm() - 0.5f64.sqrt()).abs() < 1e-15);
}

#[test]
fn ac_frequency_axis_imaginary_part_really_is_garbage_in_the_file() {
    // Guards the reason for storing the axis as real: byte 8..16 of the
    // first point is the axis' imaginary part.
    let bytes = std::fs::read(data("rc_ac.raw")).unwrap();
    let start = bytes.windows(8).position(|w| w == b"Binary:\n").unwrap() + 8;
    let im = f64::from_le_bytes(bytes[start + 8..start + 16].try_into().unwrap());
    assert_ne!(im, 0.0);
}

#[test]
fn op_then_tran_in_one_file_gives_two_plots() {
    let raw = read("divider_op_tran.raw");
    assert_eq!(raw.plots.len(), 2);
    let (op, tran) = (&raw.plots[0], &raw.plots[1]);
    assert_eq!(op.name, "Operating Point");
    assert_eq!(op.points(), 1);
    // 4 V across 3k over 1k.
    assert!((op.real("v(mid)").unwrap()[0] - 1.0).abs() < 1e-12);
    assert!((op.real("i(v1)").unwrap()[0] + 4.0 / 4e3).abs() < 1e-15);
    assert_eq!(tran.name, "Transient Analysis");
    let (vin, vmid) = (tran.real("v(in)").unwrap(), tran.real("v(mid)").unwrap());
    assert!(vin.iter().any(|&v| v > 3.9), "the pulse is in the data");
    for (a, b) in vin.iter().zip(vmid) {
        assert!((b - a / 4.0).abs() < 1e-12);
    }
}

#[test]
fn control_block_write_files_in_ascii_and_binary() {
    let tran = read("control_write_tran.raw");
    let p = &tran.plots[0];
    let names: Vec<&str> = p.variables.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names, ["time", "v(out)", "v(in)"]);
    check_rc_transient(&tran, "v(out)", 2e-3);

    let ascii = read("control_write_ac.raw");
    let binary = read("control_write_ac_binary.raw");
    let (pa, pb) = (&ascii.plots[0], &binary.plots[0]);
    // `write` puts the attribute after a space, not a tab.
    assert_eq!(pa.variables[0].kind, "frequency");
    assert_eq!(pa.variables[0].attributes, vec!["grid=3".to_string()]);
    assert_eq!(pa.real("frequency").unwrap(), &[100.0, 1000.0]);
    for (&f, &h) in pa
        .real("frequency")
        .unwrap()
        .iter()
        .zip(pa.complex("v(out)").unwrap())
    {
        assert!((h - rc_lowpass(f)).norm() < 1e-14, "{f}");
    }
    // ASCII carries 16 significant digits: the same numbers as binary.
    for (a, b) in pa
        .complex("v(out)")
        .unwrap()
        .iter()
        .zip(pb.complex("v(out)").unwrap())
    {
        assert!((a - b).norm() <= 1e-15 * b.norm());
    }
}

#[test]
fn killed_binary_run_is_read_to_the_last_whole_point() {
    let raw = read("killed_binary.raw");
    let p = &raw.plots[0];
    assert_eq!(p.declared_points, 0);
    assert_eq!(p.points(), 40);
    assert!(matches!(
        raw.warnings[..],
        [RawWarning::Truncated {
            plot: 0,
            declared: 0,
            read: 40,
            ..
        }]
    ));
    let msg = raw.warnings[0].to_string();
    assert!(msg.contains("killed"), "{msg}");
    let (t, out) = (p.real("time").unwrap(), p.real("v(out)").unwrap());
    for (&ti, &vi) in t.iter().zip(out) {
        assert!((vi - rc_step(ti)).abs() < TRAN_TOL);
    }
}

#[test]
fn killed_ascii_run_drops_the_cut_point() {
    let raw = read("killed_ascii.raw");
    let p = &raw.plots[0];
    assert_eq!(p.points(), 25, "point 25 was cut inside its third value");
    assert!(
        p.variables
            .iter()
            .all(|v| p.column(&v.name).unwrap().len() == 25)
    );
    assert_eq!(raw.warnings.len(), 1);
}

#[test]
fn option_dimensions_and_extra_attributes() {
    let text = "Title: hand made\nDate: today\nPlotname: DC transfer characteristic\n\
                Flags: real\nNo. Variables: 2\nNo. Points: 2\nDimensions: 2\n\
                Command: version 44\nCommand: dc v1 0 1 1\nOption: noinit\nOption: temp = 27\n\
                Variables:\n\t0\tv-sweep\tvoltage min=0.000000e+00 max=1.000000e+00\n\
                \t1\tv(out)\tvoltage\tcolor=red\tplot=1\n\
                Values:\n 0\t0\n\t0\n\n 1\t1\n\t0.5\n\n";
    let raw = RawFile::parse(text.as_bytes()).unwrap();
    let p = &raw.plots[0];
    assert_eq!(p.commands, ["version 44", "dc v1 0 1 1"]);
    assert_eq!(p.options, ["noinit", "temp = 27"]);
    assert_eq!(p.dimensions.as_deref(), Some("2"));
    assert_eq!(p.variables[0].attributes.len(), 2);
    assert_eq!(p.variables[1].attributes, ["color=red", "plot=1"]);
    assert_eq!(p.real("v(out)").unwrap(), &[0.0, 0.5]);
    assert_eq!(p.scale(), Some(Vector::Real(&[0.0, 1.0])));
}

#[test]
fn malformed_input_is_an_error_with_a_position() {
    let good = std::fs::read(data("rc_tran_ascii.raw")).unwrap();
    let text = String::from_utf8(good).unwrap();
    let bad = text.replacen("No. Variables: 4", "No. Variables: four", 1);
    let err = RawFile::parse(bad.as_bytes()).unwrap_err().to_string();
    assert!(err.contains("line 5") && err.contains("four"), "{err}");

    let bad = text.replacen("\t1.000000000000000e-02", "\t1.0000000x0000e-02", 1);
    let err = RawFile::parse(bad.as_bytes()).unwrap_err().to_string();
    assert!(err.contains("line ") && err.contains("a number"), "{err}");

    let err = RawFile::parse(b"").unwrap_err().to_string();
    assert!(err.contains("empty"), "{err}");

    let err = RawFile::read(data("no_such_file.raw"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("no_such_file.raw"), "{err}");
}

#[test]
fn trailing_garbage_after_binary_data_names_a_byte_offset() {
    let mut bytes = std::fs::read(data("rc_tran.raw")).unwrap();
    let len = bytes.len();
    bytes.extend(b"\x01\x02garbage\n");
    let err = RawFile::parse(&bytes).unwrap_err().to_string();
    assert!(err.contains(&format!("byte {len}")), "{err}");
}

const GOLDEN: [&str; 9] = [
    "rc_tran.raw",
    "rc_tran_ascii.raw",
    "rc_tran_ngspice44.raw",
    "rc_ac.raw",
    "divider_op_tran.raw",
    "control_write_tran.raw",
    "control_write_ac.raw",
    "killed_binary.raw",
    "killed_ascii.raw",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2048)) {
        let _ = RawFile::parse(&bytes);
    }

    #[test]
    fn header_prefixed_noise_never_panics(
        flags in prop::sample::select(vec!["real", "complex", "real unpadded", "complex unpadded", ""]),
        nvars in 0usize..4,
        points in prop::sample::select(vec!["0", "1", "3", "99999999999999", "-1"]),
        kind in prop::sample::select(vec!["Binary:", "Values:"]),
        body in proptest::collection::vec(any::<u8>(), 0..512),
    ) {
        let mut bytes = format!(
            "Title: t\nPlotname: p\nFlags: {flags}\nNo. Variables: {nvars}\nNo. Points: {points}\nVariables:\n"
        ).into_bytes();
        for i in 0..nvars {
            bytes.extend(format!("\t{i}\tv{i}\tvoltage dims=2\n").bytes());
        }
        bytes.extend(kind.bytes());
        bytes.push(b'\n');
        bytes.extend(body);
        let _ = RawFile::parse(&bytes);
    }

    #[test]
    fn mutated_real_files_never_panic(
        file in prop::sample::select(GOLDEN.to_vec()),
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8),
        cut in any::<prop::sample::Index>(),
        do_cut in any::<bool>(),
    ) {
        let mut bytes = std::fs::read(data(file)).unwrap();
        for (at, byte) in edits {
            let i = at.index(bytes.len());
            bytes[i] = byte;
        }
        if do_cut {
            bytes.truncate(cut.index(bytes.len() + 1));
        }
        if let Ok(raw) = RawFile::parse(&bytes) {
            // Whatever was read is internally consistent.
            for p in &raw.plots {
                for i in 0..p.variables.len() {
                    prop_assert!(p.vector(i).unwrap().len() <= p.points());
                }
            }
        }
    }
}
