//! `pwl`: the contact as a PWL source or include, for a netlist of the user's own.

use super::*;

pub(super) fn pwl(args: &PwlArgs) -> Result<()> {
    refuse_existing(args.output.as_deref(), args.force)?;
    let scenario = load_scenario(args.scenario.as_deref())?;
    let model = ContactModel::from(&scenario.contact);
    let (waveform, gap) = match &args.measured {
        Some(csv) => {
            let intervals = read_measured(csv)?;
            let gap = pipeline::record_gap(&scenario, &intervals);
            (Waveform::from_intervals(&intervals, &model)?, gap)
        }
        None if scenario.coil.is_some() => {
            let (chatter, _) = check::dc_step(&scenario).with_context(|| {
                format!(
                    "{}: the mechanics simulation failed",
                    scenario.origin.display()
                )
            })?;
            let gap = pipeline::record_gap(&scenario, &chatter.intervals);
            (pipeline::contact_waveform(&scenario, &chatter)?.0, gap)
        }
        None => {
            let (mechanics, surface, settings) = (
                scenario.mechanics()?,
                scenario.surface(),
                scenario.settings(),
            );
            let trajectory = chatterspice::mechanics::two_stage::step_closing(
                &mechanics,
                &scenario.two_stage(),
                &surface,
                &settings,
            )
            .with_context(|| {
                format!(
                    "{}: the mechanics simulation failed",
                    scenario.origin.display()
                )
            })?;
            let gap = GapProfile::from_trajectory(&trajectory);
            let chatter = trajectory.into_chatter();
            (pipeline::contact_waveform(&scenario, &chatter)?.0, gap)
        }
    };
    let subckt = scenario
        .circuit
        .as_ref()
        .map_or("CONTACT", |c| c.subckt.as_str());
    let element = args
        .element
        .unwrap_or_else(|| ContactElement::for_waveform(&waveform));
    let mut include = netlist::contact_include(&waveform, subckt, element)?;
    if let Some(arc) = &scenario.arc {
        include = chatterspice::netlist::arc::with_arc(include, &arc.model(), &gap)?;
    }
    if !include.data_files.is_empty() {
        let Some(output) = &args.output else {
            bail!(
                "the {} element reads data files next to the include; give -o FILE so they can be written",
                include.element
            );
        };
        let dir = output
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        for (name, contents) in &include.data_files {
            report::write_new_file(&dir.join(name), contents.as_bytes(), args.force)?;
        }
    }
    emit(&include.text, args.output.as_deref(), args.force)
}
