//! Echoing what was given in an error line: an argument, a name or a value is shown whole when
//! short and as a prefix with its length when long, so a refusal stays one readable line
//! whatever was typed (a 100000-character argument once made a 100075-character error line).
//! Every refusal of the configuration, the command line and the operator service that repeats
//! input goes through [`Echo`].

use std::fmt;

/// The most characters of a given text an error line repeats.
pub const MAX_ECHO_CHARS: usize = 64;

/// `text` as an error line shows it: whole up to [`MAX_ECHO_CHARS`] characters, else its
/// first [`MAX_ECHO_CHARS`] characters, "…" and how long it was.
#[derive(Debug, Clone, Copy)]
pub struct Echo<'a>(pub &'a str);

impl fmt::Display for Echo<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0.char_indices().nth(MAX_ECHO_CHARS) {
            None => f.write_str(self.0),
            Some((at, _)) => write!(
                f,
                "{}… ({} characters)",
                &self.0[..at],
                self.0.chars().count()
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_text_whole_long_text_a_prefix_and_its_length() {
        assert_eq!(Echo("x=100").to_string(), "x=100");
        let exact = "a".repeat(MAX_ECHO_CHARS);
        assert_eq!(Echo(&exact).to_string(), exact);
        let long = "é".repeat(100_000);
        let shown = Echo(&long).to_string();
        assert!(shown.starts_with(&"é".repeat(MAX_ECHO_CHARS)));
        assert!(shown.ends_with("… (100000 characters)"), "{shown}");
        assert!(shown.chars().count() < MAX_ECHO_CHARS + 30);
    }
}
