//! The arc inside ngspice: lines added to the contact subcircuit.
//!
//! The include keeps its interface: the contact subcircuit comes first,
//! with the terminals `a b`. Inside it, the plain contact (the
//! time-varying conductance) is instantiated as `Xcore` from a helper
//! subcircuit `<NAME>_core` written after it, between the internal node
//! `ai` and terminal `b`; a 0 V source `Vsense` from `a` to `ai` senses
//! the whole contact current. In parallel with the conductance:
//!
//! - the **arc state** `st` (1 burning or able to burn, 0 not): a
//!   voltage-controlled switch `Sst` on `|i(Vsense)|` (seen through a lag of
//!   [`STATE_LAG`]) with its threshold at
//!   I_min, closing at I_min and opening 0.4 % below it. A closed contact
//!   carrying at least I_min holds the state on, so a separation under
//!   current starts an arc at once; a current that falls below I_min puts
//!   it out;
//! - the **hold voltage** `th`: V_arc(t) = V_min + E·gap(t) while the state
//!   is on, the breakdown voltage max(V_bd(gap(t)), V_min) while it is off
//!   (both are PWL sources sampled from the gap profile), following a
//!   change of state with a lag of [`THRESHOLD_LAG`];
//! - the **clamp** `Barc`: a smooth odd current source that draws nothing
//!   while |v| < th and conducts steeply above it, so the contact voltage
//!   can exceed th only by a few millivolts (softplus of width
//!   [`CLAMP_SOFTNESS`]; at 1 A it holds th − 20 mV, at 100 A th + 9 mV).
//!
//! Its current is sensed by `Vclamp`, and `Bva` copies the contact voltage to
//! a node, so the raw file has what the arc analysis needs.
//!
//! Nothing in the include changes the rest of the user's circuit. Runs
//! with an arc integrate with Gear's method ([`ARC_OPTIONS`], which the
//! run deck carries, not the include): against a capacitance across the
//! contact (wiring, a snubber) the clamp's 10 kS make a mode of tens of
//! picoseconds, which the trapezoidal rule, not being L-stable, turns
//! into an alternation of the arc current from one time point to the next
//! (measured: 0.02 A and 1.97 A in turn about a 1 A arc); Gear's method
//! damps it. A netlist's own later `.options method` wins. A user who
//! includes the file in a circuit of their own (KiCad, a hand-written
//! deck) sets the same option there.

use super::contact::ContactInclude;
use super::contact::{comment, line, pairs};
use super::error::NetlistError;
use crate::arc::{ArcModel, GapProfile};
use crate::waveform::format_time;

/// The option line a deck that runs the arc include carries.
pub const ARC_OPTIONS: &str = ".options method=gear";

/// V, the softplus width of the clamp.
pub const CLAMP_SOFTNESS: f64 = 2e-3;

/// A, the clamp's current scale (conductance × softness): 10 kS above th.
pub const CLAMP_SCALE: f64 = 20.0;

/// Ω, the resistance of the element's two lags (RCs of this resistance
/// and lag / resistance farads). At 1 Ω the sources driving them carried
/// picoamperes, at ngspice's absolute current tolerance (abstol, 1 pA):
/// measured, a DC arc burning while a switched-off coil rang down stalled
/// ngspice in 8 of 38 loads (the time step cycling at 10–80 ps for good);
/// at 1 kΩ in none.
pub const LAG_RESISTANCE: f64 = 1e3;

/// s, the lag of the hold voltage behind the arc state (an RC of
/// [`LAG_RESISTANCE`]). A restrike drops the hold voltage from the
/// breakdown voltage to V_arc; the lag makes the circuit's capacitance
/// across the gap discharge into the arc over tens of nanoseconds, with
/// currents of amperes, as in a real restrike, instead of in one time step
/// through the clamp's 10 kS (kiloamperes for picoseconds, which no time
/// step resolves).
pub const THRESHOLD_LAG: f64 = 50e-9;

/// s, the time constant of the current the arc state sees (an RC of
/// [`LAG_RESISTANCE`]). At separation the capacitance across the
/// contact (wiring, a snubber) takes the current for the nanoseconds the
/// voltage needs to reach V_arc; a real contact bridges them with its
/// molten metal bridge, so the state must not see that dip as an
/// extinction. 100 ns delays a DC extinction by 100 ns and ignores dips
/// of a few ns.
pub const STATE_LAG: f64 = 100e-9;

/// The arc state's hysteresis, relative to I_min: on at I_min, off this
/// fraction below it.
pub const STATE_HYSTERESIS: f64 = 4e-3;

/// `include` with the arc added (see the module overview), the hold
/// voltages sampled at the gap profile's times.
pub fn with_arc(
    include: ContactInclude,
    model: &ArcModel,
    gap: &GapProfile,
) -> Result<ContactInclude, NetlistError> {
    arc_into(include, model, Some(gap), gap.at(0.0))
}

/// [`with_arc`] for a lock-step run: the gap's voltages are external
/// sources (`Vvarc`, `Vvbd`, and `Vlow` when the low-current term grows
/// with the gap) that the caller of ngspice's shared library answers at
/// every time point from the armature's position, the gap being
/// `initial_gap` (m) at t = 0.
pub fn with_arc_external(
    include: ContactInclude,
    model: &ArcModel,
    initial_gap: f64,
) -> Result<ContactInclude, NetlistError> {
    arc_into(include, model, None, initial_gap)
}

fn arc_into(
    mut include: ContactInclude,
    model: &ArcModel,
    gap: Option<&GapProfile>,
    initial_gap: f64,
) -> Result<ContactInclude, NetlistError> {
    let subckt = include.subckt.clone();
    let header = format!(".subckt {subckt} a b\n");
    let ends = format!(".ends {subckt}\n");
    let (Some(head_at), Some(ends_at)) = (include.text.find(&header), include.text.rfind(&ends))
    else {
        return Err(NetlistError::NotAContactInclude { subckt });
    };
    let mut arc = String::new();
    comment(
        &mut arc,
        &format!(
            "Arc: V_min = {} V, I_min = {} A, column gradient E = {} V/m, low-current \
             terms C = {} V*A, D = {} V*A/m. Vsense senses the contact current; switch \
             Sst holds the arc state V(st) on from I_min; the clamp Barc holds |V(a,b)| \
             at V_arc = V_min + E*gap(t) + (C + D*gap(t))/|i| while the state is on, at \
             the gap's breakdown voltage while it is off.",
            format_time(model.v_min),
            format_time(model.i_min),
            format_time(model.field),
            format_time(model.low_current),
            format_time(model.low_current_gap)
        ),
    );
    if model.capacitance > 0.0 {
        // The electrodes' own capacitance, outside the sensed arc current.
        line(
            &mut arc,
            &format!("Cgap a b {}", format_time(model.capacitance)),
        );
    }
    line(&mut arc, "Vsense a ai 0");
    line(&mut arc, &format!("Xcore ai b {subckt}_core"));
    line(&mut arc, "Vclamp ai ac 0");
    let samples = gap.map_or(&[][..], GapProfile::samples);
    if gap.is_some() {
        line(&mut arc, "Vvarc varc 0 PWL(");
        pairs(
            &mut arc,
            samples.iter().map(|&(t, g)| (t, model.arc_voltage(g))),
        );
        line(&mut arc, "Vvbd vbd 0 PWL(");
        pairs(
            &mut arc,
            samples.iter().map(|&(t, g)| (t, model.hold_voltage(g))),
        );
    } else {
        // ngspice 39 takes `external` as the whole value.
        line(&mut arc, "Vvarc varc 0 external");
        line(&mut arc, "Vvbd vbd 0 external");
    }
    line(&mut arc, "Bia iar 0 V = abs(i(Vsense))");
    line(
        &mut arc,
        &format!("Ria iar ia {}", format_time(LAG_RESISTANCE)),
    );
    line(
        &mut arc,
        &format!("Cia ia 0 {} IC=0", format_time(STATE_LAG / LAG_RESISTANCE)),
    );
    let burning = burning_voltage(&mut arc, model, gap.is_some(), samples);
    line(&mut arc, "Von on 0 1");
    line(&mut arc, "Sst on st ia 0 arc_state");
    line(&mut arc, "Rst st 0 1k");
    let half = 0.5 * STATE_HYSTERESIS * model.i_min;
    line(
        &mut arc,
        &format!(
            ".model arc_state sw vt={} vh={} ron=1m roff=1e9",
            format_time(model.i_min - half),
            format_time(half)
        ),
    );
    line(
        &mut arc,
        &format!("Bth thr 0 V = {burning} + (V(vbd) - {burning}) * (1 - V(st))"),
    );
    line(
        &mut arc,
        &format!("Rth thr th {}", format_time(LAG_RESISTANCE)),
    );
    line(
        &mut arc,
        &format!(
            "Cth th 0 {} IC={}",
            format_time(THRESHOLD_LAG / LAG_RESISTANCE),
            format_time(model.hold_voltage(initial_gap))
        ),
    );
    let s = format_time(CLAMP_SOFTNESS);
    let softplus = |x: &str| format!("(max({x}/{s},0) + ln(1 + exp(-abs({x}/{s}))))");
    line(
        &mut arc,
        &format!(
            "Barc ac b I = {} * ({} - {})",
            format_time(CLAMP_SCALE),
            softplus("(V(ac,b) - V(th))"),
            softplus("(-V(ac,b) - V(th))")
        ),
    );
    line(&mut arc, "Bva va 0 V = V(ai,b)");
    comment(
        &mut arc,
        "The clamp is stiff against any capacitance across the contact: run the \
         circuit with `.options method=gear` (the trapezoidal rule would make the arc \
         current alternate from one time point to the next).",
    );

    // The contact with its arc first, pins `a b`; the plain contact after
    // it as its helper.
    let mut text = String::with_capacity(include.text.len() + arc.len() + 64);
    text.push_str(&include.text[..head_at]);
    text.push_str(&header);
    text.push_str(&arc);
    text.push_str(&ends);
    text.push_str(&format!(".subckt {subckt}_core a b\n"));
    text.push_str(&include.text[head_at + header.len()..ends_at]);
    text.push_str(&format!(".ends {subckt}_core\n"));
    text.push_str(&include.text[ends_at + ends.len()..]);
    include.text = text;
    Ok(include)
}

/// The arc's burning voltage written into `arc`: V_min + E·gap alone
/// (`V(varc)`), or with Ayrton's low-current term (C + D·gap)/|i| on the
/// sensed current, at least I_min below which the arc is out (`V(av)`).
/// `profiled`: the gap is a PWL of `samples`, else an external source.
fn burning_voltage(
    arc: &mut String,
    model: &ArcModel,
    profiled: bool,
    samples: &[(f64, f64)],
) -> &'static str {
    if model.has_low_current_term() {
        if model.low_current_gap == 0.0 {
            line(
                arc,
                &format!("Vlow lowc 0 DC {}", format_time(model.low_current)),
            );
        } else if profiled {
            line(arc, "Vlow lowc 0 PWL(");
            pairs(
                arc,
                samples.iter().map(|&(t, g)| (t, model.low_current_term(g))),
            );
        } else {
            line(arc, "Vlow lowc 0 external");
        }
        line(
            arc,
            &format!(
                "Bav av 0 V = V(varc) + V(lowc) / max(V(ia), {})",
                format_time(model.i_min)
            ),
        );
        "V(av)"
    } else {
        "V(varc)"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chatter::{ContactState, Interval};
    use crate::netlist::{ContactElement, contact_include};
    use crate::waveform::{ContactModel, Waveform};

    fn include() -> ContactInclude {
        let iv = |state, start, end| Interval { state, start, end };
        let intervals = [
            iv(ContactState::Open, 0.0, 1e-3),
            iv(ContactState::Closed, 1e-3, 2e-3),
            iv(ContactState::Open, 2e-3, 3e-3),
        ];
        let model = ContactModel {
            r_closed: 0.05,
            r_open: 1e9,
            edge_time: 1e-8,
        };
        let waveform = Waveform::from_intervals(&intervals, &model).unwrap();
        contact_include(&waveform, "CONTACT", ContactElement::Pwl).unwrap()
    }

    #[test]
    fn the_arc_wraps_the_contact_and_samples_its_hold_voltages() {
        let arc = ArcModel {
            v_min: 12.0,
            i_min: 0.4,
            field: 1e4,
            opening_speed: 0.3,
            low_current: 0.0,
            low_current_gap: 0.0,
            capacitance: 1e-12,
        };
        let gap = GapProfile::from_samples([(0.0, 1e-3), (1e-3, 0.0), (2e-3, 0.0), (3e-3, 2e-4)]);
        let plain = include();
        let without = with_arc(
            plain.clone(),
            &ArcModel {
                capacitance: 0.0,
                ..arc
            },
            &gap,
        )
        .unwrap();
        assert!(!without.text.contains("Cgap"));
        let with = with_arc(plain.clone(), &arc, &gap).unwrap();
        let text = &with.text;
        // The electrodes' own capacitance, across the pins.
        assert!(text.contains("Cgap a b 1e-12\n"), "{text}");
        // The contact first with pins a b; the plain contact after it.
        let outer = text
            .find(".subckt CONTACT a b\n")
            .expect("the contact, pins a b");
        let core = text.find(".subckt CONTACT_core a b\n").expect("its helper");
        assert!(outer < core);
        assert_eq!(text.matches(".ends CONTACT\n").count(), 1);
        assert_eq!(text.matches(".ends CONTACT_core\n").count(), 1);
        assert!(text.contains("Xcore ai b CONTACT_core"));
        // The conductance element is untouched, between a and b.
        assert!(text.contains("B1 a b I = V(a,b) * V(g)"));
        // V_arc at the last sample: 12 V + 1e4 V/m · 0.2 mm = 14 V; the
        // breakdown voltage there (Paschen plateau or above) is ≥ 327 V.
        assert!(text.contains(&format!("{} {}", format_time(3e-3), format_time(14.0))));
        assert!(text.contains(".model arc_state sw vt=3.992e-1 vh=8e-4"));
        // Nothing that changes the user's whole circuit.
        assert!(
            !text
                .to_ascii_lowercase()
                .lines()
                .any(|l| l.starts_with(".option"))
        );
        // Not a contact include: an error, not a panic.
        let mut broken = plain;
        broken.text = broken.text.replace(".subckt CONTACT a b", "* gone");
        assert!(matches!(
            with_arc(broken, &arc, &gap),
            Err(NetlistError::NotAContactInclude { .. })
        ));
    }
}
