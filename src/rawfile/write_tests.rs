//! The tests of `write.rs`: in a file of their own, so that the
//! checkout's test data they name stays out of the module's code.

use super::*;
use crate::rawfile::RawFile;

#[test]
fn a_written_plot_reads_back_value_for_value() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/raw");
    for name in ["rc_tran.raw", "rc_ac.raw", "rc_tran_ascii.raw"] {
        let file = RawFile::read(dir.join(name)).unwrap();
        let plot = &file.plots[0];
        let again = RawFile::parse(&to_binary(plot)).unwrap();
        let back = &again.plots[0];
        assert_eq!(back.name, plot.name, "{name}");
        assert_eq!(back.points(), plot.points(), "{name}");
        assert_eq!(back.variables, plot.variables, "{name}");
        for i in 0..plot.variables.len() {
            assert_eq!(back.vector(i), plot.vector(i), "{name}: vector {i}");
        }
    }
}
