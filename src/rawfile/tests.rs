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

#[test]
fn ltspice_utf16_is_refused_with_a_reason() {
    let utf16: Vec<u8> = "Title: * x\n"
        .encode_utf16()
        .flat_map(|u| u.to_le_bytes())
        .collect();
    let err = RawFile::parse(&utf16).unwrap_err().to_string();
    assert!(err.contains("LTspice"), "{err}");
}
