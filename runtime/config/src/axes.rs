//! The cell's one list of axes: every `[[axes]]` entry in file order, each with the backend
//! that carries out its motion. Program steps, operator requests, status, the summary and the
//! recording walk this list and name axes by [`AxisRef`]; only the backends look inside.

use crate::je_c_axis::JecAxisConfig;
use crate::{AxisConfig, AxisRef};

/// The cell's axes in configuration order. The RT loop's slots (the setpoint block's columns)
/// and the MR-JE-C links each see the part they run, through [`CellAxes::on_loop`] and
/// [`CellAxes::on_link`].
#[derive(Debug, Clone, Default)]
pub struct CellAxes {
    /// Every axis in file order, as its backend's handle.
    order: Vec<AxisRef>,
    /// The axes the RT loop runs, by slot.
    on_loop: Vec<AxisConfig>,
    /// The axes driven over an MR-JE-C link, by link.
    on_link: Vec<JecAxisConfig>,
}

/// How an axis' motion is carried out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    /// The RT loop streams its setpoints every cycle (csp/csv/cst).
    Streamed,
    /// Its drive's own profile generator moves it, commanded over the cyclic bus (pp/pv/tq).
    Profile,
    /// Driven over its MR-JE-C link by an I/O thread of its own, never by the RT loop.
    Link,
}

impl Backend {
    /// The name the status, the summary and messages use.
    pub const fn as_str(self) -> &'static str {
        match self {
            Backend::Streamed => "streamed",
            Backend::Profile => "profile",
            Backend::Link => "mr-je-c link",
        }
    }
}

/// One axis of the cell, seen from the list: its handle, name and configuration.
#[derive(Debug, Clone, Copy)]
pub struct Axis<'a> {
    /// Its handle.
    pub at: AxisRef,
    /// Its configuration, by backend.
    pub config: AxisKind<'a>,
}

/// An axis' configuration, by where it runs.
#[derive(Debug, Clone, Copy)]
pub enum AxisKind<'a> {
    /// Run by the RT loop: its slot there and its configuration.
    Loop(usize, &'a AxisConfig),
    /// Driven over its MR-JE-C link: the link and its configuration.
    Link(usize, &'a JecAxisConfig),
}

impl<'a> Axis<'a> {
    /// Its name, unique in the cell.
    pub fn name(&self) -> &'a str {
        match self.config {
            AxisKind::Loop(_, a) => &a.name,
            AxisKind::Link(_, a) => &a.name,
        }
    }

    /// How its motion is carried out.
    pub fn backend(&self) -> Backend {
        match self.config {
            AxisKind::Loop(_, a) if a.profile_objects.is_some() => Backend::Profile,
            AxisKind::Loop(..) => Backend::Streamed,
            AxisKind::Link(..) => Backend::Link,
        }
    }

    /// Its velocity limit, unit/s.
    pub fn velocity_limit(&self) -> f64 {
        match self.config {
            AxisKind::Loop(_, a) => a.limits.velocity,
            AxisKind::Link(_, a) => a.velocity,
        }
    }

    /// The display name of its unit.
    pub fn unit(&self) -> &'a str {
        match self.config {
            AxisKind::Loop(_, a) => &a.unit,
            AxisKind::Link(_, a) => &a.unit,
        }
    }
    /// Drive counts per unit (position scaling).
    pub fn counts_per_unit(&self) -> f64 {
        match self.config {
            AxisKind::Loop(_, a) => a.scaling.counts_per_unit(),
            AxisKind::Link(_, a) => a.counts_per_unit,
        }
    }
}

impl AxisRef {
    /// Its RT-loop slot, for an axis the loop runs.
    pub const fn loop_slot(self) -> Option<usize> {
        match self {
            AxisRef::Loop(i) => Some(i),
            AxisRef::Link(_) => None,
        }
    }

    /// Its link, for an axis driven over an MR-JE-C link.
    pub const fn link(self) -> Option<usize> {
        match self {
            AxisRef::Link(k) => Some(k),
            AxisRef::Loop(_) => None,
        }
    }
}

impl CellAxes {
    /// Appends an axis the RT loop runs; returns its handle.
    pub(crate) fn push_loop(&mut self, axis: AxisConfig) -> AxisRef {
        let at = AxisRef::Loop(self.on_loop.len());
        self.on_loop.push(axis);
        self.order.push(at);
        at
    }

    /// Appends an axis driven over an MR-JE-C link; returns its handle.
    pub(crate) fn push_link(&mut self, axis: JecAxisConfig) -> AxisRef {
        let at = AxisRef::Link(self.on_link.len());
        self.on_link.push(axis);
        self.order.push(at);
        at
    }

    /// Every axis, in configuration order.
    pub fn iter(&self) -> impl Iterator<Item = Axis<'_>> + '_ {
        self.order.iter().map(|&at| self.get(at))
    }

    /// How many axes the cell has, whichever backend runs them (never 0 once validated).
    pub fn count(&self) -> usize {
        self.order.len()
    }

    /// The axis `at` names.
    ///
    /// # Panics
    /// If `at` is not a handle of this cell (handles come from this list).
    pub fn get(&self, at: AxisRef) -> Axis<'_> {
        let config = match at {
            AxisRef::Loop(i) => AxisKind::Loop(i, &self.on_loop[i]),
            AxisRef::Link(k) => AxisKind::Link(k, &self.on_link[k]),
        };
        Axis { at, config }
    }

    /// The axis called `name`.
    pub fn find(&self, name: &str) -> Option<Axis<'_>> {
        self.iter().find(|a| a.name() == name)
    }

    /// The axes the RT loop runs, by slot (the setpoint block's columns, the RT thread's
    /// drives, the recording's per-cycle channels).
    pub fn on_loop(&self) -> &[AxisConfig] {
        &self.on_loop
    }

    /// The RT loop's axes, to adjust before the cell starts (command-line overrides, tests).
    pub fn on_loop_mut(&mut self) -> &mut [AxisConfig] {
        &mut self.on_loop
    }

    /// The axes driven over MR-JE-C links, by link (the link threads' order).
    pub fn on_link(&self) -> &[JecAxisConfig] {
        &self.on_link
    }

    /// The MR-JE-C axes, to adjust before the cell starts (command-line overrides, tests).
    pub fn on_link_mut(&mut self) -> &mut [JecAxisConfig] {
        &mut self.on_link
    }

    /// Comma-separated names of every axis in configuration order, for messages.
    pub fn names(&self) -> String {
        self.iter().map(|a| a.name()).collect::<Vec<_>>().join(", ")
    }

    /// Comma-separated names of the RT loop's axes by slot (the recording's `axes` metadata,
    /// the columns of its per-cycle channels).
    pub fn loop_names(&self) -> String {
        let names: Vec<&str> = self.on_loop.iter().map(|a| a.name.as_str()).collect();
        names.join(", ")
    }
}
