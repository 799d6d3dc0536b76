//! Every iceoryx2 service of a cell, declared once: names, payload types and QoS.

use iceoryx2::config::Config;
use iceoryx2::node::{Node, NodeBuilder};
use iceoryx2::port::publisher::Publisher;
use iceoryx2::prelude::*;

use crate::setpoints::{AxisSetpoint, SetpointHeader, SetpointSubscriber, BLOCK_CYCLES};

/// The setpoint service's publisher type.
pub type SetpointPublisher = Publisher<ipc::Service, [AxisSetpoint], SetpointHeader>;

/// Setpoint blocks the subscriber buffers (the RT thread's lookahead, in blocks).
pub const SETPOINT_BUFFER_BLOCKS: usize = 256;

/// Errors setting up a service.
#[derive(Debug, thiserror::Error)]
#[error("iceoryx2 {what} for cell '{cell}': {detail}")]
pub struct ServiceError {
    what: &'static str,
    cell: String,
    detail: String,
}

fn service_error(what: &'static str, cell: &str, e: impl std::fmt::Debug) -> ServiceError {
    ServiceError {
        what,
        cell: cell.to_string(),
        detail: format!("{e:?}"),
    }
}

/// The setpoint service name of `cell`.
pub fn setpoint_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/setpoints")
}

/// iceoryx2 configuration: each user gets its own root directory and resource prefix, so cells
/// of different users (root and an operator) never collide on files the other may not open
/// (iceoryx2 creates them mode 0600 / 0750).
fn config() -> Config {
    let uid = nix::unistd::getuid().as_raw();
    let mut config = Config::default();
    let root = format!("{}/cellrt-iceoryx2-u{uid}/", std::env::temp_dir().display());
    if let Ok(p) = Path::new(root.as_bytes()) {
        config.global.set_root_path(&p);
    }
    if let Ok(p) = FileName::new(format!("iox2_cellrt_u{uid}_").as_bytes()) {
        config.global.prefix = p;
    }
    config
}

/// Creates an iceoryx2 node for one thread of a cell (ports are not `Send`).
pub fn node(cell: &str, role: &str) -> Result<Node<ipc::Service>, ServiceError> {
    let name = format!("cellrt-{cell}-{role}");
    let node_name = NodeName::new(&name).map_err(|e| service_error("node name", cell, e))?;
    NodeBuilder::new()
        .name(&node_name)
        .config(&config())
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| service_error("node", cell, e))
}

fn setpoint_service(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<
        ipc::Service,
        [AxisSetpoint],
        SetpointHeader,
    >,
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
