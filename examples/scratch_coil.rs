use chatterspice::coil::{CouplingOptions, run_coupled};
use chatterspice::scenario::Scenario;
use chatterspice::spice::Ngspice;
fn main() {
    let s = Scenario::load(std::path::Path::new(&std::env::args().nth(1).unwrap())).unwrap();
    let c = run_coupled(&s, &Ngspice::find().unwrap(), &CouplingOptions::default()).unwrap();
    eprintln!("{:?}", c.switching);
    for op in &c.operations { eprintln!("{op:?}"); }
    let cur = c.current();
    let v = c.voltage();
    let step = cur.len() / 40;
    for k in (0..cur.len()).step_by(step.max(1)) {
        let x = c.path[c.path.partition_point(|p| p.0 <= cur[k].0).saturating_sub(1)].1;
        println!("{:.5} i={:.5} v={:.3} x={:.4e}", cur[k].0, cur[k].1, v[k].1, x);
    }
    eprintln!("path points {}", c.path.len());
    for it in &c.iterations { eprintln!("{it:?}"); }
}
