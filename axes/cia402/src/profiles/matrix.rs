//! The README's "Supported drives" feature matrix, rendered from the profiles so the table and
//! the code cannot disagree (`axes/cia402/tests/readme_matrix.rs` checks the README against it).

use std::fmt::Write;

use super::{profile, CommCheck, DriveModel, DriveProfile, TorqueLimitSelection};

/// Marker line before the generated table in README.md.
pub const BEGIN_MARKER: &str = "<!-- drive-matrix:begin (generated from axes/cia402/src/profiles; UPDATE_README=1 cargo test -p cellrt-cia402 --test readme_matrix) -->";
/// Marker line after the generated table in README.md.
pub const END_MARKER: &str = "<!-- drive-matrix:end -->";

/// The alarm's display number ("AL.34"), or the raw code when the profile does not list it.
fn alarm_text(p: &DriveProfile, code: u16) -> String {
    p.alarm(code)
        .map_or_else(|| format!("{code:#06X}"), |a| a.display.to_owned())
}

/// The cyclic communication check, in one cell.
fn comm_text(p: &DriveProfile) -> String {
    match p.comm.check {
        CommCheck::IncrementalCounter {
            rx_index,
            tx_index,
            counter_alarm,
            loss_alarm,
            ..
        } => format!(
            "incremental counter {rx_index:04X}h/{tx_index:04X}h ({} counter, {} lost RxPDO)",
            alarm_text(p, counter_alarm),
            alarm_text(p, loss_alarm)
        ),
        CommCheck::WatchdogCounter {
            rx_index,
            tx_index,
            loss_alarm,
            ..
        } => format!(
            "watchdog counter {rx_index:04X}h/{tx_index:04X}h ({} lost process data)",
            alarm_text(p, loss_alarm)
        ),
        CommCheck::SyncErrorCounter { alarm } => {
            format!("sync-error counter 10F1h:02 ({})", alarm_text(p, alarm))
        }
    }
}

/// The FSA deviations from plain CiA 402, in one cell.
fn quirks_text(p: &DriveProfile) -> String {
    let q = p.quirks;
    let mut v = Vec::new();
    if q.shortcut_transitions {
        v.push("multi-state jumps");
    }
    if !q.has_quick_stop {
        v.push("no quick stop (bit 5 always 1)");
    } else if !q.quick_stop_returns_to_enabled {
        v.push("no QSA → OE (16)");
    }
    if p.cycle.halt_in_cyclic_modes {
        v.push("halt in cyclic modes");
    }
    if v.is_empty() {
        "—".to_owned()
    } else {
        v.join("; ")
    }
}

/// Where the torque limits come from, in one cell.
fn torque_limit_text(p: &DriveProfile) -> String {
    match p.limits.torque_limit_selection {
        TorqueLimitSelection::Objects => "60E0h/60E1h".to_owned(),
        TorqueLimitSelection::Controlword2 {
            c_tl_bit,
            c_tl1_bit,
        } => format!(
            "PA11/PA12; + PC35 (2001h bit {c_tl1_bit}); + 60E0h/60E1h (2001h bit {c_tl_bit})"
        ),
        TorqueLimitSelection::TorqueLimit2 { cptl_bit, cntl_bit } => format!(
            "60E0h/60E1h, or 2D6Dh:02/:03 by controlword bits {cptl_bit}/{cntl_bit} when 2D6Dh:01 = 1"
        ),
    }
}

/// Homing methods (6098h), the simulated ones (data set, and the searches of
/// `profiles::homing_methods`) in bold.
fn homing_text(p: &DriveProfile) -> String {
    if p.homing.methods.is_empty() {
        return "none listed".to_owned();
    }
    let v: Vec<String> = p
        .homing
        .methods
        .iter()
        .map(|m| {
            if super::homing_methods::check_emulated(p, *m).is_ok() {
                format!("**{m}**")
            } else {
                m.to_string()
            }
        })
        .collect();
    v.join(", ")
}

/// Fault-reset hold, e.g. "10 ms (20 ms from 8000 µs)".
fn reset_text(p: &DriveProfile) -> String {
    if p.faults.reset_hold_long_cycle_ms == p.faults.reset_hold_ms {
        format!("{} ms", p.faults.reset_hold_ms)
    } else {
        format!(
            "{} ms ({} ms at ≥ {} µs)",
            p.faults.reset_hold_ms, p.faults.reset_hold_long_cycle_ms, p.faults.long_cycle_from_us
        )
    }
}

/// The markdown table, one row per [`DriveModel`].
pub fn render() -> String {
    let mut s = String::new();
    s.push_str("| `model` | drive | axes/unit | modes (6060h) | cycle times | communication check | fault reset hold | FSA quirks | torque limits | homing methods (6098h; **simulated**) | stroke ends (LSP/LSN) | leaving OP enabled | following error |\n");
    s.push_str("|---|---|---:|---|---|---|---|---|---|---|---|---|---|\n");
    for &m in DriveModel::ALL {
        let p = profile(m);
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            m.as_str(),
            p.name,
            p.axes_per_unit,
            p.modes_text(),
            p.cycle_times_text(),
            comm_text(p),
            reset_text(p),
            quirks_text(p),
            torque_limit_text(p),
            homing_text(p),
            p.limits.stroke_end_warning.map_or_else(
                || "not modelled".to_owned(),
                |w| format!("{} warning, slow stop in csv", alarm_text(p, w))
            ),
            alarm_text(p, p.comm.leave_op_alarm),
            alarm_text(p, p.limits.following_error_alarm),
        );
    }
    s
}

/// `readme` with the text between the markers replaced by [`render`]; `None` without markers.
pub fn splice(readme: &str) -> Option<String> {
    let a = readme.find(BEGIN_MARKER)? + BEGIN_MARKER.len();
    let b = readme[a..].find(END_MARKER)? + a;
    Some(format!("{}\n{}{}", &readme[..a], render(), &readme[b..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_model_has_a_row_with_its_facts() {
        let t = render();
        assert_eq!(t.lines().count(), 2 + DriveModel::ALL.len());
        let j3 = t.lines().find(|l| l.contains("`mr-j3-t04`")).unwrap();
        assert!(j3.contains("AL.34") && j3.contains("2020h/2021h"), "{j3}");
        assert!(j3.contains("no quick stop"), "{j3}");
        assert!(
            j3.contains("PA11/PA12") && j3.contains("2001h bit 3"),
            "{j3}"
        );
        let j4 = t.lines().find(|l| l.contains("`mr-j4-tm`")).unwrap();
        assert!(
            !j4.contains("125,") && !j4.contains("4000"),
            "MR-J4-TM: {j4}"
        );
    }

    #[test]
    fn splice_replaces_only_between_the_markers() {
        let doc = format!("head\n{BEGIN_MARKER}\nold table\n{END_MARKER}\ntail\n");
        let out = splice(&doc).unwrap();
        assert!(out.starts_with("head\n") && out.ends_with(&format!("{END_MARKER}\ntail\n")));
        assert!(!out.contains("old table") && out.contains("`mr-j5-g-n1`"));
        assert_eq!(splice(&out).unwrap(), out, "idempotent");
        assert!(splice("no markers").is_none());
    }
}
