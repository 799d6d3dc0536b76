//! The exchange of one MR-JE-C axis over its configured transport, and the start-up writes of
//! its drive-side time-out (MR-JE-C manual §5.2.2, §5.2.3: [Pr. PN02] for the cyclic link,
//! [Pr. PN10] for SLMP and Modbus/TCP, [Pr. PF46] for Modbus RTU).

use std::net::{IpAddr, Ipv4Addr, SocketAddr, UdpSocket};

use cellrt_fieldbus::cclink_ief_basic::io_thread::CyclicIo;
use cellrt_fieldbus::cclink_ief_basic::master::MasterError;
use cellrt_fieldbus::cclink_ief_basic::master::{GroupMaster, MasterParams};
use cellrt_fieldbus::modbus::client::{ClientError, TcpClient};
use cellrt_fieldbus::modbus::serial::{LineSettings, RtuClient};
use cellrt_fieldbus::mr_je_c::cell::{CyclicDriveIo, DeviceTable, DriveIo, ObjectIo};
use cellrt_fieldbus::mr_je_c::parameters::{PF46, PN02, PN10};
use cellrt_fieldbus::mr_je_c::{ObjectId, OverModbus, Value};
use cellrt_fieldbus::slmp::client::{FrameType, SlmpClient};

use super::emulated::Reach;
use cellrt_config::je_c_axis::{JecAxisConfig, JecTransport};

/// Why an MR-JE-C axis' exchange with its drive could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum OpenError {
    /// The serial line's settings (baud rate, framing) were refused.
    #[error(transparent)]
    LineSettings(cellrt_fieldbus::modbus::serial::BaudRateError),
    /// The serial line's port could not be opened.
    #[error("{0}")]
    Port(#[source] ClientError),
    /// The Modbus RTU client refused the line's settings.
    #[error("line: {0}")]
    Line(cellrt_fieldbus::modbus::serial::BaudRateError),
    /// The Modbus RTU client refused the station.
    #[error("station: {0}")]
    Station(#[source] ClientError),
    /// The Modbus/TCP drive could not be reached.
    #[error("{at}: {source}")]
    ModbusTcp {
        /// The drive's address.
        at: SocketAddr,
        /// Why.
        source: ClientError,
    },
    /// The SLMP client could not be opened.
    #[error("{at}: {source}")]
    Slmp {
        /// The drive's (SLMP) address.
        at: SocketAddr,
        /// Why.
        source: cellrt_fieldbus::slmp::client::ClientError,
    },
    /// The cyclic (CC-Link IE Field Basic) master could not be opened.
    #[error("{at}: {source}")]
    Cyclic {
        /// The drive's address.
        at: SocketAddr,
        /// Why.
        source: MasterError,
    },
    /// No local address routes to the drive.
    #[error("route: {0}")]
    Route(#[source] std::io::Error),
    /// A serial line was given for an Ethernet transport.
    #[error("a serial line for an Ethernet transport")]
    SerialForEthernet,
    /// An address was given for a serial line.
    #[error("an address for a serial line")]
    AddressForSerial,
}

/// Where a real drive is reached: the configured address (or line).
pub fn configured(axis: &JecAxisConfig) -> Option<Reach> {
    let slmp = |a: SocketAddr| SocketAddr::new(a.ip(), cellrt_fieldbus::slmp::UDP_PORT);
    match &axis.transport {
        JecTransport::CcLink(Some(a))
        | JecTransport::Slmp(Some(a))
        | JecTransport::ModbusTcp(Some(a)) => Some(Reach::Address {
            at: *a,
            slmp: slmp(*a),
        }),
        _ => None,
    }
}

/// The local address the system routes to `to` from (the cyclic master's ID).
fn local_for(to: SocketAddr) -> std::io::Result<IpAddr> {
    let probe = UdpSocket::bind((Ipv4Addr::UNSPECIFIED, 0))?;
    probe.connect(to)?;
    Ok(probe.local_addr()?.ip())
}

/// The axis' exchange with its drive at `reach`.
pub fn open(axis: &JecAxisConfig, reach: Reach) -> Result<Box<dyn DriveIo>, OpenError> {
    let timeout = axis.response_timeout;
    let software = Default::default();
    match (reach, &axis.transport) {
        (Reach::Port(port), JecTransport::ModbusRtu { station, baud, .. }) => {
            let line = LineSettings::new(*baud, Default::default()).map_err(OpenError::Line)?;
            let client =
                RtuClient::new(port, line, *station, timeout).map_err(OpenError::Station)?;
            Ok(Box::new(ObjectIo::new(OverModbus::new(client, software))))
        }
        (Reach::Port(_), _) => Err(OpenError::SerialForEthernet),
        (Reach::Address { at, .. }, JecTransport::ModbusTcp(_)) => {
            let client = TcpClient::connect(at, timeout)
                .map_err(|source| OpenError::ModbusTcp { at, source })?;
            Ok(Box::new(ObjectIo::new(OverModbus::new(client, software))))
        }
        (Reach::Address { at, .. }, JecTransport::Slmp(_)) => {
            let client = SlmpClient::udp(at, FrameType::E4, timeout)
                .map_err(|source| OpenError::Slmp { at, source })?;
            Ok(Box::new(ObjectIo::new(client)))
        }
        (Reach::Address { at, slmp }, JecTransport::CcLink(_)) => {
            let local = SocketAddr::new(local_for(at).map_err(OpenError::Route)?, 0);
            let params = MasterParams {
                response_timeout: timeout,
                ..MasterParams::default()
            };
            let master = GroupMaster::new(local, at, &[at.ip()], params)
                .map_err(|source| OpenError::Cyclic { at, source })?;
            let client = SlmpClient::udp(slmp, FrameType::E4, timeout)
                .map_err(|source| OpenError::Slmp { at: slmp, source })?;
            let mut parameters = ObjectIo::new(client);
            let devices = match axis.mode.positioning() {
                Some(_) => DeviceTable::Positioning,
                None => DeviceTable::Profile,
            };
            Ok(Box::new(
                CyclicDriveIo::new(
                    CyclicIo::new(master),
                    Some(Box::new(move |id, v| parameters.write_object(id, v))),
                )
                .with_devices(devices),
            ))
        }
        (Reach::Address { .. }, JecTransport::ModbusRtu { .. }) => Err(OpenError::AddressForSerial),
    }
}

/// The serial line of a real modbus-rtu drive.
pub fn open_line(axis: &JecAxisConfig) -> Result<Option<Reach>, OpenError> {
    let JecTransport::ModbusRtu {
        serial: Some(path),
        baud,
        ..
    } = &axis.transport
    else {
        return Ok(None);
    };
    let line = LineSettings::new(*baud, Default::default()).map_err(OpenError::LineSettings)?;
    let port = line
        .open(&path.display().to_string())
        .map_err(OpenError::Port)?;
    Ok(Some(Reach::Port(port)))
}

/// What the drive gets at start-up: the point tables and [Pr. PT28] of a positioning axis, and
/// the drive-side time-out in its parameter's unit.
pub fn start_up_parameters(axis: &JecAxisConfig) -> Vec<(ObjectId, Value)> {
    let mut out = axis.positioning_parameters();
    let Some(t) = axis.drive_timeout else {
        return out;
    };
    let (parameter, value) = match axis.transport {
        JecTransport::CcLink(_) => (PN02, t.as_millis()),
        JecTransport::ModbusRtu { .. } => (PF46, u128::from(t.as_secs())),
        _ => (PN10, u128::from(t.as_secs())),
    };
    let value = u32::try_from(value).unwrap_or(u32::MAX);
    out.push((ObjectId::new(parameter.index(), 0), Value::U32(value)));
    out
}
