//! The `/validation` channel (`ricochet run --validate`): the referee's verdict on each
//! frame, as the recorder writes it.

use ricochet_oracle::FrameReport;
use serde::Serialize;

/// The `/validation` channel's message.
#[derive(Serialize)]
pub struct ValidationMsg<'a> {
    frame: u64,
    contacts_compared: u64,
    mismatches: u64,
    worst_depth_error: f64,
    worst_normal_error: f64,
    pairs_confirmed: u64,
    swept_confirmed: u64,
    explained: &'a std::collections::BTreeMap<&'static str, u64>,
    details: &'a [String],
}

/// The JSON Schema of `/validation`.
pub const SCHEMA: &str = include_str!("schemas/Validation.json");

impl<'a> ValidationMsg<'a> {
    /// The message for one frame's report.
    pub fn from_report(r: &'a FrameReport) -> ValidationMsg<'a> {
        ValidationMsg {
            frame: r.frame,
            contacts_compared: r.contacts_compared,
            mismatches: r.mismatches,
            worst_depth_error: r.worst_depth_error,
            worst_normal_error: r.worst_normal_error,
            pairs_confirmed: r.pairs_confirmed,
            swept_confirmed: r.swept_confirmed,
            explained: &r.explained,
            details: &r.details,
        }
    }
}
