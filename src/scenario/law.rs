//! The names a surface section picks from: its law ([`SurfaceLaw`],
//! `surface.law`) and how it lets go ([`ReleaseRule`],
//! `surface.release`).

use std::fmt;

use serde::Deserialize;

use crate::mechanics::two_stage::Release;

/// `surface.law`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SurfaceLaw {
    /// `"rigid"`: an impact of no duration that reverses the speed and
    /// scales it by `restitution` (docs/model.md §2a).
    Rigid,
    /// `"kelvin-voigt"`: a linear spring `stiffness` and damper `damping`
    /// while in contact (docs/model.md §2b).
    KelvinVoigt,
    /// `"hunt-crossley"`: the force k δⁿ (1 + χ δ̇), never negative; χ given
    /// as `chi` or as `restitution` at `reference_velocity`
    /// (docs/model.md §2c).
    HuntCrossley,
}

impl SurfaceLaw {
    /// The name used in the scenario file.
    pub fn as_str(self) -> &'static str {
        match self {
            SurfaceLaw::Rigid => "rigid",
            SurfaceLaw::KelvinVoigt => "kelvin-voigt",
            SurfaceLaw::HuntCrossley => "hunt-crossley",
        }
    }

    /// The `[surface]` keys (besides `law`) this law reads.
    pub(super) fn keys(self) -> &'static [&'static str] {
        match self {
            SurfaceLaw::Rigid => &["restitution"],
            SurfaceLaw::KelvinVoigt => &["stiffness", "damping"],
            SurfaceLaw::HuntCrossley => &[
                "stiffness",
                "exponent",
                "chi",
                "restitution",
                "reference_velocity",
            ],
        }
    }

    /// The same keys, as a reader should see them in an error.
    pub(super) fn keys_described(self) -> &'static str {
        match self {
            SurfaceLaw::Rigid => "`restitution`",
            SurfaceLaw::KelvinVoigt => "`stiffness` and `damping`",
            SurfaceLaw::HuntCrossley => {
                "`stiffness`, `exponent` and `chi` (or `restitution` with `reference_velocity`)"
            }
        }
    }
}

impl fmt::Display for SurfaceLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// `surface.release` (and `pole_face.release`): how a deformable surface
/// lets go.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ReleaseRule {
    /// `"position"`: the paper's rule, back at the surface moving out.
    #[default]
    Position,
    /// `"force"`: when the contact force falls to 0.
    Force,
}

impl From<ReleaseRule> for Release {
    fn from(r: ReleaseRule) -> Release {
        match r {
            ReleaseRule::Position => Release::Position,
            ReleaseRule::Force => Release::Force,
        }
    }
}
