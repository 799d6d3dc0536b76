//! The operator interface: an iceoryx2 request-response service per cell
//! (`cellrt/<cell>/operator`) through which the CLI and other processes power, move, halt, stop,
//! reset and query the cell. Requests and replies are JSON ([`wire`]).

pub mod client;
pub mod server;
pub mod wire;

use iceoryx2::port::client::Client;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::request_response::PortFactory;

use crate::services::{self, ServiceError};

/// Initial size of reply buffers, bytes (grown by power of two for a large status).
pub const SERVICE_RESPONSE_BYTES: usize = 16 * 1024;

/// Server end of the operator service.
pub type OperatorServerPort = Server<ipc::Service, [u8], (), [u8], ()>;
/// Client end of the operator service.
pub type OperatorClientPort = Client<ipc::Service, [u8], (), [u8], ()>;

/// The operator service (JSON bytes both ways, no user headers).
type OperatorService = PortFactory<ipc::Service, [u8], (), [u8], ()>;

/// The operator service's name for `cell`.
pub fn service_name(cell: &str) -> String {
    format!("cellrt/{cell}/operator")
}

fn service(node: &Node<ipc::Service>, cell: &str) -> Result<OperatorService, ServiceError> {
    let name = ServiceName::new(&service_name(cell))
        .map_err(|e| services::service_error("service name", cell, e))?;
    node.service_builder(&name)
        .request_response::<[u8], [u8]>()
        .max_clients(16)
        .max_servers(1)
        .max_active_requests_per_client(2)
        .max_response_buffer_size(2)
        .enable_safe_overflow_for_requests(true)
        .enable_safe_overflow_for_responses(true)
        .open_or_create()
        .map_err(|e| services::service_error("operator service", cell, e))
}

/// The event service a client notifies after sending a request, so the server answers at once
/// instead of at its next poll.
pub fn wake_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/operator-wake")
}

fn wake_service(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<iceoryx2::service::port_factory::event::PortFactory<ipc::Service>, ServiceError> {
    let name = ServiceName::new(&wake_service_name(cell))
        .map_err(|e| services::service_error("service name", cell, e))?;
    node.service_builder(&name)
        .event()
        .max_notifiers(16)
        .max_listeners(2)
        .open_or_create()
        .map_err(|e| services::service_error("operator wake service", cell, e))
}

fn wake_listener(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Listener<ipc::Service>, ServiceError> {
    wake_service(node, cell)?
        .listener_builder()
        .create()
        .map_err(|e| services::service_error("operator wake listener", cell, e))
}

fn wake_notifier(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<Notifier<ipc::Service>, ServiceError> {
    wake_service(node, cell)?
        .notifier_builder()
        .create()
        .map_err(|e| services::service_error("operator wake notifier", cell, e))
}

/// The status publish-subscribe service: the operator's [`wire::StatusReport`] as JSON, every
/// [`STATUS_PERIOD`] and after each command, history 1 (a new subscriber gets the latest).
pub fn status_service_name(cell: &str) -> String {
    format!("cellrt/{cell}/operator-status")
}

/// How often the operator status is published.
pub const STATUS_PERIOD: std::time::Duration = std::time::Duration::from_millis(100);

/// Publisher of the operator status.
pub type StatusPublisher = iceoryx2::port::publisher::Publisher<ipc::Service, [u8], ()>;
/// Subscriber of the operator status.
pub type StatusSubscriber = iceoryx2::port::subscriber::Subscriber<ipc::Service, [u8], ()>;

fn status_service(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, [u8], ()>,
    ServiceError,
> {
    let name = ServiceName::new(&status_service_name(cell))
        .map_err(|e| services::service_error("service name", cell, e))?;
    node.service_builder(&name)
        .publish_subscribe::<[u8]>()
        .max_publishers(1)
        .max_subscribers(16)
        .history_size(1)
        .subscriber_max_buffer_size(4)
        .enable_safe_overflow(true)
        .open_or_create()
        .map_err(|e| services::service_error("operator status service", cell, e))
}

fn status_publisher(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<StatusPublisher, ServiceError> {
    status_service(node, cell)?
        .publisher_builder()
        .initial_max_slice_len(SERVICE_RESPONSE_BYTES)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .backpressure_strategy(BackpressureStrategy::DiscardData)
        .create()
        .map_err(|e| services::service_error("operator status publisher", cell, e))
}

/// Subscribes to `cell`'s operator status (decode each sample with `serde_json`).
pub fn status_subscriber(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<StatusSubscriber, ServiceError> {
    status_service(node, cell)?
        .subscriber_builder()
        .create()
        .map_err(|e| services::service_error("operator status subscriber", cell, e))
}

fn server_port(node: &Node<ipc::Service>, cell: &str) -> Result<OperatorServerPort, ServiceError> {
    service(node, cell)?
        .server_builder()
        .initial_max_slice_len(SERVICE_RESPONSE_BYTES)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|e| services::service_error("operator server", cell, e))
}

fn client_port(node: &Node<ipc::Service>, cell: &str) -> Result<OperatorClientPort, ServiceError> {
    service(node, cell)?
        .client_builder()
        .initial_max_slice_len(wire::MAX_REQUEST_BYTES.min(4096))
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|e| services::service_error("operator client", cell, e))
}
