//! Test-only helpers shared by the cellrt crates (a dev-dependency, never linked into a
//! shipped binary).

#![warn(missing_docs)]

pub mod counting_alloc;
pub mod python;
pub mod sched;
pub mod veth;
