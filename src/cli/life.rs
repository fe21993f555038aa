//! `life`: the electrical life of a scenario's endurance figures and its circuit.

use super::*;

pub(super) fn life(args: &LifeArgs) -> Result<()> {
    let scenario = load_scenario(args.scenario.as_deref())?;
    let ngspice = args.simulator.ngspice()?;
    let options = chatterspice::verdict::LifeOptions {
        phases: args.phases,
        jobs: args
            .jobs
            .map_or_else(verdict::cpus, std::num::NonZeroUsize::get),
        ..chatterspice::verdict::LifeOptions::default()
    };
    let report =
        chatterspice::verdict::life(&scenario, &ngspice, &args.simulator.run_options(), &options)?;
    let text = match args.format {
        RunFormat::Json => chatterspice::verdict::life_json(&report),
        RunFormat::Table => chatterspice::life::render(&report),
    };
    emit(&text, None, false)
}
