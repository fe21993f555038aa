//! The raw reader on LTspice's dialect: the files of
//! `tests/data/ltspice/`, written by its `generate.py` in LTspice's layout
//! (see the README there), checked value by value, bit for bit, against
//! the same formulas computed here; the `raw` command on them; errors and
//! hostile input; and, when spicelib is installed, spicelib reading the
//! same values (see [`spicelib_reads_the_same_values`]).

use std::path::{Path, PathBuf};
use std::process::Command as Process;

use assert_cmd::Command;
use chatterspice::rawfile::{
    Complex64, Dialect, Encoding, Plot, RawError, RawFile, RawWarning, Step, Vector,
};
use proptest::prelude::*;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/ltspice")
        .join(name)
}

fn read(name: &str) -> RawFile {
    RawFile::read(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The value LTspice stores as `f32`, as the reader returns it.
fn single(x: f64) -> f64 {
    f64::from(x as f32)
}

/// A value stored as `f64`.
fn exact(x: f64) -> f64 {
    x
}

/// The value written as LTspice's ASCII does (16 significant digits) and
/// read back.
fn ascii(x: f64) -> f64 {
    format!("{x:.15e}").parse().unwrap()
}

/// Bit-for-bit equality, with a message naming what differs.
fn same(what: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(g.to_bits(), w.to_bits(), "{what}[{k}]: {g:e} vs {w:e}");
    }
}

fn same_complex(what: &str, got: &[Complex64], want: &[Complex64]) {
    let re = |v: &[Complex64]| v.iter().map(|c| c.re).collect::<Vec<_>>();
    let im = |v: &[Complex64]| v.iter().map(|c| c.im).collect::<Vec<_>>();
    same(&format!("{what}.re"), &re(got), &re(want));
    same(&format!("{what}.im"), &im(got), &im(want));
}

fn real<'a>(p: &'a Plot, name: &str) -> &'a [f64] {
    p.real(name)
        .unwrap_or_else(|| panic!("no real vector {name}"))
}

fn complex<'a>(p: &'a Plot, name: &str) -> &'a [Complex64] {
    p.complex(name)
        .unwrap_or_else(|| panic!("no complex vector {name}"))
}

// ---------------------------------------------------------------------------
// The generator's formulas (tests/data/ltspice/generate.py), in doubles.

const TRAN_POINTS: usize = 24;

/// Per point: time (as written: every third stamp negative), V(in),
/// V(out), I(R1), V(ref).
fn tran_rows() -> Vec<[f64; 5]> {
    (0..TRAN_POINTS)
        .map(|k| {
            let t = k as f64 * 2.5e-5;
            let written = if k % 3 == 2 { -t } else { t };
            let vin = if k == 0 { 0.0 } else { 1.0 };
            let vout = 1.0 - 1.0 / (1.0 + k as f64 / 4.0);
            [written, vin, vout, (vin - vout) / 1000.0, 0.1]
        })
        .collect()
}

fn column<const N: usize>(rows: &[[f64; N]], j: usize, f: fn(f64) -> f64) -> Vec<f64> {
    rows.iter().map(|r| f(r[j])).collect()
}

const TRAN_NAMES: [&str; 5] = ["time", "V(in)", "V(out)", "I(R1)", "V(ref)"];

/// A transient plot holds the generator's values, through `value` (as
/// `f32`, as ASCII, as they are); time, through `time` (as ASCII or as it
/// is), as its absolute value.
fn check_tran(p: &Plot, names: &[&str], time: fn(f64) -> f64, value: fn(f64) -> f64) {
    assert_eq!(p.name, "Transient Analysis");
    assert_eq!(p.dialect, Dialect::Ltspice);
    let got: Vec<&str> = p.variables.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(got, names);
    let rows = tran_rows();
    let time: Vec<f64> = rows.iter().map(|r| time(r[0]).abs()).collect();
    same("time", real(p, names[0]), &time);
    assert!(time.windows(2).all(|w| w[1] > w[0]));
    for (j, name) in names.iter().enumerate().skip(1) {
        same(name, real(p, name), &column(&rows, j, value));
    }
}

#[test]
fn binary_transient_reads_f32_values_exactly_and_time_without_its_sign() {
    let raw = read("tran.raw");
    assert!(raw.warnings.is_empty(), "{:?}", raw.warnings);
    assert_eq!(raw.plots.len(), 1);
    let p = &raw.plots[0];
    assert_eq!(p.encoding, Encoding::Utf16Le);
    check_tran(p, &TRAN_NAMES, exact, single);
    // The time stamps LTspice wrote negative are read positive.
    let rows = tran_rows();
    assert!(rows[2][0] < 0.0 && real(p, "time")[2] == -rows[2][0]);
    assert_eq!(p.title, "* C:\\sim\\relay_tran.asc");
    assert_eq!(p.date, "Tue Mar  4 10:20:30 2025");
    assert_eq!(
        p.commands,
        ["Linear Technology Corporation LTspice XVII".to_string()]
    );
    assert_eq!(
        p.other_header_lines,
        [
            "Offset:    0.0000000000000000e+00",
            "Backannotation: u1 1 2 3 4 5",
            "Backannotation: _in1 1 2"
        ]
    );
    assert_eq!(p.flags.other, ["forward"]);
    assert!(p.step.is_none());
    assert_eq!(p.declared_points, TRAN_POINTS);
    assert_eq!(p.variables[3].kind, "device_current");
}

#[test]
fn fastaccess_reads_the_same_values_as_point_after_point() {
    let fast = read("tran_fastaccess.raw");
    assert!(fast.plots[0].flags.has("FastAccess"));
    check_tran(&fast.plots[0], &TRAN_NAMES, exact, single);
    assert_eq!(fast.plots[0].vector(2), read("tran.raw").plots[0].vector(2));
}

#[test]
fn double_flag_stores_every_value_as_f64() {
    check_tran(&read("tran_double.raw").plots[0], &TRAN_NAMES, exact, exact);
}

#[test]
fn utf16_ascii_values_read_as_written() {
    let raw = read("tran_ascii.raw");
    assert_eq!(raw.plots[0].encoding, Encoding::Utf16Le);
    check_tran(&raw.plots[0], &TRAN_NAMES, ascii, ascii);
}

#[test]
fn a_utf8_header_is_told_ltspice_by_its_command_line() {
    let raw = read("tran_utf8.raw");
    assert_eq!(raw.plots[0].encoding, Encoding::Utf8);
    check_tran(&raw.plots[0], &TRAN_NAMES, exact, single);
}

#[test]
fn names_beyond_ascii_are_kept_exactly() {
    let raw = read("names.raw");
    let p = &raw.plots[0];
    let names = ["time", "V(eingang_ü)", "V(出力)", "I(R°1)", "V(𝛂)"];
    check_tran(p, &names, exact, single);
    assert_eq!(p.title, "* C:\\sim\\Prüfstand — relais.asc");
    assert_eq!(p.index_of("v(EINGANG_ü)"), Some(1), "ASCII case is ignored");
}

/// Steps of 5, 7 and 6 points: time, V(out), I(R1) per point.
fn stepped_rows() -> Vec<Vec<[f64; 3]>> {
    [5usize, 7, 6]
        .iter()
        .enumerate()
        .map(|(s, &n)| {
            (0..n)
                .map(|k| {
                    let t = k as f64 * 1e-4;
                    let vout = 1.0 - 1.0 / (1.0 + k as f64 / (s as f64 + 1.0));
                    [t, vout, vout / ((s as f64 + 1.0) * 1000.0)]
                })
                .collect()
        })
        .collect()
}

#[test]
fn stepped_transient_is_one_plot_a_step_split_where_time_restarts() {
    let raw = read("tran_stepped.raw");
    let steps = stepped_rows();
    assert_eq!(raw.plots.len(), 3);
    let mut first = 0;
    for (s, (p, rows)) in raw.plots.iter().zip(&steps).enumerate() {
        assert_eq!(
            p.step,
            Some(Step {
                index: s,
                count: 3,
                first_point: first
            })
        );
        assert_eq!(p.declared_points, 18);
        same("time", real(p, "time"), &column(rows, 0, |x| x));
        same("V(out)", real(p, "V(out)"), &column(rows, 1, single));
        same("I(R1)", real(p, "I(R1)"), &column(rows, 2, single));
        first += rows.len();
    }
    assert_eq!(raw.last_transient().unwrap().step.unwrap().index, 2);
}

/// Per point: frequency, V(in), V(out), I(C1) of a first-order low-pass.
fn ac_rows(points: usize, corner: f64) -> Vec<[Complex64; 4]> {
    (0..points)
        .map(|k| {
            let f = 10.0 * (1u64 << k) as f64;
            let x = f / corner;
            let d = 1.0 + x * x;
            let h = Complex64::new(1.0 / d, -x / d);
            [
                Complex64::new(f, 0.0),
                Complex64::new(1.0, 0.0),
                h,
                Complex64::new((1.0 - h.re) / 1000.0, -h.im / 1000.0),
            ]
        })
        .collect()
}

fn check_ac(p: &Plot, rows: &[[Complex64; 4]], value: fn(f64) -> f64) {
    assert_eq!(p.name, "AC Analysis");
    assert!(p.is_complex());
    let f: Vec<f64> = rows.iter().map(|r| value(r[0].re)).collect();
    same("frequency", real(p, "frequency"), &f);
    for (j, name) in ["V(in)", "V(out)", "I(C1)"].iter().enumerate() {
        let want: Vec<Complex64> = rows
            .iter()
            .map(|r| Complex64::new(value(r[j + 1].re), value(r[j + 1].im)))
            .collect();
        same_complex(name, complex(p, name), &want);
    }
}

#[test]
fn complex_ac_reads_pairs_of_f64_the_frequency_too() {
    let raw = read("ac.raw");
    assert!(raw.warnings.is_empty());
    check_ac(&raw.plots[0], &ac_rows(12, 1000.0), |x| x);
    assert_eq!(raw.plots[0].flags.other, ["forward", "log"]);
}

#[test]
fn ascii_ac_in_utf8_with_crlf_lines() {
    let raw = read("ac_ascii_utf8.raw");
    assert_eq!(raw.plots[0].encoding, Encoding::Utf8);
    assert_eq!(raw.plots[0].dialect, Dialect::Ltspice);
    check_ac(&raw.plots[0], &ac_rows(12, 1000.0), ascii);
}

#[test]
fn stepped_ac_is_split_where_the_frequency_restarts() {
    let raw = read("ac_stepped.raw");
    assert_eq!(raw.plots.len(), 2);
    check_ac(&raw.plots[0], &ac_rows(6, 1000.0), |x| x);
    check_ac(&raw.plots[1], &ac_rows(6, 2000.0), |x| x);
    assert_eq!(raw.plots[1].step.unwrap().first_point, 6);
}

#[test]
fn operating_point_has_no_scale_and_one_point() {
    let raw = read("op.raw");
    let p = &raw.plots[0];
    assert_eq!(p.name, "Operating Point");
    assert_eq!(p.points(), 1);
    // The first value is an f64, the others f32.
    same("V(in)", real(p, "V(in)"), &[5.0]);
    same("V(out)", real(p, "V(out)"), &[2.5]);
    same("I(R1)", real(p, "I(R1)"), &[single(0.0025)]);
    same("I(V1)", real(p, "I(V1)"), &[single(-0.0025)]);
}

#[test]
fn stepped_operating_point_is_one_plot_a_point() {
    let raw = read("op_stepped.raw");
    assert_eq!(raw.plots.len(), 4);
    for (s, p) in raw.plots.iter().enumerate() {
        let r1 = 1000.0 * (s as f64 + 1.0);
        let vout = 5.0 * 1000.0 / (r1 + 1000.0);
        assert_eq!(p.step.unwrap().first_point, s);
        same("r1", real(p, "r1"), &[r1]);
        same("V(out)", real(p, "V(out)"), &[single(vout)]);
        same("I(R1)", real(p, "I(R1)"), &[single(vout / 1000.0)]);
    }
    assert_eq!(raw.plots[0].variables[0].kind, "param");
}

#[test]
fn noise_spectral_density_keeps_its_name_and_output_line() {
    let raw = read("noise.raw");
    let name = "Noise Spectral Density - (V/Hz½ or A/Hz½)";
    let p = raw.plot_named(name).expect("the plot by its exact name");
    assert!(p.other_header_lines.contains(&"Output: out".to_string()));
    let mut want: [Vec<f64>; 4] = Default::default();
    for k in 0..10 {
        let f = 10.0 * (1u64 << k) as f64;
        let x = f / 1e4;
        let gain = 1.0 / (1.0 + x * x);
        let onoise = 1e-8 * (1.0 + 1000.0 / f);
        for (j, v) in [f, single(gain), single(onoise), single(onoise / gain)]
            .into_iter()
            .enumerate()
        {
            want[j].push(v);
        }
    }
    for (j, name) in ["frequency", "gain", "V(onoise)", "V(inoise)"]
        .iter()
        .enumerate()
    {
        same(name, real(p, name), &want[j]);
    }
}

// ---------------------------------------------------------------------------
// The `raw` command

fn raw_stdout(args: &[&str]) -> String {
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("raw")
        .args(args)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    String::from_utf8(out).unwrap()
}

fn path(name: &str) -> String {
    data(name).to_str().unwrap().to_owned()
}

#[test]
fn csv_prints_an_f32_as_the_shortest_text_of_its_exact_double() {
    let csv = raw_stdout(&[&path("tran.raw")]);
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("time,V(in),V(out),I(R1),V(ref)"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), TRAN_POINTS);
    // 0.1 as f32 is 0.100000001490116119384765625.
    assert!(rows.iter().all(|r| r.ends_with(",0.10000000149011612")));
    // Point 2's time was written negative.
    assert!(
        rows[2].starts_with("0.00005,1.0,0.3333333432674408,"),
        "{}",
        rows[2]
    );
    // The same with a UTF-8 header (which the streaming CSV writer, for
    // ngspice's files, leaves to the reader too).
    assert_eq!(raw_stdout(&[&path("tran_utf8.raw")]), csv);
    // Every cell reads back to the reader's value.
    let raw = read("tran.raw");
    let vout = real(&raw.plots[0], "V(out)");
    for (row, v) in rows.iter().zip(vout) {
        let cell: f64 = row.split(',').nth(2).unwrap().parse().unwrap();
        assert_eq!(cell.to_bits(), v.to_bits());
    }
}

#[test]
fn csv_of_a_step_and_json_listing_the_steps() {
    let csv = raw_stdout(&[&path("tran_stepped.raw"), "--plot", "1"]);
    assert_eq!(csv.lines().count(), 1 + 7);
    assert!(csv.lines().nth(1).unwrap().starts_with("0.0,0.0,0.0"));
    let json: serde_json::Value = serde_json::from_str(&raw_stdout(&[
        &path("tran_stepped.raw"),
        "--format",
        "json",
    ]))
    .unwrap();
    let plots = json["plots"].as_array().unwrap();
    assert_eq!(plots.len(), 3);
    assert_eq!(plots[2]["step"]["index"], 2);
    assert_eq!(plots[2]["step"]["count"], 3);
    assert_eq!(plots[2]["step"]["first_point"], 12);
    assert_eq!(plots[2]["points"], 6);
    assert_eq!(plots[2]["dialect"], "ltspice");
    assert_eq!(plots[2]["encoding"], "utf-16le");
    let json: serde_json::Value =
        serde_json::from_str(&raw_stdout(&[&path("noise.raw"), "--format", "json"])).unwrap();
    assert_eq!(
        json["plots"][0]["name"],
        "Noise Spectral Density - (V/Hz½ or A/Hz½)"
    );
    assert!(json["plots"][0]["step"].is_null());
}

#[test]
fn non_ascii_names_in_csv_and_signal_analysis() {
    let csv = raw_stdout(&[&path("names.raw")]);
    assert_eq!(
        csv.lines().next(),
        Some("time,V(eingang_ü),V(出力),I(R°1),V(𝛂)")
    );
    let json: serde_json::Value = serde_json::from_str(&raw_stdout(&[
        &path("names.raw"),
        "--signal",
        "V(出力)",
        "--low",
        "0.3",
        "--high",
        "0.6",
        "--format",
        "json",
    ]))
    .unwrap();
    let probe = &json["probes"][0];
    assert_eq!(probe["signal"], "V(出力)");
    assert_eq!(probe["edges"], 1);
    // The rising edge: V(out) crosses 0.6 between the last point below
    // and the first above, interpolated linearly.
    let rows = tran_rows();
    let v: Vec<f64> = column(&rows, 2, single);
    let k = v.iter().position(|&x| x > 0.6).unwrap();
    let (t0, t1) = (rows[k - 1][0].abs(), rows[k][0].abs());
    let edge = t0 + (0.6 - v[k - 1]) / (v[k] - v[k - 1]) * (t1 - t0);
    let got = probe["first_edge"].as_f64().unwrap();
    assert!((got - edge).abs() < 1e-12, "{got} vs {edge}");
}

#[test]
fn signal_analysis_of_one_step() {
    let json: serde_json::Value = serde_json::from_str(&raw_stdout(&[
        &path("tran_stepped.raw"),
        "--plot",
        "0",
        "--signal",
        "V(out)",
        "--low",
        "0.2",
        "--high",
        "0.7",
        "--format",
        "json",
    ]))
    .unwrap();
    assert_eq!(json["points"], 5);
    // Step 0: V(out) = 1 − 1/(1 + k) reaches 0.75 at its last point.
    assert_eq!(json["probes"][0]["edges"], 1);
    assert_eq!(json["probes"][0]["max"], single(0.8));
}

// ---------------------------------------------------------------------------
// Errors and hostile input

/// `text` of a UTF-16 file as a string, one char a code unit pair.
fn utf16_text(bytes: &[u8]) -> String {
    let units: Vec<u16> = bytes
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect();
    String::from_utf16_lossy(&units)
}

/// `bytes` with the UTF-16 text `from` (its first occurrence) replaced
/// by `to`.
fn replace_utf16(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let enc = |s: &str| -> Vec<u8> { s.encode_utf16().flat_map(|u| u.to_le_bytes()).collect() };
    let (from, to) = (enc(from), enc(to));
    let at = bytes
        .windows(from.len())
        .position(|w| w == from.as_slice())
        .expect("text to replace");
    [&bytes[..at], to.as_slice(), &bytes[at + from.len()..]].concat()
}

/// The byte offset of the start of the line holding `text` in a UTF-16
/// file whose header is ASCII up to there.
fn utf16_line_offset(bytes: &[u8], text: &str) -> usize {
    let s = utf16_text(bytes);
    let at = s.find(text).unwrap();
    2 * s[..at].rfind('\n').map_or(0, |n| n + 1)
}

#[test]
fn a_file_cut_mid_point_keeps_its_whole_points_and_names_the_byte() {
    let bytes = std::fs::read(data("tran.raw")).unwrap();
    let row = 8 + 4 * 4;
    let data_start = bytes.len() - TRAN_POINTS * row;
    let cut = &bytes[..data_start + 10 * row + 5];
    let raw = RawFile::parse(cut).unwrap();
    assert_eq!(raw.plots[0].points(), 10);
    assert_eq!(
        raw.warnings,
        [RawWarning::Truncated {
            plot: 0,
            declared: TRAN_POINTS,
            read: 10,
            offset: data_start + 10 * row
        }]
    );
    let text = raw.warnings[0].to_string();
    assert!(
        text.contains(&format!("byte {}", data_start + 10 * row)),
        "{text}"
    );
}

#[test]
fn cut_fastaccess_data_are_an_error_naming_where_they_start() {
    let bytes = std::fs::read(data("tran_fastaccess.raw")).unwrap();
    let data_start = bytes.len() - TRAN_POINTS * (8 + 4 * 4);
    let err = RawFile::parse(&bytes[..bytes.len() - 1]).unwrap_err();
    assert!(matches!(err, RawError::ShortFastAccess { .. }), "{err:?}");
    let text = err.to_string();
    assert!(
        text.contains(&format!("byte {data_start}")) && text.contains("FastAccess"),
        "{text}"
    );
}

#[test]
fn wrong_counts_and_garbage_in_the_header_name_line_and_byte() {
    let bytes = std::fs::read(data("tran.raw")).unwrap();
    // More variables declared than listed: `Binary:` is read as one.
    let bad = replace_utf16(&bytes, "No. Variables: 5", "No. Variables: 6");
    let err = RawFile::parse(&bad).unwrap_err().to_string();
    let at = utf16_line_offset(&bad, "Binary:");
    assert!(
        err.contains(&format!("line 17 (byte {at})")) && err.contains("Binary:"),
        "{err}"
    );
    // Fewer: the last declaration is where a header line should be.
    let bad = replace_utf16(&bytes, "No. Variables: 5", "No. Variables: 4");
    let err = RawFile::parse(&bad).unwrap_err().to_string();
    let at = utf16_line_offset(&bad, "V(ref)");
    assert!(err.contains(&format!("line 16 (byte {at})")), "{err}");
    // A count that is no number.
    let bad = replace_utf16(
        &bytes,
        "No. Points:           24",
        "No. Points:         many",
    );
    let err = RawFile::parse(&bad).unwrap_err().to_string();
    let at = utf16_line_offset(&bad, "No. Points:");
    assert!(
        err.contains(&format!("line 6 (byte {at})")) && err.contains("many"),
        "{err}"
    );
    // The header cut before `Binary:`.
    let at = utf16_line_offset(&bytes, "\t2\tV(out)");
    let err = RawFile::parse(&bytes[..at]).unwrap_err().to_string();
    assert!(
        err.contains("ends inside the `Variables:` list (2 of 5 declared)"),
        "{err}"
    );
    // ... or in the middle of a line.
    let err = RawFile::parse(&bytes[..at + 4]).unwrap_err().to_string();
    assert!(
        err.contains(&format!("line 14 (byte {at})")) && err.contains("has no name"),
        "{err}"
    );
}

#[test]
fn an_all_zero_point_after_the_declared_ones_is_left_with_a_warning() {
    let mut bytes = std::fs::read(data("tran_stepped.raw")).unwrap();
    let end = bytes.len();
    bytes.extend([0u8; 16]);
    let raw = RawFile::parse(&bytes).unwrap();
    assert_eq!(raw.plots.len(), 3);
    assert_eq!(
        raw.warnings,
        [RawWarning::TrailingData {
            plot: 2,
            declared: 18,
            offset: end,
            bytes: 16
        }]
    );
}

#[test]
fn plots_one_after_the_other_in_one_file_are_all_read() {
    let mut bytes = Vec::new();
    for f in ["op.raw", "tran_ascii.raw", "tran.raw", "ac_ascii_utf8.raw"] {
        bytes.extend(std::fs::read(data(f)).unwrap());
    }
    let raw = RawFile::parse(&bytes).unwrap();
    assert!(raw.warnings.is_empty(), "{:?}", raw.warnings);
    assert_eq!(raw.plots.len(), 4);
    assert_eq!(raw.plots[0].name, "Operating Point");
    check_tran(&raw.plots[1], &TRAN_NAMES, ascii, ascii);
    check_tran(&raw.plots[2], &TRAN_NAMES, exact, single);
    check_ac(&raw.plots[3], &ac_rows(12, 1000.0), ascii);
}

const FILES: [&str; 13] = [
    "tran.raw",
    "tran_fastaccess.raw",
    "tran_double.raw",
    "tran_ascii.raw",
    "tran_utf8.raw",
    "names.raw",
    "tran_stepped.raw",
    "ac.raw",
    "ac_ascii_utf8.raw",
    "ac_stepped.raw",
    "op.raw",
    "op_stepped.raw",
    "noise.raw",
];

#[test]
fn every_file_is_listed_here() {
    let mut on_disk: Vec<String> = std::fs::read_dir(data(""))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".raw"))
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = FILES.iter().map(|s| s.to_string()).collect();
    listed.sort();
    assert_eq!(on_disk, listed);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn mutated_ltspice_files_never_panic(
        file in prop::sample::select(FILES.to_vec()),
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
            for p in &raw.plots {
                for i in 0..p.variables.len() {
                    prop_assert!(p.vector(i).unwrap().len() <= p.points());
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------
// spicelib

/// The Python that has spicelib: `SPICELIB_PYTHON`, else `python3`.
/// `None` with a visible note when there is none; a panic instead when
/// `REQUIRE_SPICELIB=1`.
fn spicelib_python() -> Option<String> {
    let python = std::env::var("SPICELIB_PYTHON").unwrap_or_else(|_| "python3".into());
    let works = Process::new(&python)
        .args(["-c", "import spicelib"])
        .output()
        .is_ok_and(|o| o.status.success());
    if works {
        return Some(python);
    }
    let why = format!(
        "`{python} -c 'import spicelib'` fails (pip install spicelib, or set SPICELIB_PYTHON)"
    );
    if std::env::var("REQUIRE_SPICELIB").as_deref() == Ok("1") {
        panic!("REQUIRE_SPICELIB=1 but {why}");
    }
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr(),
        "note: skipping the comparison with spicelib (set REQUIRE_SPICELIB=1 to fail instead): {why}"
    );
    None
}

/// What spicelib read, per file given: its plots, or why it could not.
fn spicelib_dump(python: &str, args: &[String]) -> serde_json::Value {
    let out = Process::new(python)
        .arg(data("spicelib_dump.py"))
        .args(args)
        .output()
        .expect("python runs");
    assert!(
        out.status.success(),
        "spicelib_dump.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON from spicelib_dump.py")
}

/// Values compared and the largest difference seen.
#[derive(Default)]
struct Tally {
    values: usize,
    /// Of them, ASCII values spicelib keeps as `f32` (see
    /// [`compare_with_spicelib`]).
    rounded: usize,
    /// Imaginary parts of a frequency scale that are not 0 (this reader
    /// keeps the frequency real).
    dropped_imaginary: usize,
    max_difference: f64,
}

impl Tally {
    fn compare(&mut self, what: &str, ours: f64, theirs: u64) {
        let theirs = f64::from_bits(theirs);
        self.values += 1;
        if ours.is_nan() && theirs.is_nan() {
            return;
        }
        self.max_difference = self.max_difference.max((ours - theirs).abs());
        assert_eq!(
            ours.to_bits(),
            theirs.to_bits(),
            "{what}: chatterspice {ours:e}, spicelib {theirs:e}"
        );
    }
}

/// The plots of `raw` as the file holds them: the steps of a stepped plot
/// together.
fn file_plots(raw: &RawFile) -> Vec<Vec<&Plot>> {
    let mut groups: Vec<Vec<&Plot>> = Vec::new();
    for p in &raw.plots {
        match p.step {
            Some(s) if s.index > 0 => groups.last_mut().expect("step 0 first").push(p),
            _ => groups.push(vec![p]),
        }
    }
    groups
}

/// Compares what spicelib read of `file` with what this reader read.
///
/// spicelib stores LTspice's real vectors but the first in `float32`, as
/// binary files hold them, but does so for ASCII files too: their 16
/// digits are rounded to `f32`, where this reader keeps the `f64` the
/// text gives. For those, this reader's value rounded to `f32` is
/// compared. A frequency scale is kept real: a file of this repository
/// must have 0 as each imaginary part (`strict`); in others, imaginary
/// parts that are not are counted, not compared.
fn compare_with_spicelib(
    file: &Path,
    raw: &RawFile,
    theirs: &serde_json::Value,
    strict: bool,
    tally: &mut Tally,
) {
    let name = file.display();
    let theirs = theirs
        .as_array()
        .unwrap_or_else(|| panic!("{name}: {theirs}"));
    let ours = file_plots(raw);
    assert_eq!(ours.len(), theirs.len(), "{name}: plots");
    for (steps, plot) in ours.iter().zip(theirs) {
        let first = steps[0];
        assert_eq!(plot["name"], first.name.as_str(), "{name}: plot name");
        assert_eq!(plot["dialect"], "ltspice", "{name}");
        if let Some(points) = plot["step_points"].as_array() {
            let ours: Vec<usize> = steps.iter().map(|p| p.points()).collect();
            let theirs: Vec<usize> = points
                .iter()
                .map(|n| n.as_u64().unwrap() as usize)
                .collect();
            assert_eq!(ours, theirs, "{name}: points of each step");
        }
        let traces = plot["traces"].as_array().unwrap();
        assert_eq!(traces.len(), first.variables.len(), "{name}: vectors");
        for (j, trace) in traces.iter().enumerate() {
            let their_name = trace["name"].as_str().unwrap();
            let our_name = &first.variables[j].name;
            // spicelib decodes UTF-16 a code unit at a time: a character
            // beyond the Basic Multilingual Plane becomes two U+FFFD.
            if !their_name.contains('\u{fffd}') {
                assert_eq!(their_name, our_name, "{name}: vector {j}");
            }
            let re = trace["re"].as_array().unwrap();
            let im = trace["im"].as_array();
            let rounded = plot["raw_type"] == "values:" && trace["dtype"] == "float32";
            let mut k = 0;
            for p in steps {
                match p.vector(j).unwrap() {
                    Vector::Real(v) => {
                        for &x in v {
                            let x = if rounded {
                                tally.rounded += 1;
                                single(x)
                            } else {
                                x
                            };
                            tally.compare(
                                &format!("{name}: {our_name}[{k}]"),
                                x,
                                re[k].as_u64().unwrap(),
                            );
                            // The frequency of a complex plot, kept real:
                            // LTspice writes 0 as its imaginary part.
                            match im.map(|im| f64::from_bits(im[k].as_u64().unwrap())) {
                                Some(x) if x != 0.0 && !strict => tally.dropped_imaginary += 1,
                                Some(x) => tally.compare(
                                    &format!("{name}: {our_name}[{k}].im"),
                                    0.0,
                                    x.to_bits(),
                                ),
                                None => {}
                            }
                            k += 1;
                        }
                    }
                    Vector::Complex(v) => {
                        let im = im.expect("spicelib reads it complex too");
                        for c in v {
                            tally.compare(
                                &format!("{name}: {our_name}[{k}].re"),
                                c.re,
                                re[k].as_u64().unwrap(),
                            );
                            tally.compare(
                                &format!("{name}: {our_name}[{k}].im"),
                                c.im,
                                im[k].as_u64().unwrap(),
                            );
                            k += 1;
                        }
                    }
                }
            }
            assert_eq!(k, re.len(), "{name}: {our_name}: values");
        }
    }
}

/// `FILE` or, for a stepped file, `FILE:STEPS` for spicelib_dump.py.
fn dump_arg(file: &Path, raw: &RawFile) -> String {
    let steps = raw.plots.iter().find_map(|p| p.step).map_or(0, |s| s.count);
    let file = file.to_str().unwrap();
    if steps > 0 {
        format!("{file}:{steps}")
    } else {
        file.to_owned()
    }
}

/// spicelib (https://pypi.org/project/spicelib/) reads every file here
/// (but `tran_ascii.raw`: spicelib splits UTF-16 ASCII values at the byte
/// 0x0A and cannot read them) to the same values, bit for bit: names,
/// steps, every value. Skipped without spicelib unless
/// `REQUIRE_SPICELIB=1`.
///
/// `LTSPICE_COMPARE_DIR=DIR` adds every `*.raw` file in DIR that this
/// reader reads as LTspice's; those spicelib cannot read are listed and
/// skipped.
#[test]
fn spicelib_reads_the_same_values() {
    let Some(python) = spicelib_python() else {
        return;
    };
    let mut files: Vec<(PathBuf, bool)> = FILES
        .iter()
        .filter(|&&f| f != "tran_ascii.raw")
        .map(|f| (data(f), true))
        .collect();
    if let Ok(dir) = std::env::var("LTSPICE_COMPARE_DIR") {
        let mut extra: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("LTSPICE_COMPARE_DIR={dir}: {e}"))
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "raw"))
            .collect();
        extra.sort();
        files.extend(extra.into_iter().map(|p| (p, false)));
    }
    let mut ours = Vec::new();
    for (file, required) in files {
        match RawFile::read(&file) {
            Ok(raw) if raw.plots.iter().all(|p| p.dialect == Dialect::Ltspice) => {
                ours.push((file, raw, required))
            }
            Ok(_) => {}
            Err(e) if required => panic!("{e}"),
            // Not a file this test is about (another simulator's, say).
            Err(e) => eprintln!("not compared: {e}"),
        }
    }
    let args: Vec<String> = ours.iter().map(|(f, raw, _)| dump_arg(f, raw)).collect();
    let dump = spicelib_dump(&python, &args);
    let mut tally = Tally::default();
    let mut compared = 0;
    for ((file, raw, required), arg) in ours.iter().zip(&args) {
        let theirs = &dump[arg.as_str()];
        if let Some(error) = theirs.get("error") {
            assert!(
                !required,
                "spicelib cannot read {}: {error}",
                file.display()
            );
            eprintln!("spicelib cannot read {} ({error}): skipped", file.display());
            continue;
        }
        let before = tally.values;
        compare_with_spicelib(file, raw, theirs, *required, &mut tally);
        eprintln!("{}: {} values agree", file.display(), tally.values - before);
        compared += 1;
    }
    eprintln!(
        "spicelib agrees on {compared} files, {} values ({} of them ASCII values spicelib \
         rounds to f32); largest difference {:e}; {} imaginary parts of a frequency that are \
         not 0 not compared",
        tally.values, tally.rounded, tally.max_difference, tally.dropped_imaginary
    );
    assert!(compared >= FILES.len() - 1);
}
