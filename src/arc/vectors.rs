//! The names of the vectors the arc element gives ngspice's raw file, for
//! the arc analysis to read. The element (in the netlist room) names its
//! nodes and sources to match: `vsense` senses the contact current, `va`
//! copies the contact voltage, `st` is the arc state and `vclamp` senses
//! the clamp's current.

/// The vectors the arc analysis reads for contact instance `instance`
/// (e.g. `x1`, lowercase as ngspice names it).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArcVectors {
    /// The whole contact current, a → b.
    pub current: String,
    /// The contact voltage v(a, b).
    pub voltage: String,
    /// The arc state, 0..1.
    pub state: String,
    /// The clamp's (arc or breakdown) current.
    pub clamp: String,
}

impl ArcVectors {
    /// The vectors of `instance` at the top level of the netlist.
    pub fn of(instance: &str) -> ArcVectors {
        ArcVectors {
            current: format!("i(v.{instance}.vsense)"),
            voltage: format!("v({instance}.va)"),
            state: format!("v({instance}.st)"),
            clamp: format!("i(v.{instance}.vclamp)"),
        }
    }

    /// The four names: current, voltage, state, clamp.
    pub fn all(&self) -> [&str; 4] {
        [&self.current, &self.voltage, &self.state, &self.clamp]
    }

    /// The vectors of `instance` as `plot` names them: at the top level
    /// (`i(v.x1.vsense)`), or inside the user's own subcircuits, where ngspice
    /// prefixes the path (`i(v.x_board.x1.vsense)`; the first such path in
    /// the raw file's order). `None` when the plot has no complete set.
    pub fn in_plot(instance: &str, plot: &crate::rawfile::Plot) -> Option<ArcVectors> {
        let complete = |v: &ArcVectors| v.all().iter().all(|n| plot.index_of(n).is_some());
        let top = ArcVectors::of(instance);
        if complete(&top) {
            return Some(top);
        }
        let suffix = format!(".{}", instance.to_ascii_lowercase());
        plot.variables
            .iter()
            .filter_map(|v| {
                let name = v.name.to_ascii_lowercase();
                let path = name
                    .strip_prefix("i(v.")?
                    .strip_suffix(".vsense)")?
                    .to_owned();
                path.ends_with(&suffix).then_some(path)
            })
            .map(|path| ArcVectors::of(&path))
            .find(complete)
    }
}
