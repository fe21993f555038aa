//! A datasheet figure as the datasheet prints it: a typical value, a
//! maximum, a minimum, a tolerance, or several of them
//! (`operate_time = { typ = 5e-3, max = 10e-3 }`). A plain number is a
//! typical value.

use std::fmt;

use serde::de::{self, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The band a typical value without a printed tolerance is read with:
/// ±20 %. A nominal relay meets a typical figure when it lies within it.
pub const TYPICAL_BAND: f64 = 0.20;

/// The relative precision a figure printed without a tolerance is read
/// with when a fit is held to it: ±1 %, about the two or three digits a
/// datasheet prints.
pub const PRINTED_PRECISION: f64 = 0.01;

/// One datasheet figure as printed. At least one of `typ`, `min`, `max`;
/// `tolerance` (relative, `0.10` for ±10 %) only with `typ`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PrintedFigure {
    /// The typical value: a target for a fit, not a bound on every relay.
    pub typ: Option<f64>,
    /// The smallest value any relay of the type shows (a bound).
    pub min: Option<f64>,
    /// The largest value any relay of the type shows (a bound).
    pub max: Option<f64>,
    /// Relative tolerance around `typ` (`0.10`: ±10 %), a bound on every
    /// relay.
    pub tolerance: Option<f64>,
}

/// How a figure is stated, in words for reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FigureKind {
    /// A typical value only.
    Typical,
    /// A typical value with a tolerance or bounds.
    TypicalWithBand,
    /// A maximum only.
    Maximum,
    /// A minimum only.
    Minimum,
    /// A minimum and a maximum.
    Range,
}

impl PrintedFigure {
    /// A typical value.
    pub fn typical(value: f64) -> PrintedFigure {
        PrintedFigure {
            typ: Some(value),
            ..PrintedFigure::default()
        }
    }

    /// A maximum.
    pub fn at_most(value: f64) -> PrintedFigure {
        PrintedFigure {
            max: Some(value),
            ..PrintedFigure::default()
        }
    }

    /// A minimum.
    pub fn at_least(value: f64) -> PrintedFigure {
        PrintedFigure {
            min: Some(value),
            ..PrintedFigure::default()
        }
    }

    /// How the figure is stated.
    pub fn kind(&self) -> FigureKind {
        match (self.typ, self.min, self.max) {
            (Some(_), None, None) if self.tolerance.is_none() => FigureKind::Typical,
            (Some(_), ..) => FigureKind::TypicalWithBand,
            (None, None, Some(_)) => FigureKind::Maximum,
            (None, Some(_), None) => FigureKind::Minimum,
            _ => FigureKind::Range,
        }
    }

    /// The value that stands for the figure: the typical one, else the
    /// maximum, else the minimum.
    pub fn nominal(&self) -> f64 {
        self.typ.or(self.max).or(self.min).unwrap_or(f64::NAN)
    }

    /// The values every relay of the type shows, as printed: from the
    /// minimum and the tolerance below the typical value (the tighter),
    /// to the maximum and the tolerance above it. Unbounded sides are
    /// infinite; a typical value alone bounds nothing.
    pub fn band(&self) -> (f64, f64) {
        let mut lo = self.min.unwrap_or(f64::NEG_INFINITY);
        let mut hi = self.max.unwrap_or(f64::INFINITY);
        if let (Some(t), Some(tol)) = (self.typ, self.tolerance) {
            lo = lo.max(t * (1.0 - tol));
            hi = hi.min(t * (1.0 + tol));
        }
        (lo, hi)
    }

    /// Whether the figure bounds every relay (a minimum, a maximum or a
    /// tolerance).
    pub fn is_bound(&self) -> bool {
        let (lo, hi) = self.band();
        lo.is_finite() || hi.is_finite()
    }

    /// Whether `value` meets the figure as printed: inside its band (with
    /// a relative slack of 1e-9 for rounding). A typical value alone is
    /// met by anything: it describes the type, not each relay.
    pub fn holds(&self, value: f64) -> bool {
        let (lo, hi) = self.band();
        let slack = 1e-9;
        value >= lo - slack * lo.abs() && value <= hi + slack * hi.abs()
    }

    /// Whether a nominal relay meets the figure: inside its band, and
    /// within [`TYPICAL_BAND`] of a typical value printed without a
    /// tolerance.
    pub fn met_by_nominal(&self, value: f64) -> bool {
        let near_typical = match (self.typ, self.tolerance) {
            (Some(t), None) => ((value - t) / t).abs() <= TYPICAL_BAND + 1e-12,
            _ => true,
        };
        self.holds(value) && near_typical
    }

    /// The relative misfit a fit minimises: from the typical value when
    /// one is printed (a target), else the distance outside the band
    /// relative to the bound crossed (0 inside: a bound, not a target).
    pub fn misfit(&self, value: f64) -> f64 {
        if let Some(t) = self.typ {
            return (value - t) / t;
        }
        let (lo, hi) = self.band();
        if value > hi {
            (value - hi) / hi
        } else if value < lo {
            (value - lo) / lo
        } else {
            0.0
        }
    }

    /// The relative 1σ the figure stands for when it fixes a key: a
    /// tolerance band ±t read as a uniform spread (σ = t/√3); a value
    /// printed without one (a typical value, a bound the fit sits on)
    /// read to its printed precision ([`PRINTED_PRECISION`], again as a
    /// uniform spread).
    pub fn relative_sigma(&self) -> f64 {
        self.tolerance.unwrap_or(PRINTED_PRECISION) / 3f64.sqrt()
    }

    /// What is wrong with the figure, if anything: `Err((field, value,
    /// requirement))` naming the field (`typ`, `min`, `max`,
    /// `tolerance`, or `""` for the figure as a whole).
    pub fn check(&self) -> Result<(), (&'static str, f64, &'static str)> {
        if self.typ.is_none() && self.min.is_none() && self.max.is_none() {
            return Err((
                "",
                f64::NAN,
                "needs a value: a number (typical), or a table with `typ`, `min` and/or `max`",
            ));
        }
        for (field, v) in [("typ", self.typ), ("min", self.min), ("max", self.max)] {
            if let Some(v) = v
                && !(v > 0.0 && v.is_finite())
            {
                return Err((field, v, "must be a positive, finite number"));
            }
        }
        if let Some(t) = self.tolerance {
            if self.typ.is_none() {
                return Err((
                    "tolerance",
                    t,
                    "is relative to the typical value: give `typ` with it",
                ));
            }
            if !(t > 0.0 && t < 1.0) {
                return Err((
                    "tolerance",
                    t,
                    "must lie in (0, 1): a relative tolerance, 0.10 for ±10 %",
                ));
            }
        }
        if let (Some(lo), Some(hi)) = (self.min, self.max)
            && lo > hi
        {
            return Err(("min", lo, "must not exceed `max`"));
        }
        if let Some(t) = self.typ {
            if self.max.is_some_and(|m| t > m) {
                return Err(("typ", t, "must not exceed `max`"));
            }
            if self.min.is_some_and(|m| t < m) {
                return Err(("typ", t, "must not be below `min`"));
            }
        }
        Ok(())
    }
}

impl fmt::Display for PrintedFigure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if let Some(v) = self.typ {
            parts.push(format!("typ. {v}"));
        }
        if let Some(t) = self.tolerance {
            parts.push(format!("±{} %", t * 100.0));
        }
        if let Some(v) = self.min {
            parts.push(format!("min. {v}"));
        }
        if let Some(v) = self.max {
            parts.push(format!("max. {v}"));
        }
        f.write_str(&parts.join(", "))
    }
}

impl Serialize for PrintedFigure {
    /// A typical value alone as a plain number; anything else as a table
    /// of the fields printed.
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        if let (Some(t), FigureKind::Typical) = (self.typ, self.kind()) {
            return serializer.serialize_f64(t);
        }
        let fields = [
            ("typ", self.typ),
            ("min", self.min),
            ("max", self.max),
            ("tolerance", self.tolerance),
        ];
        let mut map = serializer.serialize_map(None)?;
        for (name, v) in fields {
            if let Some(v) = v {
                map.serialize_entry(name, &v)?;
            }
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for PrintedFigure {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(FigureVisitor)
    }
}

struct FigureVisitor;

const FIELDS: &[&str] = &["typ", "min", "max", "tolerance"];

impl<'de> Visitor<'de> for FigureVisitor {
    type Value = PrintedFigure;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number (the typical value) or a table such as { typ = 1.0, max = 2.0 }")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<PrintedFigure, E> {
        Ok(PrintedFigure::typical(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<PrintedFigure, E> {
        Ok(PrintedFigure::typical(v as f64))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<PrintedFigure, E> {
        Ok(PrintedFigure::typical(v as f64))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<PrintedFigure, A::Error> {
        let mut figure = PrintedFigure::default();
        while let Some(key) = map.next_key::<String>()? {
            let slot = match key.as_str() {
                "typ" => &mut figure.typ,
                "min" => &mut figure.min,
                "max" => &mut figure.max,
                "tolerance" => &mut figure.tolerance,
                other => return Err(de::Error::unknown_field(other, FIELDS)),
            };
            *slot = Some(map.next_value::<f64>()?);
        }
        Ok(figure)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_maximum_bounds_and_a_typical_targets() {
        let max = PrintedFigure::at_most(10e-3);
        assert!(max.holds(9e-3) && !max.holds(11e-3));
        assert_eq!(max.misfit(9e-3), 0.0);
        assert!((max.misfit(11e-3) - 0.1).abs() < 1e-12);
        let typ = PrintedFigure::typical(1e-3);
        assert!(typ.holds(5e-3), "a typical value bounds no relay");
        assert!(!typ.met_by_nominal(1.3e-3) && typ.met_by_nominal(1.1e-3));
        assert!((typ.misfit(1.1e-3) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn a_tolerance_is_a_band_around_the_typical_value() {
        let r = PrintedFigure {
            typ: Some(63.0),
            tolerance: Some(0.10),
            ..PrintedFigure::default()
        };
        let (lo, hi) = r.band();
        assert!((lo - 56.7).abs() < 1e-12 && (hi - 69.3).abs() < 1e-12);
        assert!(r.holds(69.0) && !r.holds(70.0));
        assert!((r.relative_sigma() - 0.10 / 3f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn reads_a_number_or_a_table_and_writes_them_back() {
        #[derive(Debug, Deserialize, Serialize)]
        struct T {
            a: PrintedFigure,
            b: PrintedFigure,
        }
        let t: T = toml::from_str("a = 5\nb = { typ = 1e-3, max = 5e-3 }\n").unwrap();
        assert_eq!(t.a, PrintedFigure::typical(5.0));
        assert_eq!((t.b.typ, t.b.max), (Some(1e-3), Some(5e-3)));
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(json, r#"{"a":5.0,"b":{"typ":0.001,"max":0.005}}"#);
        let bad = toml::from_str::<T>("a = 5\nb = { typo = 1 }\n").unwrap_err();
        assert!(bad.to_string().contains("typo"), "{bad}");
    }

    #[test]
    fn refuses_figures_that_say_nothing_or_contradict_themselves() {
        assert!(PrintedFigure::default().check().is_err());
        let inverted = PrintedFigure {
            min: Some(2.0),
            max: Some(1.0),
            ..PrintedFigure::default()
        };
        assert_eq!(inverted.check().unwrap_err().0, "min");
        let loose = PrintedFigure {
            max: Some(1.0),
            tolerance: Some(0.1),
            ..PrintedFigure::default()
        };
        assert_eq!(loose.check().unwrap_err().0, "tolerance");
    }
}
