//! Every iceoryx2 service of a cell, declared once: names, payload types and QoS. The cell's
//! own services (setpoints, status, commands), the operator's (requests, wake-up, status) and
//! an external planner's links (SDOs, profile commands, MR-JE-C commands and feedback).

use iceoryx2::config::Config;
use iceoryx2::node::{Node, NodeBuilder};
use iceoryx2::port::client::Client;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::server::Server;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::{event, publish_subscribe, request_response};

use crate::setpoints::{AxisSetpoint, SetpointHeader, BLOCK_CYCLES, MAX_AXES};

mod je_c_link;
mod profile_link;
pub use je_c_link::{
    je_c_command_publisher, je_c_command_service_name, je_c_command_subscriber,
    je_c_feedback_publisher, je_c_feedback_service_name, je_c_feedback_subscriber, je_c_shape,
    JecCommandSample, JecFeedbackSample, JE_C_LINK_VERSION,
};
pub use profile_link::{
    profile_command_publisher, profile_command_service_name, profile_command_subscriber,
    ProfileLinkSample,
};

/// The setpoint service's publisher type.
pub type SetpointPublisher = Publisher<ipc::Service, [AxisSetpoint], SetpointHeader>;
/// The setpoint service's subscriber type (the RT thread's end, read by
/// [`crate::rt::setpoint_stream::SetpointStream`]).
pub type SetpointSubscriber = Subscriber<ipc::Service, [AxisSetpoint], SetpointHeader>;

pub use cellrt_config::SETPOINT_BUFFER_BLOCKS;

/// Errors setting up a service.
#[derive(Debug, thiserror::Error)]
#[error("iceoryx2 {what} for cell '{cell}': {detail}")]
pub struct ServiceError {
    what: &'static str,
    cell: String,
    detail: String,
}

impl ServiceError {
    /// A helper thread of the services could not run.
    pub fn thread(detail: &str) -> ServiceError {
        ServiceError {
            what: "link thread",
            cell: String::new(),
            detail: detail.to_string(),
        }
    }
}

pub(crate) fn service_error(
    what: &'static str,
    cell: &str,
    e: impl std::fmt::Debug,
) -> ServiceError {
    ServiceError {
        what,
        cell: cell.to_string(),
        detail: format!("{e:?}"),
    }
}

/// Status of a cell as published to other processes (planner, CLI): the fields of
/// [`crate::handoff::CellStatus`] at one cycle.
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::StatusSample")]
pub struct StatusSample {
    /// Last executed cycle.
    pub cycle: u64,
    /// Cycle time, ns.
    pub cycle_time_ns: u64,
    /// `CellState as u8`.
    pub state: u8,
    /// `StopReason as u8`, 0 for none.
    pub stop_reason: u8,
    /// Reserved.
    pub reserved: [u8; 2],
    /// Motion running or last started.
    pub motion_id: u32,
    /// Last motion finished normally.
    pub motion_done: u32,
    /// Last motion whose first block the RT thread refused (never started).
    pub motion_refused: u32,
    /// Axes valid in `hold`.
    pub axis_count: u32,
    /// Cycles the motion `motion_id` started later than its first block said.
    pub motion_slip: u32,
    /// Hold position per axis, counts.
    pub hold: [f64; MAX_AXES],
    /// Latest feedback of each axis (first `axis_count` valid).
    pub live: [LiveAxis; MAX_AXES],
    /// The latest homing (`HomingStatus` packed).
    pub homing: u64,
}

/// Latest feedback of one axis, as the operator's status shows it.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::LiveAxis")]
pub struct LiveAxis {
    /// 6064h, counts.
    pub position_actual: i32,
    /// 606Ch, counts/s.
    pub velocity_actual: i32,
    /// 60F4h, counts.
    pub following_error: i32,
    /// 6041h.
    pub statusword: u16,
    /// 603Fh.
    pub error_code: u16,
    /// 6061h.
    pub mode_display: i8,
    /// 1 when MC_Power is on for the axis (the operator wants it enabled).
    pub powered: u8,
    /// The mode (6060h) the RT thread runs the axis in: its configured one, or the one a
    /// run-time mode switch left it in (`ProfileMotion::SwitchMode`).
    pub mode: i8,
    /// Padding (0).
    pub reserved: u8,
    /// 2D11h–2D13h Status DO 1–3 (0 where the drive does not map them).
    pub status_do: [u16; 3],
    /// Drive-side motions of a profile axis that have ended (any outcome), counted.
    pub profile_finished: u32,
    /// Of those, the ones refused or cancelled.
    pub profile_failed: u32,
}

impl Default for StatusSample {
    fn default() -> Self {
        StatusSample {
            cycle: 0,
            cycle_time_ns: 0,
            state: 0,
            stop_reason: 0,
            reserved: [0; 2],
            motion_id: 0,
            motion_done: 0,
            motion_refused: 0,
            axis_count: 0,
            motion_slip: 0,
            hold: [0.0; MAX_AXES],
            live: [LiveAxis::default(); MAX_AXES],
            homing: 0,
        }
    }
}

/// A command from another process (`CellCommand` code, see `CellCommand::from_code`).
#[derive(Debug, Clone, Copy, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::CommandSample")]
pub struct CommandSample {
    /// Command code.
    pub code: u32,
    /// Argument ([`HOME_COMMAND_CODE`]: the packed `HomeRequest`).
    pub arg: u32,
}

/// An operator SDO request or its outcome between an external planner and the controller, in
/// the hand-off's own encoding ([`crate::handoff::UserSdo::to_wire`],
/// [`crate::handoff::UserSdoOutcome::to_wire`]).
#[derive(Debug, Clone, Copy, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("cellrt::SdoLinkSample")]
pub struct SdoLinkSample {
    /// Sequence number and axis (request) or kind (outcome).
    pub header: u32,
    /// The request's or the outcome's data.
    pub word: u64,
}

/// The service carrying operator SDO requests from an external planner to the controller.
pub fn sdo_request_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/sdo-requests")
}

/// The service carrying their outcomes back (history 1: the latest).
pub fn sdo_outcome_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/sdo-outcomes")
}

/// The external planner's publisher of SDO requests.
pub fn sdo_request_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Publisher<ipc::Service, SdoLinkSample, ()>, ServiceError> {
    pubsub::<SdoLinkSample>(node, cell, &sdo_request_service_name(cell), 2, 1, 0)?
        .publisher_builder()
        .create()
        .map_err(|e| service_error("SDO request publisher", cell, e))
}

/// The controller's subscriber of SDO requests.
pub fn sdo_request_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Subscriber<ipc::Service, SdoLinkSample, ()>, ServiceError> {
    pubsub::<SdoLinkSample>(node, cell, &sdo_request_service_name(cell), 2, 1, 0)?
        .subscriber_builder()
        .create()
        .map_err(|e| service_error("SDO request subscriber", cell, e))
}

/// The controller's publisher of SDO outcomes.
pub fn sdo_outcome_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Publisher<ipc::Service, SdoLinkSample, ()>, ServiceError> {
    pubsub::<SdoLinkSample>(node, cell, &sdo_outcome_service_name(cell), 1, 2, 1)?
        .publisher_builder()
        .create()
        .map_err(|e| service_error("SDO outcome publisher", cell, e))
}

/// The external planner's subscriber of SDO outcomes.
pub fn sdo_outcome_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Subscriber<ipc::Service, SdoLinkSample, ()>, ServiceError> {
    pubsub::<SdoLinkSample>(node, cell, &sdo_outcome_service_name(cell), 1, 2, 1)?
        .subscriber_builder()
        .create()
        .map_err(|e| service_error("SDO outcome subscriber", cell, e))
}

/// [`CommandSample::code`] of a homing request (not a `CellCommand`: it carries an axis).
pub const HOME_COMMAND_CODE: u32 = 0x100;
/// [`CommandSample::code`] of the feed override for the profile axes' drives (arg: ‰, 0–1000).
pub const OVERRIDE_COMMAND_CODE: u32 = 0x102;
/// The `command_refused` event value of a profile command sample that was refused.
pub const PROFILE_COMMAND_CODE: u32 = 0x101;

/// The status service name of `cell`.
pub fn status_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/status")
}

/// The command service name of `cell`.
pub fn command_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/commands")
}

/// The iceoryx2 node name of a cell's planner (in-process or its own process).
pub fn planner_node_name(cell: &str) -> String {
    format!("cellrt-{cell}-planner")
}

/// The setpoint service name of `cell`.
pub fn setpoint_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/setpoints")
}

/// The operator service name of `cell` (request-response, JSON both ways).
pub fn operator_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/operator")
}

/// The event service a client notifies after sending an operator request, so the server
/// answers at once instead of at its next poll.
pub fn operator_wake_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/operator-wake")
}

/// The operator status service name of `cell`: the operator's status report as JSON, history 1
/// (a new subscriber gets the latest).
pub fn operator_status_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/operator-status")
}

/// iceoryx2 configuration: each user gets its own root directory (inside the user's private
/// runtime directory, [`crate::runtime_dir`]) and resource prefix, so cells of different users
/// (root and an operator) never collide on files the other may not open.
pub fn config() -> Config {
    let mut config = Config::default();
    let root = format!("{}/", crate::runtime_dir::iceoryx2_root().display());
    if let Ok(p) = Path::new(root.as_bytes()) {
        config.global.set_root_path(&p);
    }
    if let Ok(p) = FileName::new(shm_prefix().as_bytes()) {
        config.global.prefix = p;
    }
    config
}

/// The level of iceoryx2's own log on stderr unless `IOX2_LOG_LEVEL` says otherwise: its
/// warnings are not the operator's (e.g. it falls back to its default config while it cleans
/// up a node another process left behind), and a command's error must stay one line.
pub const ICEORYX2_LOG_LEVEL: LogLevel = LogLevel::Error;

/// Sets iceoryx2's log level once per process: [`ICEORYX2_LOG_LEVEL`] or `IOX2_LOG_LEVEL`.
pub fn quiet_iceoryx2_log() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| set_log_level_from_env_or(ICEORYX2_LOG_LEVEL));
}

/// Creates an iceoryx2 node for one thread of a cell (ports are not `Send`).
pub fn node(cell: &str, role: &str) -> Result<Node<ipc::Service>, ServiceError> {
    quiet_iceoryx2_log();
    crate::runtime_dir::ensure().map_err(|e| ServiceError {
        what: "runtime directory",
        cell: cell.to_string(),
        detail: e.to_string(),
    })?;
    let name = format!("cellrt-{cell}-{role}");
    let node_name = NodeName::new(&name).map_err(|e| service_error("node name", cell, e))?;
    let shm = std::path::Path::new(crate::shm_guard::SHM_DIR);
    let (prefix, uid) = (shm_prefix(), uid());
    let guard = |e: crate::shm_guard::ShmGuardError| ServiceError {
        what: "shared memory",
        cell: cell.to_string(),
        detail: e.to_string(),
    };
    crate::shm_guard::clear_foreign(shm, &prefix, uid).map_err(guard)?;
    let node = NodeBuilder::new()
        .name(&node_name)
        .config(&config())
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| service_error("node", cell, e))?;
    crate::shm_guard::restrict_own(shm, &prefix, uid).map_err(guard)?;
    Ok(node)
}

fn uid() -> u32 {
    nix::unistd::getuid().as_raw()
}

/// The prefix of the current user's iceoryx2 resources.
fn shm_prefix() -> String {
    format!("iox2_cellrt_u{}_", uid())
}

fn setpoint_service(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<
    publish_subscribe::PortFactory<ipc::Service, [AxisSetpoint], SetpointHeader>,
    ServiceError,
> {
    let name = ServiceName::new(&setpoint_service_name(cell))
        .map_err(|e| service_error("service name", cell, e))?;
    node.service_builder(&name)
        .publish_subscribe::<[AxisSetpoint]>()
        .user_header::<SetpointHeader>()
        .max_publishers(1)
        .max_subscribers(2)
        .history_size(0)
        .subscriber_max_buffer_size(SETPOINT_BUFFER_BLOCKS)
        .subscriber_max_borrowed_samples(4)
        .enable_safe_overflow(true)
        .open_or_create()
        .map_err(|e| service_error("setpoint service", cell, e))
}

/// The planner's end of the setpoint service, sized for blocks of `axes` axes.
pub fn setpoint_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
    axes: usize,
) -> Result<SetpointPublisher, ServiceError> {
    setpoint_service(node, cell)?
        .publisher_builder()
        .initial_max_slice_len(BLOCK_CYCLES * axes.max(1))
        .allocation_strategy(AllocationStrategy::Static)
        .backpressure_strategy(BackpressureStrategy::DiscardData)
        .max_loaned_samples(4)
        .create()
        .map_err(|e| service_error("setpoint publisher", cell, e))
}

/// The RT thread's end of the setpoint service.
pub fn setpoint_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<SetpointSubscriber, ServiceError> {
    setpoint_service(node, cell)?
        .subscriber_builder()
        .create()
        .map_err(|e| service_error("setpoint subscriber", cell, e))
}

fn pubsub<T: std::fmt::Debug + ZeroCopySend>(
    node: &Node<ipc::Service>,
    cell: &str,
    name: &str,
    publishers: usize,
    subscribers: usize,
    history: usize,
) -> Result<publish_subscribe::PortFactory<ipc::Service, T, ()>, ServiceError> {
    let service_name =
        ServiceName::new(name).map_err(|e| service_error("service name", cell, e))?;
    node.service_builder(&service_name)
        .publish_subscribe::<T>()
        .max_publishers(publishers)
        .max_subscribers(subscribers)
        .history_size(history)
        .subscriber_max_buffer_size(history.max(16))
        .enable_safe_overflow(true)
        .open_or_create()
        .map_err(|e| service_error("service", cell, e))
}

/// The controller's publisher of cell status.
pub fn status_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Publisher<ipc::Service, StatusSample, ()>, ServiceError> {
    pubsub::<StatusSample>(node, cell, &status_service_name(cell), 1, 16, 1)?
        .publisher_builder()
        .backpressure_strategy(BackpressureStrategy::DiscardData)
        .create()
        .map_err(|e| service_error("status publisher", cell, e))
}

/// A client's subscriber to cell status (the latest sample arrives on connect).
pub fn status_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Subscriber<ipc::Service, StatusSample, ()>, ServiceError> {
    pubsub::<StatusSample>(node, cell, &status_service_name(cell), 1, 16, 1)?
        .subscriber_builder()
        .create()
        .map_err(|e| service_error("status subscriber", cell, e))
}

/// A client's publisher of commands to the cell.
pub fn command_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Publisher<ipc::Service, CommandSample, ()>, ServiceError> {
    pubsub::<CommandSample>(node, cell, &command_service_name(cell), 8, 1, 0)?
        .publisher_builder()
        .backpressure_strategy(BackpressureStrategy::DiscardData)
        .create()
        .map_err(|e| service_error("command publisher", cell, e))
}

/// The controller's subscriber of commands.
pub fn command_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Subscriber<ipc::Service, CommandSample, ()>, ServiceError> {
    pubsub::<CommandSample>(node, cell, &command_service_name(cell), 8, 1, 0)?
        .subscriber_builder()
        .create()
        .map_err(|e| service_error("command subscriber", cell, e))
}

/// Largest operator request accepted, bytes.
pub const MAX_OPERATOR_REQUEST_BYTES: usize = 64 * 1024;
/// Initial size of operator reply and status buffers, bytes (grown by powers of two for a large
/// status).
pub const OPERATOR_RESPONSE_BYTES: usize = 16 * 1024;

/// Server end of the operator service.
pub type OperatorServerPort = Server<ipc::Service, [u8], (), [u8], ()>;
/// Client end of the operator service.
pub type OperatorClientPort = Client<ipc::Service, [u8], (), [u8], ()>;
/// Publisher of the operator status.
pub type OperatorStatusPublisher = Publisher<ipc::Service, [u8], ()>;
/// Subscriber of the operator status.
pub type OperatorStatusSubscriber = Subscriber<ipc::Service, [u8], ()>;

/// Operator clients (each a node with a client port and a wake-up notifier) connected to a
/// cell at once; one more is refused by iceoryx2. Above the hundred concurrent clients the
/// operator service is tested with; each costs the server about 160 KiB of shared memory (one
/// request and one response in flight per client: a client waits for each reply).
pub const MAX_OPERATOR_CLIENTS: usize = 128;

/// Nodes beside the clients that open the operator services (the planner, monitors).
const OPERATOR_OTHER_NODES: usize = 8;

/// The operator service (JSON bytes both ways, no user headers).
type OperatorService = request_response::PortFactory<ipc::Service, [u8], (), [u8], ()>;

fn operator_service(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<OperatorService, ServiceError> {
    let name = ServiceName::new(&operator_service_name(cell))
        .map_err(|e| service_error("service name", cell, e))?;
    node.service_builder(&name)
        .request_response::<[u8], [u8]>()
        .max_nodes(MAX_OPERATOR_CLIENTS + OPERATOR_OTHER_NODES)
        .max_clients(MAX_OPERATOR_CLIENTS)
        .max_servers(1)
        .max_active_requests_per_client(1)
        .max_response_buffer_size(1)
        .enable_safe_overflow_for_requests(true)
        .enable_safe_overflow_for_responses(true)
        .open_or_create()
        .map_err(|e| service_error("operator service", cell, e))
}

/// The planner thread's end of the operator service.
pub fn operator_server(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<OperatorServerPort, ServiceError> {
    operator_service(node, cell)?
        .server_builder()
        .initial_max_slice_len(OPERATOR_RESPONSE_BYTES)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|e| service_error("operator server", cell, e))
}

/// A client's end of the operator service (the CLI or another process).
pub fn operator_client(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<OperatorClientPort, ServiceError> {
    operator_service(node, cell)?
        .client_builder()
        .initial_max_slice_len(MAX_OPERATOR_REQUEST_BYTES.min(4096))
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|e| service_error("operator client", cell, e))
}

fn operator_wake_service(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<event::PortFactory<ipc::Service>, ServiceError> {
    let name = ServiceName::new(&operator_wake_service_name(cell))
        .map_err(|e| service_error("service name", cell, e))?;
    node.service_builder(&name)
        .event()
        .max_nodes(MAX_OPERATOR_CLIENTS + OPERATOR_OTHER_NODES)
        .max_notifiers(MAX_OPERATOR_CLIENTS)
        .max_listeners(2)
        .open_or_create()
        .map_err(|e| service_error("operator wake service", cell, e))
}

/// The operator server's listener: woken by a client after each request.
pub fn operator_wake_listener(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Listener<ipc::Service>, ServiceError> {
    operator_wake_service(node, cell)?
        .listener_builder()
        .create()
        .map_err(|e| service_error("operator wake listener", cell, e))
}

/// A client's notifier that wakes the operator server after a request.
pub fn operator_wake_notifier(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Notifier<ipc::Service>, ServiceError> {
    operator_wake_service(node, cell)?
        .notifier_builder()
        .create()
        .map_err(|e| service_error("operator wake notifier", cell, e))
}

fn operator_status_service(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<publish_subscribe::PortFactory<ipc::Service, [u8], ()>, ServiceError> {
    let name = ServiceName::new(&operator_status_service_name(cell))
        .map_err(|e| service_error("service name", cell, e))?;
    node.service_builder(&name)
        .publish_subscribe::<[u8]>()
        .max_publishers(1)
        .max_subscribers(16)
        .history_size(1)
        .subscriber_max_buffer_size(4)
        .enable_safe_overflow(true)
        .open_or_create()
        .map_err(|e| service_error("operator status service", cell, e))
}

/// The operator server's publisher of its status report.
pub fn operator_status_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<OperatorStatusPublisher, ServiceError> {
    operator_status_service(node, cell)?
        .publisher_builder()
        .initial_max_slice_len(OPERATOR_RESPONSE_BYTES)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .backpressure_strategy(BackpressureStrategy::DiscardData)
        .create()
        .map_err(|e| service_error("operator status publisher", cell, e))
}

/// Subscribes to `cell`'s operator status (decode each sample with `serde_json`).
pub fn operator_status_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<OperatorStatusSubscriber, ServiceError> {
    operator_status_service(node, cell)?
        .subscriber_builder()
        .create()
        .map_err(|e| service_error("operator status subscriber", cell, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    const CHILD: &str = "CELLRT_ICEORYX2_LOG_CHILD";

    /// iceoryx2 falls back to its global config (and warns on stderr) when it cleans up a node
    /// another process left behind; after a cell's first node that warning must not reach a
    /// command's stderr. Run in a child process: the log level is per process.
    #[test]
    fn iceoryx2_warnings_stay_off_stderr_after_the_first_node() {
        if std::env::var_os(CHILD).is_some() {
            let cell = format!("iox-log-{}", std::process::id());
            let _node = node(&cell, "probe").expect("node");
            let _ = Config::global_config();
            return;
        }
        let out = std::process::Command::new(std::env::current_exe().unwrap())
            .args([
                "services::tests::iceoryx2_warnings_stay_off_stderr_after_the_first_node",
                "--exact",
                "--nocapture",
                "--test-threads=1",
            ])
            .env(CHILD, "1")
            .env_remove("IOX2_LOG_LEVEL")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "child failed: {err}");
        assert!(!err.contains("Config::global_config()"), "{err}");
    }
}
