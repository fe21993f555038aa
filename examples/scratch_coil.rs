use chatterspice::coil::{CouplingOptions, run_coupled};
use chatterspice::scenario::Scenario;
use chatterspice::spice::Ngspice;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let s = Scenario::load(std::path::Path::new(&a[1])).unwrap();
    let (t0, t1): (f64, f64) = (a[2].parse().unwrap(), a[3].parse().unwrap());
    let c = run_coupled(
        &s,
        &Ngspice::find().unwrap(),
        &CouplingOptions {
            max_iterations: 25,
            ..CouplingOptions::default()
        },
    )
    .unwrap();
    for op in &c.operations {
        eprintln!("{op:?}");
    }
    eprintln!("{:?}", c.switching);
    let cur = c.current();
    let v = c.voltage();
    let idx: Vec<usize> = (0..cur.len())
        .filter(|&k| cur[k].0 >= t0 && cur[k].0 <= t1)
        .collect();
    let step = (idx.len() / 40).max(1);
    for &k in idx.iter().step_by(step) {
        let x = c.path[c
            .path
            .partition_point(|p| p.0 <= cur[k].0)
            .saturating_sub(1)]
        .1;
        println!(
            "{:.6} i={:.5} v={:.3} x={:.4e}",
            cur[k].0, cur[k].1, v[k].1, x
        );
    }
    eprintln!(
        "path points {} iterations {}",
        c.path.len(),
        c.iterations.len()
    );
}
