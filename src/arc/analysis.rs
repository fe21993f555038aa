//! Every arc and breakdown of a run, read back from its raw file.
//!
//! A sample is **arcing** when the contact is open, the arc state is on
//! and current flows; it is **breaking down** when the contact is open,
//! the state is off and the clamp conducts (more than
//! [`DISCHARGE_FRACTION`] of I_min): the gap
//! has reached its breakdown voltage with too little current to arc.
//! Consecutive samples of one kind are one event. Energies are ∫ |v·i| dt
//! of the contact voltage and the whole contact current over the event
//! (trapezoids on ngspice's own time points). The gap only dissipates;
//! the magnitude keeps ngspice's tolerance on the voltage (0.1 % of
//! 327 V is 0.3 V, thirty times the clamp's knee) from flipping the sign
//! of a few points of a discharge whose current the circuit rings
//! through zero.

use serde::Serialize;

use super::model::ArcModel;
use super::vectors::ArcVectors;
use crate::chatter::{Chatter, ContactState};
use crate::rawfile::{Plot, Vector};

/// A breakdown is a clamp current above this fraction of I_min while the
/// arc state is off. Below it is the knee of the clamp: a circuit that
/// drives the gap to within ~20 mV of its hold voltage (a 12 V supply
/// against silver's 12 V) leaks a few mA through it.
pub const DISCHARGE_FRACTION: f64 = 0.025;

/// s: events of one kind in one opening closer than this are one event
/// (an arc flickering at I_min, a discharge that collapses and restrikes).
pub const MERGE_GAP: f64 = 1e-6;

/// s, how long the arc element's own transient lasts after an arc or a
/// breakdown starts: ten times its slowest internal lag (the state's,
/// 100 ns). Within it the element's clamp settles onto the circuit, and
/// its current is the element's, not the circuit's.
pub const ELEMENT_SETTLE: f64 = 1e-6;

/// A, the largest |i| of samples `first..=last` that the circuit drives:
/// the current at the start (what flowed through the contact as it
/// separated) and every sample once [`ELEMENT_SETTLE`] has passed. On a
/// DC RL break that is the load current at separation.
fn settled_peak(time: &[f64], i: &[f64], first: usize, last: usize) -> f64 {
    let start = time[first];
    (first..=last)
        .filter(|&j| j == first || time[j] - start >= ELEMENT_SETTLE)
        .map(|j| i[j].abs())
        .fold(0.0f64, f64::max)
}

/// One arc.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArcEvent {
    /// Which operation (0-based): each break starts the next.
    pub operation: usize,
    /// `"bounce N"` (the N-th opening after the first make), `"break"`
    /// (the opening at release) or `"make"` (before the first make: a
    /// pre-strike as the gap closes).
    pub opening: String,
    /// s
    pub start: f64,
    /// s
    pub duration: f64,
    /// A, the largest |i| the circuit drives through the arc: the current
    /// at separation and the arc's current once the element's own
    /// transient ([`ELEMENT_SETTLE`]) is over.
    pub peak_current: f64,
    /// J, ∫ v·i dt.
    pub energy: f64,
    /// C, ∫ |i| dt.
    pub charge: f64,
    /// m, the gap when the arc ended.
    pub gap_at_end: f64,
    /// Why it ended: `current_below_i_min`, `contact_closed` (the bounce
    /// closed the contact under the arc) or `run_end` (still burning when
    /// the simulation stopped).
    pub ends: &'static str,
}

/// One breakdown of the open gap (the state off: the current too small
/// to arc).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Breakdown {
    /// Which operation (0-based), as [`ArcEvent::operation`].
    pub operation: usize,
    /// Which opening it happened in, as [`ArcEvent::opening`].
    pub opening: String,
    /// s
    pub start: f64,
    /// s
    pub duration: f64,
    /// V, the largest |v| across the gap.
    pub peak_voltage: f64,
    /// A, the largest |i|.
    pub peak_current: f64,
    /// J
    pub energy: f64,
    /// An arc followed at once (the discharge's current reached I_min).
    pub reignited: bool,
}

/// The totals over the run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArcTotals {
    /// The number of arcs.
    pub count: usize,
    /// J, all arcs.
    pub energy: f64,
    /// The number of breakdowns.
    pub breakdowns: usize,
    /// J, all breakdowns.
    pub breakdown_energy: f64,
    /// s, the longest arc.
    pub longest: f64,
    /// J, the most energy in one operation (arcs only): what
    /// `max_arc_energy` limits.
    pub max_operation_energy: f64,
    /// The most arcs in one operation: what `max_arc_count` limits.
    pub max_operation_count: usize,
    /// The arc still burning when the run ended, if one was: the contact
    /// did not break its load within the run (`null` when every arc went
    /// out or closed).
    pub still_burning: Option<StillBurning>,
}

/// An arc still burning when the run ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StillBurning {
    /// Which operation (0-based).
    pub operation: usize,
    /// Which opening, as [`ArcEvent::opening`].
    pub opening: String,
    /// s, when it started.
    pub start: f64,
    /// s, how long it had burned when the run ended: a lower bound on its
    /// duration.
    pub duration: f64,
    /// J, its energy so far: a lower bound.
    pub energy: f64,
    /// m, the gap when the run ended.
    pub gap: f64,
}

/// Arcs, breakdowns and totals of one run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArcReport {
    /// The arc model the run used.
    pub model: ArcModel,
    /// Every arc, in time order.
    pub arcs: Vec<ArcEvent>,
    /// Every breakdown, in time order.
    pub breakdowns: Vec<Breakdown>,
    /// Counts and energies over the run.
    pub totals: ArcTotals,
    /// V, the largest |v| across the contact over the run.
    pub peak_voltage: f64,
}

/// Why the arc vectors could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "the raw file has no vector `{vector}` (nor the same inside a subcircuit) for contact \
     instance `{instance}`, which the arc analysis reads: if the netlist has `.save` lines, \
     save everything in the contact's subcircuit, or instantiate the contact at the top level"
)]
pub struct MissingArcVector {
    /// The contact instance, e.g. `x1`.
    pub instance: String,
    /// The vector not found, e.g. `i(v.x1.vsense)`, or `time` when the
    /// plot has no real time scale.
    pub vector: String,
}

/// An opening of the contact and its label.
#[derive(Debug, Clone, PartialEq)]
struct Opening {
    start: f64,
    end: f64,
    label: String,
    operation: usize,
}

/// The openings of `chatter`, labelled. `coil_offs`: when the coil was
/// switched off (a closure followed by an opening after a coil-off is a
/// release: a break). Without a coil, only an opening that lasts to the
/// end of the record is a break.
fn openings(chatter: &Chatter, coil_offs: &[f64]) -> Vec<Opening> {
    let mut out = Vec::new();
    let mut operation = 0;
    let mut bounce = 0;
    let mut closed_since: Option<f64> = None;
    let last = chatter.intervals.len().saturating_sub(1);
    for (k, iv) in chatter.intervals.iter().enumerate() {
        match iv.state {
            ContactState::Closed => {
                closed_since.get_or_insert(iv.start);
            }
            ContactState::Open => {
                let label = match closed_since.take() {
                    None => "make".to_owned(),
                    Some(since) => {
                        let released = coil_offs.iter().any(|&t| t >= since && t <= iv.start)
                            || (coil_offs.is_empty() && k == last);
                        if released {
                            "break".to_owned()
                        } else {
                            bounce += 1;
                            format!("bounce {bounce}")
                        }
                    }
                };
                out.push(Opening {
                    start: iv.start,
                    end: iv.end,
                    label: label.clone(),
                    operation,
                });
                if label == "break" {
                    operation += 1;
                    bounce = 0;
                }
            }
        }
    }
    out
}

/// The opening an event starting at `t` belongs to.
fn opening_at(openings: &[Opening], t: f64) -> (usize, String) {
    openings
        .iter()
        .filter(|o| o.start <= t)
        .min_by(|a, b| {
            let da = if t <= a.end { 0.0 } else { t - a.end };
            let db = if t <= b.end { 0.0 } else { t - b.end };
            da.total_cmp(&db).then(b.start.total_cmp(&a.start))
        })
        .or_else(|| openings.first())
        .map_or((0, "make".to_owned()), |o| (o.operation, o.label.clone()))
}

/// The arc report of `plot`, whose contact instance `instance` (as the
/// netlist names it, e.g. `x1`) carried the arc element.
pub fn analyze(
    plot: &Plot,
    instance: &str,
    model: &ArcModel,
    gap: &super::gap::GapProfile,
    chatter: &Chatter,
    coil_offs: &[f64],
) -> Result<ArcReport, MissingArcVector> {
    let samples = Samples::of(plot, instance)?;
    let openings = openings(chatter, coil_offs);
    let runs = samples.runs(&openings, model);
    let (arcs, breakdowns) = samples.events(&runs, &openings, gap);
    let totals = totals(&arcs, &breakdowns);
    Ok(ArcReport {
        model: *model,
        arcs,
        breakdowns,
        totals,
        peak_voltage: samples.v[..samples.n]
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs())),
    })
}

/// What one sample of the open contact shows.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Quiet,
    Arc,
    Discharge,
}

/// A run of samples of one kind: (first, last, kind).
type Run = (usize, usize, Kind);

/// The vectors the analysis reads, over the points all of them have.
struct Samples<'a> {
    /// s
    time: &'a [f64],
    /// A, the contact current.
    i: &'a [f64],
    /// V, across the contact.
    v: &'a [f64],
    /// The arc state (≥ 0.5: on).
    st: &'a [f64],
    /// A, the clamp's current.
    ic: &'a [f64],
    /// The number of points every vector has.
    n: usize,
}

impl<'a> Samples<'a> {
    /// The arc vectors of contact instance `instance` in `plot`, or the
    /// first one missing.
    fn of(plot: &'a Plot, instance: &str) -> Result<Samples<'a>, MissingArcVector> {
        let vectors = ArcVectors::in_plot(instance, plot).ok_or_else(|| MissingArcVector {
            instance: instance.to_owned(),
            vector: ArcVectors::of(instance).current,
        })?;
        let real = |name: &str| {
            plot.real(name).ok_or_else(|| MissingArcVector {
                instance: instance.to_owned(),
                vector: name.to_owned(),
            })
        };
        let time = match plot.scale() {
            Some(Vector::Real(t)) => t,
            _ => {
                return Err(MissingArcVector {
                    instance: instance.to_owned(),
                    vector: "time".to_owned(),
                });
            }
        };
        let i = real(&vectors.current)?;
        let v = real(&vectors.voltage)?;
        let st = real(&vectors.state)?;
        let ic = real(&vectors.clamp)?;
        let n = time
            .len()
            .min(i.len())
            .min(v.len())
            .min(st.len())
            .min(ic.len());
        Ok(Samples {
            time,
            i,
            v,
            st,
            ic,
            n,
        })
    }

    /// The runs of arcing and of breaking-down samples, in time order:
    /// a single time point is no event, and flicker within one opening
    /// (gaps under [`MERGE_GAP`]) is one.
    fn runs(&self, openings: &[Opening], model: &ArcModel) -> Vec<Run> {
        let (time, i, st, ic, n) = (self.time, self.i, self.st, self.ic, self.n);
        // Only an open contact arcs or breaks down; while it is open the arc
        // state decides which. (The clamp's own current cannot: against a
        // capacitance across the contact, the trapezoidal rule makes it
        // alternate from one time point to the next about the circuit's
        // current, while its average, and the state, which sees it through a
        // lag, are right.)
        let kind = |k: usize| {
            if !is_open(openings, time[k]) {
                Kind::Quiet
            } else if st[k] >= 0.5 && ic[k].abs().max(i[k].abs()) > DISCHARGE_FRACTION * model.i_min
            {
                Kind::Arc
            } else if st[k] < 0.5 && ic[k].abs() > DISCHARGE_FRACTION * model.i_min {
                Kind::Discharge
            } else {
                Kind::Quiet
            }
        };

        let mut runs: Vec<Run> = Vec::new();
        let mut k = 0;
        while k < n {
            let this = kind(k);
            let first = k;
            while k + 1 < n && kind(k + 1) == this {
                k += 1;
            }
            // A single time point has no duration and no energy: ngspice
            // passing through the state, not an event.
            if this != Kind::Quiet && k > first {
                match runs.last_mut() {
                    // Flicker within one opening is one event.
                    Some(prev)
                        if prev.2 == this
                            && time[first] - time[prev.1] < MERGE_GAP
                            && opening_at(openings, time[first])
                                == opening_at(openings, time[prev.0]) =>
                    {
                        prev.1 = k;
                    }
                    _ => runs.push((first, k, this)),
                }
            }
            k += 1;
        }
        runs
    }

    /// Each run as an arc or a breakdown: its opening, duration, peaks
    /// and energy, and how it ended. The energy is the net ∫v·i into the
    /// gap (trapezoids of v·i, with v across the contact and i through it
    /// in the same sense): what a discharge puts into the gap and then
    /// gives back to the circuit (a gap that rings with its capacitance)
    /// is not counted twice. The gap is passive, so a net below zero is
    /// the integration's rounding over a discharge of a few samples, and
    /// counts as 0.
    fn events(
        &self,
        runs: &[Run],
        openings: &[Opening],
        gap: &super::gap::GapProfile,
    ) -> (Vec<ArcEvent>, Vec<Breakdown>) {
        let (time, i, v, n) = (self.time, self.i, self.v, self.n);
        let mut arcs = Vec::new();
        let mut breakdowns: Vec<Breakdown> = Vec::new();
        for (index, &(first, last, this)) in runs.iter().enumerate() {
            let (mut energy, mut charge) = (0.0, 0.0);
            for j in first..last {
                let dt = time[j + 1] - time[j];
                energy += 0.5 * (v[j] * i[j] + v[j + 1] * i[j + 1]) * dt;
                charge += 0.5 * (i[j].abs() + i[j + 1].abs()) * dt;
            }
            let energy = energy.max(0.0);
            let peak_current = settled_peak(time, i, first, last);
            let (start, end) = (time[first], time[last]);
            let (operation, opening) = opening_at(openings, start);
            match this {
                Kind::Arc => {
                    let ends = if last + 1 >= n {
                        "run_end"
                    } else if !is_open(openings, time[last + 1]) {
                        "contact_closed"
                    } else {
                        "current_below_i_min"
                    };
                    arcs.push(ArcEvent {
                        operation,
                        opening,
                        start,
                        duration: end - start,
                        peak_current,
                        energy,
                        charge,
                        gap_at_end: gap.at(end),
                        ends,
                    });
                }
                Kind::Discharge => {
                    let next = runs.get(index + 1);
                    let reignited = next.is_some_and(|&(f, _, kind)| {
                        kind == Kind::Arc && time[f] - end < MERGE_GAP
                    });
                    breakdowns.push(Breakdown {
                        operation,
                        opening,
                        start,
                        duration: end - start,
                        peak_voltage: v[first..=last].iter().fold(0.0f64, |m, x| m.max(x.abs())),
                        peak_current,
                        energy,
                        reignited,
                    });
                }
                Kind::Quiet => unreachable!("quiet runs are not kept"),
            }
        }
        (arcs, breakdowns)
    }
}

/// Whether the contact is open at `t` (s): inside one of `openings`.
fn is_open(openings: &[Opening], t: f64) -> bool {
    let k = openings.partition_point(|o| o.start <= t);
    k > 0 && t <= openings[k - 1].end
}

/// The counts and energies over the run, and the most of them in one
/// operation.
fn totals(arcs: &[ArcEvent], breakdowns: &[Breakdown]) -> ArcTotals {
    let operations = arcs.iter().map(|a| a.operation + 1).max().unwrap_or(0);
    let mut per_operation = vec![(0.0, 0usize); operations];
    for a in arcs {
        per_operation[a.operation].0 += a.energy;
        per_operation[a.operation].1 += 1;
    }
    ArcTotals {
        count: arcs.len(),
        energy: arcs.iter().map(|a| a.energy).fold(0.0, |s, e| s + e),
        breakdowns: breakdowns.len(),
        breakdown_energy: breakdowns.iter().map(|b| b.energy).fold(0.0, |s, e| s + e),
        longest: arcs.iter().map(|a| a.duration).fold(0.0, f64::max),
        max_operation_energy: per_operation.iter().map(|p| p.0).fold(0.0, f64::max),
        max_operation_count: per_operation.iter().map(|p| p.1).max().unwrap_or(0),
        still_burning: arcs
            .iter()
            .find(|a| a.ends == "run_end")
            .map(|a| StillBurning {
                operation: a.operation,
                opening: a.opening.clone(),
                start: a.start,
                duration: a.duration,
                energy: a.energy,
                gap: a.gap_at_end,
            }),
    }
}

/// For a run without `[arc]`: a warning when what the open contact saw
/// is not physical, i.e. when it separated under at least the reference
/// material's I_min and then saw more than its V_min (a real contact
/// arcs), or when an open gap saw more than its breakdown voltage.
/// `nodes` are the contact's terminal vectors (`v(a)`, `v(b)`; `None` for
/// ground); `None` when the run is physical or the vectors are missing.
pub fn unphysical_warning(
    plot: &Plot,
    nodes: (Option<&str>, Option<&str>),
    conductance: impl Fn(f64) -> f64,
    chatter: &Chatter,
    gap: &super::gap::GapProfile,
) -> Option<String> {
    let Some(Vector::Real(time)) = plot.scale() else {
        return None;
    };
    let zero = vec![0.0; time.len()];
    let node = |name: Option<&str>| match name {
        None => Some(zero.as_slice()),
        Some(n) => plot.real(n),
    };
    let (a, b) = (node(nodes.0)?, node(nodes.1)?);
    let v = |k: usize| a[k] - b[k];
    let material = super::model::REFERENCE_MATERIAL;
    let model = super::model::ArcSection {
        material: Some(material),
        ..super::model::ArcSection::default()
    }
    .model();
    let n = time.len().min(a.len()).min(b.len());
    let (mut arcs, mut breakdowns, mut worst_current, mut worst_excess) = (0, 0, 0.0f64, None);
    let mut closed_before = false;
    for iv in &chatter.intervals {
        if iv.state == ContactState::Closed {
            closed_before = true;
            continue;
        }
        let first = time.partition_point(|&t| t < iv.start);
        let last = time.partition_point(|&t| t <= iv.end).min(n);
        if first >= last {
            continue;
        }
        if closed_before && first > 0 {
            let k = first - 1;
            let current = (v(k) * conductance(time[k])).abs();
            let peak = (first..last).map(|k| v(k).abs()).fold(0.0, f64::max);
            if current >= model.i_min && peak >= model.v_min {
                arcs += 1;
                worst_current = worst_current.max(current);
            }
        }
        let mut broke = false;
        for (k, &t) in time.iter().enumerate().take(last).skip(first) {
            let g = gap.at(t);
            let hold = model.hold_voltage(g);
            if g > 0.0 && v(k).abs() > hold {
                broke = true;
                let excess = (v(k).abs(), g);
                if worst_excess.is_none_or(|(w, _): (f64, f64)| excess.0 > w) {
                    worst_excess = Some(excess);
                }
            }
        }
        breakdowns += usize::from(broke);
    }
    if arcs == 0 && breakdowns == 0 {
        return None;
    }
    let mut what = Vec::new();
    if arcs > 0 {
        what.push(format!(
            "{arcs} opening{} separated under up to {:.3} A and then saw more than {} V, \
             where a real contact arcs ({}: {} V, {} A)",
            if arcs == 1 { "" } else { "s" },
            worst_current,
            model.v_min,
            material.as_str(),
            model.v_min,
            model.i_min
        ));
    }
    if let Some((volts, g)) = worst_excess {
        what.push(format!(
            "{breakdowns} opening{} saw more than the gap's breakdown voltage (up to {:.0} V \
             across {:.3} µm, which breaks down at {:.0} V)",
            if breakdowns == 1 { "" } else { "s" },
            volts,
            g * 1e6,
            model.hold_voltage(g)
        ));
    }
    Some(format!(
        "the contact model does not arc, so this result is not physical: {}. \
         Add an [arc] section (e.g. material = \"Ag\") to simulate the arcs and breakdowns",
        what.join("; ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chatter::Interval;

    fn chatter(states: &[(ContactState, f64, f64)]) -> Chatter {
        Chatter::from_intervals(
            states
                .iter()
                .map(|&(state, start, end)| Interval { state, start, end })
                .collect(),
        )
    }

    #[test]
    fn openings_are_labelled_bounce_break_and_make() {
        use ContactState::{Closed, Open};
        let c = chatter(&[
            (Open, 0.0, 1.0),
            (Closed, 1.0, 2.0),
            (Open, 2.0, 2.1),
            (Closed, 2.1, 3.0),
            (Open, 3.0, 3.1),
            (Closed, 3.1, 10.0),
            (Open, 10.0, 20.0),
        ]);
        let labels: Vec<_> = openings(&c, &[])
            .into_iter()
            .map(|o| (o.label, o.operation))
            .collect();
        assert_eq!(
            labels,
            [
                ("make".to_owned(), 0),
                ("bounce 1".to_owned(), 0),
                ("bounce 2".to_owned(), 0),
                ("break".to_owned(), 0)
            ]
        );
        // With a coil: the opening after coil-off is the break, and the
        // next closing is operation 1.
        let c = chatter(&[
            (Open, 0.0, 1.0),
            (Closed, 1.0, 5.0),
            (Open, 5.0, 8.0),
            (Closed, 8.0, 8.5),
            (Open, 8.5, 8.6),
            (Closed, 8.6, 12.0),
            (Open, 12.0, 20.0),
        ]);
        let labels: Vec<_> = openings(&c, &[4.0, 11.0])
            .into_iter()
            .map(|o| (o.label, o.operation))
            .collect();
        assert_eq!(
            labels,
            [
                ("make".to_owned(), 0),
                ("break".to_owned(), 0),
                ("bounce 1".to_owned(), 1),
                ("break".to_owned(), 1)
            ]
        );
        assert_eq!(opening_at(&openings(&c, &[4.0, 11.0]), 8.55).1, "bounce 1");
    }
}
