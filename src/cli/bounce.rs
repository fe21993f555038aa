//! `bounce`: the mechanics alone, or a measured record, as a report.

use super::*;

pub(super) fn bounce(args: &BounceArgs) -> Result<()> {
    refuse_existing(args.output.as_deref(), args.force)?;
    if let Some(csv) = &args.measured {
        let chatter = Chatter::from_intervals(read_measured(csv)?);
        let text = report::render(args.format.into(), &chatter, None);
        return emit(&text, args.output.as_deref(), args.force);
    }
    let scenario = load_scenario(args.scenario.as_deref())?;
    let text = chatterspice::commands::bounce(&scenario, args.format.into())?;
    emit(&text, args.output.as_deref(), args.force)
}
