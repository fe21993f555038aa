//! `run`: the scenario's circuit through ngspice, switched by its relay.

use super::*;

pub(super) fn run(args: &RunArgs) -> Result<()> {
    let scenario = load_scenario(args.scenario.as_deref())?;
    if let Some(csv) = &args.measured {
        report::protect_input(csv);
    }
    if args.envelope.envelope && args.measured.is_some() {
        bail!("--envelope samples the relay's mechanics, which --measured replaces");
    }
    let _lock = match &args.out {
        Some(dir) => {
            let lock = chatterspice::output::OutputLock::acquire(dir, "run")?;
            refuse_existing_bundle(dir, args.force)?;
            Some(lock)
        }
        None => None,
    };
    let ngspice = args.simulator.ngspice()?;
    let options = RunOptions {
        keep_workdir: args.keep_workdir,
        compare_ideal: !args.no_ideal,
        ..args.simulator.run_options()
    };
    let measured = args.measured.as_deref().map(read_measured).transpose()?;
    let outcome = verdict::run(
        &scenario,
        &ngspice,
        &options,
        measured,
        &args.life.options(),
    )?;
    let result = &outcome.result;
    for sim in std::iter::once(&result.simulation).chain(&result.ideal) {
        if let Some(dir) = &sim.workdir {
            eprintln!("ngspice work directory kept: {}", dir.display());
        }
    }
    let mut text = match args.format {
        RunFormat::Json => outcome.json(),
        RunFormat::Table => report::table::render_run_with_life(result, outcome.life.as_ref()),
    };
    if args.envelope.envelope {
        let env = verdict::run_envelope(&scenario, &ngspice, &args.envelope.options(options))?;
        text = match args.format {
            RunFormat::Json => envelope::json_with_envelope(&text, &env.report),
            RunFormat::Table => format!("{text}\n{}", envelope::band_table(&env.report)),
        };
    }
    for warning in &outcome.warnings {
        eprintln!("warning: {warning}");
    }
    if let Some(dir) = &args.out {
        let files = report::bundle::run_files_with_life(
            result,
            outcome.dimensionless.as_ref(),
            outcome.life.as_ref(),
        )
        .context("the run succeeded, but its files could not be made")?;
        report::write_bundle(dir, &files, args.force)?;
    }
    emit(&text, None, false)
}
