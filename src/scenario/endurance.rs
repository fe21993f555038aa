//! `[datasheet] electrical_endurance`: the operations a datasheet prints
//! for a test load, as printed.

use serde::{Deserialize, Serialize};

/// One printed electrical endurance figure, as printed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnduranceFigure {
    /// The operations the datasheet prints at this load.
    pub operations: f64,
    /// V, the supply (RMS for AC).
    pub voltage: f64,
    /// A, the load current (RMS for AC).
    pub current: f64,
    /// `"ac"` or `"dc"`.
    pub supply: Supply,
    /// Hz, for AC (default 50).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency: Option<f64>,
    /// The load: only `"resistive"` is simulated.
    #[serde(default = "resistive")]
    pub load: String,
}

fn resistive() -> String {
    "resistive".to_owned()
}

/// The kind of supply of an endurance test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Supply {
    /// Alternating, sinusoidal.
    Ac,
    /// Direct.
    Dc,
}

impl EnduranceFigure {
    /// The test load in words: `5 A 30 VDC resistive`, `10 A 125 VAC
    /// 60 Hz resistive`.
    pub fn label(&self) -> String {
        let supply = match self.supply {
            Supply::Dc => "VDC".to_owned(),
            Supply::Ac => match self.frequency {
                Some(h) => format!("VAC {h} Hz"),
                None => "VAC".to_owned(),
            },
        };
        format!("{} A {} {supply} {}", self.current, self.voltage, self.load)
    }
}
