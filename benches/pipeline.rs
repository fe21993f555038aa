//! The tool's own cost on the default `run`, against the whole process.
//!
//! `cargo bench --bench pipeline`
//!
//! - `pipeline/default_without_ngspice`: the whole pipeline on the built-in
//!   default (mechanics, contact include, deck, reading two raw files,
//!   analysis, and rendering the table) with a fake
//!   runner serving the raw files ngspice wrote for this very run: every
//!   cost but ngspice's.
//! - `pipeline/out_files`: making the files of `--out` (CSV, SVG, JSON)
//!   from a finished run, which only `--out` pays for.
//! - `pipeline/default_process`: `chatterspice run` as a user starts it,
//!   ngspice included.
//!
//! The overhead target is the first at most 5 % of the second.
//! Needs ngspice (once, to record the raw files, and for the process).

use std::hint::black_box;
use std::process::Command;

use chatterspice::mechanics::Dimensionless;
use chatterspice::pipeline::{self, RunOptions};
use chatterspice::report;
use chatterspice::scenario::Scenario;
use chatterspice::spice::{FakeRunner, Ngspice};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let scenario = Scenario::builtin_default();
    let ngspice = Ngspice::find().expect("this benchmark needs ngspice");
    let recorded = pipeline::run(
        &scenario,
        &ngspice,
        &RunOptions {
            keep_workdir: true,
            ..RunOptions::default()
        },
    )
    .expect("the default run succeeds");
    let raw_of = |sim: &pipeline::Simulation| {
        sim.workdir
            .as_ref()
            .expect("work directory kept")
            .join("out.raw")
    };
    let ideal = recorded
        .ideal
        .as_ref()
        .expect("the default has an ideal run");
    // Both runs get the bounced run's raw file: the two decks differ only
    // in the include, which the fake does not see, and the two raw files
    // are of a size.
    let fake = FakeRunner::serving(raw_of(&recorded.simulation));
    let dimensionless = Dimensionless::of(&scenario.mechanics().unwrap(), &scenario.surface());

    let mut group = c.benchmark_group("pipeline");
    group.bench_function("default_without_ngspice", |b| {
        b.iter(|| {
            let run = pipeline::run(black_box(&scenario), &fake, &RunOptions::default()).unwrap();
            black_box(report::table::render_run(&run))
        })
    });
    let run = pipeline::run(&scenario, &fake, &RunOptions::default()).unwrap();
    group.bench_function("out_files", |b| {
        b.iter(|| {
            black_box(report::bundle::run_files(
                black_box(&run),
                Some(&dimensionless),
            ))
        })
    });
    let exe = env!("CARGO_BIN_EXE_chatterspice");
    group.sample_size(20);
    group.bench_function("default_process", |b| {
        b.iter(|| {
            let out = Command::new(exe).arg("run").output().unwrap();
            assert!(out.status.success());
            black_box(out.stdout)
        })
    });
    group.finish();

    for sim in [&recorded.simulation, ideal] {
        let _ = std::fs::remove_dir_all(sim.workdir.as_ref().unwrap());
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
