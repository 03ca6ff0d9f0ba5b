//! `--junit FILE`: the results as JUnit XML, the report CI systems (GitLab, Jenkins, GitHub
//! actions that read test reports) show per test. One `<testsuite>` with its `tests` and
//! `failures` counts, one `<testcase>` per scenario, a `<failure>` whose message is the
//! verdict line (the first divergence). No times: the file is the same bytes for the same
//! results, like the printed lines.

use std::path::{Path, PathBuf};

use anyhow::Context;
use quick_xml::Writer;
use quick_xml::events::{BytesDecl, BytesText, Event};

use super::item::{ItemResult, default_golden, name_of};

/// Whether XML 1.0 allows `c` in a document (its `Char` production): tab, LF, CR, and
/// everything from U+0020 but U+FFFE and U+FFFF (surrogates are not `char`s).
fn xml_char(c: char) -> bool {
    matches!(c, '\t' | '\n' | '\r' | '\u{20}'..='\u{fffd}' | '\u{10000}'..)
}

/// A name or message for the report. XML 1.0 has no escape for the characters it forbids
/// (a character reference to one is not well-formed either), and one of them makes the
/// whole report unreadable, so each is written as a Rust escape (`\u{fffe}`), as on the
/// terminal; so are the other control characters, as `escape_controls` writes them.
fn xml_text(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if c.is_control() || !xml_char(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// The JUnit XML of `results` (in the order given), as bytes. `suite` names the testsuite.
pub fn render(suite: &str, results: &[ItemResult]) -> std::io::Result<Vec<u8>> {
    let suite = xml_text(suite);
    let suite = suite.as_str();
    let failures = results.iter().filter(|r| !r.verdict.passed()).count();
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    let (tests, failed) = (results.len().to_string(), failures.to_string());
    w.create_element("testsuites")
        .with_attributes([("tests", tests.as_str()), ("failures", failed.as_str())])
        .write_inner_content(|w| {
            w.create_element("testsuite")
                .with_attributes([
                    ("name", suite),
                    ("tests", tests.as_str()),
                    ("failures", failed.as_str()),
                    ("errors", "0"),
                    ("skipped", "0"),
                ])
                .write_inner_content(|w| {
                    for r in results {
                        let (name, file) = (xml_text(&r.name), xml_text(&r.scenario));
                        let case = w.create_element("testcase").with_attributes([
                            ("name", name.as_str()),
                            ("classname", suite),
                            ("file", file.as_str()),
                        ]);
                        if r.verdict.passed() {
                            case.write_empty()?;
                        } else {
                            let message = xml_text(&r.line);
                            case.write_inner_content(|w| {
                                w.create_element("failure")
                                    .with_attribute(("message", message.as_str()))
                                    .write_text_content(BytesText::new(&format!(
                                        "{file}: {message}"
                                    )))?;
                                Ok(())
                            })?;
                        }
                    }
                    Ok(())
                })?;
            Ok(())
        })?;
    let mut bytes = w.into_inner();
    bytes.push(b'\n');
    Ok(bytes)
}

/// Fails if the report can't go to `path` (a directory, a device, no folder: see
/// [`crate::files::check_writable`]) or if `path` is one of the run's inputs: a scenario of
/// `items`, or its golden log or digest, which the report would overwrite. Before any item.
pub fn check(
    path: &Path,
    items: &[PathBuf],
    golden: Option<&Path>,
    keep: Option<&Path>,
) -> anyhow::Result<()> {
    let goldens: Vec<PathBuf> = items
        .iter()
        .flat_map(|s| {
            let dir = golden.map_or_else(|| default_golden(s), Path::to_owned);
            let name = name_of(s);
            [
                dir.join(format!("{name}.mcap")),
                dir.join(format!("{name}.digest")),
            ]
        })
        .collect();
    let inputs: Vec<&Path> = items.iter().chain(&goldens).map(PathBuf::as_path).collect();
    crate::files::check_outputs(&[("--junit", path)], &inputs)?;
    // The logs `--keep` writes are outputs too: the report would replace one, or it the
    // report.
    if let Some(keep) = keep {
        for s in items {
            let kept = keep.join(format!("{}.mcap", name_of(s)));
            if crate::files::same_file(path, &kept) {
                anyhow::bail!(
                    "--junit {} is where --keep keeps the fresh log of {}: give the report \
                     a path of its own",
                    path.display(),
                    s.display()
                );
            }
        }
    }
    Ok(())
}

/// Writes the report to `path` through a temporary file renamed into place.
pub fn write(path: &Path, suite: &str, results: &[ItemResult]) -> anyhow::Result<()> {
    let bytes = render(suite, results).context("building the JUnit report")?;
    crate::files::write(path, &bytes)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;
    use quick_xml::events::Event;

    use super::super::item::{FORMAT, ItemResult, Verdict};
    use super::render;

    /// XML 1.0's `Char` production (section 2.2), as the spec writes it: `#x9 | #xA | #xD |
    /// [#x20-#xD7FF] | [#xE000-#xFFFD] | [#x10000-#x10FFFF]`.
    fn allowed(c: char) -> bool {
        let c = u32::from(c);
        c == 0x9
            || c == 0xA
            || c == 0xD
            || (0x20..=0xD7FF).contains(&c)
            || (0xE000..=0xFFFD).contains(&c)
            || (0x10000..=0x10_FFFF).contains(&c)
    }

    /// `None` if `xml` is a well-formed document as far as a reader sees it: only characters
    /// XML allows, every element closed, every attribute and reference well-formed.
    fn malformed(xml: &str) -> Option<String> {
        if let Some(c) = xml.chars().find(|c| !allowed(*c)) {
            return Some(format!("U+{:04X} is not an XML character", u32::from(c)));
        }
        let mut reader = quick_xml::Reader::from_str(xml);
        loop {
            match reader.read_event() {
                Err(e) => return Some(e.to_string()),
                Ok(Event::Eof) => return None,
                Ok(Event::Start(e) | Event::Empty(e)) => {
                    for a in e.attributes() {
                        let a = match a {
                            Ok(a) => a,
                            Err(e) => return Some(e.to_string()),
                        };
                        if let Err(e) = a.normalized_value(quick_xml::XmlVersion::Implicit1_0) {
                            return Some(e.to_string());
                        }
                    }
                }
                Ok(Event::Text(t)) => {
                    if let Err(e) = quick_xml::escape::unescape(&t.xml10_content()) {
                        return Some(e.to_string());
                    }
                }
                Ok(_) => {}
            }
        }
    }

    fn result(name: String, scenario: String, line: String, passed: bool) -> ItemResult {
        ItemResult {
            format: FORMAT,
            scenario,
            name,
            verdict: if passed {
                Verdict::Ok
            } else {
                Verdict::Differs
            },
            line,
            digest: None,
            first: None,
            log: None,
        }
    }

    /// Any character, with XML's forbidden and special ones often.
    fn text() -> impl Strategy<Value = String> {
        let special = prop::sample::select(vec![
            '\u{fffe}', '\u{ffff}', '\0', '\u{1b}', '\u{b}', '\u{7f}', '\u{85}', '\t', '\n', '\r',
            '<', '&', '"', '\'', ']', '>',
        ]);
        prop::collection::vec(prop_oneof![any::<char>(), special], 0..24)
            .prop_map(|cs| cs.into_iter().collect())
    }

    #[test]
    fn noncharacters_in_a_name_and_a_message_are_escaped() {
        let r = result(
            "a\u{fffe}b".to_owned(),
            "scenarios/a\u{fffe}b.toml".to_owned(),
            "error: \u{ffff} at \u{fffe}".to_owned(),
            false,
        );
        let xml = String::from_utf8(render("suite\u{ffff}", &[r]).unwrap()).unwrap();
        assert_eq!(malformed(&xml), None, "{xml}");
        assert!(xml.contains(r#"name="a\u{fffe}b""#), "{xml}");
        assert!(
            xml.contains(r#"message="error: \u{ffff} at \u{fffe}""#),
            "{xml}"
        );
    }

    proptest! {
        #[test]
        fn any_names_and_messages_make_a_well_formed_report(
            cases in prop::collection::vec((text(), text(), text(), any::<bool>()), 0..4),
            suite in text(),
        ) {
            let results: Vec<ItemResult> = cases
                .into_iter()
                .map(|(name, scenario, line, passed)| result(name, scenario, line, passed))
                .collect();
            let bytes = render(&suite, &results).unwrap();
            let xml = String::from_utf8(bytes).unwrap();
            prop_assert_eq!(malformed(&xml), None, "{}", xml);
        }
    }
}
