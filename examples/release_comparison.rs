//! The release of one relay in two drivers: a plain flyback diode
//! (examples/scenarios/relay-driver.toml) and a diode + 24 V zener clamp
//! (relay-driver-zener.toml). Both run coupled to ngspice over the whole
//! cycle; this prints each operation's timing as a Markdown table and
//! draws the coil current and the armature of both to an SVG.
//!
//!     cargo run --release --example release_comparison [-- OUT.svg]
//!
//! The README's figures and docs/release.svg come from this program.

use std::error::Error;
use std::path::{Path, PathBuf};

use chatterspice::analysis::{Direction, Edge};
use chatterspice::pipeline::{Coupled, CouplingOptions, run_coupled};
use chatterspice::report::svg::{self, ProbePanel, Series, SvgPlot};
use chatterspice::scenario::Scenario;
use chatterspice::spice::Ngspice;

fn main() -> Result<(), Box<dyn Error>> {
    let out = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from("release.svg"), PathBuf::from);
    let ngspice = Ngspice::find()?;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios");
    let mut runs = Vec::new();
    for (label, file) in [
        ("diode", "relay-driver.toml"),
        ("diode + zener", "relay-driver-zener.toml"),
    ] {
        let scenario = Scenario::load(&root.join(file))?;
        let run = run_coupled(&scenario, &ngspice, &CouplingOptions::default())?;
        runs.push((label, scenario, run));
    }

    println!(
        "| driver | operate | closed for good | bounces | release | NC make | NC bounces | NC bounce time | ngspice runs |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let ms = |t: Option<f64>| t.map_or_else(|| "-".to_owned(), |t| format!("{:.3} ms", t * 1e3));
    for (label, _, run) in &runs {
        for op in &run.operations {
            println!(
                "| {label} | {} | {} | {} | {} | {} | {} | {} | {} |",
                ms(op.operate_time),
                ms(op.settle_time),
                op.stroke.bounces,
                ms(op.release_time),
                ms(op.nc_make_time),
                op.stroke.back_bounces,
                ms(op.nc_bounce_time),
                run.iterations.len(),
            );
        }
    }

    let series: Vec<Traces> = runs.iter().map(|(_, _, run)| Traces::of(run)).collect();
    let mut panels = Vec::new();
    for ((label, scenario, run), traces) in runs.iter().zip(&series) {
        // The current below which the pull no longer holds the closed
        // contact: ½ i² L'(g) = p + s·g.
        let coil = scenario.coil.as_ref().expect("a coil scenario");
        let m = &scenario.mechanics;
        let k = chatterspice::coil::MU0 * f64::from(coil.turns).powi(2) * coil.pole_area;
        let gap = coil.air_gap + coil.iron_gap - m.gap;
        let hold = gap * (2.0 * (m.preload + m.stiffness * m.gap) / k).sqrt();
        let marks = |t: Option<f64>| {
            t.map(|time| Edge {
                time,
                direction: Direction::Falling,
                width: None,
            })
            .into_iter()
            .collect::<Vec<_>>()
        };
        let op = run.operations.first();
        panels.push(ProbePanel {
            name: format!("{label}: coil current (threshold: the hold current)"),
            unit: "A".to_owned(),
            series: Series {
                time: &traces.time,
                value: &traces.current,
            },
            low: hold,
            high: hold,
            edges: marks(op.and_then(|o| o.stroke.break_time)),
        });
        panels.push(ProbePanel {
            name: format!("{label}: armature (m; the rest stop and the contact)"),
            unit: "m".to_owned(),
            series: Series {
                time: &traces.path_time,
                value: &traces.path_x,
            },
            low: 0.0,
            high: m.gap,
            edges: marks(op.and_then(|o| o.stroke.back_make)),
        });
    }
    let plot = SvgPlot {
        title: "Release: flyback diode vs diode + 24 V zener, coil off at 20 ms".to_owned(),
        window: (0.0, runs[0].1.simulation.t_end),
        // Each driver's contact differs: the panels mark their own break.
        contact: None,
        probes: panels,
        arcs: Vec::new(),
        pole_face: Vec::new(),
    };
    std::fs::write(&out, svg::render(&plot)?)?;
    eprintln!("wrote {}", out.display());
    Ok(())
}

/// A run's samples, split into the columns the plot takes.
struct Traces {
    time: Vec<f64>,
    current: Vec<f64>,
    path_time: Vec<f64>,
    path_x: Vec<f64>,
}

impl Traces {
    fn of(run: &Coupled) -> Traces {
        let (time, current) = run.current().into_iter().unzip();
        let (path_time, path_x) = run.path.iter().copied().unzip();
        Traces {
            time,
            current,
            path_time,
            path_x,
        }
    }
}
