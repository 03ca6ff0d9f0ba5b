//! The 3000 shared ground-truth cases (`tests/data/collision-cases.json`, copied from
//! `shared/collision-cases`), scored exactly as their README says:
//! - overlap: on every case whose class is not `ambiguous`, the yes/no must match;
//! - depth: on overlapping cases, `|depth - truth.depth| <= tol`;
//! - normal: on overlapping cases, within 1e-3 rad of the truth or an alternative; where the
//!   normal is not unique, any normal that separates the pair when `b` is pushed by
//!   `truth.depth` counts; where it is free (concentric circles), anything unit counts.
//!
//! Separated cases are scored on their distance too (`-depth` against `truth.distance`),
//! because `ricochet collide` reports it.

use std::collections::BTreeMap;

use ricochet_geom::{Case, Contact, Pose, Vec2, contact, contact_deeper_than, parse_case_file};
use serde_json::Value;

use crate::util::data;

struct Truth {
    pair: String,
    scenario: String,
    class: String,
    overlap: bool,
    depth: f64,
    normal: Vec2,
    alternatives: Vec<Vec2>,
    unique: bool,
    free: bool,
    tol: f64,
}

fn vec2(v: &Value) -> Vec2 {
    Vec2::new(v[0].as_f64().unwrap(), v[1].as_f64().unwrap())
}

fn load() -> Vec<(Case, Truth)> {
    let text = std::fs::read_to_string(data("collision-cases.json")).expect("test data exists");
    let cases = parse_case_file(&text).expect("every shared case is valid input");
    let doc: Value = serde_json::from_str(&text).unwrap();
    let truths = doc["cases"].as_array().unwrap().iter().map(|c| {
        let t = &c["truth"];
        Truth {
            pair: c["pair"].as_str().unwrap().to_owned(),
            scenario: c["scenario"].as_str().unwrap().to_owned(),
            class: t["class"].as_str().unwrap().to_owned(),
            overlap: t["overlap"].as_bool().unwrap(),
            depth: t["depth"].as_f64().unwrap(),
            normal: vec2(&t["normal"]),
            alternatives: t["normal_alternatives"]
                .as_array()
                .unwrap()
                .iter()
                .map(vec2)
                .collect(),
            unique: t["normal_unique"].as_bool().unwrap(),
            free: t["normal_free"].as_bool().unwrap(),
            tol: t["tol"].as_f64().unwrap(),
        }
    });
    cases.into_iter().zip(truths).collect()
}

fn angle_between(a: Vec2, b: Vec2) -> f64 {
    libm::atan2(a.perp_dot(b), a.dot(b)).abs()
}

/// What went wrong with one case, if anything.
fn score(case: &Case, t: &Truth) -> Option<String> {
    let c = contact(&case.a.shape, &case.a.pose, &case.b.shape, &case.b.pose);
    if !c.depth.is_finite() || !c.normal.is_finite() || !c.point.is_finite() {
        return Some(format!("non-finite result {c:?}"));
    }
    if (c.normal.length() - 1.0).abs() > 1e-12 {
        return Some(format!("normal {} is not unit", c.normal));
    }
    if t.class != "ambiguous" && c.overlaps() != t.overlap {
        return Some(format!(
            "overlap {} (depth {}), truth {}",
            c.overlaps(),
            c.depth,
            t.depth
        ));
    }
    if t.class != "ambiguous" && (c.depth - t.depth).abs() > t.tol {
        return Some(format!(
            "depth {} vs truth {} (tol {})",
            c.depth, t.depth, t.tol
        ));
    }
    if !t.overlap || t.free {
        return None;
    }
    let close = std::iter::once(t.normal)
        .chain(t.alternatives.iter().copied())
        .any(|n| angle_between(n, c.normal) <= 1e-3);
    if close {
        return None;
    }
    if !t.unique {
        let pushed = Pose::new(case.b.pose.position + c.normal * t.depth, case.b.pose.angle);
        let after = contact(&case.a.shape, &case.a.pose, &case.b.shape, &pushed);
        if after.depth <= t.tol {
            return None;
        }
    }
    Some(format!("normal {} vs truth {}", c.normal, t.normal))
}

#[test]
fn every_shared_case_matches_its_ground_truth() {
    let cases = load();
    assert_eq!(cases.len(), 3000, "the shared case file has 3000 cases");
    // (pair, scenario) -> (cases, misses); BTreeMap so the table prints in a stable order.
    let mut table: BTreeMap<(String, String), (usize, usize)> = BTreeMap::new();
    let mut misses = Vec::new();
    for (case, truth) in &cases {
        let row = table
            .entry((truth.pair.clone(), truth.scenario.clone()))
            .or_default();
        row.0 += 1;
        if let Some(why) = score(case, truth) {
            row.1 += 1;
            misses.push(format!(
                "case {} ({} {}): {why}",
                case.id, truth.pair, truth.scenario
            ));
        }
    }
    let mut report = String::from("pair              scenario       cases  misses\n");
    for ((pair, scenario), (n, m)) in &table {
        report += &format!("{pair:<17} {scenario:<13} {n:>6} {m:>7}\n");
    }
    assert!(
        misses.is_empty(),
        "{} of 3000 shared cases missed:\n{}\n{report}",
        misses.len(),
        misses
            .iter()
            .take(40)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n")
    );
    // Every pairing is present 200 times: the scoring above covered all 15.
    let mut per_pair: BTreeMap<&str, usize> = BTreeMap::new();
    for (pair, _) in table.keys() {
        *per_pair.entry(pair).or_default() += table
            .iter()
            .filter(|((p, _), _)| p == pair)
            .map(|(_, (n, _))| n)
            .sum::<usize>();
    }
    assert_eq!(per_pair.len(), 15, "{report}");
}

/// The narrow phase's early-out (`contact_deeper_than`, what `detect` calls for pairs that
/// don't `separate`) on the 3000 shared cases: the ground truth's overlap yes/no wherever it
/// is not ambiguous, and `contact`'s bits wherever it answers, at thresholds around each
/// case's own depth (one ulp either side, where a slip in its margin would show).
#[test]
fn the_early_out_keeps_every_shared_case_exact() {
    let bits =
        |c: Contact| [c.depth, c.normal.x, c.normal.y, c.point.x, c.point.y].map(f64::to_bits);
    for (case, truth) in &load() {
        let (a, b) = (&case.a, &case.b);
        let exact = contact(&a.shape, &a.pose, &b.shape, &b.pose);
        let overlap = contact_deeper_than(&a.shape, &a.pose, &b.shape, &b.pose, 0.0);
        if truth.class != "ambiguous" {
            assert_eq!(overlap.is_some(), truth.overlap, "case {}", case.id);
        }
        let d = exact.depth;
        for threshold in [0.0, d, d.next_down(), d.next_up(), d - 1e-6, d + 1e-6] {
            let want = (d > threshold).then_some(exact);
            let got = contact_deeper_than(&a.shape, &a.pose, &b.shape, &b.pose, threshold);
            assert_eq!(
                got.map(bits),
                want.map(bits),
                "case {} at {threshold:e}",
                case.id
            );
        }
    }
}
