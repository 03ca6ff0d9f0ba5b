//! The study's chart, and the one `ricochet sweep` draws: a hand-written log-log SVG of
//! errors against run time ([`draw`] a [`LogLog`]); [`svg_text`] is the study's, error
//! against wall time per simulated second.

use std::fmt::Write as _;

use super::{Row, series};

/// The series drawn: (scene, method, kind, legend text).
const CHART: [(&str, &str, &str, &str); 11] = [
    (
        "projectile",
        "euler",
        "position",
        "projectile: position at 2 s (units)",
    ),
    (
        "projectile",
        "rapier",
        "position",
        "projectile, rapier2d: position at 2 s (units)",
    ),
    (
        "spring",
        "prescribed",
        "position",
        "spring, prescribed: max position (units)",
    ),
    (
        "spring",
        "state",
        "position",
        "spring, state force: max position (units)",
    ),
    (
        "orbit",
        "prescribed",
        "position",
        "orbit, prescribed: max position (units)",
    ),
    (
        "orbit",
        "state",
        "position",
        "orbit, state force: max position (units)",
    ),
    (
        "orbit",
        "prescribed",
        "energy",
        "orbit, prescribed: max energy (relative)",
    ),
    (
        "orbit",
        "state",
        "energy",
        "orbit, state force: max energy (relative)",
    ),
    ("drop", "euler", "rest_height", "drop: rest height (units)"),
    (
        "bullets",
        "swept",
        "wrong_first_hits",
        "bullets, swept: wrong first hits (of 24)",
    ),
    (
        "bullets",
        "discrete",
        "wrong_first_hits",
        "bullets, discrete: wrong first hits (of 24)",
    ),
];

const COLOURS: [&str; 11] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22", "#17becf", "#000000",
];

/// `10^k` as SVG text.
fn power_label(k: i32) -> String {
    match k {
        0 => "1".to_owned(),
        1 => "10".to_owned(),
        _ => format!("10<tspan dy=\"-7\" font-size=\"10\">{k}</tspan>"),
    }
}

/// The chart of `rows` as an SVG document.
#[must_use]
pub fn svg_text(rows: &[Row]) -> String {
    let dash = |method: &str, kind: &str| {
        if kind == "energy" {
            Dash::Long
        } else if method == "discrete" {
            Dash::Dotted
        } else {
            Dash::Solid
        }
    };
    let point = |r: &&Row| (r.wall, r.error);
    let series = CHART
        .iter()
        .map(|(scene, method, kind, legend)| Series {
            legend: (*legend).to_owned(),
            dash: dash(method, kind),
            points: series(rows, scene, method, kind)
                .iter()
                .map(point)
                .collect(),
            open: series(rows, scene, &format!("{method}+substeps"), kind)
                .iter()
                .map(point)
                .collect(),
        })
        .collect();
    draw(&LogLog {
        title: format!(
            "Ricochet accuracy: error against run time (ricochet accuracy, {} build)",
            build()
        ),
        x_label: "wall seconds per simulated second (log scale; smaller dt is further right)"
            .to_owned(),
        y_label: "error against the exact answer (log scale; units per series in the legend)"
            .to_owned(),
        series,
        notes: [
            "Filled points: dt = 1/30, 1/60, ... 1/960 s, one step per frame.",
            "Open circles: 60 Hz frames with 1, 2, 4 sim steps each.",
            "Errors of exactly 0 sit on the bottom line.",
            "Wall time: one 2-core machine; compare within one chart.",
        ]
        .map(str::to_owned)
        .to_vec(),
    })
}

/// `debug` or `release`: timings of the two differ tenfold, so a chart says which.
#[must_use]
pub fn build() -> &'static str {
    if cfg!(debug_assertions) {
        "debug"
    } else {
        "release"
    }
}

/// How a series' line is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dash {
    /// A solid line.
    Solid,
    /// Long dashes (the study's energy series).
    Long,
    /// Dots (the study's discrete bullets).
    Dotted,
}

/// One line of a [`LogLog`] chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The legend's text.
    pub legend: String,
    /// The line's dash.
    pub dash: Dash,
    /// Filled points joined by the line, `(x, y)`; a non-finite `y` is not drawn, and a `y`
    /// of 0 sits on the chart's bottom line ("0 (exact)").
    pub points: Vec<(f64, f64)>,
    /// Open circles, not joined.
    pub open: Vec<(f64, f64)>,
}

/// A log-log chart of errors (y) against run times (x): the study's, and `ricochet sweep`'s.
#[derive(Clone, Debug, PartialEq)]
pub struct LogLog {
    /// The title line.
    pub title: String,
    /// Under the x axis.
    pub x_label: String,
    /// Beside the y axis.
    pub y_label: String,
    /// The lines, coloured in order.
    pub series: Vec<Series>,
    /// Lines of small text under the legend.
    pub notes: Vec<String>,
}

/// The chart as an SVG document.
#[must_use]
pub fn draw(chart: &LogLog) -> String {
    let (width, height) = (1000.0, 640.0);
    let (left, right, top, bottom) = (80.0, 620.0, 60.0, 570.0);
    let all = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().chain(&s.open));
    let walls = all
        .clone()
        .filter(|(x, _)| *x > 0.0)
        .map(|(x, _)| libm::log10(*x));
    let x_lo = walls.clone().fold(f64::INFINITY, f64::min).floor() as i32;
    let x_hi = walls.fold(f64::NEG_INFINITY, f64::max).ceil() as i32;
    let errors = all
        .filter(|(_, e)| *e > 0.0 && e.is_finite())
        .map(|(_, e)| libm::log10(*e));
    let y_lo = errors.clone().fold(f64::INFINITY, f64::min).floor() as i32;
    let y_hi = errors.fold(f64::NEG_INFINITY, f64::max).ceil() as i32;
    // An empty chart (no point, or no error above 0) still gets one decade each way.
    let x_lo = if x_lo == i32::MAX { 0 } else { x_lo };
    let y_lo = if y_lo == i32::MAX { 0 } else { y_lo };
    let x_hi = x_hi.max(x_lo + 1);
    // One decade below the smallest error is the row of exact zeros.
    let y_zero = y_lo - 1;
    let y_hi = y_hi.max(y_zero + 1);
    let sx = |w: f64| {
        left + (libm::log10(w) - f64::from(x_lo)) / f64::from(x_hi - x_lo) * (right - left)
    };
    let sy_log =
        |l: f64| bottom - (l - f64::from(y_zero)) / f64::from(y_hi - y_zero) * (bottom - top);
    let sy = |e: f64| {
        if e > 0.0 {
            sy_log(libm::log10(e).max(f64::from(y_zero)))
        } else {
            sy_log(f64::from(y_zero))
        }
    };

    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
         viewBox=\"0 0 {width} {height}\" font-family=\"sans-serif\" font-size=\"12\">"
    );
    let _ = writeln!(s, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"28\" font-size=\"16\" text-anchor=\"middle\">{}</text>",
        width / 2.0,
        escape(&chart.title)
    );
    // Grid and ticks.
    for k in x_lo..=x_hi {
        let x = left + f64::from(k - x_lo) / f64::from(x_hi - x_lo) * (right - left);
        let _ = writeln!(
            s,
            "<line x1=\"{x:.1}\" y1=\"{top}\" x2=\"{x:.1}\" y2=\"{bottom}\" stroke=\"#e0e0e0\"/>\
             <text x=\"{x:.1}\" y=\"{}\" text-anchor=\"middle\">{}</text>",
            bottom + 18.0,
            power_label(k)
        );
    }
    for k in y_zero..=y_hi {
        let y = sy_log(f64::from(k));
        let label = if k == y_zero {
            "0 (exact)".to_owned()
        } else {
            power_label(k)
        };
        let _ = writeln!(
            s,
            "<line x1=\"{left}\" y1=\"{y:.1}\" x2=\"{right}\" y2=\"{y:.1}\" stroke=\"{}\"/>\
             <text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{label}</text>",
            if k == y_zero { "#999999" } else { "#e0e0e0" },
            left - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        "<rect x=\"{left}\" y=\"{top}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>",
        right - left,
        bottom - top
    );
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>",
        (left + right) / 2.0,
        bottom + 42.0,
        escape(&chart.x_label)
    );
    let _ = writeln!(
        s,
        "<text transform=\"translate(22 {}) rotate(-90)\" text-anchor=\"middle\">{}</text>",
        (top + bottom) / 2.0,
        escape(&chart.y_label)
    );
    // Series: a polyline through the filled points, open circles apart.
    let finite = |p: &&(f64, f64)| p.1.is_finite();
    for (n, line) in chart.series.iter().enumerate() {
        let colour = COLOURS[n % COLOURS.len()];
        let dash = dash_attribute(line.dash);
        let points: Vec<String> = line
            .points
            .iter()
            .filter(finite)
            .map(|&(x, e)| format!("{:.1},{:.1}", sx(x), sy(e)))
            .collect();
        let _ = writeln!(
            s,
            "<polyline fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.6\"{dash} points=\"{}\"/>",
            points.join(" ")
        );
        for &(x, e) in line.points.iter().filter(finite) {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"{colour}\"/>",
                sx(x),
                sy(e)
            );
        }
        for &(x, e) in line.open.iter().filter(finite) {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"5\" fill=\"none\" stroke=\"{colour}\"/>",
                sx(x),
                sy(e)
            );
        }
    }
    // Legend.
    let lx = right + 20.0;
    for (n, line) in chart.series.iter().enumerate() {
        let y = top + 10.0 + 22.0 * n as f64;
        let colour = COLOURS[n % COLOURS.len()];
        let _ = writeln!(
            s,
            "<line x1=\"{lx}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"{colour}\" stroke-width=\"1.6\"{}/>\
             <circle cx=\"{}\" cy=\"{y}\" r=\"3\" fill=\"{colour}\"/>\
             <text x=\"{}\" y=\"{}\">{}</text>",
            lx + 26.0,
            dash_attribute(line.dash),
            lx + 13.0,
            lx + 32.0,
            y + 4.0,
            escape(&line.legend)
        );
    }
    for (n, note) in chart.notes.iter().enumerate() {
        let _ = writeln!(
            s,
            "<text x=\"{lx}\" y=\"{}\" font-size=\"11\" fill=\"#444444\">{}</text>",
            top + 10.0 + 22.0 * chart.series.len() as f64 + 12.0 + 16.0 * n as f64,
            escape(note)
        );
    }
    s.push_str("</svg>\n");
    s
}

fn dash_attribute(dash: Dash) -> &'static str {
    match dash {
        Dash::Solid => "",
        Dash::Long => " stroke-dasharray=\"6 3\"",
        Dash::Dotted => " stroke-dasharray=\"2 3\"",
    }
}

/// Text as SVG character data: a body or file name may hold `&` or `<`.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
