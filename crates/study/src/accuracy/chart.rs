//! The chart of the study: a hand-written SVG, error against wall time per simulated second,
//! log-log.

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
    let (width, height) = (1000.0, 640.0);
    let (left, right, top, bottom) = (80.0, 620.0, 60.0, 570.0);
    let drawn: Vec<&Row> = rows
        .iter()
        .filter(|r| {
            CHART.iter().any(|(scene, method, kind, _)| {
                r.scene == *scene
                    && r.kind == *kind
                    && (r.method == *method || r.method == format!("{method}+substeps"))
            })
        })
        .collect();
    let walls = drawn.iter().map(|r| libm::log10(r.wall));
    let x_lo = walls.clone().fold(f64::INFINITY, f64::min).floor() as i32;
    let x_hi = walls.fold(f64::NEG_INFINITY, f64::max).ceil() as i32;
    let errors = drawn
        .iter()
        .filter(|r| r.error > 0.0 && r.error.is_finite())
        .map(|r| libm::log10(r.error));
    let y_lo = errors.clone().fold(f64::INFINITY, f64::min).floor() as i32;
    let y_hi = errors.fold(f64::NEG_INFINITY, f64::max).ceil() as i32;
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
        "<text x=\"{}\" y=\"28\" font-size=\"16\" text-anchor=\"middle\">Ricochet accuracy: error \
         against run time (ricochet accuracy, {} build)</text>",
        width / 2.0,
        if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        }
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
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">wall seconds per simulated second \
         (log scale; smaller dt is further right)</text>",
        (left + right) / 2.0,
        bottom + 42.0
    );
    let _ = writeln!(
        s,
        "<text transform=\"translate(22 {}) rotate(-90)\" text-anchor=\"middle\">error against \
         the exact answer (log scale; units per series in the legend)</text>",
        (top + bottom) / 2.0
    );
    // Series: a polyline over the dt sweep (1/30 to 1/960), open circles for the substep rows.
    for (n, (scene, method, kind, _)) in CHART.iter().enumerate() {
        let colour = COLOURS[n];
        let dash = if *kind == "energy" {
            " stroke-dasharray=\"6 3\""
        } else if *method == "discrete" {
            " stroke-dasharray=\"2 3\""
        } else {
            ""
        };
        let line = series(rows, scene, method, kind);
        let points: Vec<String> = line
            .iter()
            .filter(|r| r.error.is_finite())
            .map(|r| format!("{:.1},{:.1}", sx(r.wall), sy(r.error)))
            .collect();
        let _ = writeln!(
            s,
            "<polyline fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.6\"{dash} points=\"{}\"/>",
            points.join(" ")
        );
        for r in line.iter().filter(|r| r.error.is_finite()) {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"{colour}\"/>",
                sx(r.wall),
                sy(r.error)
            );
        }
        for r in series(rows, scene, &format!("{method}+substeps"), kind)
            .iter()
            .filter(|r| r.error.is_finite())
        {
            let _ = writeln!(
                s,
                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"5\" fill=\"none\" stroke=\"{colour}\"/>",
                sx(r.wall),
                sy(r.error)
            );
        }
    }
    // Legend.
    let lx = right + 20.0;
    for (n, (_, method, kind, text)) in CHART.iter().enumerate() {
        let y = top + 10.0 + 22.0 * n as f64;
        let dash = if *kind == "energy" {
            " stroke-dasharray=\"6 3\""
        } else if *method == "discrete" {
            " stroke-dasharray=\"2 3\""
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "<line x1=\"{lx}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" stroke=\"{}\" stroke-width=\"1.6\"{dash}/>\
             <circle cx=\"{}\" cy=\"{y}\" r=\"3\" fill=\"{}\"/>\
             <text x=\"{}\" y=\"{}\">{text}</text>",
            lx + 26.0,
            COLOURS[n],
            lx + 13.0,
            COLOURS[n],
            lx + 32.0,
            y + 4.0
        );
    }
    let notes = [
        "Filled points: dt = 1/30, 1/60, ... 1/960 s, one step per frame.",
        "Open circles: 60 Hz frames with 1, 2, 4 sim steps each.",
        "Errors of exactly 0 sit on the bottom line.",
        "Wall time: one 2-core machine; compare within one chart.",
    ];
    for (n, note) in notes.iter().enumerate() {
        let _ = writeln!(
            s,
            "<text x=\"{lx}\" y=\"{}\" font-size=\"11\" fill=\"#444444\">{note}</text>",
            top + 10.0 + 22.0 * CHART.len() as f64 + 12.0 + 16.0 * n as f64
        );
    }
    s.push_str("</svg>\n");
    s
}
