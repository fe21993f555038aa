//! Unit tests of fit.rs.
use super::problem::{event_residuals, halton};
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

mod spring_start {
    use crate::calibrate::fit::start::{Currents, bisect, solve_spring};
    use crate::coil::Coil;
    use crate::coil::pick_up::{BladeLoad, LoadLine, drop_out, pick_up};

    /// The reference relay of docs/model.md §7.
    fn coil() -> Coil {
        Coil {
            resistance: 70.0,
            turns: 3000.0,
            pole_area: 2e-5,
            air_gap: 0.6e-3,
            iron_gap: 0.05e-3,
        }
    }

    fn truth() -> LoadLine {
        LoadLine {
            preload: 0.1,
            stiffness: 800.0,
            gap: 0.45e-3,
            blade: None,
        }
    }

    fn currents(c: &Coil, l: &LoadLine) -> Currents {
        Currents {
            pick_up: Some(pick_up(c, l).current),
            drop_out: Some(drop_out(c, l).current),
        }
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        ((a - b) / b).abs() <= rel
    }

    #[test]
    fn both_voltages_give_the_preload_and_the_spring_together() {
        let c = coil();
        let prior = LoadLine {
            preload: 0.2,
            stiffness: 400.0,
            ..truth()
        };
        // The datasheet's rounded figures.
        let given = Currents {
            pick_up: Some(1.54603 / 70.0),
            drop_out: Some(0.89285 / 70.0),
        };
        let l = solve_spring(&c, &prior, given, true, true).expect("a root");
        assert!(close(l.preload, 0.1, 1e-4), "{l:?}");
        assert!(close(l.stiffness, 800.0, 1e-4), "{l:?}");
        // The exact currents give the truth to the bisection's precision.
        let l = solve_spring(&c, &prior, currents(&c, &truth()), true, true).unwrap();
        assert!(close(l.preload, 0.1, 1e-10) && close(l.stiffness, 800.0, 1e-10));
        // The rest rule's preload from the same pick-up is 30 % high.
        let i = 1.54603 / 70.0;
        let rest_rule = 0.5 * i * i * c.d_inductance(0.0);
        assert!(rest_rule / l.preload > 1.3, "{rest_rule}");
    }

    #[test]
    fn one_free_key_is_solved_from_its_figure() {
        let c = coil();
        let given = currents(&c, &truth());
        let off_p = LoadLine {
            preload: 0.3,
            ..truth()
        };
        let l = solve_spring(&c, &off_p, given, true, false).unwrap();
        assert!(
            close(l.preload, 0.1, 1e-10) && l.stiffness == 800.0,
            "{l:?}"
        );
        let only_drop = Currents {
            pick_up: None,
            ..given
        };
        let l = solve_spring(&c, &off_p, only_drop, true, false).unwrap();
        assert!(close(l.preload, 0.1, 1e-12), "{l:?}");
        let off_s = LoadLine {
            stiffness: 300.0,
            ..truth()
        };
        let l = solve_spring(&c, &off_s, given, false, true).unwrap();
        assert!(close(l.stiffness, 800.0, 1e-12), "{l:?}");
        let only_pick = Currents {
            drop_out: None,
            ..given
        };
        let l = solve_spring(&c, &off_s, only_pick, false, true).unwrap();
        assert!(close(l.stiffness, 800.0, 1e-10), "{l:?}");
        // Nothing given for the free key: nothing solved.
        let none = Currents {
            pick_up: None,
            drop_out: None,
        };
        assert!(solve_spring(&c, &off_s, none, true, true).is_none());
    }

    #[test]
    fn figures_no_load_line_meets_give_no_start() {
        let c = coil();
        // This magnet's pick-up is 1.50 to 3.25 times its drop-out (from a
        // preload-less spring to a spring-less preload): a pick-up below
        // the drop-out is met by no spring ≥ 0 and preload ≥ 0.
        let given = Currents {
            pick_up: Some(0.5 / 70.0),
            drop_out: Some(0.89285 / 70.0),
        };
        assert!(solve_spring(&c, &truth(), given, true, true).is_none());
        // Nor one above what a spring-less load line needs.
        let given = Currents {
            pick_up: Some(4.0 / 70.0),
            ..given
        };
        assert!(solve_spring(&c, &truth(), given, true, true).is_none());
    }

    #[test]
    fn a_blade_with_a_pole_face_is_part_of_the_load_to_solve_for() {
        let c = coil();
        let with_blade = LoadLine {
            blade: Some(BladeLoad {
                stiffness: 2.0e3,
                overtravel: Some(0.05e-3),
            }),
            ..truth()
        };
        let given = currents(&c, &with_blade);
        let prior = LoadLine {
            preload: 0.05,
            stiffness: 1500.0,
            ..with_blade
        };
        let l = solve_spring(&c, &prior, given, true, true).unwrap();
        assert!(close(l.preload, 0.1, 1e-9) && close(l.stiffness, 800.0, 1e-9));
    }

    #[test]
    fn bisection_needs_a_sign_change() {
        let r = bisect(|x| x * x - 2.0, 0.0, 2.0).unwrap();
        assert!((r - 2f64.sqrt()).abs() < 1e-15);
        assert!(bisect(|x| x * x + 1.0, -1.0, 1.0).is_none());
        assert_eq!(bisect(|x| x - 1.0, 1.0, 3.0), Some(1.0));
    }
}
