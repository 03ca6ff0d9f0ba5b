//! What a game copies compiles in a game (issue #35): README's rust snippets, the examples of
//! the game-facing crates and the code in their doc comments import nothing from
//! `ricochet_geom`, which a game does not depend on; `ricochet_sim::prelude::*` (or the
//! crate root's re-exports) has the geometry a game needs.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn rust_files(dir: &Path, into: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, into);
        } else if path.extension().is_some_and(|x| x == "rs") {
            into.push(path);
        }
    }
}

/// The lines of the code blocks of `text`'s doc comments (`doc`: lines starting `//!` or
/// `///`) or of a Markdown file's ```` ```rust ```` blocks (`doc` false), with line numbers.
fn code_blocks(text: &str, doc: bool) -> Vec<(usize, String)> {
    // Whether a fence is open, and whether its block is Rust.
    let (mut open, mut rust) = (false, false);
    let mut code = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let t = line.trim_start();
        let body = if doc {
            match t.strip_prefix("//!").or_else(|| t.strip_prefix("///")) {
                Some(b) => b.trim_start(),
                None => {
                    open = false;
                    continue;
                }
            }
        } else {
            t
        };
        if let Some(lang) = body.strip_prefix("```") {
            open = !open;
            // A doc comment's bare fence is Rust; a Markdown file's must say so.
            rust = open && (lang.starts_with("rust") || (doc && lang.trim().is_empty()));
            continue;
        }
        if open && rust {
            code.push((n + 1, body.to_owned()));
        }
    }
    code
}

#[test]
fn examples_and_doc_examples_use_the_prelude_not_ricochet_geom() {
    let root = root();
    let mut found = Vec::new();
    let mut check = |path: &Path, lines: Vec<(usize, String)>| {
        for (n, line) in lines {
            if line.contains("ricochet_geom") {
                found.push(format!("{}:{n}: {line}", path.display()));
            }
        }
    };
    let readme = root.join("README.md");
    let text = std::fs::read_to_string(&readme).unwrap();
    let blocks = code_blocks(&text, false);
    assert!(
        blocks.len() > 50,
        "README's rust blocks: {} lines",
        blocks.len()
    );
    check(&readme, blocks);
    let mut examples = Vec::new();
    for dir in [
        "crates/sim/examples",
        "crates/record/examples",
        "crates/serve/examples",
        "tests/embed/src",
    ] {
        rust_files(&root.join(dir), &mut examples);
    }
    assert!(examples.len() >= 7, "{examples:?}");
    for path in examples {
        let text = std::fs::read_to_string(&path).unwrap();
        check(
            &path,
            text.lines()
                .map(str::to_owned)
                .enumerate()
                .map(|(n, l)| (n + 1, l))
                .collect(),
        );
    }
    let mut sources = Vec::new();
    for dir in ["crates/sim/src", "crates/record/src", "crates/serve/src"] {
        rust_files(&root.join(dir), &mut sources);
    }
    let mut doc_code = 0;
    for path in sources {
        let text = std::fs::read_to_string(&path).unwrap();
        let blocks = code_blocks(&text, true);
        doc_code += blocks.len();
        check(&path, blocks);
    }
    // The crate docs' examples were read (lib.rs alone has two).
    assert!(doc_code > 40, "{doc_code} lines of doc examples");
    assert!(
        found.is_empty(),
        "imports a game cannot make:\n{}",
        found.join("\n")
    );
}
