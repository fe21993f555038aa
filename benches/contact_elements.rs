//! Whole-process benchmark of the contact elements: each run writes the
//! include and a deck, runs `ngspice -b -r` through the real runner and
//! times the process (wall clock). Prints Markdown tables for
//! `docs/contact-elements.md`.
//!
//! A plain timed program, not criterion: one 10 000-bounce PWL run takes
//! minutes, far beyond criterion's sampling.
//!
//! ```text
//! cargo bench --bench contact_elements                 # everything (~8 min)
//! cargo bench --bench contact_elements -- --quick      # 10 and 100 bounces
//! cargo bench --bench contact_elements -- --bounces 1000,10000 --elements event-ramp
//! cargo bench --bench contact_elements -- --only scaling|robustness|reading
//! ```
//!
//! The circuit: 3.3 V, 10 kΩ pull-up, 100 pF input, the contact to ground
//! (an MCU input read through a relay). Synthetic chatter: open to 100 µs,
//! then N bounces of 15 µs closed and 5 µs open, then closed for 100 µs;
//! `.tran 1u <end + 50 µs>` (TMAX = 1 µs).
//!
//! Besides the library's elements it measures `filesource`: an XSPICE
//! `filesource` reading `t G` rows into the same B-source, emitted here
//! because the library does not offer it (it sets no breakpoints, needs a
//! small TMAX, and rings; see the notes).

use std::time::{Duration, Instant};

use chatterspice::chatter::{ContactState, Interval};
use chatterspice::netlist::{
    ContactElement, DEFAULT_POINTS_PER_SOURCE, DeckRequest, contact_include_split, prepare_deck,
};
use chatterspice::spice::{Ngspice, RunRequest, Runner};
use chatterspice::waveform::{ContactModel, Waveform, format_time};

const NETLIST: &str = "Contact benchmark: 3.3 V pull-up, 10 k, 100 pF input, contact to ground
V1 vdd 0 DC 3.3
R1 vdd in 10k
C1 in 0 100p
X1 in 0 CONTACT
.tran 1u STOP
.end
";

/// A library element, or the XSPICE `filesource` measured for comparison.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Element {
    Lib(ContactElement),
    FileSource,
}

impl std::fmt::Display for Element {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Element::Lib(e) => write!(f, "{e}"),
            Element::FileSource => f.write_str("filesource"),
        }
    }
}

fn all_elements() -> Vec<Element> {
    let mut v: Vec<Element> = ContactElement::ALL
        .iter()
        .map(|&e| Element::Lib(e))
        .collect();
    v.push(Element::FileSource);
    v
}

fn parse_element(name: &str) -> Element {
    if name == "filesource" {
        Element::FileSource
    } else {
        Element::Lib(name.parse().expect("an element name"))
    }
}

struct Include {
    text: String,
    data_files: Vec<(String, String)>,
    points: usize,
    pwl_sources: usize,
    /// s, the TMAX the element needs.
    tmax: Option<f64>,
}

fn include(w: &Waveform, element: Element, per_source: usize) -> Include {
    match element {
        Element::Lib(e) => {
            let inc = contact_include_split(w, "CONTACT", e, per_source).expect("an include");
            Include {
                text: inc.text,
                data_files: inc.data_files,
                points: inc.points,
                pwl_sources: inc.pwl_sources,
                tmax: None,
            }
        }
        Element::FileSource => filesource_include(w),
    }
}

/// `t G` rows read by an XSPICE filesource into V(g). TMAX: half the
/// shortest span of two consecutive segments, so every plateau and every
/// opening gets a time point.
fn filesource_include(w: &Waveform) -> Include {
    let p = w.points();
    let mut data = String::new();
    for q in p {
        data.push_str(&format!(
            "{} {}\n",
            format_time(q.time),
            format_time(q.conductance)
        ));
    }
    // At the end of its file filesource drops its output to 0 V (measured,
    // ngspice 39); a row far beyond the stop time holds the last value.
    data.push_str(&format!(
        "1e9 {}\n",
        format_time(p[p.len() - 1].conductance)
    ));
    let text = ".subckt CONTACT a b
A1 %v([g]) contact_g
.model contact_g filesource (file=\"contact_g.txt\" amploffset=[0] amplscale=[1]
+ timeoffset=0 timescale=1 timerelative=false amplstep=false)
B1 a b I = V(a,b) * V(g)
.ends CONTACT
"
    .to_owned();
    Include {
        text,
        data_files: vec![("contact_g.txt".into(), data)],
        points: p.len(),
        pwl_sources: 0,
        tmax: p
            .windows(3)
            .map(|q| (q[2].time - q[0].time) / 2.0)
            .reduce(f64::min),
    }
}

struct Args {
    quick: bool,
    bounces: Vec<usize>,
    elements: Vec<Element>,
    only: Option<String>,
    repeat: usize,
}

fn args() -> Args {
    let mut a = Args {
        quick: false,
        bounces: vec![10, 100, 1000, 10000],
        elements: all_elements(),
        only: None,
        repeat: 3,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "--quick" => {
                a.quick = true;
                a.bounces = vec![10, 100];
            }
            "--bounces" => {
                a.bounces = it
                    .next()
                    .expect("--bounces 10,100")
                    .split(',')
                    .map(|n| n.parse().expect("a bounce count"))
                    .collect()
            }
            "--elements" => {
                a.elements = it
                    .next()
                    .expect("--elements pwl,event-ramp")
                    .split(',')
                    .map(parse_element)
                    .collect()
            }
            "--only" => a.only = it.next(),
            "--repeat" => a.repeat = it.next().expect("--repeat 3").parse().expect("a count"),
            _ => {} // cargo bench passes `--bench`
        }
    }
    a
}

fn chatter(bounces: usize, model: &ContactModel) -> Waveform {
    let mut ivs = vec![Interval {
        state: ContactState::Open,
        start: 0.0,
        end: 1e-4,
    }];
    let mut t = 1e-4;
    for _ in 0..bounces {
        for (state, d) in [(ContactState::Closed, 15e-6), (ContactState::Open, 5e-6)] {
            ivs.push(Interval {
                state,
                start: t,
                end: t + d,
            });
            t += d;
        }
    }
    ivs.push(Interval {
        state: ContactState::Closed,
        start: t,
        end: t + 1e-4,
    });
    Waveform::from_intervals(&ivs, model).expect("a valid chatter")
}

/// Closed `d`, open `d` for each `d` in `spans`, between an open start
/// at 100 µs and a closed end.
fn shrinking(spans: &[f64], model: &ContactModel) -> Waveform {
    let mut ivs = vec![Interval {
        state: ContactState::Open,
        start: 0.0,
        end: 1e-4,
    }];
    let mut t = 1e-4;
    for &d in spans {
        for state in [ContactState::Closed, ContactState::Open] {
            ivs.push(Interval {
                state,
                start: t,
                end: t + d,
            });
            t += d;
        }
    }
    ivs.push(Interval {
        state: ContactState::Closed,
        start: t,
        end: t + 1e-4,
    });
    Waveform::from_intervals(&ivs, model).expect("a valid chatter")
}

struct Outcome {
    wall: Duration,
    steps: usize,
    edges: usize,
    /// s, the largest delay from an edge's start in the waveform to the
    /// threshold crossing it causes.
    worst_delay: f64,
    /// V, the lowest and highest v(in): a 3.3 V pull-up stays within 0..3.3.
    v_range: (f64, f64),
    failure: Option<String>,
}

fn run(ng: &Ngspice, inc: &Include, w: &Waveform, stop: f64) -> Outcome {
    run_netlist(ng, inc, w, stop, NETLIST)
}

fn run_netlist(ng: &Ngspice, inc: &Include, w: &Waveform, stop: f64, netlist: &str) -> Outcome {
    let end = w.points()[w.points().len() - 1].time;
    let mut stop_text = format_time(stop);
    if let Some(tmax) = inc.tmax {
        stop_text = format!("{stop_text} 0 {}", format_time(tmax.min(1e-6)));
    }
    let netlist = netlist.replace("STOP", &stop_text);
    let deck = prepare_deck(&DeckRequest {
        netlist_text: &netlist,
        netlist_path: std::path::Path::new("bench.cir"),
        include_file_name: "contact.inc",
        subckt: "CONTACT",
        coil: None,
        probes: &["v(in)"],
        chatter_end: end.min(stop),
        stop_at_least: end.min(stop),
        options: &[],
    })
    .expect("the bench deck is valid");
    let mut req = RunRequest::new(deck.text);
    req.includes.push(("contact.inc".into(), inc.text.clone()));
    req.includes.extend(inc.data_files.iter().cloned());
    req.timeout = Duration::from_secs(3600);
    req.keep_workdir = std::env::var_os("BENCH_KEEP_WORKDIR").is_some();
    let started = Instant::now();
    match ng.run(&req) {
        Ok(out) => {
            let plot = out
                .raw
                .plot_named("transient analysis")
                .expect("a transient plot");
            let v = plot.real("v(in)").expect("v(in)");
            let time = plot.real("time").expect("time");
            let crossings = schmitt_crossings(time, v, 0.99, 2.31);
            let starts = edge_starts(w);
            let worst_delay = crossings
                .iter()
                .zip(&starts)
                .map(|(c, s)| c - s)
                .fold(0.0, f64::max);
            Outcome {
                wall: out.elapsed,
                steps: plot.points(),
                edges: crossings.len(),
                worst_delay,
                v_range: v
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                        (lo.min(x), hi.max(x))
                    }),
                failure: None,
            }
        }
        Err(e) => Outcome {
            wall: started.elapsed(),
            steps: 0,
            edges: 0,
            worst_delay: f64::NAN,
            v_range: (f64::NAN, f64::NAN),
            failure: Some(e.to_string().lines().next().unwrap_or("").to_owned()),
        },
    }
}

/// s, the times (interpolated) at which `v` crosses `low` going down or
/// `high` going up, alternately.
fn schmitt_crossings(time: &[f64], v: &[f64], low: f64, high: f64) -> Vec<f64> {
    let mut high_state = v[0] > (low + high) / 2.0;
    let mut out = Vec::new();
    for i in 1..v.len() {
        let threshold = if high_state { low } else { high };
        let crossed = if high_state { v[i] < low } else { v[i] > high };
        if crossed {
            let f = (threshold - v[i - 1]) / (v[i] - v[i - 1]);
            out.push(time[i - 1] + f * (time[i] - time[i - 1]));
            high_state = !high_state;
        }
    }
    out
}

/// s, where each edge of the waveform starts.
fn edge_starts(w: &Waveform) -> Vec<f64> {
    w.points()
        .windows(2)
        .filter(|p| p[0].conductance != p[1].conductance)
        .map(|p| p[0].time)
        .collect()
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

const MODEL: ContactModel = ContactModel {
    r_closed: 0.05,
    r_open: 1e9,
    edge_time: 1e-8,
};

fn main() {
    let a = args();
    let ng = Ngspice::find().expect("ngspice is needed for this benchmark");
    println!(
        "ngspice {}; {} run(s) per point below 1000 bounces, median wall time of the whole process\n",
        ng.version().unwrap_or("?"),
        a.repeat
    );
    let wants = |part: &str| a.only.as_deref().is_none_or(|o| o == part);

    if wants("scaling") {
        println!(
            "| element | bounces | points | PWL sources | ngspice wall (s) | time points | edges seen / expected |"
        );
        println!("|---|---:|---:|---:|---:|---:|---|");
        for &n in &a.bounces {
            let w = chatter(n, &MODEL);
            let stop = w.points()[w.points().len() - 1].time + 5e-5;
            for &element in &a.elements {
                let inc = include(&w, element, DEFAULT_POINTS_PER_SOURCE);
                let reps = if n >= 1000 { 1 } else { a.repeat };
                let outs: Vec<Outcome> = (0..reps).map(|_| run(&ng, &inc, &w, stop)).collect();
                let last = &outs[outs.len() - 1];
                let wall = median(outs.iter().map(|o| o.wall).collect());
                let edges = match &last.failure {
                    Some(f) => format!("failed: {f}"),
                    None => format!("{} / {}", last.edges, w.edge_count()),
                };
                println!(
                    "| {element} | {n} | {} | {} | {:.3} | {} | {edges} |",
                    inc.points,
                    inc.pwl_sources,
                    wall.as_secs_f64(),
                    last.steps
                );
            }
        }
        println!();
    }

    if wants("robustness") {
        let n = if a.quick { 10 } else { 100 };
        println!("Robustness, {n} bounces:\n");
        println!(
            "| element | r_closed (Ω) | r_open (Ω) | ngspice wall (s) | edges seen / expected |"
        );
        println!("|---|---:|---:|---:|---|");
        for (r_closed, r_open) in [(1e-3, 1e9), (0.05, 1e9), (1.0, 1e6)] {
            let model = ContactModel {
                r_closed,
                r_open,
                ..MODEL
            };
            let w = chatter(n, &model);
            let stop = w.points()[w.points().len() - 1].time + 5e-5;
            for &element in &a.elements {
                let inc = include(&w, element, DEFAULT_POINTS_PER_SOURCE);
                let o = run(&ng, &inc, &w, stop);
                let edges = match &o.failure {
                    Some(f) => format!("failed: {f}"),
                    None => format!("{} / {}", o.edges, w.edge_count()),
                };
                println!(
                    "| {element} | {} | {} | {:.3} | {edges} |",
                    format_time(r_closed),
                    format_time(r_open),
                    o.wall.as_secs_f64()
                );
            }
        }
        println!();
    }

    if wants("accuracy") {
        // Bounces shrinking to 30 ns openings; a 0.1 pF input (RC = 1 ns)
        // so that the circuit itself resolves every one.
        let spans = [
            40e-6, 20e-6, 8e-6, 3e-6, 1e-6, 400e-9, 200e-9, 100e-9, 60e-9, 30e-9,
        ];
        let w = shrinking(&spans, &MODEL);
        let stop = w.points()[w.points().len() - 1].time + 5e-5;
        println!(
            "Accuracy: {} bounces shrinking from 40 µs to 30 ns (closed and open alike), \
             10 ns edges, 0.1 pF input:\n",
            spans.len()
        );
        println!(
            "| element | ngspice wall (s) | time points | edges seen / expected | worst edge delay (ns) | v(in) range (V) |"
        );
        println!("|---|---:|---:|---|---:|---|");
        for &element in &a.elements {
            let inc = include(&w, element, DEFAULT_POINTS_PER_SOURCE);
            let o = run_netlist(&ng, &inc, &w, stop, &NETLIST.replace("100p", "0.1p"));
            let edges = match &o.failure {
                Some(f) => format!("failed: {f}"),
                None => format!("{} / {}", o.edges, w.edge_count()),
            };
            let delay = if o.edges == w.edge_count() {
                format!("{:.1}", o.worst_delay * 1e9)
            } else {
                "-".to_owned()
            };
            println!(
                "| {element} | {:.3} | {} | {edges} | {delay} | {:.3} to {:.3} |",
                o.wall.as_secs_f64(),
                o.steps,
                o.v_range.0,
                o.v_range.1
            );
        }
        println!();
    }

    if wants("reading") && !a.quick {
        // The deck-reading cost alone: the same include, a 1 µs analysis.
        println!("Reading the include (a 1 µs analysis, so the run itself is negligible):\n");
        println!("| bounces | points | PWL sources | ngspice wall (s) |");
        println!("|---:|---:|---:|---:|");
        for n in [1000, 10000] {
            let w = chatter(n, &MODEL);
            for per_source in [usize::MAX, DEFAULT_POINTS_PER_SOURCE] {
                let inc = include(&w, Element::Lib(ContactElement::Pwl), per_source);
                let walls: Vec<Duration> = (0..a.repeat)
                    .map(|_| run(&ng, &inc, &w, 1e-6).wall)
                    .collect();
                println!(
                    "| {n} | {} | {} | {:.3} |",
                    inc.points,
                    inc.pwl_sources,
                    median(walls).as_secs_f64()
                );
            }
        }
        println!();
    }

    if wants("split") && !a.quick {
        // Whether the split changes the run time (it should not, see notes).
        println!("PWL run time, one source against windows:\n");
        println!("| bounces | PWL sources | ngspice wall (s) | edges seen / expected |");
        println!("|---:|---:|---:|---|");
        for n in [500, 1000, 2000] {
            let w = chatter(n, &MODEL);
            let stop = w.points()[w.points().len() - 1].time + 5e-5;
            for per_source in [usize::MAX, DEFAULT_POINTS_PER_SOURCE] {
                let inc = include(&w, Element::Lib(ContactElement::Pwl), per_source);
                let o = run(&ng, &inc, &w, stop);
                println!(
                    "| {n} | {} | {:.3} | {} / {} |",
                    inc.pwl_sources,
                    o.wall.as_secs_f64(),
                    o.edges,
                    w.edge_count()
                );
            }
        }
    }
}
