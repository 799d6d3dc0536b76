//! Errors of bring-up and shutdown, naming the drive and the step.

/// A bring-up or shutdown that failed, naming the drive and the step.
#[derive(Debug, thiserror::Error)]
pub enum EthercatError {
    /// An ethercrab operation failed.
    #[error("EtherCAT {step}: {source}")]
    Bringup {
        /// What was being done.
        step: String,
        /// ethercrab's error.
        source: ethercrab::error::Error,
    },
    /// The PDO configuration in PRE-OP failed, with the causes the model's manual gives for it.
    #[error(
        "EtherCAT PDO configuration of axis '{axis}' (SubDevice {position}): {source}{causes}"
    )]
    PdoConfiguration {
        /// Position.
        position: usize,
        /// Axis.
        axis: String,
        /// ethercrab's error.
        source: ethercrab::error::Error,
        /// "; likely cause: …" from the model's bring-up causes, or empty.
        causes: String,
    },
    /// The segment does not have the configured number of drives.
    #[error("EtherCAT segment has {found} SubDevice(s), the cell config names {expected}")]
    Count {
        /// Configured.
        expected: usize,
        /// Found on the wire.
        found: usize,
    },
    /// A drive's identity does not match its configured model.
    #[error(
        "EtherCAT SubDevice {position} (axis '{axis}', configured as {model}): identity vendor \
         {found_vendor:#010x} product {found_product:#010x} does not match the model (expected vendor \
         {expected_vendor:#010x}{expected_product})"
    )]
    Identity {
        /// Position in the line.
        position: usize,
        /// The axis.
        axis: String,
        /// The configured model.
        model: &'static str,
        /// 1018h:01 found.
        found_vendor: u32,
        /// 1018h:02 found.
        found_product: u32,
        /// Required vendor.
        expected_vendor: u32,
        /// ", product …" or "".
        expected_product: String,
    },
    /// The cycle time is not one the model allows.
    #[error("axis '{axis}': {model} does not support a {cycle_us} µs cycle (allowed: {allowed})")]
    CycleTime {
        /// The axis.
        axis: String,
        /// The model.
        model: &'static str,
        /// The cell's cycle.
        cycle_us: u32,
        /// The model's cycles.
        allowed: String,
    },
    /// The axes' amplifier labels and slots do not describe the units.
    #[error("axis '{axis}' (config keys amplifier / amplifier_axis): {what}")]
    Amplifier {
        /// The axis.
        axis: String,
        /// What is wrong.
        what: String,
    },
    /// The mode is not one the model runs (pv and tq on a multi-axis unit, MR-J5-G-N1 manual §1.1, §6.1, §7.4,
    /// TV-8).
    #[error("axis '{axis}': {model} does not run mode {mode} (allowed: {allowed})")]
    Mode {
        /// The axis.
        axis: String,
        /// The model.
        model: &'static str,
        /// The configured mode.
        mode: &'static str,
        /// The model's modes.
        allowed: String,
    },
    /// A drive refused the process image, or the image does not fit.
    #[error("EtherCAT SubDevice {position} (axis '{axis}'): {what}")]
    ProcessImage {
        /// Position.
        position: usize,
        /// Axis.
        axis: String,
        /// What is wrong.
        what: String,
    },
    /// A state change did not complete.
    #[error("EtherCAT: SubDevice {position} did not reach {state} (AL status {status:#04x}, AL status code {code:#06x})")]
    State {
        /// Position.
        position: usize,
        /// The requested state.
        state: &'static str,
        /// AL status read.
        status: u8,
        /// AL status code read.
        code: u16,
    },
    /// A SubDevice refused its cycle time 1C32h:02 (absent or read-only with another value)
    /// and runs without SYNC0, so nothing sets its cycle.
    #[error(
        "EtherCAT SubDevice {position} (axis '{axis}'): {sdo}{read_text}, and distributed clocks are off for it ([axes.ethercat] distributed_clocks = false): nothing sets its cycle to {wanted} ns; switch distributed clocks on or set the drive's cycle time to it",
        read_text = read.map(|v| format!(" (it reports {v} ns)")).unwrap_or_default()
    )]
    CycleTimeNotSet {
        /// Position.
        position: usize,
        /// Axis.
        axis: String,
        /// The refused SDO.
        sdo: super::refusal::RefusedSdo,
        /// The value read, where it could be.
        read: Option<u32>,
        /// The cell's cycle, ns.
        wanted: u32,
    },
    /// A download of the start-up list was refused.
    #[error(
        "EtherCAT SubDevice {position} (axis '{axis}'): start-up SDO {object} := {value} ([[axes.ethercat.startup_sdo]] entry {entry}) refused with abort code {code:#010x} ({})",
        super::refusal::abort_meaning(*code)
    )]
    StartupSdo {
        /// Position.
        position: usize,
        /// Axis.
        axis: String,
        /// 1-based entry of the axis' list.
        entry: usize,
        /// The object as the manuals print it.
        object: String,
        /// The value, as the bytes hold it (little-endian, unsigned).
        value: u64,
        /// The abort code.
        code: u32,
    },
    /// Distributed clocks are configured for a SubDevice whose ESC has none.
    #[error(
        "EtherCAT SubDevice {position} '{name}' (axis '{axis}'): its ESC reports no distributed clocks (feature register 0008h bit 2); set [axes.ethercat] distributed_clocks = false to run it free (SM2-synchronous)"
    )]
    NoDistributedClocks {
        /// Position.
        position: usize,
        /// Its SII name.
        name: String,
        /// Axis.
        axis: String,
    },
    /// A SubDevice refused a state change during bring-up.
    #[error("{0}")]
    StateRefused(Box<super::refusal::StateRefusal>),
    /// The link failed.
    #[error("EtherCAT link: {0}")]
    Link(#[from] super::link::LinkError),
}

/// An ethercrab result as a bring-up step's: `what` names the step in the error.
pub(super) fn step<T>(
    what: impl Into<String>,
    r: Result<T, ethercrab::error::Error>,
) -> Result<T, EthercatError> {
    r.map_err(|source| EthercatError::Bringup {
        step: what.into(),
        source,
    })
}
