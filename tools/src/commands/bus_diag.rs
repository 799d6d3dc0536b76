//! `cellrt bus diag`: a running EtherCAT cell's segment diagnostics, as a table per SubDevice
//! (or JSON). Two readings `--interval-ms` apart: a port whose own error counters (invalid
//! frames, RX errors, lost links) grew between them is marked `<< errors here`, the place to
//! look for a bad cable or connector; one that only passed on frames an earlier ESC had marked
//! (forwarded errors) is marked `< forwarded`.

use std::time::Duration;

use cellrt_ethercat::master::{PortDiag, SubDeviceDiag};
use cellrt_ethercat::register::al_code;
use cellrt_runtime::host::operator::bus_diag::BusDiagReply;
use cellrt_runtime::host::operator::client::OperatorClient;
use cellrt_runtime::host::operator::wire::{Reply, Request};

use super::operate::Target;
use crate::exit::Exit;

/// Runs `cellrt bus diag`.
pub fn run(target: &Target, interval_ms: u64, json: bool) -> Exit {
    let client = match OperatorClient::connect(target.cell.as_deref()) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::Unreachable;
        }
    };
    let timeout = Duration::from_secs_f64(target.reply_timeout);
    let read = || -> Result<BusDiagReply, Exit> {
        match client.request(&Request::BusDiag, timeout) {
            Ok(Reply::BusDiag(r)) => Ok(*r),
            Ok(Reply::Rejected { reason }) => {
                eprintln!("error: {reason}");
                Err(Exit::Rejected)
            }
            Ok(other) => {
                eprintln!("error: unexpected reply {other:?}");
                Err(Exit::Failed)
            }
            Err(e) => {
                eprintln!("error: {e}");
                Err(Exit::Unreachable)
            }
        }
    };
    let first = match read() {
        Ok(r) => r,
        Err(code) => return code,
    };
    let second = if interval_ms > 0 {
        std::thread::sleep(Duration::from_millis(interval_ms));
        match read() {
            Ok(r) => Some(r),
            Err(code) => return code,
        }
    } else {
        None
    };
    if json {
        let v = serde_json::json!({ "first": first, "second": second, "interval_ms": interval_ms });
        println!("{v}");
    } else {
        print!(
            "{}",
            render(&first, second.as_ref(), interval_ms, client.cell())
        );
    }
    Exit::Ok
}

/// The table: the latest reading, ports whose counters grew since the earlier one marked.
pub fn render(
    first: &BusDiagReply,
    second: Option<&BusDiagReply>,
    interval_ms: u64,
    cell: &str,
) -> String {
    let last = second.unwrap_or(first);
    let seg = &last.segment;
    let mut out = format!(
        "cell {cell}: {} SubDevice(s); frames {}  lost {}  working-counter errors {}  mailbox frames lost {}  notices dropped {}\n",
        seg.subdevices.len(),
        seg.frames,
        seg.frames_lost,
        seg.wkc_errors,
        seg.mailbox_frames_lost,
        seg.notices_dropped
    );
    if let Some(s) = second {
        let f = &first.segment;
        out += &format!(
            "in {interval_ms} ms: frames {:+}  lost {:+}  working-counter errors {:+}\n",
            s.segment.frames as i64 - f.frames as i64,
            s.segment.frames_lost as i64 - f.frames_lost as i64,
            s.segment.wkc_errors as i64 - f.wkc_errors as i64
        );
    }
    out += &format!(
        "{:<4} {:<7} {:<14} {:<18} {:<8} {:<4} {:>7} {:>6} {:>6} {:>6}  {}\n",
        "pos", "address", "model", "axes", "AL", "port", "invalid", "rx err", "fwd", "lost", "link"
    );
    for (k, d) in seg.subdevices.iter().enumerate() {
        let name = last.stations.get(k);
        let before = second.and(first.segment.subdevices.get(k));
        out += &station_lines(d, before, name);
    }
    out
}

fn station_lines(
    d: &SubDeviceDiag,
    before: Option<&SubDeviceDiag>,
    name: Option<&cellrt_runtime::host::operator::bus_diag::StationName>,
) -> String {
    let model = name.map_or("", |n| n.model.as_str());
    let axes = name.map_or(String::new(), |n| n.axes.join(","));
    let al = if d.answered {
        format!("{}{}", d.al_state, if d.al_error { "+E" } else { "" })
    } else {
        "silent".into()
    };
    let mut out = String::new();
    for (p, port) in d.ports.iter().enumerate() {
        let mark = before.map_or("", |b| growth(port, &b.ports[p]));
        // Unused ports (no link, no counts) are left out, port 0 always shown.
        if p > 0 && !port.link && port.errors() == 0 {
            continue;
        }
        let head = if p == 0 {
            format!(
                "{:<4} {:<7} {:<14} {:<18} {:<8}",
                d.position,
                format!("{:#06x}", d.address),
                model,
                axes,
                al
            )
        } else {
            format!("{:<4} {:<7} {:<14} {:<18} {:<8}", "", "", "", "", "")
        };
        out += &format!(
            "{head} {:<4} {:>7} {:>6} {:>6} {:>6}  {}{}\n",
            p,
            port.invalid_frames,
            port.rx_errors,
            port.forwarded_errors,
            port.lost_links,
            link_text(port),
            mark
        );
    }
    if d.al_code != 0 || d.emergencies != 0 || d.dc_difference_ns != 0 {
        out += &format!(
            "{:<4} AL code {:#06x} ({})  DC difference {} ns  mailbox {} (Emergencies {})\n",
            "",
            d.al_code,
            al_code::name(d.al_code),
            d.dc_difference_ns,
            d.mailbox_messages,
            d.emergencies
        );
    }
    out
}

/// The mark of a port whose counters grew from `was` to `now`.
fn growth(now: &PortDiag, was: &PortDiag) -> &'static str {
    let own = |p: &PortDiag| {
        u32::from(p.invalid_frames) + u32::from(p.rx_errors) + u32::from(p.lost_links)
    };
    if own(now) > own(was) {
        "  << errors here"
    } else if now.forwarded_errors > was.forwarded_errors {
        "  < forwarded"
    } else {
        ""
    }
}

fn link_text(p: &PortDiag) -> &'static str {
    if p.link {
        "up"
    } else {
        "down"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_ethercat::master::SegmentDiag;
    use cellrt_runtime::host::operator::bus_diag::StationName;

    fn reading(invalid_at_2: u8) -> BusDiagReply {
        let sub = |k: usize, invalid: u8| SubDeviceDiag {
            position: k,
            address: 0x1000 + k as u16,
            answered: true,
            al_state: "OP".into(),
            al_error: false,
            al_code: 0,
            ports: [
                PortDiag {
                    link: true,
                    invalid_frames: invalid,
                    ..Default::default()
                },
                PortDiag {
                    link: k < 2,
                    ..Default::default()
                },
                PortDiag::default(),
                PortDiag::default(),
            ],
            processing_errors: 0,
            pdi_errors: 0,
            dc_difference_ns: 0,
            mailbox_messages: 0,
            emergencies: 0,
        };
        BusDiagReply {
            stations: (0..3)
                .map(|k| StationName {
                    model: "mr-j4-tm".into(),
                    axes: vec![format!("a{k}")],
                })
                .collect(),
            segment: SegmentDiag {
                subdevices: vec![sub(0, 0), sub(1, 0), sub(2, invalid_at_2)],
                frames: 1000,
                frames_lost: 3,
                wkc_errors: 0,
                mailbox_frames_lost: 0,
                notices_dropped: 0,
            },
        }
    }

    /// Only the port whose own counters grew between the readings is marked as the place.
    #[test]
    fn the_port_with_growing_errors_is_marked() {
        let t = render(&reading(4), Some(&reading(9)), 1000, "c");
        let marked: Vec<&str> = t.lines().filter(|l| l.contains("<< errors here")).collect();
        assert_eq!(marked.len(), 1, "{t}");
        assert!(
            marked[0].contains("a2") && marked[0].contains("  9 "),
            "{t}"
        );
        let mut later = reading(4);
        later.segment.subdevices[0].ports[1].forwarded_errors = 5;
        let t = render(&reading(4), Some(&later), 1000, "c");
        assert!(
            !t.contains("errors here") && t.contains("< forwarded"),
            "{t}"
        );
        let t = render(&reading(9), Some(&reading(9)), 1000, "c");
        assert!(
            !t.contains("errors here") && !t.contains("forwarded"),
            "{t}"
        );
        assert!(!render(&reading(9), None, 0, "c").contains('<'));
    }
}
