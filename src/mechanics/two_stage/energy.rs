//! When a closing is over: an energy bound.
//!
//! With the drive frozen at its present value (a constant force, or the
//! coil's pull at its present flux, which does not depend on where the
//! armature is) the relay is a mechanical system with the potential
//!
//! ```text
//! V(x_a, x_b) = ½ s x_a² + p x_a − W(x_a) + ½ s_b (x_a − x_b)²
//!             + E_c(x_b − g) + E_pole(x_a − g − o) + E_rest(−x_a)
//! ```
//!
//! (`W` the drive's work from 0, `E_*` the energies the surfaces store),
//! and every damper and every surface dissipates: the total energy
//! `E = ½ m v_a² + ½ m_b v_b² + V` never grows. V is convex in
//! `(x_a, x_b)` (convex springs and surface energies, a linear `W`).
//!
//! - A contact released by position opens only through `x_b = g`, where
//!   `E ≥ V ≥ min V(·, g)`: if `E` is already below that minimum, it
//!   never opens again: `stuck`.
//! - Released by force, a Kelvin–Voigt contact opens where
//!   `s0 δ + r0 δ̇ ≤ 0`, i.e. with `½ m_b δ̇² ≥ ½ m_b (s0 δ / r0)²`; the
//!   bound is the minimum over `δ ≥ 0` of `min V(·, g + δ)` plus that
//!   kinetic energy. A Hunt–Crossley contact opens by force only at
//!   `δ̇ ≤ −1/χ`: the bound is the global minimum of V plus `½ m_b/χ²`,
//!   or the position bound, whichever is lower.
//! - An open contact that was touched is reached again only through
//!   `x_b = g` (or, pressed in past it after a release by force, by the
//!   release's own condition): below the same bound it `ends_open`.
//! - The pole face releases the armature, or is reached again, only
//!   through `x_a = g + o` (or, released by force, where its own law
//!   lets go): below the least energy there the pole face never changes
//!   its state again, and its record is complete.
//!
//! Under a constant drive the bounds depend on the relay alone and are
//! found once per run; a check then costs one energy. Minima of a convex
//! function of one variable are found by golden section; of two, by
//! golden section nested in golden section.

use super::model::{RelayModel, StopModes, Y};
use super::relay::Release;
use crate::mechanics::driven::DriveModel;
use crate::mechanics::surface::{Surface, surface_energy};

/// Golden-section iterations: the bracket shrinks by 0.618^80 ≈ 2e-17.
const ITERATIONS: usize = 80;

/// The energy bound's state: when it was last checked, and under a
/// constant drive the bounds themselves, which then depend on the relay
/// alone and are found once.
pub(crate) struct EnergyBound {
    steps: usize,
    cached: Option<Bounds>,
}

/// The least energies at which a stop can change its state, with the
/// drive frozen.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    /// J, the closed contact releases (or, pressed in past its surface
    /// after a release by force, engages again).
    release: f64,
    /// J, the open contact, back behind its surface, reaches it again.
    reach: f64,
    /// J, the pole face releases the armature or is reached again
    /// (infinite without a pole face: it never changes).
    pole: f64,
}

impl EnergyBound {
    pub(crate) fn new() -> EnergyBound {
        EnergyBound {
            steps: 0,
            cached: None,
        }
    }

    /// A new count of steps, with the bounds found so far.
    pub(crate) fn fresh(&self) -> EnergyBound {
        EnergyBound {
            steps: 0,
            cached: self.cached,
        }
    }

    /// Whether to check at this step: every fourth accepted step.
    pub(crate) fn due(&mut self) -> bool {
        self.steps += 1;
        self.steps % 4 == 0
    }

    /// The energy of `y` with the drive frozen at `t`, and the bounds
    /// there.
    fn at<D: DriveModel>(&mut self, model: &RelayModel<'_, D>, t: f64, y: &Y) -> (f64, Bounds) {
        let frozen = Frozen::at(model, t, y);
        let bounds = match self.cached {
            Some(b) => b,
            None => {
                let b = frozen.bounds();
                if model.drive.constant().is_some() {
                    self.cached = Some(b);
                }
                b
            }
        };
        (frozen.energy(y), bounds)
    }

    /// Whether energy `e` is below `bound` beyond a margin for rounding.
    fn below<D: DriveModel>(model: &RelayModel<'_, D>, e: f64, bound: f64) -> bool {
        let m = model.m;
        let margin = 1e-9 * (e.abs() + bound.abs() + m.stiffness * m.gap * m.gap);
        e < bound - margin
    }

    /// Whether the closed contact can never release again.
    pub(crate) fn cannot_release<D: DriveModel>(
        &mut self,
        model: &RelayModel<'_, D>,
        t: f64,
        y: &Y,
        _modes: StopModes,
    ) -> bool {
        let (e, b) = self.at(model, t, y);
        Self::below(model, e, b.release)
    }

    /// Whether the open contact can never be reached again: behind its
    /// surface it must come back through it; pressed in past it (let go
    /// by its force) it engages again as a release would.
    pub(crate) fn cannot_reach<D: DriveModel>(
        &mut self,
        model: &RelayModel<'_, D>,
        t: f64,
        y: &Y,
        _modes: StopModes,
    ) -> bool {
        let (e, b) = self.at(model, t, y);
        let contact_u = if model.build.blade.is_some() {
            y[2]
        } else {
            y[0]
        };
        let bound = if contact_u > 0.0 { b.release } else { b.reach };
        Self::below(model, e, bound)
    }

    /// Whether the pole face can never change its state again (released
    /// or reached): always, without a pole face.
    pub(crate) fn pole_settled<D: DriveModel>(
        &mut self,
        model: &RelayModel<'_, D>,
        t: f64,
        y: &Y,
    ) -> bool {
        if model.build.pole_face.is_none() {
            return true;
        }
        let (e, b) = self.at(model, t, y);
        Self::below(model, e, b.pole)
    }
}

/// The model with its drive frozen at (t, e).
struct Frozen<'m, 'a, D> {
    model: &'m RelayModel<'a, D>,
    t: f64,
    e: f64,
    /// m, the range of armature positions to search.
    lo: f64,
    hi: f64,
}

impl<'m, 'a, D: DriveModel> Frozen<'m, 'a, D> {
    fn at(model: &'m RelayModel<'a, D>, t: f64, y: &Y) -> Self {
        let m = model.m;
        let g = m.gap;
        let o = model.build.pole_face.map_or(0.0, |p| p.overtravel);
        let push = model.drive.force(t, g + y[0], y[4]).abs() + m.preload;
        let reach = 4.0 * (g + o + push / m.stiffness) + (g + y[0]).abs();
        let lo = match (model.rest, &model.back) {
            (true, None | Some(Surface::Rigid { .. })) => 0.0,
            _ => -reach,
        };
        let mut hi = reach;
        if let Some(p) = &model.build.pole_face
            && matches!(p.surface, Surface::Rigid { .. })
        {
            hi = g + p.overtravel;
        }
        hi = hi.min(model.drive.pole() * (1.0 - 1e-9));
        Frozen {
            model,
            t,
            e: y[4],
            lo,
            hi,
        }
    }

    /// J, the potential at armature `xa`, contact point `xb`.
    fn potential(&self, xa: f64, xb: f64) -> f64 {
        let model = self.model;
        let m = model.m;
        let g = m.gap;
        let mut v = 0.5 * m.stiffness * xa * xa + m.preload * xa
            - model.drive.held_work(self.t, self.e, 0.0, xa);
        match &model.build.blade {
            Some(b) => {
                v += 0.5 * b.stiffness * (xa - xb) * (xa - xb);
                v += surface_energy(&model.contact, xb - g);
            }
            None => v += surface_energy(&model.contact, xa - g),
        }
        if let Some(p) = &model.build.pole_face {
            v += surface_energy(&p.surface, xa - g - p.overtravel);
        }
        if let (true, Some(b)) = (model.rest, &model.back) {
            v += surface_energy(b, -xa);
        }
        v
    }

    /// J, the total energy of state `y`.
    fn energy(&self, y: &Y) -> f64 {
        let model = self.model;
        let g = model.m.gap;
        let kinetic = 0.5 * model.m.mass * y[1] * y[1]
            + model
                .build
                .blade
                .map_or(0.0, |b| 0.5 * b.mass * y[3] * y[3]);
        let xb = if model.build.blade.is_some() {
            g + y[2]
        } else {
            g + y[0]
        };
        kinetic + self.potential(g + y[0], xb)
    }

    /// J, the least potential with the contact point at `g + delta`.
    fn at_contact(&self, delta: f64) -> f64 {
        let xb = self.model.m.gap + delta;
        if self.model.build.blade.is_none() {
            return self.potential(xb, xb);
        }
        golden(|xa| self.potential(xa, xb), self.lo, self.hi).1
    }

    /// The least energies at which each stop can change its state.
    fn bounds(&self) -> Bounds {
        let model = self.model;
        let reach = self.at_contact(0.0);
        let contact_mass = model.build.blade.map_or(model.m.mass, |b| b.mass);
        let release = match model.build.release {
            Release::Position => reach,
            Release::Force => {
                self.by_force(&model.contact, contact_mass, reach, |d| self.at_contact(d))
            }
        };
        let pole = match &model.build.pole_face {
            None => f64::INFINITY,
            Some(p) => {
                let plane = self.at_pole(0.0);
                match p.release {
                    Release::Position => plane,
                    Release::Force => {
                        self.by_force(&p.surface, model.m.mass, plane, |d| self.at_pole(d))
                    }
                }
            }
        };
        Bounds {
            release,
            reach,
            pole,
        }
    }

    /// J, the least energy at which a surface released by its force lets
    /// go of a body of `mass`, `plane` the least potential with the body
    /// on the surface and `at(δ)` the least at penetration δ.
    ///
    /// A Kelvin–Voigt surface lets go where `s0 δ + r0 δ̇ ≤ 0`, i.e. with
    /// the kinetic energy `½ mass (s0 δ / r0)²` at least: the least over
    /// `δ ≥ 0` of `at(δ)` plus that, a convex function. Past the δ where
    /// that kinetic energy alone exceeds `plane` less the least potential
    /// anywhere, the sum exceeds `plane` (its value at δ = 0), so the
    /// search stops there and the bound depends on the relay alone. A
    /// Hunt–Crossley surface lets go only at `δ̇ ≤ −1/χ`: the least
    /// potential anywhere plus `½ mass/χ²`, or `plane`, the lower.
    fn by_force(&self, surface: &Surface, mass: f64, plane: f64, at: impl Fn(f64) -> f64) -> f64 {
        match *surface {
            Surface::KelvinVoigt { stiffness, damping } if damping > 0.0 => {
                let need = |d: f64| 0.5 * mass * (stiffness * d / damping).powi(2);
                let room = (plane - self.global()).max(0.0);
                let top = damping / stiffness * (2.0 * room / mass).sqrt();
                if top <= 0.0 {
                    return plane;
                }
                golden(|d| at(d) + need(d), 0.0, top).1.min(plane)
            }
            Surface::HuntCrossley { chi, .. } if chi > 0.0 => {
                plane.min(self.global() + 0.5 * mass / (chi * chi))
            }
            _ => plane,
        }
    }

    /// J, the least potential with the armature at `δ` past the pole face.
    fn at_pole(&self, delta: f64) -> f64 {
        let model = self.model;
        let o = model.build.pole_face.map_or(0.0, |p| p.overtravel);
        let xa = model.m.gap + o + delta;
        if model.build.blade.is_none() {
            return self.potential(xa, xa);
        }
        golden(
            |xb| self.potential(xa, xb),
            self.lo,
            self.hi.max(xa) + model.m.gap,
        )
        .1
    }

    /// J, the least potential anywhere.
    fn global(&self) -> f64 {
        let model = self.model;
        if model.build.blade.is_none() {
            return golden(|x| self.potential(x, x), self.lo, self.hi).1;
        }
        let inner = |xa: f64| {
            golden(
                |xb| self.potential(xa, xb),
                self.lo,
                self.hi.max(xa) + model.m.gap,
            )
            .1
        };
        golden(inner, self.lo, self.hi).1
    }
}

/// (x, f(x)) at the minimum of a convex `f` on `[lo, hi]`.
fn golden(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> (f64, f64) {
    golden_to(f, lo, hi, 1e-15)
}

/// [`golden`], stopped once the bracket is within `relative` of its
/// ends' size.
fn golden_to(f: impl Fn(f64) -> f64, lo: f64, hi: f64, relative: f64) -> (f64, f64) {
    const R: f64 = 0.618_033_988_749_894_9;
    let (mut a, mut b) = (lo, hi);
    let mut c = b - R * (b - a);
    let mut d = a + R * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..ITERATIONS {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - R * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + R * (b - a);
            fd = f(d);
        }
        if b - a <= relative * (a.abs() + b.abs()) {
            break;
        }
    }
    let (fa, fb) = (f(lo), f(hi));
    [(lo, fa), (hi, fb), (c, fc), (d, fd)]
        .into_iter()
        .fold((c, fc), |best, p| if p.1 < best.1 { p } else { best })
}

/// J, the total energy of state `y` under a constant force (the force's
/// work folded into the potential), or `None` under a drive that varies.
/// It never grows when every stop is released by position (every damper
/// and surface dissipates); an event where it has grown is an engine
/// error, never a result.
pub(crate) fn step_energy<D: DriveModel>(model: &RelayModel<'_, D>, y: &Y) -> Option<f64> {
    model.drive.constant()?;
    Some(Frozen::at(model, 0.0, y).energy(y))
}

/// m, the widest opening of the contact that energy `j` allows under a
/// constant force: the contact point cannot go back past the least `x_b`
/// at which the least potential over the armature, `min V(·, x_b)`, is at
/// most `j`. The pole face is left out (it only adds energy), so the bound
/// is loose but never wrong.
/// `(a, b, c)`: the least over `x_a` of `½ s x_a² − net x_a + ½ s_b (x_a − x_b)²`
/// (the armature's spring, the force's work and the blade) is the
/// quadratic `a x_b² + b x_b + c` in `x_b`; with no blade, `½ s x² − net x`
/// itself.
fn least_over_armature<D: DriveModel>(model: &RelayModel<'_, D>, net: f64) -> (f64, f64, f64) {
    let s = model.m.stiffness;
    match &model.build.blade {
        Some(blade) => {
            let sb = blade.stiffness;
            (
                0.5 * sb * s / (s + sb),
                -net * sb / (s + sb),
                -net * net / (2.0 * (s + sb)),
            )
        }
        None => (0.5 * s, -net, 0.0),
    }
}

pub(crate) fn widest_opening<D: DriveModel>(model: &RelayModel<'_, D>, j: f64) -> Option<f64> {
    let force = model.drive.constant()?;
    let m = model.m;
    let net = force - m.preload;
    let (a, b, c) = least_over_armature(model, net);
    let disc = b * b - 4.0 * a * (c - j);
    if disc < 0.0 {
        return Some(0.0);
    }
    let back = (-b - disc.sqrt()) / (2.0 * a);
    Some((m.gap - back).max(0.0))
}

/// After a `stuck` ending under a constant force: the least and largest
/// force the closed contact's law can still give, from the energy `j` of
/// state `y` (the energy only falls). The contact point stays where the
/// least potential over the armature's positions, plus the contact's own
/// energy, is below `j`: a convex function of the penetration `δ`, whose
/// sublevel set `[δ_lo, δ_hi]` is bracketed from the present `δ` and
/// bisected; the blade's speed is at most `√(2 (j − min V)/m_b)`. `None`
/// where there is no such bound (a drive that varies, a rest stop, a
/// rigid contact, whose force is the blade's spring).
pub(crate) fn force_reach<D: DriveModel>(model: &RelayModel<'_, D>, y: &Y) -> Option<(f64, f64)> {
    let force = model.drive.constant()?;
    if model.rest || matches!(model.contact, Surface::Rigid { .. }) {
        return None;
    }
    let j = step_energy(model, y)?;
    let m = model.m;
    let (g, s, net) = (m.gap, m.stiffness, force - m.preload);
    let pole = model.build.pole_face.map(|p| (g + p.overtravel, p.surface));
    // The armature's part of the potential at x_a, the blade's spring
    // to x_b included.
    let armature = |xa: f64, xb: f64, sb: f64| {
        let mut v = 0.5 * s * xa * xa - net * xa + 0.5 * sb * (xa - xb) * (xa - xb);
        if let Some((plane, surface)) = &pole {
            v += surface_energy(surface, xa - plane);
        }
        v
    };
    // Its least value over x_a, at x_b: the unconstrained minimum when
    // the pole face is not pressed there, else searched between the pole
    // face's plane and that minimum (convex).
    let least = |xb: f64| -> f64 {
        let Some(blade) = &model.build.blade else {
            return armature(xb, xb, 0.0);
        };
        let sb = blade.stiffness;
        let free = (net + sb * xb) / (s + sb);
        match &pole {
            Some((plane, _)) if free > *plane => golden(|xa| armature(xa, xb, sb), *plane, free).1,
            _ => armature(free, xb, sb),
        }
    };
    let h = |delta: f64| least(g + delta) + surface_energy(&model.contact, delta);
    let now = if model.build.blade.is_some() {
        y[2]
    } else {
        y[0]
    };
    // Not inside its own set (a NaN, or rounding past the edge): no
    // bound.
    if !matches!(
        h(now).partial_cmp(&j),
        Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
    ) {
        return None;
    }
    let mass = model.build.blade.map_or(m.mass, |b| b.mass);
    // Without a pole face, with a Kelvin–Voigt contact pressed in over
    // the whole set: `h` is the quadratic `A δ² + B δ + C` there, and
    // the set and its least energy are had in closed form.
    if let (None, Surface::KelvinVoigt { stiffness, damping }) = (&pole, model.contact) {
        let (a, b, c) = least_over_armature(model, net);
        let qa = a + 0.5 * stiffness;
        let qb = 2.0 * a * g + b;
        let qc = a * g * g + b * g + c;
        let floor = qc - qb * qb / (4.0 * qa);
        let disc = qb * qb - 4.0 * qa * (qc - j);
        if disc >= 0.0 {
            let root = disc.sqrt();
            // Each root from the form that does not cancel.
            let far = if qb >= 0.0 {
                (-qb - root) / (2.0 * qa)
            } else {
                (-qb + root) / (2.0 * qa)
            };
            let near = if far != 0.0 {
                (qc - j) / (qa * far)
            } else {
                0.0
            };
            let (lo, hi) = (far.min(near), far.max(near));
            if lo > 0.0 {
                // Widened by the rounding of the quadratic's coefficients.
                let pad = 1e-12 * (hi.abs() + g);
                let (lo, hi) = (lo - pad, hi + pad);
                let speed = (2.0 * (j - floor).max(0.0) / mass).sqrt();
                return Some((
                    stiffness * lo - damping * speed,
                    stiffness * hi + damping * speed,
                ));
            }
        }
    }
    // The sublevel set's end on one side of `now`: widened until above
    // `j`, then bisected.
    let edge = |dir: f64| {
        let mut step = now.abs().max(1e-6 * g);
        let mut inside = now;
        let mut outside = now + dir * step;
        let mut widenings = 0;
        while h(outside) <= j {
            inside = outside;
            step *= 2.0;
            outside = now + dir * step;
            widenings += 1;
            if widenings > 200 {
                return None;
            }
        }
        // To 1e-11 of the penetration: the force's bound to well under
        // the 1e-9 it is held to.
        let resolution = 1e-11 * now.abs().max(1e-6 * g);
        while (outside - inside).abs() > resolution {
            let mid = 0.5 * (inside + outside);
            if mid == inside || mid == outside {
                break;
            }
            if h(mid) <= j {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        Some(outside)
    };
    let (lo, hi) = (edge(-1.0)?, edge(1.0)?);
    // The least energy to 1e-16 of its scale: its minimiser to 1e-8.
    let floor = golden_to(h, lo, hi, 1e-8).1;
    let speed = (2.0 * (j - floor).max(0.0) / mass).sqrt();
    let (least_force, largest) = match model.contact {
        Surface::KelvinVoigt { stiffness, damping } => (
            stiffness * lo - damping * speed,
            stiffness * hi + damping * speed,
        ),
        Surface::HuntCrossley {
            stiffness,
            exponent,
            chi,
        } => {
            let spring = |d: f64| stiffness * d.max(0.0).powf(exponent);
            (
                spring(lo) * (1.0 - chi * speed),
                spring(hi) * (1.0 + chi * speed),
            )
        }
        Surface::Rigid { .. } => return None,
    };
    Some((least_force, largest))
}

#[cfg(test)]
mod tests {
    use super::golden;

    #[test]
    fn golden_section_finds_a_parabola_s_minimum() {
        let (x, fx) = golden(|x| (x - 0.3) * (x - 0.3) + 2.0, -1.0, 4.0);
        assert!((x - 0.3).abs() < 1e-7, "{x}");
        assert!((fx - 2.0).abs() < 1e-13);
        // At a bound when the minimum lies outside.
        let (x, _) = golden(|x| (x - 9.0) * (x - 9.0), -1.0, 4.0);
        assert_eq!(x, 4.0);
    }
}
