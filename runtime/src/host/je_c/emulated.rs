//! Emulated MR-JE-Cs for the axes that ask for one (`[axes.je_c] emulate = true`): a drive
//! served on loopback at free ports (Ethernet transports), or on an RS-485 line over a
//! pseudo-terminal whose other end the axis opens (modbus-rtu). They run in the controller's
//! process, so a cell with emulated drives needs no root and no second command.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};

use cellrt_emulator::mr_je_c::cyclic::LinkLayout;
use cellrt_emulator::mr_je_c::rs485::Rs485Line;
use cellrt_emulator::mr_je_c::server::{Ports, Server};
use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams};
use cellrt_fieldbus::modbus::serial::LineSettings;
use serialport::{SerialPort, TTYPort};

use cellrt_config::je_c_axis::{JecAxisConfig, JecTransport};

/// A running emulated drive.
pub enum Emulated {
    /// Served on loopback sockets.
    Sockets(Server),
    /// On an RS-485 line.
    Line(Rs485Line),
}

impl Emulated {
    /// The drive, for tests and the summary: its alarm, if any.
    pub fn alarm(&self) -> Option<cellrt_fieldbus::mr_je_c::Alarm> {
        match self {
            Emulated::Sockets(s) => s.drive().alarm(),
            Emulated::Line(l) => l.drives().first().and_then(|d| d.alarm()),
        }
    }

    /// Cuts (or restores) the emulated drive's Ethernet link; an RS-485 line cannot be cut.
    pub fn cut_link(&self, cut: bool) -> bool {
        match self {
            Emulated::Sockets(s) => {
                s.cut_link(cut);
                true
            }
            Emulated::Line(_) => false,
        }
    }
}

/// Where the axis reaches its drive.
pub enum Reach {
    /// The transport's socket address, and SLMP's for the start-up writes beside the cyclic
    /// link.
    Address {
        /// The transport's address.
        at: SocketAddr,
        /// SLMP over UDP.
        slmp: SocketAddr,
    },
    /// This end of the pseudo-terminal.
    Port(Box<dyn SerialPort>),
}

/// Starts the emulated drive of `axis`.
pub fn start(axis: &JecAxisConfig) -> std::io::Result<(Emulated, Reach)> {
    let link_layout = match axis.mode.positioning() {
        Some(_) => LinkLayout::Positioning,
        None => LinkLayout::Profile,
    };
    let params = MrJeCParams {
        rated_speed_rpm: axis.rated_speed.round() as u32,
        link_layout,
        ..MrJeCParams::default()
    };
    if let JecTransport::ModbusRtu { station, baud, .. } = axis.transport {
        let (master, slave) = TTYPort::pair().map_err(std::io::Error::other)?;
        let mut drive = MrJeC::on_rs485_line(params, station);
        // The drive commissioned for the configured line (the client's framing: the default).
        let line = LineSettings::new(baud, Default::default()).map_err(std::io::Error::other)?;
        drive.set_rtu_line(&line);
        let line = Rs485Line::start(vec![drive], Box::new(master), line)?;
        return Ok((Emulated::Line(line), Reach::Port(Box::new(slave))));
    }
    let loopback = IpAddr::V4(Ipv4Addr::LOCALHOST);
    let server = Server::start(MrJeC::new(params), loopback, Ports::ANY)?;
    let at = match axis.transport {
        JecTransport::CcLink(_) => server.cclink,
        JecTransport::Slmp(_) => server.slmp_udp,
        _ => server.modbus_tcp,
    };
    let slmp = server.slmp_udp;
    Ok((Emulated::Sockets(server), Reach::Address { at, slmp }))
}
