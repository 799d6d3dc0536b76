//! The master's communication watchdog per model, on the in-process EtherCAT segment: a lost
//! link (every frame lost) stops the cell through the master within `watchdogs.max_lost_frames`
//! cycles, on models without an incremental counter (MR-JET, MR-J5, generic CiA 402) as on
//! those with one, and the recording names the watchdog; dropped datagrams trip
//! `max_working_counter_errors` the same way. Judged in cycles of the recording.

mod common;

use common::{read_recording, run_recorded, unique_cell_name, Recording};

const PROGRAM: &str =
    "[[step]]\ndo = \"power_on\"\n[[step]]\ndo = \"move\"\ntarget = { x = 400.0 }\n";

/// A one-axis EtherCAT cell of `drive` on the in-process segment with `watchdogs` and
/// `inject` appended; the counter levels are set so high that only the frame watchdogs trip.
fn cell(drive: &str, watchdogs: &str, inject: &str) -> String {
    let identity = match drive {
        "cia402" => "ethercat = { vendor_id = 0xCE110000, product_code = 0xCE110402 }\n",
        // The MR-J5 and MR-JET manuals give no encoder resolution: the axis states its own.
        "mr-jet-g-n1" | "mr-j5-g-n1" => "motor = { counts_per_rev = 10000 }\n",
        _ => "",
    };
    format!(
        "[cell]\nname = \"{name}\"\ncycle_time_us = 1000\nprogram = \"program.toml\"\n\
         [setpoints]\nlookahead_ms = 1000\n\
         [watchdogs]\nmax_consecutive_overruns = 0\ncounter_continuous_errors = 1000\n\
         counter_intermittent_errors = 0\ncounter_intermittent_window = 1000\n{watchdogs}\n\
         [ethercat]\ninterface = \"in-process\"\n\
         [[axes]]\nname = \"x\"\ndrive = \"{drive}\"\ntransport = \"ethercat\"\nmode = \"csp\"\n\
         unit = \"mm\"\ncounts_per_unit = 1000\n\
         limits = {{ position = [0.0, 800.0], velocity = 400.0, acceleration = 2000.0, jerk = 20000.0 }}\n\
         sim = {{ initial_position = 50.0 }}\n{identity}{inject}",
        name = unique_cell_name(),
    )
}

/// Runs the cell (the program must fail: the cell stops) and returns its recording.
fn run_stopped(text: &str) -> Recording {
    let dir = tempfile::tempdir().unwrap();
    let (out, rec_path) = run_recorded(dir.path(), text, PROGRAM);
    assert_eq!(
        out.status.code(),
        Some(1),
        "the cell must stop: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    read_recording(&rec_path)
}

/// The first event of `kind`'s cycle and detail.
fn first(rec: &Recording, kind: &str) -> (u64, String) {
    rec.events
        .iter()
        .find(|e| e.kind == kind)
        .map(|e| (e.cycle, e.detail.clone()))
        .unwrap_or_else(|| panic!("no {kind} event: {:?}", rec.events))
}

/// The fault started at the `fault_injected` cycle; the watchdog named by `key` tripped at the
/// `max`-th faulty frame (the `max`-th cycle the loop executed from the injection on: cycle
/// injected + max − 1 unless an overrun skipped cycles) and the communication reaction started
/// in the next cycle.
fn assert_tripped(rec: &Recording, key: &str, max: u64, what: &str) {
    let (injected, _) = first(rec, "fault_injected");
    let (tripped, detail) = first(rec, "communication_error");
    assert!(detail.contains(key), "{what}: {detail}");
    let executed = rec
        .cycles
        .iter()
        .filter(|c| (injected..=tripped).contains(&c.cycle))
        .count() as u64;
    assert_eq!(executed, max, "{what}: {detail} at cycle {tripped}");
    assert!(
        tripped >= injected + max - 1,
        "{what}: {detail} at cycle {tripped}"
    );
    let (stop, why) = first(rec, "stop_started");
    let next = rec
        .cycles
        .iter()
        .map(|c| c.cycle)
        .find(|&c| c > tripped)
        .unwrap_or(tripped + 1);
    assert_eq!(stop, next, "{what}: {why}");
    assert!(why.starts_with("communication"), "{what}: {why}");
}

#[test]
fn a_lost_link_stops_every_model_through_the_master_within_max_lost_frames() {
    for drive in [
        "mr-j3-t04",
        "mr-j4-tm",
        "mr-jet-g-n1",
        "mr-j5-g-n1",
        "cia402",
    ] {
        for max in [2u64, 5] {
            let text = cell(
                drive,
                &format!("max_lost_frames = {max}"),
                "[[inject]]\nat_ms = 600\nfault = \"link_loss\"\nduration_ms = 30\n",
            );
            let rec = run_stopped(&text);
            assert_tripped(
                &rec,
                "watchdogs.max_lost_frames",
                max,
                &format!("{drive}, max_lost_frames = {max}"),
            );
        }
    }
}

#[test]
fn dropped_datagrams_stop_the_cell_within_max_working_counter_errors() {
    for drive in ["mr-jet-g-n1", "cia402"] {
        let text = cell(
            drive,
            "max_working_counter_errors = 4",
            "[[inject]]\nat_ms = 600\nfault = \"datagram_drop\"\nduration_ms = 30\n",
        );
        let rec = run_stopped(&text);
        assert_tripped(&rec, "watchdogs.max_working_counter_errors", 4, drive);
    }
}
