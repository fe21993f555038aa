//! The fit's speed: a record of at most 10 events (the assertion below
//! checks), plus one spurious glitch pair, fitted in 4 free keys from a prior 1.6–2×
//! off in each. `cargo bench --bench fit`. Target: ≤ 2 s on one core.

use std::hint::black_box;
use std::path::Path;

use chatterspice::calibrate::fit::{EventKind, FitRequest, Record, fit, model_events};
use chatterspice::scenario::Scenario;
use chatterspice::{ContactState, Interval};
use criterion::{Criterion, criterion_group, criterion_main};

const TRUTH: &str = r#"
[mechanics]
mass = 2.0e-4
stiffness = 800.0
damping = 0.02
force = 0.5
gap = 5.0e-4

[surface]
law = "kelvin-voigt"
stiffness = 8.0e4
damping = 2.0
"#;

fn request() -> (Scenario, FitRequest) {
    let truth = Scenario::parse(TRUTH, Path::new("truth.toml")).unwrap();
    let events = model_events(&truth, None).unwrap();
    assert!(events.len() <= 10, "{} events", events.len());
    let offset = 3e-4;
    let mut intervals = vec![Interval {
        state: ContactState::Open,
        start: 0.0,
        end: events[0].time - offset,
    }];
    let mut times: Vec<(ContactState, f64)> = events
        .iter()
        .map(|e| {
            let state = if e.kind == EventKind::Make {
                ContactState::Closed
            } else {
                ContactState::Open
            };
            (state, e.time - offset)
        })
        .collect();
    let last = times.last().unwrap().1;
    times.push((ContactState::Open, last + 4e-4));
    times.push((ContactState::Closed, last + 4.03e-4));
    for (i, &(state, start)) in times.iter().enumerate() {
        let end = times.get(i + 1).map_or(last + 2e-3, |t| t.1);
        intervals.push(Interval { state, start, end });
    }
    let prior = Scenario::parse(
        &TRUTH
            .replacen("stiffness = 800.0", "stiffness = 1600.0", 1)
            .replacen("force = 0.5", "force = 0.3", 1)
            .replacen("stiffness = 8.0e4", "stiffness = 4.0e4", 1)
            .replacen("damping = 2.0", "damping = 4.0", 1),
        Path::new("prior.toml"),
    )
    .unwrap();
    let request = FitRequest {
        record: Some(Record {
            name: "bench.csv".into(),
            intervals,
        }),
        free: [
            "mechanics.stiffness",
            "mechanics.force",
            "surface.stiffness",
            "surface.damping",
        ]
        .map(String::from)
        .to_vec(),
    };
    (prior, request)
}

fn bench(c: &mut Criterion) {
    let (prior, request) = request();
    let report = fit(&prior, &request).unwrap();
    let stiffness = report.parameters[0].value;
    assert!(
        (stiffness / 800.0 - 1.0).abs() < 0.05,
        "{:?}",
        report.parameters
    );
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    group.bench_function("ten_events_four_keys", |b| {
        b.iter(|| fit(black_box(&prior), black_box(&request)).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
