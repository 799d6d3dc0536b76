//! Topic and schema names of a recording, defined once for the writer, readers and docs.

/// Per-cycle timing, schema `cellrt.CycleStats`.
pub const CYCLE_TOPIC: &str = "/cell/cycle";
/// Events, schema `cellrt.Event`.
pub const EVENTS_TOPIC: &str = "/cell/events";
/// Prefix of the per-axis topics: `/axis/<name>`, schema `cellrt.AxisCycle`.
pub const AXIS_TOPIC_PREFIX: &str = "/axis/";

/// Schema name of [`CYCLE_TOPIC`].
pub const CYCLE_SCHEMA: &str = "cellrt.CycleStats";
/// Schema name of the axis topics.
pub const AXIS_SCHEMA: &str = "cellrt.AxisCycle";
/// Schema name of [`EVENTS_TOPIC`].
pub const EVENT_SCHEMA: &str = "cellrt.Event";

/// Prefix of the MR-JE-C axes' topics: `/je_c/<name>`, schema `cellrt.JecExchange`.
pub const JE_C_TOPIC_PREFIX: &str = "/je_c/";
/// Schema name of the MR-JE-C topics.
pub const JE_C_SCHEMA: &str = "cellrt.JecExchange";

/// MCAP metadata record holding the cell description.
pub const CELL_METADATA: &str = "cellrt.cell";

/// The topic of axis `name`.
pub fn axis_topic(name: &str) -> String {
    format!("{AXIS_TOPIC_PREFIX}{name}")
}

/// The topic of MR-JE-C axis `name`.
pub fn je_c_topic(name: &str) -> String {
    format!("{JE_C_TOPIC_PREFIX}{name}")
}
