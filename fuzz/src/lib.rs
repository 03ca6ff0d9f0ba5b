//! The checks behind Ricochet's fuzz targets. They live in [`checks`], a file with no other
//! dependency than the two library crates, so that `tests/fuzz_corpus.rs` can include the very
//! same file (`#[path]`) and replay the corpus as an ordinary test.

pub mod checks;
