//! `check`: the scenario's limits, with `--envelope` against every relay its datasheet allows.

use super::*;

pub(super) fn check(args: &CheckArgs) -> Result<Status> {
    let scenario = load_scenario(args.scenario.as_deref())?;
    let options = args.simulator.run_options();
    let ngspice = args.simulator.lazy();
    if args.envelope.envelope {
        let env = verdict::check_envelope(&scenario, &ngspice, &args.envelope.options(options))?;
        return check_envelope(args, &env);
    }
    let measured = args.measured.as_deref().map(read_measured).transpose()?;
    let outcome = verdict::check(
        &scenario,
        &ngspice,
        &options,
        measured,
        &args.life.options(),
    )?;
    for note in &outcome.notes {
        eprintln!("note: {note}");
    }
    let text = match args.format {
        RunFormat::Json => outcome.json(),
        RunFormat::Table => {
            let evidence = &outcome.evidence;
            let mut text = report::table::render_check(
                &outcome.verdict,
                evidence.chatter(),
                evidence.operations(),
            );
            if let Some(life) = &outcome.life {
                text.push_str("\nelectrical life\n");
                text.push_str(&chatterspice::life::render(life));
            }
            text
        }
    };
    for warning in &outcome.warnings {
        eprintln!("warning: {warning}");
    }
    emit(&text, None, false)?;
    Ok(if outcome.verdict.passed {
        Status::Success
    } else {
        Status::CheckFailed
    })
}

/// `check --envelope`: every limit against the worst relay the envelope
/// keeps.
pub(super) fn check_envelope(args: &CheckArgs, env: &envelope::Envelope) -> Result<Status> {
    let worst = env
        .worst()
        .expect("an envelope that kept a relay has a worst one");
    let verdict = &env.verdict;
    let text = match args.format {
        RunFormat::Json => verdict::envelope_check_json(env),
        RunFormat::Table => format!(
            "{}\n{}",
            report::table::render_check_of(
                &format!(
                    "worst relay (index {} of {} drawn)",
                    worst.index, env.report.samples
                ),
                verdict,
                worst.evidence.chatter(),
                worst.evidence.operations()
            ),
            envelope::band_table(&env.report)
        ),
    };
    emit(&text, None, false)?;
    Ok(if verdict.passed {
        Status::Success
    } else {
        Status::CheckFailed
    })
}
