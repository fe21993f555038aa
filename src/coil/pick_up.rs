//! Pick-up and drop-out of the magnet against the armature's load line
//! (docs/model.md §7).
//!
//! The armature is held back by a load that grows along its travel: the
//! return spring's preload and stiffness, `p + s·x` for `0 ≤ x < g`, and,
//! in a relay with a contact blade that the armature deflects after the
//! contacts touch, the blade's `s_b·(x − g)` on top for `g ≤ x ≤ g + o`
//! (`o` the overtravel to the pole face). The coil pulls with
//! `½ i² L'(x) = k i² / (2 (a − x)²)`, `k = μ0 N² A`, `a = g_a + l_eq`.
//!
//! **Pick-up** (must-operate) is the smallest current whose pull beats the
//! load at every position of the travel, not only at rest:
//!
//! ```text
//! i_pu = max over 0 ≤ x ≤ x_end of √(2·load(x) / L'(x))
//! ```
//!
//! On a linear piece `P + S·x` the squared current needed is
//! `2 (P + S x)(a − x)² / k`, which rises until
//! `x* = (S·a − 2P)/(3S)` and falls after it, so the maximum over the
//! travel is at the end of a piece or at an `x*` inside one. Without a
//! blade it sits at rest only when `s·a ≤ 2p`; a stiffer spring lets the
//! armature lift off at the current that beats the preload and stall
//! part-way, where the spring has grown faster than the pull. The rule
//! "the pull at rest equals the preload" then gives a pick-up voltage
//! that is too low (14 % for the reference relay of docs/model.md §7).
//!
//! **Drop-out** (must-release) is the current at which the pull at the
//! closed position only just holds the load there,
//! `½ i² L'(x_c) = load(x_c)`, with `x_c` the end of the travel (the
//! pole face, or the contact position without one): below it the
//! armature leaves the closed position.

use super::magnet::Coil;
use crate::mechanics::Mechanics;

/// A contact blade that the armature deflects once the contacts touch
/// (a two-stage load line). SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BladeLoad {
    /// N/m, the blade's stiffness `s_b`, loading the armature from the
    /// contact position `g` on.
    pub stiffness: f64,
    /// m, the overtravel `o` beyond the contact position at which the
    /// armature meets its pole face; `None` when there is no pole face and
    /// the travel ends where the contacts touch.
    pub overtravel: Option<f64>,
}

/// The load that holds the armature back along its travel. SI units;
/// positions `x` in m from the rest stop, toward closing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadLine {
    /// N, the return spring's preload `p` at rest.
    pub preload: f64,
    /// N/m, the return spring's stiffness `s`.
    pub stiffness: f64,
    /// m, the contact travel `g`: where the contacts touch.
    pub gap: f64,
    /// The contact blade, if the armature deflects one after the contacts
    /// touch.
    pub blade: Option<BladeLoad>,
}

/// The pick-up (must-operate) point of a coil against a load line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PickUp {
    /// A, the smallest coil current that pulls the armature through its
    /// whole travel.
    pub current: f64,
    /// V, that current times the coil's resistance.
    pub voltage: f64,
    /// m, where along the travel the pull only just beats the load at
    /// that current: 0 when the preload at rest is what must be beaten.
    pub binding_position: f64,
}

/// The drop-out (must-release) point of a coil against a load line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DropOut {
    /// A, the coil current at which the pull at the closed position equals
    /// the load there.
    pub current: f64,
    /// V, that current times the coil's resistance.
    pub voltage: f64,
}

impl LoadLine {
    /// The load line of a relay's mechanics: its preload, spring and
    /// contact travel.
    pub fn of_mechanics(m: &Mechanics) -> LoadLine {
        LoadLine {
            preload: m.preload,
            stiffness: m.stiffness,
            gap: m.gap,
            // A two-stage relay's contact blade is to be read here, from
            // the mechanics that describe it; until then the load line is
            // the return spring alone.
            blade: None,
        }
    }

    /// The load line of a relay as built: its armature's mechanics and,
    /// with a contact blade, the blade's stiffness from the make on (to
    /// the pole face, when there is one).
    pub fn of_relay(m: &Mechanics, build: &crate::mechanics::two_stage::TwoStage) -> LoadLine {
        LoadLine {
            blade: build.blade.map(|b| BladeLoad {
                stiffness: b.stiffness,
                overtravel: build.pole_face.map(|p| p.overtravel),
            }),
            ..LoadLine::of_mechanics(m)
        }
    }

    /// N, the load at position `x` (m): `p + s·x`, plus `s_b·(x − g)` past
    /// the contact position when a blade with a pole face is deflected.
    pub fn load(&self, x: f64) -> f64 {
        let spring = self.preload + self.stiffness * x;
        match self.blade {
            Some(b) if b.overtravel.is_some() && x > self.gap => {
                spring + b.stiffness * (x - self.gap)
            }
            _ => spring,
        }
    }

    /// m, where the travel ends: at the pole face `g + o` when a blade has
    /// one, else where the contacts touch, `g`.
    pub fn travel_end(&self) -> f64 {
        match self.blade {
            Some(BladeLoad {
                overtravel: Some(o),
                ..
            }) => self.gap + o,
            _ => self.gap,
        }
    }

    /// m, where the armature rests while the relay is operated: the end
    /// of its travel ([`LoadLine::travel_end`]).
    pub fn closed_position(&self) -> f64 {
        self.travel_end()
    }

    /// The linear pieces of the load over the travel: `(x0, x1, P, S)`
    /// with the load `P + S·x` on `[x0, x1]`.
    fn pieces(&self) -> Vec<(f64, f64, f64, f64)> {
        let mut out = vec![(0.0, self.gap, self.preload, self.stiffness)];
        if let Some(BladeLoad {
            stiffness,
            overtravel: Some(o),
        }) = self.blade
        {
            out.push((
                self.gap,
                self.gap + o,
                self.preload - stiffness * self.gap,
                self.stiffness + stiffness,
            ));
        }
        out
    }
}

/// The pick-up of `coil` against `line`: the largest, over the travel, of
/// the current whose pull equals the load, and where it is reached (the
/// end of a linear piece of the load, or the point inside one where the
/// load grows as fast as the pull).
pub fn pick_up(coil: &Coil, line: &LoadLine) -> PickUp {
    let a = coil.total_gap(0.0);
    // The current squared that balances the load at x.
    let needed = |x: f64| (2.0 * line.load(x) / coil.d_inductance(x)).max(0.0);
    let mut best = (needed(0.0), 0.0);
    for (x0, x1, p, s) in line.pieces() {
        let mut candidates = vec![x0, x1];
        if s > 0.0 {
            let critical = (s * a - 2.0 * p) / (3.0 * s);
            if critical > x0 && critical < x1 {
                candidates.push(critical);
            }
        }
        for x in candidates {
            let i2 = needed(x);
            // Ties go to the earlier position, where the armature stalls
            // first.
            if i2 > best.0 || (i2 == best.0 && x < best.1) {
                best = (i2, x);
            }
        }
    }
    let current = best.0.sqrt();
    PickUp {
        current,
        voltage: coil.resistance * current,
        binding_position: best.1,
    }
}

/// The drop-out of `coil` against `line`: the current whose pull at the
/// closed position equals the load there.
pub fn drop_out(coil: &Coil, line: &LoadLine) -> DropOut {
    let x = line.closed_position();
    let current = (2.0 * line.load(x) / coil.d_inductance(x)).max(0.0).sqrt();
    DropOut {
        current,
        voltage: coil.resistance * current,
    }
}

impl PickUp {
    /// Whether the pick-up is set at rest (the preload is what must be
    /// beaten) rather than part-way along the travel.
    pub fn at_rest(&self) -> bool {
        self.binding_position <= 0.0
    }

    /// Where the pick-up binds, in words: `at rest (x = 0)`, or
    /// `part-way, at x = 0.1333 mm of the 0.45 mm travel` (on the blade,
    /// or at the end of the travel, when it is there).
    pub fn binding_text(&self, line: &LoadLine) -> String {
        let x = self.binding_position;
        let end = line.travel_end();
        let mm = |v: f64| {
            let t = format!("{:.4}", v * 1e3);
            let t = t.trim_end_matches('0').trim_end_matches('.');
            t.to_owned()
        };
        if self.at_rest() {
            "at rest (x = 0)".to_owned()
        } else if x >= end {
            format!("at the end of the travel, x = {} mm", mm(x))
        } else if line.blade.is_some() && x > line.gap {
            format!(
                "part-way, on the blade, at x = {} mm of the {} mm travel",
                mm(x),
                mm(end)
            )
        } else {
            format!("part-way, at x = {} mm of the {} mm travel", mm(x), mm(end))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    fn line() -> LoadLine {
        LoadLine {
            preload: 0.1,
            stiffness: 800.0,
            gap: 0.45e-3,
            blade: None,
        }
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        ((a - b) / b).abs() <= rel
    }

    /// The pick-up current by brute force: the largest balancing current
    /// over `n + 1` evenly spaced positions of the travel.
    fn scanned(c: &Coil, l: &LoadLine, n: usize) -> (f64, f64) {
        let end = l.travel_end();
        (0..=n)
            .map(|k| {
                let x = end * k as f64 / n as f64;
                ((2.0 * l.load(x) / c.d_inductance(x)).sqrt(), x)
            })
            .fold((0.0, 0.0), |acc, v| if v.0 > acc.0 { v } else { acc })
    }

    #[test]
    fn the_reference_relay_picks_up_part_way() {
        let (c, l) = (coil(), line());
        let pu = pick_up(&c, &l);
        assert!(close(pu.voltage, 1.54603, 1e-5), "{pu:?}");
        assert!(close(pu.binding_position, 0.4e-3 / 3.0, 1e-5), "{pu:?}");
        assert!(close(pu.current * c.resistance, pu.voltage, 1e-15));
        assert!(!pu.at_rest());
        assert_eq!(
            pu.binding_text(&l),
            "part-way, at x = 0.1333 mm of the 0.45 mm travel"
        );
        let (i, x) = scanned(&c, &l, 200_000);
        assert!(close(pu.current, i, 1e-9), "{pu:?} against {i} at {x}");
        let d = drop_out(&c, &l);
        assert!(close(d.voltage, 0.89285, 1e-5), "{d:?}");
        assert_eq!(l.closed_position(), l.gap);
    }

    #[test]
    fn the_pull_at_rest_would_be_fourteen_percent_low() {
        let (c, l) = (coil(), line());
        let at_rest = c.resistance * (2.0 * l.preload / c.d_inductance(0.0)).sqrt();
        assert!(close(at_rest, 1.35296, 1e-5), "{at_rest}");
        let pu = pick_up(&c, &l);
        // At the rest rule's current the armature lifts off but stalls
        // where the spring has outgrown the pull.
        let i = at_rest / c.resistance;
        let x = pu.binding_position;
        assert!(c.force(i, x) < l.load(x));
        assert!(pu.voltage / at_rest - 1.0 > 0.14, "{pu:?} vs {at_rest}");
    }

    #[test]
    fn a_weak_spring_picks_up_at_rest() {
        let c = coil();
        // s·a ≤ 2p: the pull grows faster than the spring all the way.
        let l = LoadLine {
            stiffness: 2.0 * 0.1 / c.total_gap(0.0) * 0.9,
            ..line()
        };
        let pu = pick_up(&c, &l);
        assert!(pu.at_rest(), "{pu:?}");
        assert_eq!(pu.binding_text(&l), "at rest (x = 0)");
        let rest = c.resistance * (2.0 * l.preload / c.d_inductance(0.0)).sqrt();
        assert!(close(pu.voltage, rest, 1e-14));
    }

    #[test]
    fn a_stiff_blade_binds_on_its_own_piece() {
        let c = coil();
        let blade = BladeLoad {
            stiffness: 5.0e4,
            overtravel: Some(0.1e-3),
        };
        let l = LoadLine {
            blade: Some(blade),
            ..line()
        };
        assert!(close(l.travel_end(), 0.55e-3, 1e-12));
        assert_eq!(l.closed_position(), l.travel_end());
        // The load is continuous at the contact and steeper after it.
        assert!(close(l.load(0.45e-3), 0.46, 1e-12));
        assert!(close(l.load(0.55e-3), 0.1 + 800.0 * 0.55e-3 + 5.0, 1e-12));
        let pu = pick_up(&c, &l);
        assert!(
            pu.binding_position > l.gap && pu.binding_position < l.travel_end(),
            "{pu:?}"
        );
        // Independently: scan the travel on a fine grid.
        let (i, x) = scanned(&c, &l, 400_000);
        assert!(close(pu.current, i, 1e-8), "{pu:?} against {i} at {x}");
        assert!((pu.binding_position - x).abs() < 2e-9, "{pu:?} against {x}");
        assert!(pu.binding_text(&l).contains("on the blade"));
        // It needs more than the spring alone, which binds earlier.
        let alone = pick_up(&c, &line());
        assert!(pu.current > alone.current);
        // Drop-out holds the blade's force at the pole face too.
        let d = drop_out(&c, &l);
        let x_c = l.closed_position();
        assert!(close(
            c.force(d.current, x_c),
            0.1 + 800.0 * x_c + 5.0e4 * 0.1e-3,
            1e-12
        ));
    }

    #[test]
    fn a_blade_without_a_pole_face_ends_the_travel_at_the_contact() {
        let l = LoadLine {
            blade: Some(BladeLoad {
                stiffness: 6000.0,
                overtravel: None,
            }),
            ..line()
        };
        assert_eq!(l.travel_end(), l.gap);
        let c = coil();
        assert_eq!(pick_up(&c, &l), pick_up(&c, &line()));
        assert_eq!(drop_out(&c, &l), drop_out(&c, &line()));
    }

    #[test]
    fn the_load_line_of_the_mechanics() {
        let m = Mechanics {
            mass: 2e-4,
            stiffness: 800.0,
            damping: 0.04,
            force: 0.0,
            gap: 0.45e-3,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.1,
        };
        assert_eq!(LoadLine::of_mechanics(&m), line());
    }
}
