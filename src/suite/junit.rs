//! `--junit FILE`: the results as JUnit XML, the report CI systems (GitLab, Jenkins, GitHub
//! actions that read test reports) show per test. One `<testsuite>` with its `tests` and
//! `failures` counts, one `<testcase>` per scenario, a `<failure>` whose message is the
//! verdict line (the first divergence). No times: the file is the same bytes for the same
//! results, like the printed lines.

use std::path::Path;

use anyhow::Context;
use quick_xml::Writer;
use quick_xml::events::{BytesDecl, BytesText, Event};

use super::item::ItemResult;
use crate::out::escape_controls;

/// The JUnit XML of `results` (in the order given), as bytes. `suite` names the testsuite.
pub fn render(suite: &str, results: &[ItemResult]) -> std::io::Result<Vec<u8>> {
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
                        // XML 1.0 has no escape for control characters: they are written
                        // as Rust escapes, as on the terminal.
                        let (name, file) = (escape_controls(&r.name), escape_controls(&r.scenario));
                        let case = w.create_element("testcase").with_attributes([
                            ("name", name.as_str()),
                            ("classname", suite),
                            ("file", file.as_str()),
                        ]);
                        if r.verdict.passed() {
                            case.write_empty()?;
                        } else {
                            let message = escape_controls(&r.line);
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

/// Writes the report to `path` through a temporary file renamed into place.
pub fn write(path: &Path, suite: &str, results: &[ItemResult]) -> anyhow::Result<()> {
    let bytes = render(suite, results).context("building the JUnit report")?;
    crate::files::write(path, &bytes)
}
