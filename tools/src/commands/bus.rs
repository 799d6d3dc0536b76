//! `cellrt bus scan --interface IF`: the EtherCAT SubDevices on a network interface, read
//! without configuring anything (identity, SII name, AL state and code, mailbox protocols, DC);
//! `cellrt bus diag` ([`super::bus_diag`]): a running cell's segment diagnostics.

use std::time::Duration;

use cellrt_ethercat::master::scan::{mailbox_protocol_names, scan, ScannedSubDevice};
use cellrt_ethercat::master::RawSocketLink;
use cellrt_ethercat::register::al_code;

use crate::cli::{BusArgs, BusCommand};
use crate::exit::Exit;

/// How long a scan frame may take to come back (no cycle runs; generous for a loaded host).
const SCAN_FRAME_TIMEOUT: Duration = Duration::from_millis(100);

/// Runs `cellrt bus`.
pub fn run(args: BusArgs, target: super::operate::Target) -> Exit {
    use super::bus_commission as commission;
    let (interface, json) = match args.command {
        BusCommand::Scan { interface, json } => (interface, json),
        BusCommand::Diag { interval_ms, json } => {
            return super::bus_diag::run(&target, interval_ms, json)
        }
        BusCommand::Sdo { command } => return commission::sdo(command),
        BusCommand::Pdos {
            interface,
            position,
            json,
        } => return commission::pdos(&interface, position, json),
        BusCommand::States {
            interface,
            position,
            state,
            timeout,
            json,
        } => {
            let timeout = Duration::from_secs_f64(timeout);
            return commission::states(&interface, position, state, timeout, json);
        }
        BusCommand::Sii { command } => return commission::sii(command),
    };
    let mut link = match RawSocketLink::open(&interface, SCAN_FRAME_TIMEOUT) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("error: EtherCAT interface '{interface}': {e}");
            return Exit::of_open_error(&e);
        }
    };
    match scan(&mut link) {
        Ok(found) if json => {
            println!("{}", scan_json(&interface, &found));
            Exit::Ok
        }
        Ok(found) => {
            print!("{}", format_scan(&interface, &found));
            Exit::Ok
        }
        Err(e) => {
            eprintln!("error: bus scan on '{interface}': {e}");
            Exit::Failed
        }
    }
}

/// The scan as one JSON document: the interface and per SubDevice its position, identity,
/// name, AL state (with the error flag and the status code in words), mailbox protocols and DC.
pub fn scan_json(interface: &str, found: &[ScannedSubDevice]) -> String {
    let subdevices: Vec<serde_json::Value> = found
        .iter()
        .map(|d| {
            let id = d.identity;
            serde_json::json!({
                "position": d.position,
                "vendor_id": id.vendor_id,
                "product_code": id.product_code,
                "revision": id.revision,
                "serial": id.serial,
                "name": d.name,
                "al_state": d.al.state.map(|s| s.as_str()),
                "al_error": d.al.error,
                "al_status_code": d.al.code,
                "al_status": al_code::name(d.al.code),
                "mailbox": mailbox_protocol_names(d.mailbox_protocols),
                "dc": d.dc,
            })
        })
        .collect();
    serde_json::json!({ "interface": interface, "subdevices": subdevices }).to_string()
}

/// The scan as a table: a header line, then one line per SubDevice.
pub fn format_scan(interface: &str, found: &[ScannedSubDevice]) -> String {
    let mut out = format!("{} SubDevice(s) on {interface}\n", found.len());
    if found.is_empty() {
        return out;
    }
    out.push_str(&format!(
        "{:<4} {:<10} {:<10} {:<10} {:<10} {:<24} {:<10} {:<40} {:<12} {}\n",
        "pos",
        "vendor",
        "product",
        "revision",
        "serial",
        "name",
        "AL state",
        "AL status code",
        "mailbox",
        "DC"
    ));
    for d in found {
        out.push_str(&format_line(d));
        out.push('\n');
    }
    out
}

/// One SubDevice's line of [`format_scan`].
fn format_line(d: &ScannedSubDevice) -> String {
    let id = d.identity;
    let state = match (d.al.state, d.al.error) {
        (Some(s), false) => s.as_str().to_string(),
        (Some(s), true) => format!("{}+ERROR", s.as_str()),
        (None, _) => "unknown".to_string(),
    };
    let code = format!("{:#06x} {}", d.al.code, al_code::name(d.al.code));
    let mailbox = mailbox_protocol_names(d.mailbox_protocols).join(",");
    let name = if d.name.is_empty() { "-" } else { &d.name };
    format!(
        "{:<4} {:#010x} {:#010x} {:#010x} {:#010x} {:<24} {:<10} {:<40} {:<12} {}",
        d.position,
        id.vendor_id,
        id.product_code,
        id.revision,
        id.serial,
        name,
        state,
        code,
        if mailbox.is_empty() { "none" } else { &mailbox },
        if d.dc { "yes" } else { "no" }
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_ethercat::identity::SubDeviceIdentity;
    use cellrt_ethercat::register::{AlState, AlStatus};

    fn device(position: usize, al: AlStatus, mailbox: u16, dc: bool) -> ScannedSubDevice {
        ScannedSubDevice {
            position,
            identity: SubDeviceIdentity {
                vendor_id: 0x0A1E,
                product_code: 0x0201,
                revision: 0x0002_0002,
                serial: 7,
            },
            name: "MR-J4-TM".into(),
            al,
            mailbox_protocols: mailbox,
            dc,
        }
    }

    #[test]
    fn each_subdevice_is_one_line_with_identity_name_state_code_mailbox_and_dc() {
        let ok = AlStatus::from_registers(AlState::PreOp as u16, 0);
        let refused = AlStatus::from_registers(AlState::PreOp as u16 | 0x10, 0x0030);
        let text = format_scan(
            "ecat0",
            &[device(0, ok, 0x000C, true), device(1, refused, 0, false)],
        );
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 4, "{text}");
        assert_eq!(lines[0], "2 SubDevice(s) on ecat0");
        assert!(lines[1].starts_with("pos  vendor"), "{text}");
        for part in [
            "0x00000a1e",
            "0x00000201",
            "0x00020002",
            "0x00000007",
            "MR-J4-TM",
            "PRE-OP ",
            "0x0000 no error",
            "CoE,FoE",
        ] {
            assert!(lines[2].contains(part), "{part:?} in {}", lines[2]);
        }
        assert!(lines[2].ends_with("yes"), "{}", lines[2]);
        for part in [
            "PRE-OP+ERROR",
            "0x0030 invalid DC SYNC configuration",
            "none",
        ] {
            assert!(lines[3].contains(part), "{part:?} in {}", lines[3]);
        }
        assert!(lines[3].ends_with("no"), "{}", lines[3]);
    }

    #[test]
    fn an_empty_line_says_so() {
        assert_eq!(format_scan("eth1", &[]), "0 SubDevice(s) on eth1\n");
    }
}
