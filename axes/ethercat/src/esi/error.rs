//! What is wrong with an ESI file, named by element (and attribute) with its line.

use std::fmt;

/// A malformed or unusable ESI file: the XML itself, or an element or attribute that
/// ETG.2000 requires and the file lacks or spells wrongly.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EsiError {
    /// The element path, e.g. "Device/RxPdo/Entry/Index", or "XML" for a syntax error.
    pub element: String,
    /// The attribute, where the fault is in one.
    pub attribute: Option<String>,
    /// 1-based line in the file, where known.
    pub line: Option<u32>,
    /// What is wrong.
    pub message: String,
}

impl EsiError {
    /// An error at `element` (line `line`).
    pub fn at(element: impl Into<String>, line: u32, message: impl Into<String>) -> Self {
        EsiError {
            element: element.into(),
            attribute: None,
            line: Some(line),
            message: message.into(),
        }
    }

    /// The same error, in attribute `attribute` of the element.
    pub fn in_attribute(mut self, attribute: &str) -> Self {
        self.attribute = Some(attribute.to_owned());
        self
    }

    /// An error about the file as a whole (no element to point at).
    pub fn file(message: impl Into<String>) -> Self {
        EsiError {
            element: "EtherCATInfo".into(),
            attribute: None,
            line: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for EsiError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(line) = self.line {
            write!(f, "line {line}: ")?;
        }
        write!(f, "<{}>", self.element)?;
        if let Some(a) = &self.attribute {
            write!(f, " attribute {a}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for EsiError {}
