//! The relays the mechanics benches share.

use chatterspice::mechanics::two_stage::{Blade, Release, TwoStage};
use chatterspice::{Mechanics, Settings, Surface};

/// The paper's reference sequence (docs/model.md): Kelvin–Voigt, 18
/// contacts, run to t = 100.
pub fn reference() -> (Mechanics, Surface, Settings) {
    (
        Mechanics {
            mass: 1.0,
            stiffness: 1.0,
            damping: 0.1,
            force: 1.0,
            gap: 0.9,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        },
        Surface::KelvinVoigt {
            stiffness: 100.0,
            damping: 2.0 * 0.4692,
        },
        Settings {
            t_end: 100.0,
            ..Settings::default()
        },
    )
}

/// The reference armature carrying a blade of a fifth of its mass, as
/// stiff as the contact (s_b = 100 s, r_b = 1): also 18 contacts, by the
/// two-stage engine.
pub fn on_a_blade() -> TwoStage {
    TwoStage {
        blade: Some(Blade {
            mass: 0.2,
            stiffness: 100.0,
            damping: 1.0,
        }),
        pole_face: None,
        release: Release::Position,
    }
}
