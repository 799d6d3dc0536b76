//! `cellrt param` and `cellrt alarms` end to end on the simulated drives and on the in-process
//! emulated EtherCAT segment: the parameters by their manual names (MR-J3-T04 manual §5.1, the
//! torque limit 2 parameters of MR-JET-G-N1 manual §9.1), range-checked before anything is
//! sent, saved with 1010h, compared with their initial values, and the alarm history with an
//! alarm the emulator raises (MR-J3-T04 AL.36, §8.9), and each refusal.

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

use cellrt_runtime::host::operator::wire::{Reply, SdoAnswer};
use common::cell::Cell;

/// An alarm the emulator raises itself: x's RxPDOs are lost for 100 ms, and the MR-J3-T04
/// raises AL.36 after about 7 ms (manual §8.11.1).
const RX_LOSS_ON_X: &str =
    "[[inject]]\nat_ms = 300\nfault = \"rx_loss\"\naxis = \"x\"\nduration_ms = 100\n";

/// x's SubDevice stalls for 30 ms (below the SubDevices' sync manager watchdog, so they stay
/// in OP): once it answers again the emulated MR-J3-T04 counts the SYNC0s without process data
/// and raises AL.36.
const STALL_OF_X: &str =
    "[[inject]]\nat_ms = 1000\nfault = \"subdevice_stall\"\naxis = \"x\"\nduration_ms = 30\n";

/// The shipped MR-J3-T04 cell, once it answers (`status`: a request lost while the cell
/// starts waits out the client's reply timeout, 30 s for `param`).
fn sim_cell(dir: &Path, toml: &str) -> Cell {
    let ready = ["status"];
    Cell::shipped(dir, "mr-j3-t04.toml", "mr-j3-t04", &[], toml, &ready)
}

fn ethercat_cell(dir: &Path, toml: &str) -> Cell {
    let extra = ["--interface", "in-process"];
    let ready = ["sdo", "read", "x", "6041"];
    Cell::shipped(dir, "ethercat-cell.toml", "ethercat", &extra, toml, &ready)
}

/// The parameter names of a printed list.
fn names(list: &str) -> Vec<&str> {
    list.lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect()
}

/// Waits until `cellrt alarms AXIS` shows `alarm` (a read the drive refuses while its
/// SubDevice is stalled is tried again); returns the printed history.
fn history_with(cell: &Cell, axis: &str, alarm: &str) -> String {
    let end = Instant::now() + Duration::from_secs(20);
    loop {
        let (code, out, err) = cell.cli(&["alarms", axis]);
        let h = out.trim().to_string();
        if code == 0 && h.contains(alarm) {
            return h;
        }
        assert!(
            code == 0 || err.contains("refused by the drive"),
            "cellrt alarms {axis}: {out}{err}"
        );
        assert!(
            Instant::now() < end,
            "{alarm} never reached the history: {h}"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The refusals made before anything is sent, on MR-J3-T04 axis x; nothing is written.
fn mr_j3_t04_refusals(cell: &Cell) {
    let before = cell.out(&["param", "list", "x"]);
    cell.refused(
        &["param", "set", "x", "PB03", "20001"],
        "param: PB03 (Position command acceleration/deceleration time constant) takes \
         0..20000: 20001 is out of it; not written",
    );
    cell.refused(
        &["param", "set", "x", "PO03", "0x0100"],
        "takes hex digit 0: 0/1/2/3, digit 1: 0, digit 2: 0/2: 0100h is out of it",
    );
    cell.refused(
        &["param", "set", "x", "PA01", "2"],
        "param: PA01 (Control mode) is not to be changed",
    );
    cell.refused(
        &["param", "set", "x", "PA02", "1"],
        "param: PA02 is not a parameter of axis 'x' (mr-j3-t04; MR-J3-T04 manual §5.1",
    );
    cell.refused(&["param", "get", "w", "PA19"], "unknown axis 'w'");
    cell.refused(
        &["sdo", "write", "x", "2301:3", "30000"],
        "(Position command acceleration/deceleration time constant) takes 0..20000 (stated range)",
    );
    assert_eq!(cell.out(&["param", "list", "x"]), before, "nothing written");
}

#[test]
fn param_list_get_set_diff_save_on_simulated_mr_j3_t04_drives() {
    let dir = tempfile::tempdir().unwrap();
    let cell = sim_cell(dir.path(), "");
    let list = cell.out(&["param", "list", "x"]);
    assert_eq!(names(&list).len(), 21, "{list}");
    assert!(
        list.contains("PA19  *BLK   = 000Eh      (initial 000Eh; 0000h..FFFFh; after power cycle) 2300h:13 Parameter writing inhibit"),
        "{list}"
    );
    assert_eq!(
        cell.out(&["param", "get", "x", "pc02"]),
        "x PC02  STB    = 0          (initial 0; 0..50000 ms; immediately) 2302h:02 Deceleration time constant"
    );
    assert_eq!(
        cell.out(&["param", "diff", "x"]),
        "x: every parameter at its initial value"
    );
    assert_eq!(
        cell.out(&["param", "set", "x", "PA14", "1"]),
        "x PA14 written: 1\nx: PA14 takes effect after a power cycle; save it first \
         (cellrt param save) or it is lost"
    );
    assert_eq!(
        cell.out(&["param", "set", "x", "PO03", "0200h"]),
        "x PO03 written: 0200h\nx: PO03 takes effect after a power cycle; save it first \
         (cellrt param save) or it is lost"
    );
    assert_eq!(names(&cell.out(&["param", "diff", "x"])), ["PA14", "PO03"]);
    let (code, out, _) = cell.cli(&["param", "get", "x", "PO03", "--json"]);
    assert_eq!(code, 0);
    match serde_json::from_str::<Reply>(&out).unwrap() {
        Reply::Param(r) => {
            let p = &r.parameters[0];
            assert_eq!((p.object.as_str(), p.value), ("2309h:03", Some(0x0200)));
            assert_eq!(p.effect, "after power cycle");
        }
        other => panic!("{other:?}"),
    }
    // The same object by `cellrt sdo`: PO03 is 2309h:03 (manual §8.10.1), I32.
    assert_eq!(
        cell.out(&["sdo", "read", "x", "2309:3"]),
        "x 2309h:03 Communication protection switch (INTEGER32) = 512 (0x00000200)"
    );
    mr_j3_t04_refusals(&cell);
    // PC02 acts at once on the slow-stop ramp: refused while x is enabled; PA14 (`*`) is not.
    cell.out(&["power", "on", "x"]);
    cell.refused(
        &["param", "set", "x", "PC02", "200"],
        "param: PC02 (Deceleration time constant) of axis 'x' takes effect at once and is not \
         written while the axis is enabled",
    );
    cell.out(&["param", "set", "x", "PA14", "0"]);
    cell.out(&["power", "off"]);
    cell.out(&["param", "set", "x", "PC02", "200"]);
    assert_eq!(names(&cell.out(&["param", "diff", "x"])), ["PC02", "PO03"]);
    assert_eq!(
        cell.out(&["param", "save", "x"]),
        "x: saved: 1010h:01 written 65766173h (MR-J3-T04 manual §8.10.2)"
    );
    // MR-J3-T04 manual §8.10.2: a read of 1010h:01 returns 3, storing available (PA19 000Eh).
    assert_eq!(
        cell.out(&["sdo", "read", "x", "1010:1"]),
        "x 1010h:01 Store all parameters (UNSIGNED32) = 3 (0x00000003)"
    );
    assert_eq!(cell.out(&["alarms", "y"]), "y: alarm history empty");
}

#[test]
fn alarms_show_the_alarm_the_simulated_drive_raised_and_clear() {
    let dir = tempfile::tempdir().unwrap();
    let cell = sim_cell(dir.path(), RX_LOSS_ON_X);
    let h = history_with(&cell, "x", "AL.36");
    // Each entry with the manual's cause and remedy (MR-J3-T04 manual §7.2).
    assert_eq!(
        h,
        "x alarm history (mr-j3-t04, newest first):\n0  AL.36 Receive error 2 (0036h) at 0 h, detail 0\n   \
         cause: PDO communication faulty: EtherCAT cable faulty, master communication settings/processing faulty, or faulty parts in the servo amplifier or option unit\n   \
         remedy: Replace the EtherCAT cable; use a master that satisfies the EtherCAT standards; else replace the servo amplifier or the option unit"
    );
    assert_eq!(cell.out(&["alarms", "y"]), "y: alarm history empty");
    let (code, out, _) = cell.cli(&["alarms", "x", "--json"]);
    assert_eq!(code, 0);
    match serde_json::from_str::<Reply>(&out).unwrap() {
        Reply::Alarms(r) => {
            assert_eq!(r.entries.len(), 1);
            assert_eq!((r.entries[0].entry, r.entries[0].number), (0, 0x0036));
        }
        other => panic!("{other:?}"),
    }
    // 2030h:01 is the newest entry's Alarm No. (manual §8.9).
    assert_eq!(
        cell.out(&["sdo", "read", "x", "2030:1"]),
        "x 2030h:01 Alarm No. (UNSIGNED16) = 54 (0x0036)"
    );
    assert_eq!(
        cell.out(&["alarms", "x", "--clear"]),
        "x: alarm history cleared"
    );
    assert_eq!(cell.out(&["alarms", "x"]), "x: alarm history empty");
    cell.refused(
        &["sdo", "read", "x", "2040"],
        "sdo: 2040h:00 of axis 'x' (Clear alarm history) is write-only",
    );
}

#[test]
fn param_and_alarms_on_the_emulated_ethercat_segment() {
    let dir = tempfile::tempdir().unwrap();
    let cell = ethercat_cell(dir.path(), STALL_OF_X);
    // x (MR-J3-T04): its SubDevice stalled, the emulated drive raised AL.36.
    let h = history_with(&cell, "x", "AL.36");
    assert!(
        h.starts_with(
            "x alarm history (mr-j3-t04, newest first):\n0  AL.36 Receive error 2 (0036h)"
        ),
        "{h}"
    );
    assert_eq!(names(&cell.out(&["param", "list", "x"])).len(), 21);
    assert_eq!(
        cell.out(&["param", "set", "x", "PO03", "0x0200"]),
        "x PO03 written: 0200h\nx: PO03 takes effect after a power cycle; save it first \
         (cellrt param save) or it is lost"
    );
    assert_eq!(names(&cell.out(&["param", "diff", "x"])), ["PO03"]);
    assert_eq!(
        cell.out(&["param", "save", "x"]),
        "x: saved: 1010h:01 written 65766173h (MR-J3-T04 manual §8.10.2)"
    );
    mr_j3_t04_refusals(&cell);
    assert_eq!(
        cell.out(&["alarms", "x", "--clear"]),
        "x: alarm history cleared"
    );
    assert_eq!(cell.out(&["alarms", "x"]), "x: alarm history empty");
    // z (MR-JET-G-N1): PC43 is 2D6Dh:02, initial 10000, 0..10000 (manual §9.1).
    assert_eq!(
        cell.out(&["param", "get", "z", "PC43"]),
        "z PC43         = 10000      (initial 10000; 0..10000 0.1 % rated; immediately) 2D6Dh:02 Forward rotation torque limit 2"
    );
    assert_eq!(
        cell.out(&["param", "set", "z", "PC43", "5000"]),
        "z PC43 written: 5000"
    );
    assert_eq!(names(&cell.out(&["param", "diff", "z"])), ["PC43"]);
    cell.refused(
        &["param", "set", "z", "PC44", "10001"],
        "param: PC44 (Reverse rotation torque limit 2) takes 0..10000: 10001 is out of it",
    );
    assert_eq!(
        cell.out(&["param", "save", "z"]),
        "z: saved: 1010h:01 written 65766173h (MR-JET-G-N1 / MR-J5-G-N1 manuals §3.2)"
    );
    cell.refused(
        &["alarms", "z"],
        "alarms: axis 'z' (mr-jet-g-n1) has no alarm history: the MR-JET-G-N1 and MR-J5-G-N1 \
         communication manuals give no alarm history object",
    );
    // y (MR-J4-TM): the manual's parameter chapters are missing.
    for args in [
        &["param", "list", "y"][..],
        &["param", "get", "y", "PA01"],
        &["param", "save", "y"],
        &["alarms", "y"],
    ] {
        cell.refused(args, "MR-J4-TM manual's parameter objects (§6.5)");
    }
    // The JSON of a read carries the drive's answer; sdo reads of the history object agree.
    let (code, out, _) = cell.cli(&["sdo", "read", "x", "2030:1", "--json"]);
    assert_eq!(code, 0);
    match serde_json::from_str::<Reply>(&out).unwrap() {
        Reply::Sdo(r) => assert_eq!(r.outcome, SdoAnswer::Read { value: 0 }),
        other => panic!("{other:?}"),
    }
}
