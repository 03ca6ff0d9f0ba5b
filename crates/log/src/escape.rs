//! Names from a file (a body's, a topic's), made safe to print.

/// A name from a file, for printing: control characters (terminal escape sequences,
/// newlines) are written as Rust escapes (`\u{1b}`), so a name can't drive the terminal or
/// forge a line of output.
pub fn escape_controls(name: &str) -> String {
    let mut s = String::with_capacity(name.len());
    for c in name.chars() {
        if c.is_control() {
            s.extend(c.escape_default());
        } else {
            s.push(c);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::escape_controls;

    #[test]
    fn control_characters_are_escaped_and_the_rest_kept() {
        assert_eq!(escape_controls("rock_a"), "rock_a");
        assert_eq!(escape_controls("été ☄"), "été ☄");
        assert_eq!(
            escape_controls("a\u{1b}[2Jb\nc\u{7}"),
            "a\\u{1b}[2Jb\\nc\\u{7}"
        );
    }
}
