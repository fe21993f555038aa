//! The sweep library: the sampler's distributions and determinism, and
//! the runner's rows (independent of the number of jobs and of sharding)
//! on the mechanics alone, where no ngspice is needed.

use std::num::NonZeroUsize;
use std::path::Path;

use chatterspice::scenario::{DEFAULT_SCENARIO_TOML, Scenario};
use chatterspice::sweep::{
    self, NoProgress, SampleVerdict, Sampler, Shard, SweepMode, SweepOptions,
};

/// The built-in relay with `sweep` (TOML) appended, placed beside the
/// built-in scenario so that its netlist resolves.
fn scenario(sweep: &str) -> Scenario {
    let origin = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/sweep-test.toml");
    Scenario::parse(&format!("{DEFAULT_SCENARIO_TOML}\n{sweep}\n"), &origin)
        .unwrap_or_else(|e| panic!("{e}"))
}

fn draws(sampler: &Sampler, n: u64) -> Vec<Vec<f64>> {
    (0..n).map(|i| sampler.values_vec(i).unwrap()).collect()
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

#[test]
fn uniform_draws_stay_within_bounds_and_fill_them_evenly() {
    let s = scenario("[sweep.vary]\n\"mechanics.mass\" = 0.1");
    let sampler = Sampler::new(&s, Some(20_000), Some(42)).unwrap();
    let nominal = 1.0e-4;
    let values: Vec<f64> = draws(&sampler, 20_000).iter().map(|v| v[0]).collect();
    assert!(
        values
            .iter()
            .all(|&m| (nominal * 0.9..nominal * 1.1).contains(&m))
    );
    let (mean, sd) = mean_sd(&values);
    // Uniform on ±10 %: σ = 0.1/√3 of the nominal.
    let sigma = 0.1 * nominal / 3f64.sqrt();
    assert!(
        (mean - nominal).abs() < 4.0 * sigma / (20_000f64).sqrt(),
        "{mean}"
    );
    assert!((sd / sigma - 1.0).abs() < 0.03, "{sd} vs {sigma}");
    // Each tenth of the interval holds about a tenth of the draws.
    for decile in 0..10 {
        let lo = nominal * (0.9 + 0.02 * decile as f64);
        let count = values
            .iter()
            .filter(|&&m| (lo..lo + 0.02 * nominal).contains(&m))
            .count();
        assert!((1_800..2_200).contains(&count), "decile {decile}: {count}");
    }
}

#[test]
fn normal_draws_have_the_mean_and_sigma_and_are_cut_at_four_sigma() {
    let s = scenario("[sweep.vary]\n\"surface.damping\" = { normal = 0.05 }");
    let n = 20_000;
    let sampler = Sampler::new(&s, Some(n), Some(3)).unwrap();
    let nominal = 1.92;
    let sigma = 0.05 * nominal;
    let values: Vec<f64> = draws(&sampler, n).iter().map(|v| v[0]).collect();
    let (mean, sd) = mean_sd(&values);
    assert!(
        (mean - nominal).abs() < 4.0 * sigma / (n as f64).sqrt(),
        "{mean}"
    );
    assert!((sd / sigma - 1.0).abs() < 0.03, "{sd} vs {sigma}");
    assert!(values.iter().all(|v| (v - nominal).abs() <= 4.0 * sigma));
    let within_one = values
        .iter()
        .filter(|v| (*v - nominal).abs() < sigma)
        .count() as f64
        / n as f64;
    assert!((within_one - 0.6827).abs() < 0.015, "{within_one}");
}

#[test]
fn a_bounded_key_is_redrawn_inside_its_bound() {
    let text = DEFAULT_SCENARIO_TOML.replace(
        "law = \"kelvin-voigt\"\nstiffness = 5.0e5",
        "law = \"rigid\"\nrestitution = 0.95\n#",
    );
    let text = text.replace("damping = 1.92 ", "#");
    let origin = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/sweep-test.toml");
    let s = Scenario::parse(
        &format!("{text}\n[sweep.vary]\n\"surface.restitution\" = 0.1\n"),
        &origin,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let sampler = Sampler::new(&s, Some(2_000), None).unwrap();
    let values: Vec<f64> = draws(&sampler, 2_000).iter().map(|v| v[0]).collect();
    assert!(values.iter().all(|&e| (0.855..=1.0).contains(&e)));
    assert!(values.iter().any(|&e| e > 0.99));
}

#[test]
fn a_sample_s_values_depend_only_on_seed_key_and_index() {
    let one = scenario("[sweep.vary]\n\"mechanics.mass\" = 0.1");
    let two = scenario("[sweep.vary]\n\"mechanics.mass\" = 0.1\n\"mechanics.force\" = 0.2");
    let a = Sampler::new(&one, Some(10), Some(9)).unwrap();
    let b = Sampler::new(&two, Some(10), Some(9)).unwrap();
    assert_eq!(b.keys(), ["mechanics.force", "mechanics.mass"]);
    for i in [7, 0, 3] {
        assert_eq!(a.values_vec(i).unwrap()[0], b.values_vec(i).unwrap()[1]);
    }
    let c = Sampler::new(&one, Some(10), Some(10)).unwrap();
    assert_ne!(a.values_vec(0).unwrap(), c.values_vec(0).unwrap());
    // The file's seed and samples, unless overridden.
    let filed = scenario("[sweep]\nsamples = 5\nseed = 9\n[sweep.vary]\n\"mechanics.mass\" = 0.1");
    let d = Sampler::new(&filed, None, None).unwrap();
    assert_eq!((d.count(), d.seed()), (5, Some(9)));
    assert_eq!(d.values_vec(4).unwrap(), a.values_vec(4).unwrap());
}

#[test]
fn a_grid_steps_the_outer_key_slowest() {
    let s = scenario(
        "[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 2.0, steps = 4 }\n\
         \"surface.damping\" = { from = 1.0, to = 3.0, steps = 3 }",
    );
    let sampler = Sampler::new(&s, None, None).unwrap();
    assert_eq!(sampler.count(), 12);
    assert!(sampler.is_grid());
    assert_eq!(sampler.values_vec(0).unwrap(), [0.5, 1.0]);
    assert_eq!(sampler.values_vec(1).unwrap(), [0.5, 2.0]);
    assert_eq!(sampler.values_vec(5).unwrap(), [1.0, 3.0]);
    assert_eq!(sampler.values_vec(11).unwrap(), [2.0, 3.0]);
    assert!(
        Sampler::new(&s, Some(3), None).is_err(),
        "--samples with a grid"
    );
    assert!(
        Sampler::new(&scenario(""), None, None).is_err(),
        "no [sweep]"
    );
}

fn csv_of(s: &Scenario, sampler: &Sampler, jobs: usize, shard: Shard) -> Vec<u8> {
    let mut options = SweepOptions::new(SweepMode::Mechanics);
    options.jobs = NonZeroUsize::new(jobs).unwrap();
    options.shard = shard;
    let mut out = Vec::new();
    sweep::run(s, sampler, &options, &mut out, &NoProgress).unwrap();
    out
}

#[test]
fn rows_do_not_depend_on_jobs_and_shards_merge_into_one_run() {
    let s = scenario(
        "[sweep.vary]\n\"mechanics.mass\" = 0.2\n\"surface.damping\" = { normal = 0.1 }\n\
         \"mechanics.force\" = 0.5",
    );
    // Several chunks, one of them partial.
    let sampler = Sampler::new(&s, Some(1_300), Some(5)).unwrap();
    let one = csv_of(&s, &sampler, 1, Shard::WHOLE);
    assert_eq!(one, csv_of(&s, &sampler, 2, Shard::WHOLE));
    assert_eq!(one, csv_of(&s, &sampler, 3, Shard::WHOLE));
    let text = String::from_utf8(one.clone()).unwrap();
    assert_eq!(text.lines().count(), 1 + 1_300);
    for (i, line) in text.lines().skip(1).enumerate() {
        assert!(line.starts_with(&format!("{i},")), "row {i}: {line}");
    }

    let shards: Vec<(std::path::PathBuf, std::io::Cursor<Vec<u8>>)> = (1..=3)
        .map(|k| {
            let shard = Shard { index: k, count: 3 };
            (
                format!("shard{k}").into(),
                std::io::Cursor::new(csv_of(&s, &sampler, 2, shard)),
            )
        })
        .collect();
    let mut merged = Vec::new();
    let report = sweep::table::merge(shards, &mut merged, Some(1_300), false).unwrap();
    assert_eq!(report.rows, 1_300);
    assert_eq!(merged, one);
}

#[test]
fn samples_that_never_close_or_are_invalid_are_recorded_and_the_sweep_goes_on() {
    // At 0.1 N the relay cannot reach its gap (gap / static deflection
    // k0 = 7 > 2): it never closes.
    let s = scenario("[sweep.grid]\n\"mechanics.force\" = { from = 0.1, to = 1.0, steps = 10 }");
    let sampler = Sampler::new(&s, None, None).unwrap();
    let options = SweepOptions::new(SweepMode::Mechanics);
    let mut out = Vec::new();
    let collected = sweep::run(&s, &sampler, &options, &mut out, &NoProgress).unwrap();
    let summary = collected.summary(&sampler).unwrap();
    assert_eq!(summary.samples, 10);
    assert!(
        summary.outcomes["never_closes"] >= 2,
        "{:?}",
        summary.outcomes
    );
    assert_eq!(summary.outcomes.values().sum::<u64>(), 10);
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains(",never_closes,0,,,,pass,"), "{text}");

    // A sample the scenario's rules refuse: recorded as an error row.
    let record = sweep::run_sample(&s, &sampler, 0, &options);
    assert_eq!(record.verdict, SampleVerdict::Pass);
    let bad = scenario("[sweep.vary]\n\"contact.r_closed\" = 0.5");
    let mut bad = bad;
    bad.set_number("contact.r_open", 0.051).unwrap();
    let sampler = Sampler::new(&bad, Some(40), None).unwrap();
    let mut out = Vec::new();
    let collected = sweep::run(&bad, &sampler, &options, &mut out, &NoProgress).unwrap();
    let summary = collected.summary(&sampler).unwrap();
    assert!(
        summary.errors > 0 && summary.errors < 40,
        "{}",
        summary.errors
    );
    assert!(
        summary.first_errors[0].error.contains("contact.r_open"),
        "{:?}",
        summary.first_errors
    );
    let text = String::from_utf8(out).unwrap();
    assert_eq!(text.lines().count(), 41);
}

#[test]
fn the_summary_finds_the_worst_sample_and_the_plot_draws() {
    let s = scenario("[sweep.vary]\n\"mechanics.mass\" = 0.2\n\"mechanics.force\" = 0.3");
    let sampler = Sampler::new(&s, Some(300), Some(1)).unwrap();
    let mut out = Vec::new();
    let collected = sweep::run(
        &s,
        &sampler,
        &SweepOptions::new(SweepMode::Mechanics),
        &mut out,
        &NoProgress,
    )
    .unwrap();
    let summary = collected.summary(&sampler).unwrap();
    let worst = summary.worst.as_ref().unwrap();
    let longest = summary.bounce_time.unwrap().max;
    assert_eq!(worst.bounce_time, Some(longest));
    assert_eq!(worst.values.len(), 2);
    let json: serde_json::Value = serde_json::from_str(&summary.to_json()).unwrap();
    assert_eq!(json["samples"], 300);
    assert_eq!(json["worst"]["index"], worst.index);
    let svg = sweep::plot::render(&collected, &sampler).unwrap();
    assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
    assert!(!svg.contains("NaN"));
    assert!(summary.render_table().contains("worst: sample"));
}

/// A disk that fills up after `room` bytes.
struct Full {
    room: usize,
}

impl std::io::Write for Full {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if buf.len() > self.room {
            return Err(std::io::Error::other("no space left"));
        }
        self.room -= buf.len();
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn a_failing_output_stops_the_sweep_with_an_error_instead_of_hanging() {
    let s = scenario("[sweep.vary]\n\"mechanics.mass\" = 0.1");
    let sampler = Sampler::new(&s, Some(1_000_000), None).unwrap();
    let mut options = SweepOptions::new(SweepMode::Mechanics);
    options.jobs = NonZeroUsize::new(2).unwrap();
    let err = sweep::run(
        &s,
        &sampler,
        &options,
        &mut Full { room: 200_000 },
        &NoProgress,
    )
    .unwrap_err();
    assert!(matches!(err, sweep::SweepError::Write(_)), "{err}");
}
