//! How each backend carries out an operator's request on its axes. Streamed axes go through
//! the motion engine (`host::motion`); profile axes get drive-side motions the RT thread hands
//! to their drives ([`profile`]); MR-JE-C axes get commands for their link threads ([`link`]).
//! A request's axes are named and checked once ([`split`]), then each backend takes its part.

pub(crate) mod link;
pub mod profile;

use std::collections::BTreeMap;

use cellrt_config::{AxisRef, CellConfig};

use super::targets::{axis_ref, TargetError};

/// An axis driven over an MR-JE-C link that a request names: its link, name and the value
/// asked.
pub(crate) type LinkTarget = (usize, String, f64);

/// A request's axes and values by backend: the RT loop's (streamed or profile axes) by name,
/// and the MR-JE-C links'.
#[derive(Debug, Default)]
pub(crate) struct Split {
    /// Axes on the RT loop, by name.
    pub(crate) on_loop: BTreeMap<String, f64>,
    /// Axes driven over an MR-JE-C link.
    pub(crate) on_link: Vec<LinkTarget>,
}

/// Splits a request's `targets` by backend; an unknown axis is refused here, naming every
/// axis of the cell.
pub(crate) fn split(
    cell: &CellConfig,
    targets: &BTreeMap<String, f64>,
) -> Result<Split, TargetError> {
    let mut s = Split::default();
    for (name, &v) in targets {
        match axis_ref(cell, name)? {
            AxisRef::Loop(_) => {
                s.on_loop.insert(name.clone(), v);
            }
            AxisRef::Link(k) => s.on_link.push((k, name.clone(), v)),
        }
    }
    Ok(s)
}

/// The axes a request names (`power`, `halt`) by backend: RT-loop slots and MR-JE-C links.
#[derive(Debug, Default)]
pub(crate) struct Named {
    /// Slots on the RT loop.
    pub(crate) on_loop: Vec<usize>,
    /// MR-JE-C links.
    pub(crate) on_link: Vec<usize>,
}

/// Names `names` by backend; an unknown axis or one named twice is refused here.
pub(crate) fn name_axes(cell: &CellConfig, names: &[String]) -> Result<Named, TargetError> {
    let mut n = Named::default();
    let mut seen = Vec::with_capacity(names.len());
    for name in names {
        let at = axis_ref(cell, name)?;
        if seen.contains(&at) {
            return Err(TargetError::Twice { axis: name.clone() });
        }
        seen.push(at);
        match at {
            AxisRef::Loop(i) => n.on_loop.push(i),
            AxisRef::Link(k) => n.on_link.push(k),
        }
    }
    Ok(n)
}

/// What a backend says of one axis a tracked command waits for.
pub(crate) enum AxisProgress<E> {
    /// Its part still runs.
    Running,
    /// Its part ended.
    Done,
    /// Its part failed: why.
    Failed(E),
}

/// The axes a tracked command waits for, each with what its backend noted before the command
/// was sent (`B`): one wait for every backend. The command ends once every axis is done, and
/// fails with the first axis that failed.
#[derive(Debug)]
pub(crate) struct Pending<B> {
    /// The command id, and per axis what was noted before it.
    waiting: Option<(u64, Vec<B>)>,
}

impl<B> Default for Pending<B> {
    fn default() -> Self {
        Pending { waiting: None }
    }
}

impl<B> Pending<B> {
    /// Command `id` waits for the axes noted in `before`.
    pub(crate) fn expect(&mut self, id: u64, before: Vec<B>) {
        self.waiting = Some((id, before));
    }

    /// Whether command `active` still waits for an axis (`judge` says how each one stands); the
    /// first failure. Forgets a command that is no longer the active one, or that ended.
    pub(crate) fn progress<E>(
        &mut self,
        active: Option<u64>,
        mut judge: impl FnMut(&B) -> AxisProgress<E>,
    ) -> Result<bool, E> {
        let Some((id, before)) = &self.waiting else {
            return Ok(false);
        };
        if Some(*id) != active {
            self.waiting = None;
            return Ok(false);
        }
        for b in before {
            match judge(b) {
                AxisProgress::Failed(e) => {
                    self.waiting = None;
                    return Err(e);
                }
                AxisProgress::Running => return Ok(true),
                AxisProgress::Done => {}
            }
        }
        self.waiting = None;
        Ok(false)
    }
}
