//! `cellrt je-c read|write`: one object of an MR-JE-C over SLMP or Modbus/TCP, for
//! commissioning (MR-JE-C manual §2.4, §3.6, §7.3).

use std::net::{IpAddr, SocketAddr};
use std::time::Duration;

use clap::{Args, Subcommand, ValueEnum};

use cellrt_axes::modbus::client::TcpClient;
use cellrt_axes::mr_je_c::{
    entry, AccessError, DataType, ObjectAccess, ObjectId, OverModbus, SoftwareVersion, Value,
};
use cellrt_axes::slmp::client::{FrameType, SlmpClient};

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
}

impl Via {
    fn default_port(self) -> u16 {
        match self {
            Via::Slmp => cellrt_axes::slmp::UDP_PORT,
            Via::SlmpTcp => cellrt_axes::slmp::TCP_PORT,
            Via::ModbusTcp => cellrt_axes::modbus::tcp::PORT,
        }
    }
}

/// Where the drive is and how to reach it.
#[derive(Debug, Args)]
pub struct Target {
    /// The drive: IP or IP:PORT (default port per transport).
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
}

/// Runs `cellrt je-c`.
pub fn run(args: JeCArgs) -> Exit {
    let (target, value) = match args.command {
        JeCCommand::Read(t) => (t, None),
        JeCCommand::Write { target, value } => (target, Some(value)),
    };
    let Some((_, row)) = entry(target.object, target.software) else {
        eprintln!(
            "error: object {}: not in the MR-JE-C object dictionary (software {})",
            target.object, target.software
        );
        return Exit::BadInput;
    };
    let write = match value.map(|v| parse_value(row.ty, &v)).transpose() {
        Ok(w) => w,
        Err(e) => {
            eprintln!("error: value for {} ({:?}): {e}", target.object, row.ty);
            return Exit::BadInput;
        }
    };
    let addr = match resolve(&target.addr, target.via.default_port()) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    let mut drive = match connect(&target, addr) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("error: {addr} ({:?}): {e}", target.via);
            return Exit::Unreachable;
        }
    };
    let result = match &write {
        Some(v) => drive.write_object(target.object, v).map(|()| v.clone()),
        None => drive.read_object(target.object),
    };
    match result {
        Ok(v) => {
            let name = if row.name.is_empty() {
                cellrt_axes::mr_je_c::object(target.object.index, target.software)
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

fn connect(t: &Target, addr: SocketAddr) -> Result<Box<dyn ObjectAccessDyn>, String> {
    let timeout = Duration::from_millis(t.timeout_ms.max(1));
    let slmp = |mut c: SlmpClient| -> Box<dyn ObjectAccessDyn> {
        c.software = t.software;
        Box::new(c)
    };
    match t.via {
        Via::Slmp => SlmpClient::udp(addr, FrameType::E4, timeout)
            .map(slmp)
            .map_err(|e| e.to_string()),
        Via::SlmpTcp => SlmpClient::tcp(addr, FrameType::E4, timeout)
            .map(slmp)
            .map_err(|e| e.to_string()),
        Via::ModbusTcp => TcpClient::connect(addr, timeout)
            .map(|c| Box::new(OverModbus::new(c, t.software)) as Box<dyn ObjectAccessDyn>)
            .map_err(|e| e.to_string()),
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

fn resolve(addr: &str, port: u16) -> Result<SocketAddr, String> {
    if let Ok(a) = addr.parse::<SocketAddr>() {
        return Ok(a);
    }
    addr.parse::<IpAddr>()
        .map(|ip| SocketAddr::new(ip, port))
        .map_err(|_| format!("drive address {addr:?}: expected IP or IP:PORT"))
}

/// `s` as a value of `ty`: decimal, 0x-prefixed or h-suffixed hex.
fn parse_value(ty: DataType, s: &str) -> Result<Value, String> {
    let n = crate::numbers::integer(s)?;
    Value::from_i64(ty, n).ok_or_else(|| format!("{s} does not fit the object's type"))
}
