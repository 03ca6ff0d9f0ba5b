//! The benchmark as people read it: the table `ricochet bench` prints, the CSV, and each
//! scene's contact summaries (against rapier, against Box2D).

use std::fmt::Write as _;

use super::measure::Row;

/// The CSV header, one row per scene below it.
pub const CSV_HEADER: &str = "scene,frames,ricochet_median_ms,ricochet_p95_ms,rapier_median_ms,\
                              rapier_p95_ms,ratio,contact_agreement,peak_mem_mb,\
                              ricochet_alone_median_ms,box2d_collide_median_ms,\
                              box2d_collide_p95_ms,box2d_step_median_ms,box2d_sync_median_ms,\
                              box2d_ratio,box2d_contact_agreement,box2d_mem_mb,\
                              ricochet_alone_2t_median_ms";

/// What the table's columns mean, printed below it.
pub const NOTES: &str = "median and p95 (nearest rank) of each engine's time per frame, \
                         frame 0 untimed; ratio = rapier median / ricochet median; memory = \
                         VmHWM of the scene's own process (ricochet: after its setup and frame \
                         0, before the other engines' worlds exist; peak: at the end); alone = \
                         median of as many further Ricochet frames with the others idle (caches \
                         to itself), 1 thread, and the same frames again with 2 threads (alone \
                         2t; the ratios are 1 thread against 1); box2d collide = broad + narrow phase from Box2D's own \
                         profile (pairs + collide), box2d step = its whole b2World_Step (solver \
                         included), box2d sync = copying the changed poses in \
                         (b2Body_SetTransform through boxdd's checked API: Box2D moves a \
                         shape's tree proxy there when it leaves its fat box), all medians; \
                         b2 ratio = box2d collide median / ricochet \
                         median; box2d agree = end-of-frame pairs agreed/compared by \
                         ricochet_box2d::compare_box2d";

/// About three significant digits, without an exponent down to 0.001.
fn sig3(x: f64) -> String {
    let a = x.abs();
    if a >= 100.0 || a == 0.0 || !a.is_finite() {
        format!("{x:.0}")
    } else if a >= 10.0 {
        format!("{x:.1}")
    } else if a >= 1.0 {
        format!("{x:.2}")
    } else if a >= 0.1 {
        format!("{x:.3}")
    } else if a >= 0.01 {
        format!("{x:.4}")
    } else if a >= 0.001 {
        format!("{x:.5}")
    } else {
        format!("{x:.2e}")
    }
}

/// Megabytes with one decimal, or `n/a`.
fn mb(v: Option<f64>) -> String {
    v.map_or_else(|| "n/a".to_owned(), |v| format!("{v:.1}"))
}

/// One line of the table: eighteen cells, right-aligned but for the scene's name.
fn line(s: &mut String, c: [String; 18]) {
    let _ = writeln!(
        s,
        "{:<26} {:>8} {:>6} {:>10} {:>10} {:>10} {:>10} {:>8} {:>19} {:>9} {:>9} {:>10} \
         {:>10} {:>10} {:>10} {:>10} {:>8} {:>19}",
        c[0],
        c[1],
        c[2],
        c[3],
        c[4],
        c[5],
        c[6],
        c[7],
        c[8],
        c[9],
        c[10],
        c[11],
        c[12],
        c[13],
        c[14],
        c[15],
        c[16],
        c[17]
    );
}

/// The table of every scene.
#[must_use]
pub fn table(rows: &[Row]) -> String {
    let mut s = String::new();
    let heads = [
        [
            "scene",
            "bodies",
            "frames",
            "ricochet",
            "p95",
            "rapier",
            "p95",
            "ratio",
            "contacts agree",
            "ricochet",
            "peak",
            "alone",
            "alone 2t",
            "box2d",
            "box2d",
            "box2d",
            "b2 ratio",
            "box2d agree",
        ],
        [
            "",
            "",
            "",
            "ms/frame",
            "ms",
            "ms/frame",
            "ms",
            "",
            "agreed/compared",
            "MB",
            "MB",
            "ms/frame",
            "ms/frame",
            "collide ms",
            "step ms",
            "sync ms",
            "",
            "agreed/compared",
        ],
    ];
    for h in heads {
        line(&mut s, h.map(str::to_owned));
    }
    for r in rows {
        let ms = |v: f64| format!("{v:.3}");
        line(
            &mut s,
            [
                r.scene.clone(),
                r.bodies.to_string(),
                r.frames.to_string(),
                ms(r.ricochet_median_ms),
                ms(r.ricochet_p95_ms),
                ms(r.rapier_median_ms),
                ms(r.rapier_p95_ms),
                sig3(r.ratio()),
                format!("{}/{}", r.agreement.agreed, r.agreement.compared),
                mb(r.ricochet_mb),
                mb(r.peak_mb),
                ms(r.ricochet_alone_median_ms),
                ms(r.ricochet_alone_2t_median_ms),
                ms(r.box2d_collide_median_ms),
                ms(r.box2d_step_median_ms),
                ms(r.box2d_sync_median_ms),
                sig3(r.box2d_ratio()),
                format!(
                    "{}/{}",
                    r.box2d_agreement.agreed, r.box2d_agreement.compared
                ),
            ],
        );
    }
    s
}

/// The CSV: [`CSV_HEADER`], then one line per scene.
#[must_use]
pub fn csv_text(rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{CSV_HEADER}");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{:.4},{:.4},{:.4},{:.4},{:.6},{}/{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.6},\
             {}/{},{:.1},{:.4}",
            r.scene,
            r.frames,
            r.ricochet_median_ms,
            r.ricochet_p95_ms,
            r.rapier_median_ms,
            r.rapier_p95_ms,
            r.ratio(),
            r.agreement.agreed,
            r.agreement.compared,
            r.peak_mb.map_or_else(String::new, |v| format!("{v:.1}")),
            r.ricochet_alone_median_ms,
            r.box2d_collide_median_ms,
            r.box2d_collide_p95_ms,
            r.box2d_step_median_ms,
            r.box2d_sync_median_ms,
            r.box2d_ratio(),
            r.box2d_agreement.agreed,
            r.box2d_agreement.compared,
            r.box2d_mb,
            r.ricochet_alone_2t_median_ms
        );
    }
    s
}

/// How a scene's contact sets compared: against rapier, one line of counts, then each kept
/// disagreement on its own indented line; then the same against Box2D.
#[must_use]
pub fn scene_summary(row: &Row) -> String {
    let a = &row.agreement;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "bench: {}: contacts {}/{} agree ({} in both, {} touching, {} where rapier kept stale \
         contact points, {} checked at their own poses, {} excluded as wrapped; {} Ricochet \
         only, {} rapier only)",
        row.scene,
        a.agreed,
        a.compared,
        a.both,
        a.touching,
        a.rapier_cached,
        a.at_record_poses,
        a.excluded,
        a.ricochet_only,
        a.rapier_only
    );
    for d in &a.details {
        let _ = writeln!(s, "  {d}");
    }
    let b = &row.box2d_agreement;
    let _ = writeln!(
        s,
        "bench: {}: Box2D contacts {}/{} agree ({} in both, {} touching, {} met by a swept \
         test; {} records at other poses not compared, {} excluded as wrapped; {} Ricochet \
         only, {} Box2D only; depths in both differ by at most {:.1e}); Box2D p95 collide \
         {:.3} ms, {:.1} MB allocated",
        row.scene,
        b.agreed,
        b.compared,
        b.both,
        b.touching,
        b.swept,
        b.other_poses,
        b.excluded,
        b.ricochet_only,
        b.box2d_only,
        b.max_depth_difference,
        row.box2d_collide_p95_ms,
        row.box2d_mb
    );
    for d in &b.details {
        let _ = writeln!(s, "  {d}");
    }
    s
}
