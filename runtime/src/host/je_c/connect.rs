//! The exchange of one MR-JE-C axis over its configured transport, and the start-up writes of
//! its drive-side time-out (MR-JE-C manual §5.2.2, §5.2.3: [Pr. PN02] for the cyclic link,
//! [Pr. PN10] for SLMP and Modbus/TCP, [Pr. PF46] for Modbus RTU).

use std::net::{IpAddr, Ipv4Addr, SocketAddr, UdpSocket};

use cellrt_fieldbus::cclink_ief_basic::io_thread::CyclicIo;
use cellrt_fieldbus::cclink_ief_basic::master::{GroupMaster, MasterParams};
use cellrt_fieldbus::modbus::client::TcpClient;
use cellrt_fieldbus::modbus::serial::{LineSettings, RtuClient};
use cellrt_fieldbus::mr_je_c::cell::{CyclicDriveIo, DeviceTable, DriveIo, ObjectIo};
use cellrt_fieldbus::mr_je_c::parameters::{PF46, PN02, PN10};
use cellrt_fieldbus::mr_je_c::{ObjectId, OverModbus, Value};
use cellrt_fieldbus::slmp::client::{FrameType, SlmpClient};

use super::emulated::Reach;
use cellrt_config::je_c_axis::{JecAxisConfig, JecTransport};

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
pub fn open(axis: &JecAxisConfig, reach: Reach) -> Result<Box<dyn DriveIo>, String> {
    let timeout = axis.response_timeout;
    let software = Default::default();
    let e = |what: &str, e: &dyn std::fmt::Display| format!("{what}: {e}");
    match (reach, &axis.transport) {
        (Reach::Port(port), JecTransport::ModbusRtu { station, baud, .. }) => {
            let line = LineSettings::new(*baud, Default::default()).map_err(|m| e("line", &m))?;
            let client =
                RtuClient::new(port, line, *station, timeout).map_err(|x| e("station", &x))?;
            Ok(Box::new(ObjectIo::new(OverModbus::new(client, software))))
        }
        (Reach::Port(_), _) => Err("a serial line for an Ethernet transport".into()),
        (Reach::Address { at, .. }, JecTransport::ModbusTcp(_)) => {
            let client = TcpClient::connect(at, timeout).map_err(|x| e(&at.to_string(), &x))?;
            Ok(Box::new(ObjectIo::new(OverModbus::new(client, software))))
        }
        (Reach::Address { at, .. }, JecTransport::Slmp(_)) => {
            let client =
                SlmpClient::udp(at, FrameType::E4, timeout).map_err(|x| e(&at.to_string(), &x))?;
            Ok(Box::new(ObjectIo::new(client)))
        }
        (Reach::Address { at, slmp }, JecTransport::CcLink(_)) => {
            let local = SocketAddr::new(local_for(at).map_err(|x| e("route", &x))?, 0);
            let params = MasterParams {
                response_timeout: timeout,
                ..MasterParams::default()
            };
            let master = GroupMaster::new(local, at, &[at.ip()], params)
                .map_err(|x| e(&at.to_string(), &x))?;
            let client = SlmpClient::udp(slmp, FrameType::E4, timeout)
                .map_err(|x| e(&slmp.to_string(), &x))?;
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
        (Reach::Address { .. }, JecTransport::ModbusRtu { .. }) => {
            Err("an address for a serial line".into())
        }
    }
}

/// The serial line of a real modbus-rtu drive.
pub fn open_line(axis: &JecAxisConfig) -> Result<Option<Reach>, String> {
    let JecTransport::ModbusRtu {
        serial: Some(path),
        baud,
        ..
    } = &axis.transport
    else {
        return Ok(None);
    };
    let line = LineSettings::new(*baud, Default::default())?;
    let port = line
        .open(&path.display().to_string())
        .map_err(|e| e.to_string())?;
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
