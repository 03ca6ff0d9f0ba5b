//! Narrow-phase micro-benchmarks: `overlaps` and `contact` per pairing, over the 200 shared
//! ground-truth cases of each pairing (random, near-touching, deep, contained, thin, huge,
//! tiny, mixed-scale and aligned poses). One iteration runs all 200 pairs of a pairing, so
//! divan's time divided by 200 is the cost per pair; the `item/s` column is pairs per second.
//!
//! Run: `cargo bench -p ricochet-geom --bench narrow_phase`

use divan::{Bencher, black_box, counter::ItemsCount};
use ricochet_geom::{Case, contact, overlaps, pair_name, parse_case_file};

const PAIRS: &[&str] = &[
    "circle-circle",
    "circle-aabb",
    "circle-obb",
    "circle-capsule",
    "circle-polygon",
    "aabb-aabb",
    "aabb-obb",
    "aabb-capsule",
    "aabb-polygon",
    "obb-obb",
    "obb-capsule",
    "obb-polygon",
    "capsule-capsule",
    "capsule-polygon",
    "polygon-polygon",
];

fn main() {
    divan::main();
}

fn cases(pair: &str) -> Vec<Case> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../tests/data/collision-cases.json"
    );
    let text = std::fs::read_to_string(path).expect("the shared cases are in tests/data");
    parse_case_file(&text)
        .expect("the shared cases are valid")
        .into_iter()
        .filter(|c| {
            let kind = |s: &ricochet_geom::Shape| s.primitives()[0].kind();
            pair_name(kind(&c.a.shape), kind(&c.b.shape)) == pair
        })
        .collect()
}

/// The cheap yes/no test.
#[divan::bench(args = PAIRS)]
fn overlaps_per_pairing(bencher: Bencher, pair: &str) {
    let cases = cases(pair);
    bencher.counter(ItemsCount::new(cases.len())).bench(|| {
        for c in &cases {
            black_box(overlaps(
                black_box(&c.a.shape),
                &c.a.pose,
                black_box(&c.b.shape),
                &c.b.pose,
            ));
        }
    });
}

/// The full contact: signed depth, normal and point.
#[divan::bench(args = PAIRS)]
fn contact_per_pairing(bencher: Bencher, pair: &str) {
    let cases = cases(pair);
    bencher.counter(ItemsCount::new(cases.len())).bench(|| {
        for c in &cases {
            black_box(contact(
                black_box(&c.a.shape),
                &c.a.pose,
                black_box(&c.b.shape),
                &c.b.pose,
            ));
        }
    });
}
