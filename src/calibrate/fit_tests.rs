//! Unit tests of fit.rs.
use super::*;

fn ev(kind: EventKind, time: f64) -> Event {
    Event { kind, time }
}

#[test]
fn the_offset_is_the_mean_difference_and_extra_events_cost() {
    use EventKind::*;
    let measured = [ev(Make, 0.0), ev(Break, 1e-4), ev(Make, 3e-4)];
    let model = [ev(Make, 1e-3), ev(Break, 1.1e-3), ev(Make, 1.3e-3)];
    let (r, offset) = event_residuals(&measured, &model);
    assert!((offset - 1e-3).abs() < 1e-15);
    assert!(r.iter().all(|x| x.abs() < 1e-15), "{r:?}");
    let longer = [
        model[0],
        model[1],
        model[2],
        ev(Break, 1.4e-3),
        ev(Make, 1.5e-3),
    ];
    let (r, _) = event_residuals(&measured, &longer);
    let extra = r.last().copied().unwrap();
    assert!(
        (extra - (2e-4 + 2.0 * COUNT_PENALTY)).abs() < 1e-12,
        "{extra}"
    );
}

#[test]
fn halton_points_spread_in_the_unit_interval() {
    assert_eq!(halton(1, 2), 0.5);
    assert_eq!(halton(2, 2), 0.25);
    assert!((halton(1, 3) - 1.0 / 3.0).abs() < 1e-15);
}
