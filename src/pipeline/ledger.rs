//! The energy ledger of a run: what the circuit's independent sources
//! delivered, what its inductors and capacitors held at the start and the
//! end, what its resistors, the contact's arcs and the gap's breakdowns
//! took, and the rest (diodes, switches, the closed contact, the coil).
//! Energy is conserved, so arcs and breakdowns can never take more than
//! the sources delivered and the stores gave back: a run that says they
//! did is an error, not a result.

use serde::Serialize;

use crate::arc::ArcReport;
use crate::netlist::elements::{Element, Elements};
use crate::rawfile::{Plot, Vector};

/// How much more than the circuit gave the arcs and breakdowns may take
/// before the run is refused, relative to the energy that went round: the
/// integration of sampled waveforms, not physics.
pub const TOLERANCE: f64 = 0.05;

/// J, the same in absolute terms (a run that moves microjoules).
pub const TOLERANCE_ABSOLUTE: f64 = 1e-6;

/// What one independent source delivered.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceEnergy {
    /// The source, as ngspice names it (lower case).
    pub name: String,
    /// J, net ∫ p dt delivered into the circuit (negative: it absorbed).
    pub delivered: f64,
}

/// A run's energy ledger (J throughout).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EnergyLedger {
    /// Each independent source at the deck's top level.
    pub sources: Vec<SourceEnergy>,
    /// All of them together.
    pub delivered: f64,
    /// ½LI² and ½CV² of the top-level inductors and capacitors at the
    /// run's start.
    pub stored_start: f64,
    /// The same at its end.
    pub stored_end: f64,
    /// Taken by the top-level resistors, ∫ v²/R dt (`null`: a resistor's
    /// value is not a plain number).
    pub resistors: Option<f64>,
    /// Taken by the contact's arcs (net), as `arc_totals.energy`.
    pub arcs: f64,
    /// Taken by the gap's breakdowns (net).
    pub breakdowns: f64,
    /// The rest: delivered + stored_start − stored_end − resistors − arcs
    /// − breakdowns, taken by everything else (semiconductors, switches,
    /// the closed contact, the coil and its relay).
    pub elsewhere: Option<f64>,
    /// Elements the ledger does not account for (a controlled source, a
    /// subcircuit with a source of its own, a vector the run did not
    /// save); empty when the ledger is complete and the balance was
    /// checked.
    pub unaccounted: Vec<String>,
}

impl EnergyLedger {
    /// Whether every element that can deliver energy is in the ledger.
    pub fn complete(&self) -> bool {
        self.unaccounted.is_empty()
    }

    /// What the arcs and breakdowns took beyond what the circuit gave,
    /// past the tolerance, when the ledger is complete: the reason the
    /// run is not a result.
    pub fn violation(&self) -> Option<String> {
        let given = self.delivered + self.stored_start - self.stored_end;
        let taken = self.arcs + self.breakdowns;
        let scale = self.delivered.abs() + self.stored_start + self.stored_end;
        (self.complete() && taken > given + TOLERANCE * scale + TOLERANCE_ABSOLUTE).then(|| {
            format!(
                "the arcs ({:.4e} J) and breakdowns ({:.4e} J) take more than the circuit gave \
                 ({:.4e} J delivered by its sources, {:.4e} J from its stores): the contact's \
                 energy does not add up, a numerical artefact of this run, not a result; try \
                 `.options method=gear` and a smaller `.tran` step",
                self.arcs,
                self.breakdowns,
                self.delivered,
                self.stored_start - self.stored_end
            )
        })
    }
}

/// The ledger of `plot` over the deck's top level `elements`, with the
/// arcs and breakdowns of `arcs`.
pub fn ledger(plot: &Plot, elements: &Elements, arcs: Option<&ArcReport>) -> EnergyLedger {
    let mut unaccounted = elements.unaccounted.clone();
    let time: &[f64] = match plot.scale() {
        Some(Vector::Real(t)) => t,
        _ => &[],
    };
    let zero = vec![0.0; time.len()];
    let mut missing = |what: String| {
        if !unaccounted.contains(&what) {
            unaccounted.push(what);
        }
    };
    let node = |name: &str| -> Option<&[f64]> {
        if name == "0" || name.eq_ignore_ascii_case("gnd") {
            Some(&zero)
        } else {
            plot.real(&format!("v({name})"))
        }
    };
    let branch = |name: &str| {
        plot.real(&format!("i({name})"))
            .or_else(|| plot.real(&format!("{name}#branch")))
    };
    let across = |e: &Element| -> Option<Vec<f64>> {
        let (a, b) = (node(&e.nodes[0])?, node(&e.nodes[1])?);
        Some(a.iter().zip(b).map(|(x, y)| x - y).collect())
    };

    let mut sources = Vec::new();
    let (mut start, mut end) = (0.0, 0.0);
    let mut resistors = Some(0.0);
    for e in &elements.elements {
        match e.kind {
            'V' => match (across(e), branch(&e.name)) {
                // ngspice's current through a source flows from its +
                // node through it: delivered power is −v·i.
                (Some(v), Some(i)) => sources.push(SourceEnergy {
                    name: e.name.clone(),
                    delivered: -integral(time, |k| v[k] * i[k]),
                }),
                _ => missing(format!("{} (its voltage or current is not saved)", e.name)),
            },
            'I' => missing(format!("{} (a current source)", e.name)),
            'R' => match (across(e), e.value) {
                (Some(v), Some(r)) if r > 0.0 => {
                    if let Some(total) = resistors.as_mut() {
                        *total += integral(time, |k| v[k] * v[k] / r);
                    }
                }
                (None, _) => {
                    missing(format!("{} (its nodes are not saved)", e.name));
                    resistors = None;
                }
                _ => resistors = None,
            },
            'L' => match (branch(&e.name), e.value) {
                (Some(i), Some(l)) if !i.is_empty() => {
                    start += 0.5 * l * i[0] * i[0];
                    end += 0.5 * l * i[i.len() - 1] * i[i.len() - 1];
                }
                _ => missing(format!(
                    "{} (its current is not saved, or its value is not a number)",
                    e.name
                )),
            },
            'C' => match (across(e), e.value) {
                (Some(v), Some(c)) if !v.is_empty() => {
                    start += 0.5 * c * v[0] * v[0];
                    end += 0.5 * c * v[v.len() - 1] * v[v.len() - 1];
                }
                _ => missing(format!(
                    "{} (its nodes are not saved, or its value is not a number)",
                    e.name
                )),
            },
            _ => {}
        }
    }
    let delivered = sources.iter().map(|s| s.delivered).sum::<f64>();
    let (arc_energy, breakdowns) =
        arcs.map_or((0.0, 0.0), |a| (a.totals.energy, a.totals.breakdown_energy));
    EnergyLedger {
        elsewhere: resistors.map(|r| delivered + start - end - r - arc_energy - breakdowns),
        sources,
        delivered,
        stored_start: start,
        stored_end: end,
        resistors,
        arcs: arc_energy,
        breakdowns,
        unaccounted,
    }
}

/// ∫ f dt over the samples `time` by the trapezoidal rule.
fn integral(time: &[f64], f: impl Fn(usize) -> f64) -> f64 {
    (1..time.len())
        .map(|k| 0.5 * (f(k) + f(k - 1)) * (time[k] - time[k - 1]))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ledger_of(delivered: f64, start: f64, end: f64, arcs: f64, breakdowns: f64) -> EnergyLedger {
        EnergyLedger {
            sources: vec![SourceEnergy {
                name: "v1".into(),
                delivered,
            }],
            delivered,
            stored_start: start,
            stored_end: end,
            resistors: Some(0.0),
            arcs,
            breakdowns,
            elsewhere: Some(delivered + start - end - arcs - breakdowns),
            unaccounted: Vec::new(),
        }
    }

    #[test]
    fn arcs_may_take_what_the_sources_and_stores_gave_and_no_more() {
        // An inductor's 0.8 mJ and nothing delivered: 0.8 mJ may go.
        assert!(
            ledger_of(0.0, 0.8e-3, 0.0, 0.5e-3, 0.3e-3)
                .violation()
                .is_none()
        );
        // 3.55 mJ of breakdowns from 0.8 mJ is refused, and says why.
        let why = ledger_of(0.0, 0.8e-3, 0.0, 0.0, 3.55e-3)
            .violation()
            .unwrap();
        assert!(
            why.contains("breakdowns") && why.contains("not a result"),
            "{why}"
        );
        // Within the tolerance: sampling, not physics.
        assert!(ledger_of(1.0, 0.0, 0.0, 1.04, 0.0).violation().is_none());
        assert!(ledger_of(1.0, 0.0, 0.0, 1.06, 0.0).violation().is_some());
        // A ledger that does not know every source never refuses.
        let mut open = ledger_of(0.0, 0.0, 0.0, 1.0, 0.0);
        open.unaccounted.push("e1 (a controlled source)".into());
        assert!(open.violation().is_none());
    }
}
