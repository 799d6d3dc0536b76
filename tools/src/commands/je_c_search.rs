//! `cellrt je-c scan` and `cellrt je-c set-ip`: NodeSearch and IPAddressSet on UDP 61451
//! (MR-JE-C manual §2.4.3, §2.5.2), to find the drives on a network and give one its address.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::time::Duration;

use clap::Args;

use cellrt_fieldbus::cclink_ief_basic::SEARCH_PORT;
use cellrt_fieldbus::slmp::discovery::SearchLink;
use cellrt_fieldbus::slmp::node_search::{IpAddressSet, Mac};

use crate::exit::Exit;

/// Where a search or address set is sent.
#[derive(Debug, Args)]
pub struct SearchTo {
    /// The address to send to: a broadcast address (the default, 255.255.255.255) or one
    /// drive's, with an optional port (61451).
    #[arg(long, value_name = "ADDR[:PORT]", default_value = "255.255.255.255")]
    pub to: String,
    /// The interface to send through (needs root or CAP_NET_RAW); its MAC is the master's.
    #[arg(long, value_name = "IF")]
    pub interface: Option<String>,
}

/// `cellrt je-c scan`.
#[derive(Debug, Args)]
pub struct ScanArgs {
    /// Where to search.
    #[command(flatten)]
    pub to: SearchTo,
    /// How long to collect answers, ms.
    #[arg(long, default_value_t = 1000)]
    pub wait_ms: u64,
    /// Print JSON (one object per drive) instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `cellrt je-c set-ip`.
#[derive(Debug, Args)]
pub struct SetIpArgs {
    /// The drive's MAC address (as `scan` shows it).
    pub mac: Mac,
    /// Its new IP address.
    pub ip: Ipv4Addr,
    /// Its new subnet mask.
    #[arg(long, default_value = "255.255.255.0")]
    pub subnet: Ipv4Addr,
    /// Its new default gateway (not changed when absent).
    #[arg(long)]
    pub gateway: Option<Ipv4Addr>,
    /// Where to send.
    #[command(flatten)]
    pub to: SearchTo,
    /// How long to wait for the drive's answer, ms.
    #[arg(long, default_value_t = 1000)]
    pub timeout_ms: u64,
}

/// Why `--to` is refused.
#[derive(Debug, thiserror::Error)]
enum SearchToError {
    /// Neither an IP address nor IP:PORT.
    #[error("--to {to:?}: expected IP or IP:PORT")]
    NotAnAddress {
        /// The argument.
        to: String,
    },
    /// An IPv6 address.
    #[error("--to {to}: NodeSearch is IPv4 only")]
    NotIpv4 {
        /// The address.
        to: SocketAddr,
    },
}

impl SearchTo {
    fn link(&self) -> Result<SearchLink, SearchToError> {
        let to = if let Ok(a) = self.to.parse::<SocketAddr>() {
            a
        } else {
            let ip: IpAddr = self.to.parse().map_err(|_| SearchToError::NotAnAddress {
                to: self.to.clone(),
            })?;
            SocketAddr::new(ip, SEARCH_PORT)
        };
        if !to.is_ipv4() {
            return Err(SearchToError::NotIpv4 { to });
        }
        Ok(SearchLink {
            to,
            interface: self.interface.clone(),
        })
    }
}

/// Runs `cellrt je-c scan`.
pub fn scan(args: &ScanArgs) -> Exit {
    let link = match args.to.link() {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    let found = match link.search(Duration::from_millis(args.wait_ms)) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("error: NodeSearch to {}: {e}", link.to);
            return Exit::Unreachable;
        }
    };
    if args.json {
        for f in &found {
            let n = &f.node;
            println!(
                "{}",
                serde_json::json!({
                    "mac": n.mac.to_string(), "ip": n.ip.to_string(),
                    "subnet": n.subnet.to_string(), "gateway": n.gateway.to_string(),
                    "vendor_code": n.vendor_code, "model_code": n.model_code,
                    "status": n.status, "port": n.port, "from": f.from.to_string(),
                })
            );
        }
    } else {
        println!(
            "{:<17}  {:<15}  {:<15}  {:<15}  status",
            "MAC", "IP", "subnet", "gateway"
        );
        for f in &found {
            let n = &f.node;
            println!(
                "{:<17}  {:<15}  {:<15}  {:<15}  {:04X}h",
                n.mac.to_string(),
                n.ip.to_string(),
                n.subnet.to_string(),
                n.gateway.to_string(),
                n.status
            );
        }
    }
    eprintln!(
        "{} drive(s) answered within {} ms",
        found.len(),
        args.wait_ms
    );
    Exit::Ok
}

/// Runs `cellrt je-c set-ip`.
pub fn set_ip(args: &SetIpArgs) -> Exit {
    let link = match args.to.link() {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    let set = IpAddressSet {
        mac: args.mac,
        ip: args.ip,
        subnet: args.subnet,
        gateway: args.gateway,
    };
    match link.set_address(&set, Duration::from_millis(args.timeout_ms)) {
        Ok(true) => {
            println!(
                "{}: IP {} subnet {}{} set ([Pr. PN11]–[Pr. PN22]); effective at the drive's next power-on",
                args.mac,
                args.ip,
                args.subnet,
                args.gateway.map_or(String::new(), |g| format!(" gateway {g}"))
            );
            Exit::Ok
        }
        Ok(false) => {
            eprintln!(
                "error: no drive with MAC {} answered within {} ms (IPAddressSet to {})",
                args.mac, args.timeout_ms, link.to
            );
            Exit::Unreachable
        }
        Err(e) => {
            eprintln!("error: IPAddressSet to {}: {e}", link.to);
            Exit::Unreachable
        }
    }
}
