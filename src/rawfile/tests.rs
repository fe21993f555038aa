//! Unit tests of the raw reader.

use super::*;

fn header(flags: &str, nvars: usize, points: &str, vars: &str, kind: &str) -> Vec<u8> {
    format!(
        "Title: t\nDate: d\nPlotname: Transient Analysis\nFlags: {flags}\n\
         No. Variables: {nvars}\nNo. Points: {points}\nVariables:\n{vars}{kind}\n"
    )
    .into_bytes()
}

fn binary(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

const TWO: &str = "\t0\ttime\ttime\n\t1\tv(out)\tvoltage\n";

#[test]
fn binary_real_plot_reads_columns_by_name_in_any_case() {
    let mut f = header("real", 2, "3       ", TWO, "Binary:");
    f.extend(binary(&[0.0, 1.0, 1.0, 2.0, 2.0, 3.0]));
    let raw = RawFile::parse(&f).unwrap();
    let p = &raw.plots[0];
    assert_eq!(p.points(), 3);
    assert_eq!(p.real("V(OUT)").unwrap(), &[1.0, 2.0, 3.0]);
    assert_eq!(p.real("time").unwrap(), &[0.0, 1.0, 2.0]);
    assert!(raw.warnings.is_empty());
}

#[test]
fn killed_binary_run_reads_whole_points_and_warns() {
    let mut f = header("real", 2, "0       ", TWO, "Binary:");
    f.extend(binary(&[0.0, 1.0, 1.0, 2.0]));
    f.extend(&[1, 2, 3, 4, 5]); // a cut third point
    let raw = RawFile::parse(&f).unwrap();
    assert_eq!(raw.plots[0].points(), 2);
    assert!(matches!(
        raw.warnings[..],
        [RawWarning::Truncated {
            declared: 0,
            read: 2,
            ..
        }]
    ));
}

#[test]
fn header_only_failed_run_is_an_empty_plot_without_warning() {
    let f = header("real", 2, "0       ", TWO, "Binary:");
    let raw = RawFile::parse(&f).unwrap();
    assert_eq!(raw.plots[0].points(), 0);
    assert!(raw.warnings.is_empty());
}

#[test]
fn ascii_both_layouts_read_alike() {
    let batch = "0\t\t0.0e0\n\t1.5\n1\t\t1e-3\n\t2.5\n";
    let write = " 0\t0.0e0\n\t1.5\n\n 1\t1e-3\n\t2.5\n\n";
    for body in [batch, write] {
        let mut f = header("real", 2, "2", TWO, "Values:");
        f.extend(body.as_bytes());
        let raw = RawFile::parse(&f).unwrap();
        assert_eq!(raw.plots[0].real("v(out)").unwrap(), &[1.5, 2.5]);
    }
}

#[test]
fn ascii_complex_with_spaces_around_the_comma() {
    let vars = "\t0\tfrequency\tfrequency grid=3\n\t1\tv(out)\tvoltage\n";
    let mut f = header("complex", 2, "1", vars, "Values:");
    f.extend(b" 0\t1.0e2,7.0\n\t0.5 , -0.25\n");
    let raw = RawFile::parse(&f).unwrap();
    let p = &raw.plots[0];
    assert_eq!(p.real("frequency").unwrap(), &[100.0]);
    assert_eq!(p.complex("v(out)").unwrap(), &[Complex64::new(0.5, -0.25)]);
    assert_eq!(p.variables[0].attributes, vec!["grid=3".to_string()]);
}

#[test]
fn ascii_cut_mid_number_drops_the_point() {
    let mut f = header("real", 2, "0", TWO, "Values:");
    f.extend(b"0\t\t0.0\n\t1.5\n1\t\t1e-3\n\t2.5");
    let raw = RawFile::parse(&f).unwrap();
    assert_eq!(raw.plots[0].points(), 1);
    assert_eq!(raw.warnings.len(), 1);
}

#[test]
fn unpadded_short_vector_binary() {
    let vars = "\t0\ttime\ttime\n\t1\tx\tvoltage dims=1\n";
    let mut f = header("real unpadded", 2, "2", vars, "Binary:");
    f.extend(binary(&[0.0, 9.0, 1.0]));
    let raw = RawFile::parse(&f).unwrap();
    let p = &raw.plots[0];
    assert_eq!(p.real("time").unwrap(), &[0.0, 1.0]);
    assert_eq!(p.real("x").unwrap(), &[9.0]);
}

#[test]
fn errors_name_the_line() {
    let mut f = header("real", 2, "1", TWO, "Values:");
    f.extend(b"0\t\t0.0\n\tbogus\n");
    let err = RawFile::parse(&f).unwrap_err().to_string();
    assert!(err.contains("line 12"), "{err}");
    let err = RawFile::parse(b"Title: x\nNo. Points: many\n")
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 2") && err.contains("many"), "{err}");
}

#[test]
fn huge_claims_do_not_allocate() {
    let mut f = header("real", 2, "18446744073709551615", TWO, "Binary:");
    f.extend(binary(&[0.0, 1.0]));
    let raw = RawFile::parse(&f).unwrap();
    assert_eq!(raw.plots[0].points(), 1);
    assert_eq!(raw.warnings.len(), 1);
}

fn utf16(text: &str) -> Vec<u8> {
    text.encode_utf16().flat_map(|u| u.to_le_bytes()).collect()
}

/// An LTspice header (UTF-16) and `Binary:`, then `data`.
fn ltspice(flags: &str, points: usize, vars: &str, data: &[u8]) -> Vec<u8> {
    let nvars = vars.lines().count();
    let mut f = utf16(&format!(
        "Title: * x.asc\nDate: d\nPlotname: Transient Analysis\nFlags: {flags}\n\
         No. Variables: {nvars}\nNo. Points: {points:>12}\nOffset:    0.0e+00\n\
         Command: Linear Technology Corporation LTspice XVII\nVariables:\n{vars}Binary:\n"
    ));
    f.extend(data);
    f
}

/// A point of time (`f64`) and `f32` values.
fn point(t: f64, values: &[f32]) -> Vec<u8> {
    let mut b = t.to_le_bytes().to_vec();
    for v in values {
        b.extend(v.to_le_bytes());
    }
    b
}

#[test]
fn ltspice_utf16_binary_is_read_with_f32_values_and_unsigned_time() {
    let mut data = point(0.0, &[0.1]);
    data.extend(point(-1e-3, &[0.25])); // LTspice's sign bit on a time stamp
    let f = ltspice("real forward", 2, TWO, &data);
    let raw = RawFile::parse(&f).unwrap();
    let p = &raw.plots[0];
    assert_eq!(
        (p.dialect, p.encoding),
        (Dialect::Ltspice, Encoding::Utf16Le)
    );
    assert_eq!(p.real("time").unwrap(), &[0.0, 1e-3]);
    assert_eq!(p.real("v(out)").unwrap(), &[f64::from(0.1f32), 0.25]);
    assert_eq!(p.other_header_lines, vec!["Offset:    0.0e+00".to_string()]);
    assert!(raw.warnings.is_empty());
}

#[test]
fn utf16_offsets_map_back_across_characters_beyond_ascii() {
    // "aé𝛂\n": 1, 1 and 2 UTF-16 units; 1, 2 and 4 UTF-8 bytes.
    let t = ltspice::transcode(&utf16("aé𝛂\nb"), false);
    assert_eq!(t.text, "aé𝛂\nb".as_bytes());
    let cases = [(0, 0), (1, 2), (3, 4), (7, 8), (8, 10), (9, 12)];
    for (text, input) in cases {
        assert_eq!(t.input_offset(text), input, "text offset {text}");
    }
    // An odd last byte and a lone surrogate become U+FFFD.
    let mut odd = utf16("a");
    odd.extend([0x00, 0xd8, b'b', 0, 7]);
    assert_eq!(
        String::from_utf8(ltspice::transcode(&odd, false).text).unwrap(),
        "a\u{fffd}b\u{fffd}"
    );
}

#[test]
fn errors_in_a_utf16_header_name_the_input_byte() {
    let mut f = ltspice("real forward", 1, TWO, &point(0.0, &[1.0]));
    let text = String::from_utf16_lossy(
        &f.chunks_exact(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]))
            .collect::<Vec<_>>(),
    );
    // Line 5 is `No. Variables: 2`: make it unreadable.
    let at = text.find("No. Variables: 2").unwrap() + "No. Variables: ".len();
    f[2 * at] = b'x';
    let err = RawFile::parse(&f).unwrap_err().to_string();
    let line_start = 2 * text.find("No. Variables").unwrap();
    assert!(
        err.contains(&format!("line 5 (byte {line_start})")),
        "{err}"
    );
}

#[test]
fn a_big_endian_header_is_refused_with_a_reason() {
    let mut f = vec![0xfe, 0xff];
    f.extend("Title: x\n".encode_utf16().flat_map(|u| u.to_be_bytes()));
    let err = RawFile::parse(&f).unwrap_err().to_string();
    assert!(err.contains("big-endian"), "{err}");
}

#[test]
fn a_byte_order_mark_is_skipped() {
    let mut f = vec![0xff, 0xfe];
    f.extend(ltspice("real forward", 1, TWO, &point(0.5, &[2.0])));
    let raw = RawFile::parse(&f).unwrap();
    assert_eq!(raw.plots[0].real("time").unwrap(), &[0.5]);
}

#[test]
fn fastaccess_is_vector_after_vector() {
    let mut data = Vec::new();
    for t in [0.0f64, 1.0, 2.0] {
        data.extend(t.to_le_bytes());
    }
    for v in [5.0f32, 6.0, 7.0] {
        data.extend(v.to_le_bytes());
    }
    let f = ltspice("real forward fastaccess", 3, TWO, &data);
    let p = &RawFile::parse(&f).unwrap().plots[0];
    assert_eq!(p.real("time").unwrap(), &[0.0, 1.0, 2.0]);
    assert_eq!(p.real("v(out)").unwrap(), &[5.0, 6.0, 7.0]);
    // Cut short: the vectors cannot be told apart.
    let f = ltspice("real forward fastaccess", 3, TWO, &data[..30]);
    let err = RawFile::parse(&f).unwrap_err().to_string();
    assert!(
        err.contains("need 36 bytes") && err.contains("holds 30"),
        "{err}"
    );
}

#[test]
fn stepped_plot_is_one_plot_a_step() {
    let mut data = Vec::new();
    for (t, v) in [(0.0, 1.0), (1.0, 2.0), (0.0, 3.0), (-1.0, 4.0), (2.0, 5.0)] {
        data.extend(point(t, &[v]));
    }
    let f = ltspice("real forward stepped", 5, TWO, &data);
    let raw = RawFile::parse(&f).unwrap();
    assert_eq!(raw.plots.len(), 2);
    let steps: Vec<_> = raw.plots.iter().map(|p| p.step.unwrap()).collect();
    assert_eq!(
        steps,
        [
            Step {
                index: 0,
                count: 2,
                first_point: 0
            },
            Step {
                index: 1,
                count: 2,
                first_point: 2
            },
        ]
    );
    assert_eq!(raw.plots[1].real("time").unwrap(), &[0.0, 1.0, 2.0]);
    assert_eq!(raw.plots[1].real("v(out)").unwrap(), &[3.0, 4.0, 5.0]);
    assert_eq!(raw.plots[0].declared_points, 5);
}

#[test]
fn a_cut_ltspice_file_keeps_its_whole_points_and_says_where() {
    let mut data = point(0.0, &[1.0]);
    data.extend(point(1.0, &[2.0]));
    let f = ltspice("real forward stepped", 3, TWO, &data[..data.len() - 3]);
    let raw = RawFile::parse(&f).unwrap();
    assert_eq!(raw.plots[0].points(), 1);
    let offset = f.len() - (12 - 3);
    assert_eq!(
        raw.warnings,
        [RawWarning::Truncated {
            plot: 0,
            declared: 3,
            read: 1,
            offset
        }]
    );
}

#[test]
fn bytes_after_the_declared_points_are_a_warning() {
    let mut data = point(0.0, &[1.0]);
    data.extend([0u8; 12]);
    let f = ltspice("real forward", 1, TWO, &data);
    let raw = RawFile::parse(&f).unwrap();
    assert_eq!(raw.plots[0].points(), 1);
    assert_eq!(
        raw.warnings,
        [RawWarning::TrailingData {
            plot: 0,
            declared: 1,
            offset: f.len() - 12,
            bytes: 12
        }]
    );
}

#[test]
fn utf16_ascii_values_are_read() {
    let mut f = utf16(
        "Title: x\nDate: d\nPlotname: Transient Analysis\nFlags: real forward\n\
         No. Variables: 2\nNo. Points: 2\nVariables:\n\t0\ttime\ttime\n\t1\tV(ü)\tvoltage\n\
         Values:\n0\t\t0.0e+00\n\t1.5e+00\n1\t\t-2.0e-03\n\t2.5e+00\n",
    );
    let raw = RawFile::parse(&f).unwrap();
    let p = &raw.plots[0];
    assert_eq!(p.real("time").unwrap(), &[0.0, 2e-3]);
    assert_eq!(p.real("V(ü)").unwrap(), &[1.5, 2.5]);
    // A bad value is named by line and input byte.
    let at = f.len() - 2 * "2.5e+00\n".len();
    f[at] = b'x';
    let err = RawFile::parse(&f).unwrap_err().to_string();
    assert!(err.contains(&format!("line 14 (byte {at})")), "{err}");
}
