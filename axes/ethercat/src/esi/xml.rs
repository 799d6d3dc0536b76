//! Small helpers over `roxmltree` nodes: children by name, trimmed text, numbers, with errors
//! that name the element path and its line.

use roxmltree::{Document, Node};

use super::error::EsiError;
use super::number::{boolean, hex_dec};

/// A parsed document and the element path being read, for error messages.
#[derive(Clone, Copy)]
pub(super) struct At<'a, 'input> {
    pub doc: &'a Document<'input>,
}

impl<'a, 'input> At<'a, 'input> {
    /// 1-based line of `node`.
    pub fn line(&self, node: Node<'_, '_>) -> u32 {
        self.doc.text_pos_at(node.range().start).row
    }

    /// An error at `node`, named `path`.
    pub fn err(&self, node: Node<'_, '_>, path: &str, message: impl Into<String>) -> EsiError {
        EsiError::at(path, self.line(node), message)
    }

    /// The required child `name` of `node` (`path` names `node`).
    pub fn child(
        &self,
        node: Node<'a, 'input>,
        path: &str,
        name: &str,
    ) -> Result<Node<'a, 'input>, EsiError> {
        child(node, name).ok_or_else(|| {
            self.err(
                node,
                &format!("{path}/{name}"),
                format!("missing (required in <{path}>)"),
            )
        })
    }

    /// The number in the text of child `name` (a `HexDecValue`).
    pub fn child_number(
        &self,
        node: Node<'a, 'input>,
        path: &str,
        name: &str,
    ) -> Result<i64, EsiError> {
        let c = self.child(node, path, name)?;
        self.number(c, &format!("{path}/{name}"))
    }

    /// The number in the text of child `name` where present.
    pub fn opt_child_number(
        &self,
        node: Node<'a, 'input>,
        path: &str,
        name: &str,
    ) -> Result<Option<i64>, EsiError> {
        child(node, name)
            .map(|c| self.number(c, &format!("{path}/{name}")))
            .transpose()
    }

    /// The text of `node` as a `HexDecValue`.
    pub fn number(&self, node: Node<'_, '_>, path: &str) -> Result<i64, EsiError> {
        let t = text(node);
        hex_dec(&t).ok_or_else(|| {
            self.err(
                node,
                path,
                format!("{t:?} is not a number (#x… hex or decimal)"),
            )
        })
    }

    /// Attribute `attr` of `node` as a `HexDecValue`, `None` where absent.
    pub fn attr_number(
        &self,
        node: Node<'_, '_>,
        path: &str,
        attr: &str,
    ) -> Result<Option<i64>, EsiError> {
        node.attribute(attr)
            .map(|t| {
                hex_dec(t).ok_or_else(|| {
                    self.err(
                        node,
                        path,
                        format!("{t:?} is not a number (#x… hex or decimal)"),
                    )
                    .in_attribute(attr)
                })
            })
            .transpose()
    }

    /// Boolean attribute `attr` of `node`, `default` where absent.
    pub fn attr_bool(
        &self,
        node: Node<'_, '_>,
        path: &str,
        attr: &str,
        default: bool,
    ) -> Result<bool, EsiError> {
        match node.attribute(attr) {
            None => Ok(default),
            Some(t) => boolean(t).ok_or_else(|| {
                self.err(
                    node,
                    path,
                    format!("{t:?} is not a boolean (1, 0, true, false)"),
                )
                .in_attribute(attr)
            }),
        }
    }

    /// `number` checked to fit `T`.
    pub fn fit<T: TryFrom<i64>>(
        &self,
        node: Node<'_, '_>,
        path: &str,
        v: i64,
    ) -> Result<T, EsiError> {
        T::try_from(v).map_err(|_| {
            self.err(
                node,
                path,
                format!(
                    "{v} is out of range for a {}",
                    std::any::type_name::<T>()
                        .rsplit("::")
                        .next()
                        .unwrap_or("value")
                ),
            )
        })
    }
}

/// The first child element `name` of `node`.
pub(super) fn child<'a, 'input>(node: Node<'a, 'input>, name: &str) -> Option<Node<'a, 'input>> {
    node.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

/// Every child element `name` of `node`.
pub(super) fn children<'a, 'input: 'a>(
    node: Node<'a, 'input>,
    name: &'a str,
) -> impl Iterator<Item = Node<'a, 'input>> + 'a {
    node.children()
        .filter(move |c| c.is_element() && c.tag_name().name() == name)
}

/// The trimmed text content of `node` (CDATA included).
pub(super) fn text(node: Node<'_, '_>) -> String {
    let t: String = node
        .children()
        .filter(|c| c.is_text())
        .filter_map(|c| c.text())
        .collect();
    t.trim().to_owned()
}

/// The text of child `name`, "" where absent.
pub(super) fn child_text(node: Node<'_, '_>, name: &str) -> String {
    child(node, name).map(text).unwrap_or_default()
}

/// The English `Name` (LcId 1033) of `node`, else its first `Name`.
pub(super) fn english_name(node: Node<'_, '_>) -> String {
    children(node, "Name")
        .find(|n| n.attribute("LcId") == Some("1033"))
        .or_else(|| child(node, "Name"))
        .map(text)
        .unwrap_or_default()
}
