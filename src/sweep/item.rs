//! `ricochet sweep … --item N|reference`: one run of a sweep in its own process, printed as
//! one JSON line ([`ItemLine`], docs/suites.md), the unit a cluster worker runs
//! (`ricochet sweep --cluster`, through `suite::cluster` like `ricochet test`). The runner
//! reads the lines back into [`Row`]s and puts them in combination order, so the CSV and
//! the chart are written from the same values as a local run's.
//!
//! Every float travels as the text Rust prints for it (`{:?}`, the shortest that reads back
//! to the same bits) because JSON has no NaN (a run that overflowed has a NaN error) and the
//! rows must come back bit for bit.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::report::Row;
use super::time::Ratio;
use crate::suite::cluster::ResultLine;

/// The version of the line's format. A field is only ever added; a change to an existing
/// one bumps this.
pub const FORMAT: u32 = 1;

/// The result line of `ricochet sweep … --item`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct ItemLine {
    /// [`FORMAT`].
    pub format: u32,
    /// Whether this is the reference run (`--item reference`) rather than a combination.
    pub reference: bool,
    /// The run, measured against the reference.
    pub row: Row,
}

impl ResultLine for ItemLine {
    /// `frames N digest X`: the final state of the run.
    fn digest_text(&self) -> String {
        format!("frames {} digest {:016x}", self.row.frames, self.row.digest)
    }
}

/// Which run an item process does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Which {
    /// The reference run, timed.
    Reference,
    /// Combination `N` (its index among all the sweep's combinations, from 0).
    Combination(usize),
}

impl std::str::FromStr for Which {
    type Err = String;

    fn from_str(s: &str) -> Result<Which, String> {
        if s == "reference" {
            return Ok(Which::Reference);
        }
        s.parse().map(Which::Combination).map_err(|_| {
            format!("--item {s:?}: expected `reference` or a combination's index (0, 1, …)")
        })
    }
}

impl std::fmt::Display for Which {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Which::Reference => f.write_str("reference"),
            Which::Combination(i) => write!(f, "{i}"),
        }
    }
}

/// `f64` as its shortest exact text (`0.1`, `NaN`, `inf`).
pub mod exact {
    use super::{Deserialize, Deserializer, Serializer};

    /// Writes `x` as `{x:?}`.
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&format!("{x:?}"))
    }

    /// Reads what [`serialize`] wrote, to the same bits.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        let text = String::deserialize(d)?;
        text.parse()
            .map_err(|_| serde::de::Error::custom(format!("not a number: {text:?}")))
    }
}

/// A timestep as `NUM/DEN` (or `NUM`).
pub mod ratio {
    use super::{Deserialize, Deserializer, Ratio, Serializer};

    /// Writes `r` as it prints.
    pub fn serialize<S: Serializer>(r: &Ratio, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&r.to_string())
    }

    /// Reads `NUM/DEN` or `NUM`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Ratio, D::Error> {
        let text = String::deserialize(d)?;
        let (num, den) = text.split_once('/').unwrap_or((&text, "1"));
        num.parse()
            .ok()
            .zip(den.parse().ok())
            .and_then(|(n, d)| Ratio::new(n, d))
            .ok_or_else(|| serde::de::Error::custom(format!("not a timestep: {text:?}")))
    }
}

/// A digest as 16 hex digits.
pub mod hex {
    use super::{Deserialize, Deserializer, Serializer};

    /// Writes `x` as `{x:016x}`.
    pub fn serialize<S: Serializer>(x: &u64, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&format!("{x:016x}"))
    }

    /// Reads 16 hex digits.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<u64, D::Error> {
        let text = String::deserialize(d)?;
        u64::from_str_radix(&text, 16)
            .map_err(|_| serde::de::Error::custom(format!("not a digest: {text:?}")))
    }
}

/// Prints the line of one run.
pub fn print(reference: bool, row: Row) -> anyhow::Result<()> {
    let line = ItemLine {
        format: FORMAT,
        reference,
        row,
    };
    crate::out::print(&(serde_json::to_string(&line)? + "\n"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::error::Measures;

    #[test]
    fn a_line_reads_back_to_the_same_bits_nan_included() {
        let row = Row {
            index: 3,
            values: vec!["1/60".into(), "circle:1.2".into()],
            dt: Ratio::new(1, 60).unwrap(),
            frames: 120,
            rounded: 1,
            step_seconds: 1.234_567_890_123_456_7e-6,
            digest: 0x00ab_cdef_0123_4567,
            error: Measures {
                matched_frames: 121,
                position_max: f64::NAN,
                position_rms: 0.1 + 0.2,
                worst_body: "ship".into(),
                energy_drift: -1e-300,
                energy_error: f64::INFINITY,
                ..Measures::default()
            },
            overflow: None,
        };
        let line = ItemLine {
            format: FORMAT,
            reference: false,
            row: row.clone(),
        };
        let text = serde_json::to_string(&line).unwrap();
        assert!(text.contains(r#""dt":"1/60""#), "{text}");
        assert!(text.contains(r#""digest":"00abcdef01234567""#), "{text}");
        let back: ItemLine = serde_json::from_str(&text).unwrap();
        let bits = |r: &Row| {
            [
                r.step_seconds,
                r.error.position_max,
                r.error.position_rms,
                r.error.energy_drift,
                r.error.energy_error,
            ]
            .map(f64::to_bits)
        };
        assert_eq!(bits(&back.row), bits(&row));
        assert_eq!((back.row.dt, back.row.digest), (row.dt, row.digest));
        assert_eq!(back.row.values, row.values);
    }

    #[test]
    fn which_item_reads_reference_or_an_index() {
        assert_eq!("reference".parse::<Which>(), Ok(Which::Reference));
        assert_eq!("7".parse::<Which>(), Ok(Which::Combination(7)));
        assert!("-1".parse::<Which>().unwrap_err().contains("--item"));
    }
}
