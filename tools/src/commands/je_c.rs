//! `cellrt je-c read|write`: one object of an MR-JE-C over SLMP, Modbus/TCP or Modbus RTU, for
//! commissioning (MR-JE-C manual §2.4, §3.6, §4.8, §7.3); `scan` and `set-ip` are in
//! [`super::je_c_search`].

use std::net::{IpAddr, SocketAddr};
use std::time::Duration;

use clap::{Args, Subcommand, ValueEnum};

use cellrt_fieldbus::modbus::client::TcpClient;
use cellrt_fieldbus::modbus::serial::{Framing, LineSettings, RtuClient};
use cellrt_fieldbus::modbus::WordOrder;
use cellrt_fieldbus::mr_je_c::{
    entry, AccessError, DataType, ObjectAccess, ObjectId, OverModbus, SoftwareVersion, Value,
};
use cellrt_fieldbus::slmp::client::{FrameType, SlmpClient};

use crate::exit::Exit;

/// `cellrt je-c`.
#[derive(Debug, Args)]
pub struct JeCArgs {
    /// What to do.
    #[command(subcommand)]
    pub command: JeCCommand,
}

/// The transport to the drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Via {
    /// SLMP 4020h over UDP (port 5010).
    Slmp,
    /// SLMP 4020h over TCP (port 5012).
    SlmpTcp,
    /// Modbus/TCP (port 502).
    ModbusTcp,
    /// Modbus RTU on an RS-485 line: ADDR is the serial device (e.g. /dev/ttyUSB0).
    ModbusRtu,
}

impl Via {
    fn default_port(self) -> u16 {
        match self {
            Via::Slmp => cellrt_fieldbus::slmp::UDP_PORT,
            Via::SlmpTcp => cellrt_fieldbus::slmp::TCP_PORT,
            Via::ModbusTcp | Via::ModbusRtu => cellrt_fieldbus::modbus::tcp::PORT,
        }
    }
}

/// Where the drive is and how to reach it.
#[derive(Debug, Args)]
pub struct Target {
    /// The drive: IP or IP:PORT (default port per transport), or with `--via modbus-rtu` the
    /// serial device of its RS-485 line.
    pub addr: String,
    /// The object: index in hex with an optional sub-index, e.g. 6041 or 1018:2.
    pub object: ObjectId,
    /// The transport.
    #[arg(long, value_enum, default_value = "slmp")]
    pub via: Via,
    /// The drive's software version (which objects exist): A0, A3 or A4.
    #[arg(long, default_value = "A4")]
    pub software: SoftwareVersion,
    /// How long to wait for the drive's answer, ms.
    #[arg(long, default_value_t = 1000)]
    pub timeout_ms: u64,
    /// Modbus RTU: the drive's station number, 1–247 (rotary switch or [Pr. PC70]).
    #[arg(long, default_value_t = 1)]
    pub station: u8,
    /// Modbus RTU: bit rate ([Pr. PC71]).
    #[arg(long, default_value_t = 115_200)]
    pub baud: u32,
    /// Modbus RTU: parity and stop bits ([Pr. PF45]): even, odd (1 stop) or none (2 stop).
    #[arg(long, default_value = "even")]
    pub framing: Framing,
    /// Modbus RTU: 32-bit values high word first (the drive's [Pr. PC72] = 1).
    #[arg(long)]
    pub high_word_first: bool,
}

/// `cellrt je-c` subcommands.
#[derive(Debug, Subcommand)]
pub enum JeCCommand {
    /// Read one object and print it with its name and unit.
    Read(Target),
    /// Write one object (decimal, or hex as 0x1EA5 / 1EA5h).
    Write {
        /// The drive and object.
        #[command(flatten)]
        target: Target,
        /// The value.
        #[arg(allow_hyphen_values = true)]
        value: String,
    },
    /// Find the drives on a network (NodeSearch, UDP 61451).
    Scan(super::je_c_search::ScanArgs),
    /// Give the drive with a MAC address its IP address, subnet and gateway (IPAddressSet;
    /// effective at its next power-on).
    SetIp(super::je_c_search::SetIpArgs),
}

/// Runs `cellrt je-c`.
pub fn run(args: JeCArgs) -> Exit {
    let (target, value) = match args.command {
        JeCCommand::Read(t) => (t, None),
        JeCCommand::Write { target, value } => (target, Some(value)),
        JeCCommand::Scan(a) => return super::je_c_search::scan(&a),
        JeCCommand::SetIp(a) => return super::je_c_search::set_ip(&a),
    };
    let Some((_, row)) = entry(target.object, target.software) else {
        eprintln!(
            "error: object {}: not in the MR-JE-C object dictionary (software {})",
            target.object, target.software
        );
        return Exit::BadInput;
    };
    if value.is_some() && row.access == cellrt_fieldbus::mr_je_c::Access::Ro {
        eprintln!(
            "error: object {}: read-only in the MR-JE-C object dictionary (manual §7.3); nothing sent",
            target.object
        );
        return Exit::BadInput;
    }
    let write = match value.map(|v| parse_value(row.ty, &v)).transpose() {
        Ok(w) => w,
        Err(e) => {
            eprintln!("error: value for {} ({:?}): {e}", target.object, row.ty);
            return Exit::BadInput;
        }
    };
    let (addr, mut drive) = match open(&target) {
        Ok(d) => d,
        Err(e) => return e,
    };
    let result = match &write {
        Some(v) => drive.write_object(target.object, v).map(|()| v.clone()),
        None => drive.read_object(target.object),
    };
    match result {
        Ok(v) => {
            let name = if row.name.is_empty() {
                cellrt_fieldbus::mr_je_c::object(target.object.index, target.software)
                    .map_or("", |o| o.name)
            } else {
                row.name
            };
            let verb = if write.is_some() { "written" } else { "=" };
            let line = format!("{} {name} {verb} {v} {}", target.object, row.unit);
            println!("{}", line.trim_end());
            Exit::Ok
        }
        Err(e) => {
            eprintln!("error: {addr}: {e}");
            match e {
                AccessError::EndCode { .. } | AccessError::Exception { .. } => Exit::Rejected,
                AccessError::Unknown(..) | AccessError::Type { .. } => Exit::BadInput,
                AccessError::Timeout(_) | AccessError::Link(_) => Exit::Unreachable,
            }
        }
    }
}

/// The drive's place as messages name it, and the access to it; a refusal's exit code.
fn open(t: &Target) -> Result<(String, Box<dyn ObjectAccessDyn>), Exit> {
    if t.via == Via::ModbusRtu {
        return open_rtu(t);
    }
    let addr = resolve(&t.addr, t.via.default_port()).map_err(|e| {
        eprintln!("error: {e}");
        Exit::BadInput
    })?;
    let drive = connect(t, addr).map_err(|e| {
        eprintln!("error: {addr} ({:?}): {e}", t.via);
        Exit::Unreachable
    })?;
    Ok((addr.to_string(), drive))
}

/// Station `t.station` on the RS-485 line at the serial device `t.addr`.
fn open_rtu(t: &Target) -> Result<(String, Box<dyn ObjectAccessDyn>), Exit> {
    let line = LineSettings::new(t.baud, t.framing).map_err(|e| {
        eprintln!("error: --baud: {e}");
        Exit::BadInput
    })?;
    let place = format!("{} station {}", t.addr, t.station);
    let timeout = Duration::from_millis(t.timeout_ms.max(1));
    let port = line.open(&t.addr).map_err(|e| {
        eprintln!("error: {e}");
        Exit::Unreachable
    })?;
    let client = RtuClient::new(port, line, t.station, timeout).map_err(|e| {
        eprintln!("error: --station {}: {e}", t.station);
        Exit::BadInput
    })?;
    let order = if t.high_word_first {
        WordOrder::HighFirst
    } else {
        WordOrder::LowFirst
    };
    let access = OverModbus::new(client, t.software).with_word_order(order);
    Ok((place, Box::new(access)))
}

/// Why a drive cannot be reached over IP, or its address or a value is refused.
#[derive(Debug, thiserror::Error)]
enum DriveAccessError {
    /// SLMP cannot open its socket.
    #[error(transparent)]
    Slmp(#[from] cellrt_fieldbus::slmp::client::ClientError),
    /// Modbus TCP cannot connect.
    #[error(transparent)]
    Modbus(#[from] cellrt_fieldbus::modbus::client::ClientError),
    /// Modbus RTU asked for at an IP address.
    #[error("Modbus RTU runs on a serial line, not an IP address")]
    RtuNeedsSerialLine,
    /// Neither an IP address nor IP:PORT.
    #[error("drive address \"{}\": expected IP or IP:PORT", cellrt_config::echo::Echo(.addr))]
    NotAnAddress {
        /// The argument.
        addr: String,
    },
    /// A value that is not a number.
    #[error(transparent)]
    Number(#[from] crate::numbers::NumberError),
    /// A value the object's type cannot hold.
    #[error("{} does not fit the object's type", cellrt_config::echo::Echo(.text))]
    DoesNotFit {
        /// The value as given.
        text: String,
    },
}

fn connect(t: &Target, addr: SocketAddr) -> Result<Box<dyn ObjectAccessDyn>, DriveAccessError> {
    let timeout = Duration::from_millis(t.timeout_ms.max(1));
    let slmp = |mut c: SlmpClient| -> Box<dyn ObjectAccessDyn> {
        c.software = t.software;
        Box::new(c)
    };
    match t.via {
        Via::Slmp => Ok(SlmpClient::udp(addr, FrameType::E4, timeout).map(slmp)?),
        Via::SlmpTcp => Ok(SlmpClient::tcp(addr, FrameType::E4, timeout).map(slmp)?),
        Via::ModbusTcp => Ok(TcpClient::connect(addr, timeout)
            .map(|c| Box::new(OverModbus::new(c, t.software)) as Box<dyn ObjectAccessDyn>)?),
        Via::ModbusRtu => Err(DriveAccessError::RtuNeedsSerialLine),
    }
}

/// [`ObjectAccess`] without its generic methods, for a transport chosen at run time.
trait ObjectAccessDyn {
    fn read_object(&mut self, id: ObjectId) -> Result<Value, AccessError>;
    fn write_object(&mut self, id: ObjectId, v: &Value) -> Result<(), AccessError>;
}

impl<T: ObjectAccess> ObjectAccessDyn for T {
    fn read_object(&mut self, id: ObjectId) -> Result<Value, AccessError> {
        ObjectAccess::read_object(self, id)
    }
    fn write_object(&mut self, id: ObjectId, v: &Value) -> Result<(), AccessError> {
        ObjectAccess::write_object(self, id, v)
    }
}

fn resolve(addr: &str, port: u16) -> Result<SocketAddr, DriveAccessError> {
    if let Ok(a) = addr.parse::<SocketAddr>() {
        return Ok(a);
    }
    addr.parse::<IpAddr>()
        .map(|ip| SocketAddr::new(ip, port))
        .map_err(|_| DriveAccessError::NotAnAddress {
            addr: addr.to_string(),
        })
}

/// `s` as a value of `ty`: decimal, 0x-prefixed or h-suffixed hex.
fn parse_value(ty: DataType, s: &str) -> Result<Value, DriveAccessError> {
    let n = crate::numbers::integer(s)?;
    Value::from_i64(ty, n).ok_or_else(|| DriveAccessError::DoesNotFit {
        text: s.to_string(),
    })
}
