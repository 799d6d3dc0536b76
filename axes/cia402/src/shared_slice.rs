//! A table that is either compile-time data or built at run time and shared, so a profile's
//! built-in tables stay constants while a derived profile owns what it rebuilt.

use std::hash::{Hash, Hasher};
use std::ops::Deref;
use std::sync::Arc;

/// A read-only slice: a `'static` constant or an owned, reference-counted copy. Cloning it
/// never copies the elements. Constants name [`SharedSlice::Static`] directly: a constant built
/// by a function call could not be the base of another constant's `..base`.
#[derive(Debug, Clone)]
pub enum SharedSlice<T: 'static> {
    /// Compile-time data.
    Static(&'static [T]),
    /// Built at run time (a remapped PDO, the modes an ESI file lists).
    Owned(Arc<[T]>),
}

impl<T: 'static> SharedSlice<T> {
    /// The elements.
    pub fn as_slice(&self) -> &[T] {
        match self {
            SharedSlice::Static(s) => s,
            SharedSlice::Owned(s) => s,
        }
    }
}

impl<T: 'static> Deref for SharedSlice<T> {
    type Target = [T];

    fn deref(&self) -> &[T] {
        self.as_slice()
    }
}

impl<T: 'static> From<Vec<T>> for SharedSlice<T> {
    fn from(items: Vec<T>) -> Self {
        SharedSlice::Owned(items.into())
    }
}

impl<T: Clone + 'static> From<&[T]> for SharedSlice<T> {
    fn from(items: &[T]) -> Self {
        SharedSlice::Owned(items.into())
    }
}

impl<T: PartialEq + 'static> PartialEq for SharedSlice<T> {
    fn eq(&self, other: &Self) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl<T: Eq + 'static> Eq for SharedSlice<T> {}

impl<T: PartialEq + 'static> PartialEq<[T]> for SharedSlice<T> {
    fn eq(&self, other: &[T]) -> bool {
        self.as_slice() == other
    }
}

impl<T: PartialEq + 'static> PartialEq<&[T]> for SharedSlice<T> {
    fn eq(&self, other: &&[T]) -> bool {
        self.as_slice() == *other
    }
}

impl<T: PartialEq + 'static> PartialEq<SharedSlice<T>> for Vec<T> {
    fn eq(&self, other: &SharedSlice<T>) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl<T: Hash + 'static> Hash for SharedSlice<T> {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.as_slice().hash(state);
    }
}

impl<'a, T: 'static> IntoIterator for &'a SharedSlice<T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;

    fn into_iter(self) -> Self::IntoIter {
        self.as_slice().iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn static_and_owned_compare_by_content() {
        const A: SharedSlice<u8> = SharedSlice::Static(&[1, 2, 3]);
        let b = SharedSlice::from(vec![1u8, 2, 3]);
        assert_eq!(A, b);
        assert_eq!(&*b, &[1, 2, 3]);
        assert_ne!(A, SharedSlice::from(vec![1u8]));
    }
}
