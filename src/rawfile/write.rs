//! Writing a plot back out as an ngspice binary raw file, as ngspice's own
//! `write` command lays it out: the header lines, `Binary:`, then each time
//! point's values one after the other as little-endian `f64` (pairs for a
//! complex plot). `run --out` keeps its runs' plots this way, so that any
//! raw reader (ngspice's own `load`, spicelib, this crate's) opens them.

use super::types::{Plot, Vector};

/// The plot as an ngspice binary raw file: every vector at every point, the
/// header's title, date, plot name, flags and variables as read.
pub fn to_binary(plot: &Plot) -> Vec<u8> {
    let complex = plot.flags.complex;
    let points = plot.points();
    let mut out = String::new();
    out += &format!("Title: {}\n", plot.title);
    out += &format!("Date: {}\n", plot.date);
    out += &format!("Plotname: {}\n", plot.name);
    out += &format!("Flags: {}\n", if complex { "complex" } else { "real" });
    out += &format!("No. Variables: {}\n", plot.variables.len());
    out += &format!("No. Points: {points}\n");
    for c in &plot.commands {
        out += &format!("Command: {c}\n");
    }
    out += "Variables:\n";
    for (i, v) in plot.variables.iter().enumerate() {
        out += &format!("\t{i}\t{}\t{}", v.name, v.kind);
        for a in &v.attributes {
            out += &format!(" {a}");
        }
        out += "\n";
    }
    out += "Binary:\n";
    let mut bytes = out.into_bytes();
    let width = if complex { 16 } else { 8 };
    bytes.reserve(points * plot.variables.len() * width);
    let vectors: Vec<Option<Vector<'_>>> =
        (0..plot.variables.len()).map(|i| plot.vector(i)).collect();
    for p in 0..points {
        for v in &vectors {
            let (re, im) = match v {
                Some(Vector::Real(x)) => (x.get(p).copied().unwrap_or(f64::NAN), 0.0),
                Some(Vector::Complex(x)) => x.get(p).map_or((f64::NAN, 0.0), |c| (c.re, c.im)),
                None => (f64::NAN, 0.0),
            };
            bytes.extend_from_slice(&re.to_le_bytes());
            if complex {
                bytes.extend_from_slice(&im.to_le_bytes());
            }
        }
    }
    bytes
}

#[cfg(test)]
#[path = "write_tests.rs"]
mod tests;
