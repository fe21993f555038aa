//! Sweep throughput.
//!
//! `cargo bench --bench sweep`
//!
//! - `sweep/mechanics_only`: `sweep::run` with the mechanics alone on one
//!   thread, 10 000 samples of the default relay with three varied keys,
//!   CSV rows and summary included (written to memory). Target:
//!   ≥ 100 000 samples/s on one core.
//! - `sweep/draw_values`, `sweep/set_numbers`, `sweep/simulate`: the parts
//!   of one sample, to see where the time goes.
//! - `sweep_ngspice/jobs_1`, `jobs_2`: the whole `chatterspice sweep`
//!   process on real ngspice, 16 samples; target jobs_1/jobs_2 ≥ 1.8 on two
//!   cores. Needs ngspice (skipped with a note without it).

use std::hint::black_box;
use std::num::NonZeroUsize;
use std::path::Path;
use std::process::Command;

use chatterspice::scenario::{DEFAULT_SCENARIO_TOML, Scenario};
use chatterspice::simulate;
use chatterspice::spice::Ngspice;
use chatterspice::sweep::{self, NoProgress, Sampler, SweepMode, SweepOptions};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const VARY: &str = "[sweep.vary]\n\"mechanics.mass\" = 0.1\n\
                    \"surface.damping\" = { normal = 0.1 }\n\"mechanics.force\" = 0.2\n";

fn scenario() -> Scenario {
    let origin = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/sweep-bench.toml");
    Scenario::parse(&format!("{DEFAULT_SCENARIO_TOML}\n{VARY}"), &origin).unwrap()
}

fn mechanics(c: &mut Criterion) {
    let s = scenario();
    let samples = 10_000;
    let sampler = Sampler::new(&s, Some(samples), Some(1)).unwrap();
    let mut options = SweepOptions::new(SweepMode::Mechanics);
    options.jobs = NonZeroUsize::MIN;
    let mut group = c.benchmark_group("sweep");
    group.throughput(Throughput::Elements(samples));
    group.sample_size(20);
    group.bench_function("mechanics_only", |b| {
        b.iter(|| {
            let mut out = Vec::with_capacity(2 << 20);
            let collected = sweep::run(&s, &sampler, &options, &mut out, &NoProgress).unwrap();
            black_box(collected.summary(&sampler).unwrap());
            black_box(out)
        })
    });
    group.throughput(Throughput::Elements(1));
    group.sample_size(100);
    let mut values = vec![0.0; 3];
    let mut i = 0u64;
    group.bench_function("draw_values", |b| {
        b.iter(|| {
            i += 1;
            sampler.values(black_box(i), &mut values).unwrap();
            black_box(&values);
        })
    });
    let keys: Vec<&str> = sampler.keys().iter().map(String::as_str).collect();
    let mut work = s.clone();
    group.bench_function("set_numbers", |b| {
        b.iter(|| {
            i += 1;
            sampler.values(i, &mut values).unwrap();
            let pairs: Vec<(&str, f64)> =
                keys.iter().copied().zip(values.iter().copied()).collect();
            work.set_numbers(black_box(&pairs)).unwrap();
        })
    });
    let (m, surface, settings) = (s.mechanics().unwrap(), s.surface(), s.settings());
    group.bench_function("simulate", |b| {
        b.iter(|| black_box(simulate(black_box(&m), &surface, &settings).unwrap()))
    });
    group.finish();
}

fn ngspice(c: &mut Criterion) {
    if let Err(e) = Ngspice::find() {
        eprintln!("note: skipping the ngspice sweep benchmark: {e}");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let netlist = Path::new(env!("CARGO_MANIFEST_DIR")).join("netlists/mcu_input.cir");
    let text =
        DEFAULT_SCENARIO_TOML.replace("../netlists/mcu_input.cir", &netlist.to_string_lossy());
    let path = dir.path().join("relay.toml");
    std::fs::write(&path, format!("{text}\n{VARY}")).unwrap();
    let exe = env!("CARGO_BIN_EXE_chatterspice");
    let mut group = c.benchmark_group("sweep_ngspice");
    group.sample_size(10);
    group.throughput(Throughput::Elements(16));
    for jobs in ["1", "2"] {
        group.bench_function(format!("jobs_{jobs}"), |b| {
            b.iter(|| {
                let out = Command::new(exe)
                    .arg("sweep")
                    .arg(&path)
                    .args(["--samples", "16", "--force", "--jobs", jobs, "--out"])
                    .arg(dir.path().join("out"))
                    .output()
                    .unwrap();
                assert!(
                    out.status.success(),
                    "{}",
                    String::from_utf8_lossy(&out.stderr)
                );
            })
        });
    }
    group.finish();
}

criterion_group!(benches, mechanics, ngspice);
criterion_main!(benches);
