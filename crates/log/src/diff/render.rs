//! The human-readable report of a comparison: its head (equal, or the first difference), then
//! the counts per topic. The head can be printed on its own as soon as the first difference
//! is known ([`super::diff_files_with`]), the counts when both logs have been read.

use std::path::Path;

use super::{Divergence, Report};

/// The human-readable report: [`render_head`] then [`render_counts`].
pub fn render(report: &Report, a: &Path, b: &Path) -> String {
    render_head(report.first.as_ref(), report.tolerance, a, b) + &render_counts(report)
}

/// The report's first lines: that the logs are equal (within `tolerance`), or that they
/// differ and where first.
pub fn render_head(first: Option<&Divergence>, tolerance: f64, a: &Path, b: &Path) -> String {
    let mut s = String::new();
    match first {
        None => {
            s += &format!(
                "{} and {} are equal{}\n",
                a.display(),
                b.display(),
                if tolerance > 0.0 {
                    format!(" within {tolerance}")
                } else {
                    String::new()
                }
            )
        }
        Some(d) => {
            s += &format!("{} and {} differ\n", a.display(), b.display());
            let frame = d.frame.map_or_else(
                || format!("t = {} ns", d.time_ns),
                |f| format!("frame {f} (t = {:.6} s)", d.time_ns as f64 * 1e-9),
            );
            if d.field == "schema" {
                s += &format!("first difference: the schema of topic {}", d.topic);
            } else {
                s += &format!("first difference: {frame}, topic {}", d.topic);
            }
            match &d.body {
                Some(pair) if pair.starts_with("pair ") => s += &format!(", {pair}"),
                Some(body) => s += &format!(", body {body}"),
                None => {}
            }
            s += &format!("\n  field {}\n  A: {}\n  B: {}\n", d.field, d.a, d.b);
        }
    }
    s
}

/// The report's table: how many messages differ per topic, of how many in each log.
pub fn render_counts(report: &Report) -> String {
    let mut s = "per topic (differing messages / messages in A, B):\n".to_owned();
    let width = report.topics.keys().map(String::len).max().unwrap_or(0);
    for (t, c) in &report.topics {
        s += &format!(
            "  {t:<width$} {:>6} / {}, {}\n",
            c.differing, c.messages_a, c.messages_b
        );
    }
    s
}
