//! Surface laws: what the fixed contact does once it is touched
//! (docs/model.md §2). Let δ = x − g ≥ 0 be the penetration and Fc the force of
//! the fixed contact on the moving one (positive pushes it back).

/// The fixed contact's surface law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Surface {
    /// Rigid, with constant restitution `e ∈ [0, 1]`: at the touch
    /// `ẋ ← −e ẋ`, contact time zero.
    Rigid {
        /// e, the ratio of rebound to impact speed, in [0, 1].
        restitution: f64,
    },
    /// The paper's linear "equivalent stiffness surface":
    /// `Fc = s0 δ + r0 δ̇` (N/m, N·s/m). Released when x returns to g
    /// moving away (the paper's rule), so Fc may be negative just before
    /// release (the Kelvin–Voigt "sticky force").
    KelvinVoigt {
        /// N/m, the surface stiffness s0.
        stiffness: f64,
        /// N·s/m, the surface damping r0.
        damping: f64,
    },
    /// Hunt–Crossley: `Fc = k δⁿ (1 + χ δ̇)`, clamped at Fc ≥ 0.
    /// `stiffness` is k (N/mⁿ), `exponent` n (1 for the paper's linear
    /// spring, 1.5 for Hertz), `chi` χ = λ/k (s/m).
    HuntCrossley {
        /// N/mⁿ, k.
        stiffness: f64,
        /// n, dimensionless.
        exponent: f64,
        /// s/m, χ = λ/k.
        chi: f64,
    },
}

impl Surface {
    /// The contact force (N) at penetration `delta` ≥ 0 (m) and
    /// penetration rate `delta_dot` (m/s). Zero for a rigid surface, whose
    /// force is an impulse.
    pub fn force(&self, delta: f64, delta_dot: f64) -> f64 {
        match *self {
            Surface::Rigid { .. } => 0.0,
            Surface::KelvinVoigt { stiffness, damping } => stiffness * delta + damping * delta_dot,
            Surface::HuntCrossley {
                stiffness,
                exponent,
                chi,
            } => {
                // x¹ is x to the last bit, and no power function to call.
                let d = delta.max(0.0);
                let spring = stiffness * if exponent == 1.0 { d } else { d.powf(exponent) };
                (spring * (1.0 + chi * delta_dot)).max(0.0)
            }
        }
    }
}

/// Hunt–Crossley χ (s/m) that gives restitution `e` for a free impact at
/// `reference_velocity` (m/s), from the exact relation
/// `χ v (1 + e) = ln[(1 + χ v)/(1 − χ e v)]` (independent of k, n and m).
///
/// `e` must lie in (0, 1]; e = 1 gives χ = 0. Returns `None` outside that
/// range or for a non-positive velocity.
pub fn hunt_crossley_chi(e: f64, reference_velocity: f64) -> Option<f64> {
    let valid = e > 0.0 && e <= 1.0 && reference_velocity > 0.0 && reference_velocity.is_finite();
    if !valid {
        return None;
    }
    if e == 1.0 {
        return Some(0.0);
    }
    // h(u) = ln((1+u)/(1−e u)) − u(1+e), u = χ v: h(0) = 0, h < 0 just
    // above 0 (h''(0) = e² − 1), h → +∞ as u → 1/e; one root in (0, 1/e).
    let h = |u: f64| ((1.0 + u) / (1.0 - e * u)).ln() - u * (1.0 + e);
    let mut hi = 1.0 / e;
    // Start below the pole where h is finite and positive.
    let mut k = 1.0;
    while h(hi * (1.0 - 1e-3 * k)).is_nan() || h(hi * (1.0 - 1e-3 * k)) <= 0.0 {
        k *= 0.5;
        if k < 1e-12 {
            return None;
        }
    }
    hi *= 1.0 - 1e-3 * k;
    // The low end: where h is still negative. h ≈ −(1−e²)u²/2 + O(u³).
    let mut lo = hi * 0.5;
    while h(lo) >= 0.0 {
        lo *= 0.5;
        if lo < 1e-300 {
            return None;
        }
    }
    let u = super::root::bisect(h, lo, hi, 1e-15)?;
    Some(u / reference_velocity)
}

/// The exact free-impact restitution of a Hunt–Crossley surface at impact
/// speed `v` (m/s): the root e of `χ v (1 + e) = ln[(1 + χ v)/(1 − χ e v)]`.
pub fn hunt_crossley_restitution(chi: f64, v: f64) -> Option<f64> {
    let u = chi * v;
    if u.is_nan() || u < 0.0 || u.is_infinite() {
        return None;
    }
    if u == 0.0 {
        return Some(1.0);
    }
    // g(e) = ln((1+u)/(1−e u)) − u(1+e) is negative at e = 0 and grows
    // to +∞ as e → 1/u (if 1/u < 1); the root is the one in (0, 1].
    let g = |e: f64| ((1.0 + u) / (1.0 - e * u)).ln() - u * (1.0 + e);
    let hi = if u < 1.0 {
        1.0
    } else {
        (1.0 / u) * (1.0 - 1e-15)
    };
    if g(hi) <= 0.0 {
        return Some(hi);
    }
    super::root::bisect(g, 0.0, hi, 1e-15)
}

/// N, a surface's force at penetration `u` (m) and rate `v` (m/s); zero
/// off the surface and for a rigid one.
pub(crate) fn surface_force(surface: &Surface, u: f64, v: f64) -> f64 {
    match *surface {
        Surface::Rigid { .. } => 0.0,
        // The paper's rule: no clamp, the surface may pull before release.
        Surface::KelvinVoigt { stiffness, damping } => stiffness * u + damping * v,
        Surface::HuntCrossley { .. } if u <= 0.0 => 0.0,
        _ => surface.force(u, v),
    }
}

/// W, the power a surface dissipates at penetration `u` and rate `v`: its
/// force times the rate, less what its spring stores.
pub(crate) fn surface_loss(surface: &Surface, u: f64, v: f64) -> f64 {
    match *surface {
        Surface::Rigid { .. } => 0.0,
        Surface::KelvinVoigt { damping, .. } => damping * v * v,
        Surface::HuntCrossley {
            stiffness,
            exponent,
            ..
        } => {
            if u <= 0.0 {
                0.0
            } else {
                (surface_force(surface, u, v) - stiffness * u.powf(exponent)) * v
            }
        }
    }
}

/// J, the energy a surface stores at penetration `u`.
pub(crate) fn surface_energy(surface: &Surface, u: f64) -> f64 {
    match *surface {
        Surface::Rigid { .. } => 0.0,
        Surface::KelvinVoigt { stiffness, .. } => 0.5 * stiffness * u.max(0.0).powi(2),
        Surface::HuntCrossley {
            stiffness,
            exponent,
            ..
        } => stiffness * u.max(0.0).powf(exponent + 1.0) / (exponent + 1.0),
    }
}
