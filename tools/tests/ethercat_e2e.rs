//! The EtherCAT cell end to end: the example cell's program over the in-process emulated
//! segment matches the same program on `transport = "sim"`, and over a veth pair with the
//! emulator in a network namespace (`cellrt drive-sim ethercat`, root only; skipped plainly
//! otherwise) it runs to completion and shuts down with no drive alarm.

mod common;

use cellrt_rt_tests::netns::VethNamespace;
use common::{read_recording, unique_cell_name, Recording};

/// The two runs here are not run side by side: each is a real-time cell whose drives count a
/// late frame as lost, as real ones do, so they must not load each other's CPUs.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// configs/ethercat-cell.toml with a unique name, the demo program beside it, no CPU pinning,
/// a long lookahead, no overrun watchdog and late cycles stretching the cell's clock
/// (`rt.missed_deadlines = "stretch"`: the machine's load is not under test, and the drives,
/// which live on the master's clock, then see the same cycles whatever it is), on `interface`.
/// On a NIC, a cyclic frame is lost only after 100 ms: the emulator in its namespace, held back
/// by a loaded machine, answers late, not never.
fn ethercat_cell(dir: &std::path::Path, interface: &str) -> std::path::PathBuf {
    let configs = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs");
    let text = std::fs::read_to_string(format!("{configs}/ethercat-cell.toml")).unwrap();
    let text = text
        .replace(
            "name = \"ethercat\"",
            &format!("name = \"{}\"", unique_cell_name()),
        )
        .replace("cpu = 1", "# cpu = 1")
        .replace(
            "priority = 80\n",
            "priority = 80\nmissed_deadlines = \"stretch\"\n",
        )
        .replace("lookahead_ms = 50", "lookahead_ms = 1000")
        .replace(
            "max_consecutive_overruns = 100",
            "max_consecutive_overruns = 0",
        )
        .replace(
            "interface = \"ecat0\"",
            &format!("interface = \"{interface}\""),
        );
    assert!(text.contains(&format!("interface = \"{interface}\"")));
    let text = if interface == "in-process" {
        text
    } else {
        text.replace("frame_timeout_us = 500", "frame_timeout_us = 100000")
    };
    assert_eq!(text.matches("missed_deadlines = \"stretch\"").count(), 1);
    std::fs::copy(
        format!("{configs}/demo-program.toml"),
        dir.join("demo-program.toml"),
    )
    .unwrap();
    let cfg = dir.join("ethercat.toml");
    std::fs::write(&cfg, text).unwrap();
    cfg
}

fn run(cfg: &std::path::Path, rec: &std::path::Path) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(cfg)
        .arg("--record")
        .arg(rec)
        .output()
        .unwrap()
}

/// The cycles at which each motion started.
fn motion_starts(rec: &Recording) -> Vec<u64> {
    rec.events
        .iter()
        .filter(|e| e.kind == "motion_started")
        .map(|e| e.cycle)
        .collect()
}

/// `axis`' actual position at `cycle`; `None` where the recording has no such cycle.
fn position_at(rec: &Recording, axis: &str, cycle: u64) -> Option<f64> {
    let a = &rec.axes[axis];
    let i = a.partition_point(|r| r.cycle < cycle);
    a.get(i)
        .filter(|r| r.cycle == cycle)
        .map(|r| r.actual_position)
}

#[test]
fn the_demo_program_over_emulated_ethercat_matches_the_same_program_on_sim() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let ec = ethercat_cell(dir.path(), "in-process");
    let text = std::fs::read_to_string(&ec).unwrap();
    // The same cell on the in-process simulated drives: no [ethercat] section, transport sim.
    let section = text.find("[ethercat]").unwrap();
    let axes = text.find("[[axes]]").unwrap();
    let sim_text = format!("{}{}", &text[..section], &text[axes..])
        .replace("transport = \"ethercat\"", "transport = \"sim\"")
        .replace(
            &text[text.find("name = \"t").unwrap()..]
                .lines()
                .next()
                .unwrap()
                .to_string(),
            &format!("name = \"{}\"", unique_cell_name()),
        );
    let sim = dir.path().join("sim.toml");
    std::fs::write(&sim, sim_text).unwrap();

    // Both runs stretch the cell's clock over a stall of the machine: judged cycle by cycle.
    let ec = compare_runs(&ec, &sim, dir.path());
    // The EtherCAT run went through the bus without an error event.
    let bus_errors: Vec<_> = ec.events.iter().filter(|e| e.kind == "bus_error").collect();
    assert!(bus_errors.len() <= 2, "{bus_errors:?}");
}

#[test]
fn the_ethercat_cell_runs_over_a_veth_pair_with_the_drives_in_a_network_namespace() {
    let ns = match VethNamespace::create(&format!("e{}", std::process::id() % 100_000)) {
        Ok(ns) => ns,
        Err(why) => {
            eprintln!("SKIPPED: EtherCAT over veth in a network namespace: {why}");
            return;
        }
    };
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let cfg = ethercat_cell(dir.path(), &ns.near);
    // As the README recommends for an emulated segment: the controller's RT thread and the
    // emulator on one CPU (the emulator one priority above), so a frame is answered at once.
    if std::thread::available_parallelism().map_or(1, |n| n.get()) >= 2 {
        let text = std::fs::read_to_string(&cfg)
            .unwrap()
            .replace("# cpu = 1", "cpu = 1");
        std::fs::write(&cfg, text).unwrap();
    }
    let rec = dir.path().join("veth.mcap");
    let (out, rest, status) = veth_run(&ns, &cfg, &rec);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "cellrt run over veth: {stdout}{stderr}"
    );
    assert!(stdout.contains("program completed"), "{stdout}{stderr}");
    assert!(status.success(), "drive-sim: {rest:?}");
    // Clean shutdown: every SubDevice in PRE-OP, no leaving-OP alarm.
    let states: Vec<&String> = rest.iter().filter(|l| l.contains("AL state")).collect();
    assert_eq!(states.len(), 4, "{rest:?}");
    assert!(
        states
            .iter()
            .all(|l| l.contains("PRE-OP") && !l.contains("alarm")),
        "{rest:?}"
    );
    let rec = read_recording(&rec);
    for (axis, target) in [("x", 50.0), ("y", 50.0), ("z", 0.0), ("c", 0.0)] {
        let last = rec.axes[axis].last().unwrap().actual_position;
        assert!((last - target).abs() < 0.01, "{axis} ended at {last}");
    }
}

/// One run over the veth pair: `cellrt drive-sim ethercat --excuse-host-stalls` in the
/// namespace, `cellrt run` on the near end, then SIGINT to the emulator. Returns the run's
/// output, the emulator's last lines and its exit status.
fn veth_run(
    ns: &VethNamespace,
    cfg: &std::path::Path,
    rec: &std::path::Path,
) -> (std::process::Output, Vec<String>, std::process::ExitStatus) {
    let (mut drives, lines) = common::spawn_drive_sim(ns, cfg);
    let out = run(cfg, rec);
    let _ = nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(drives.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    );
    let rest: Vec<String> = lines.map_while(Result::ok).collect();
    let status = drives.wait().unwrap();
    (out, rest, status)
}

#[test]
fn a_wire_fault_moved_to_a_nic_by_interface_is_left_to_the_segment_on_the_far_end() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = ethercat_cell(dir.path(), "in-process");
    let text = std::fs::read_to_string(&cfg).unwrap()
        + "\n[[inject]]\nat_ms = 100\nfault = \"frame_corruption\"\nduration_ms = 10\n";
    std::fs::write(&cfg, text).unwrap();
    // No such NIC here: the run is refused as bad input (exit 2) before anything starts, after
    // it has said what it leaves to the far end (it no longer refuses the fault).
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(&cfg)
        .args(["--interface", "crtnone0", "--no-record"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(
            "wire fault(s) frame_corruption at cycle 100 are left to the segment on the far end of 'crtnone0'"
        ),
        "{stderr}"
    );
    assert!(
        stderr.contains("error: EtherCAT interface 'crtnone0'")
            && stderr.contains("does not exist"),
        "{stderr}"
    );
}

/// The cycle of `a_lost_link_on_the_far_end…`'s link loss, and the window in which the master
/// must see it: the emulator counts from the first process-data frame, which `cellrt run`
/// sends (its priming exchange) about a cycle before its loop's cycle 0.
const FAR_LINK_LOSS_CYCLE: u64 = 600;
const FAR_LINK_LOSS_WINDOW: std::ops::RangeInclusive<u64> = 590..=605;

#[test]
fn a_lost_link_on_the_far_end_of_a_veth_pair_stops_the_cell_and_every_drive_raises_its_communication_alarm(
) {
    let ns = match VethNamespace::create(&format!("f{}", std::process::id() % 100_000)) {
        Ok(ns) => ns,
        Err(why) => {
            eprintln!("SKIPPED: wire faults injected by drive-sim over veth: {why}");
            return;
        }
    };
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let cfg = ethercat_cell(dir.path(), &ns.near);
    let mut text = std::fs::read_to_string(&cfg)
        .unwrap()
        .replace(
            "program = \"demo-program.toml\"",
            "program = \"fault-program.toml\"",
        )
        .replace(
            "sim = { initial_position",
            "sim = { motor_speed_factor = 2.5, initial_position",
        );
    if std::thread::available_parallelism().map_or(1, |n| n.get()) >= 2 {
        text = text.replace("# cpu = 1", "cpu = 1");
    }
    // The master's own link, on the drives' side of the veth pair, down for 30 ms mid-move.
    text += &format!(
        "\n[[inject]]\nat_ms = {FAR_LINK_LOSS_CYCLE}\nfault = \"link_loss\"\nduration_ms = 30\n"
    );
    std::fs::write(&cfg, text).unwrap();
    std::fs::write(
        dir.path().join("fault-program.toml"),
        "[[step]]\ndo = \"power_on\"\n[[step]]\ndo = \"move\"\ntarget = { x = 400.0, y = 300.0 }\n",
    )
    .unwrap();
    let rec_path = dir.path().join("far-link-loss.mcap");
    let (out, rest, status) = veth_run(&ns, &cfg, &rec_path);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        rec_path.exists(),
        "cellrt run over veth left no recording: {stderr}"
    );
    if let Err(why) = judge_far_link_loss(&out, &rest, status, &read_recording(&rec_path)) {
        panic!("{why}");
    }
}

/// The checks of `a_lost_link_on_the_far_end…`: the master left the fault to the segment and
/// recorded it, its communication watchdog stopped the cell within a few cycles of the first
/// lost frame, every drive raised its lost-process-data alarm, and drive-sim says it injected
/// the fault.
fn judge_far_link_loss(
    out: &std::process::Output,
    sim: &[String],
    sim_status: std::process::ExitStatus,
    rec: &Recording,
) -> Result<(), String> {
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let all = format!("{stdout}{stderr}\ndrive-sim: {sim:?}");
    let check = |ok: bool, what: &str| {
        if ok {
            Ok(())
        } else {
            Err(format!("{what}: {all}"))
        }
    };
    check(
        !out.status.success(),
        "the program must fail: the cell stops",
    )?;
    check(
        stderr.matches("left to the segment on the far end").count() == 1,
        "cellrt run says once that it leaves the fault to the segment",
    )?;
    check(sim_status.success(), "drive-sim exits cleanly")?;
    check(
        sim.iter()
            .any(|l| l.contains("cycle 600 (600 ms): link_loss in front of x, 30 frames")),
        "drive-sim announces the fault",
    )?;
    check(
        sim.iter()
            .any(|l| l.contains("injected 1 of 1 scheduled wire fault(s): 1 link_loss")),
        "drive-sim counts the fault it injected",
    )?;
    // The master recorded the fault as left to the segment, at its cycle, and injected nothing.
    let left: Vec<_> = rec
        .events
        .iter()
        .filter(|e| e.kind == "fault_left_to_segment")
        .collect();
    check(
        left.len() == 1
            && left[0].detail == "link_loss"
            && left[0].axis == "x"
            && (FAR_LINK_LOSS_CYCLE..FAR_LINK_LOSS_CYCLE + 5).contains(&left[0].cycle),
        &format!("one fault_left_to_segment event for link_loss on x at cycle {FAR_LINK_LOSS_CYCLE}: {left:?}"),
    )?;
    check(
        !rec.events.iter().any(|e| e.kind == "fault_injected"),
        "no fault_injected event on a network interface",
    )?;
    // The lost frames, then the communication watchdog's controlled stop within a few cycles.
    let at = |kind: &str| rec.events.iter().find(|e| e.kind == kind).map(|e| e.cycle);
    let lost = at("bus_error").ok_or_else(|| format!("no bus_error: {all}"))?;
    check(
        FAR_LINK_LOSS_WINDOW.contains(&lost),
        &format!("first lost frame at cycle {lost}, the link loss is due at {FAR_LINK_LOSS_CYCLE}"),
    )?;
    let stop = at("stop_started").ok_or_else(|| format!("no controlled stop: {all}"))?;
    check(
        stop > lost && stop <= lost + 5,
        &format!("stop at {stop}, first lost frame at {lost}"),
    )?;
    // No frame reached any drive for 30 ms: each one's lost-process-data alarm, as on the
    // in-process segment, in the recording and in drive-sim's final states.
    let mut faults = drive_faults(rec);
    faults.sort();
    check(
        faults == [("c", 0x0861), ("x", 0x36), ("y", 0x0861), ("z", 0x0861)],
        &format!("drive faults {faults:?}"),
    )?;
    let states: Vec<&String> = sim.iter().filter(|l| l.contains("AL state")).collect();
    check(
        states.len() == 4 && states.iter().all(|l| l.contains("alarm")),
        "every emulated drive ends with its alarm",
    )?;
    Ok(())
}

#[test]
fn a_stalled_subdevice_stops_the_cell_and_faults_its_drive() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().unwrap();
    let cfg = ethercat_cell(dir.path(), "in-process");
    // y (MR-J4-TM) stops answering for 30 ms during a move.
    let text = std::fs::read_to_string(&cfg).unwrap().replace(
        "program = \"demo-program.toml\"",
        "program = \"stall-program.toml\"",
    ) + "\n[[inject]]\nat_ms = 600\nfault = \"subdevice_stall\"\naxis = \"y\"\nduration_ms = 30\n";
    std::fs::write(&cfg, text).unwrap();
    std::fs::write(
        dir.path().join("stall-program.toml"),
        "[[step]]\ndo = \"power_on\"\n[[step]]\ndo = \"move\"\ntarget = { x = 400.0, y = 300.0 }\n",
    )
    .unwrap();
    let rec_path = dir.path().join("stall.mcap");
    let out = run(&cfg, &rec_path);
    let rec = read_recording(&rec_path);
    assert!(
        !out.status.success(),
        "the program must fail: the cell stops"
    );
    let at = |kind: &str| rec.events.iter().find(|e| e.kind == kind).map(|e| e.cycle);
    let injected = at("fault_injected").expect("fault_injected event");
    // The master: a working-counter error in the very cycle, then the communication
    // watchdog's controlled stop within a few cycles.
    assert_eq!(at("bus_error"), Some(injected));
    let stop = at("stop_started").expect("controlled stop");
    assert!(
        stop > injected && stop <= injected + 5,
        "stop at {stop}, stall at {injected}"
    );
    // The stalled drive: its lost-process-data alarm (MR-J4-TM AL. 86.1, 603Fh 0861h).
    // (603Fh is not in its TxPDO: the master reads it by SDO on the fault edge.)
    let faults: Vec<(&str, i64)> = rec
        .events
        .iter()
        .filter(|e| e.kind == "drive_fault")
        .map(|e| (e.axis.as_str(), e.value))
        .collect();
    assert_eq!(faults, [("y", 0x0861)], "{faults:?}");
    // The others were stopped by the master, not faulted, and came to rest.
    for axis in ["x", "z", "c"] {
        let a = &rec.axes[axis];
        assert!(
            a.last().unwrap().actual_velocity.abs() < 1e-3,
            "{axis} still moving"
        );
    }
}

/// The example cell on the in-process segment, moving x and y, with `inject` appended; runs it
/// and returns the output and the recording.
fn run_with_wire_fault(inject: &str) -> (std::process::Output, Recording) {
    let dir = tempfile::tempdir().unwrap();
    let cfg = ethercat_cell(dir.path(), "in-process");
    let text = std::fs::read_to_string(&cfg).unwrap().replace(
        "program = \"demo-program.toml\"",
        "program = \"fault-program.toml\"",
    ) + inject;
    std::fs::write(&cfg, text).unwrap();
    std::fs::write(
        dir.path().join("fault-program.toml"),
        "[[step]]\ndo = \"power_on\"\n[[step]]\ndo = \"move\"\ntarget = { x = 400.0, y = 300.0 }\n",
    )
    .unwrap();
    let rec_path = dir.path().join("fault.mcap");
    let out = run(&cfg, &rec_path);
    (out, read_recording(&rec_path))
}

/// The cell was stopped by the master's communication watchdog within a few cycles of the
/// injection (a `bus_error` in the very cycle), and the `fault_injected` event names `fault`
/// on `axis`.
fn assert_stopped_by_the_watchdog(rec: &Recording, fault: &str, axis: &str) {
    let injected = rec
        .events
        .iter()
        .find(|e| e.kind == "fault_injected")
        .expect("fault_injected event");
    assert_eq!(
        (injected.detail.as_str(), injected.axis.as_str()),
        (fault, axis)
    );
    let at = |kind: &str| rec.events.iter().find(|e| e.kind == kind).map(|e| e.cycle);
    assert_eq!(at("bus_error"), Some(injected.cycle));
    let stop = at("stop_started").expect("controlled stop");
    assert!(
        stop > injected.cycle && stop <= injected.cycle + 5,
        "stop at {stop}, {fault} at {}",
        injected.cycle
    );
}

/// `drive_fault` events as (axis, 603Fh code).
fn drive_faults(rec: &Recording) -> Vec<(&str, i64)> {
    rec.events
        .iter()
        .filter(|e| e.kind == "drive_fault")
        .map(|e| (e.axis.as_str(), e.value))
        .collect()
}

#[test]
fn a_lost_link_stops_the_cell_and_every_drive_behind_it_raises_its_communication_alarm() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    // The master's own link (the default) down for 30 ms during the move.
    let (out, rec) =
        run_with_wire_fault("\n[[inject]]\nat_ms = 600\nfault = \"link_loss\"\nduration_ms = 30\n");
    assert!(
        !out.status.success(),
        "the program must fail: the cell stops"
    );
    assert_stopped_by_the_watchdog(&rec, "link_loss", "x");
    // No frame reached any drive for 30 ms: each one's lost-process-data alarm once the link
    // is back (MR-J3-T04 AL.36 after about 7 ms; MR-J4-TM AL. 86.1; MR-JET and MR-J5 AL.086.1
    // by the sync-error counter).
    let mut faults = drive_faults(&rec);
    faults.sort();
    assert_eq!(
        faults,
        [("c", 0x0861), ("x", 0x36), ("y", 0x0861), ("z", 0x0861)],
        "{faults:?}"
    );
}

#[test]
fn a_corrupted_link_stops_the_cell_and_faults_only_the_drives_behind_it() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    // Bit errors on the link between y and z for 30 ms: x and y still take every frame, z and
    // c count CRC errors and get nothing; the master's NIC discards every frame.
    let (out, rec) = run_with_wire_fault(
        "\n[[inject]]\nat_ms = 600\nfault = \"frame_corruption\"\naxis = \"z\"\nduration_ms = 30\n",
    );
    assert!(
        !out.status.success(),
        "the program must fail: the cell stops"
    );
    assert_stopped_by_the_watchdog(&rec, "frame_corruption", "z");
    let mut faults = drive_faults(&rec);
    faults.sort();
    assert_eq!(faults, [("c", 0x0861), ("z", 0x0861)], "{faults:?}");
    // x and y were stopped by the master, not faulted, and came to rest.
    for axis in ["x", "y"] {
        let a = &rec.axes[axis];
        assert!(
            a.last().unwrap().actual_velocity.abs() < 1e-3,
            "{axis} still moving"
        );
    }
}

#[test]
fn a_dropped_datagram_stops_the_cell_and_every_drive_raises_its_communication_alarm() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    // The cyclic LRW removed from the frame for 30 ms: working counter 0 at the master, no
    // process data at any drive.
    let (out, rec) = run_with_wire_fault(
        "\n[[inject]]\nat_ms = 600\nfault = \"datagram_drop\"\nduration_ms = 30\n",
    );
    assert!(
        !out.status.success(),
        "the program must fail: the cell stops"
    );
    assert_stopped_by_the_watchdog(&rec, "datagram_drop", "");
    let mut faults = drive_faults(&rec);
    faults.sort();
    assert_eq!(
        faults,
        [("c", 0x0861), ("x", 0x36), ("y", 0x0861), ("z", 0x0861)],
        "{faults:?}"
    );
}

#[test]
fn frames_delayed_past_the_timeout_stop_the_cell_but_reach_the_drives_late() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    // 900 µs late for 30 ms against the 500 µs frame timeout: lost at the master every cycle,
    // but the drives take each frame, one cycle late (past its SYNC0).
    let (out, rec) = run_with_wire_fault(
        "\n[[inject]]\nat_ms = 600\nfault = \"frame_delay\"\ndelay_us = 900\nduration_ms = 30\n",
    );
    assert!(
        !out.status.success(),
        "the program must fail: the cell stops"
    );
    assert_stopped_by_the_watchdog(&rec, "frame_delay", "");
    let injected = rec
        .events
        .iter()
        .find(|e| e.kind == "fault_injected")
        .unwrap()
        .cycle;
    let lost: Vec<u64> = rec
        .events
        .iter()
        .filter(|e| e.kind == "bus_error")
        .map(|e| e.cycle)
        .collect();
    assert_eq!(
        lost,
        (injected..injected + 30).collect::<Vec<_>>(),
        "one lost frame per delayed cycle"
    );
    // No drive missed process data long enough for its communication alarm (where the
    // delay ends, two frames meet at one SYNC0 and a drive at speed may see two cycles'
    // travel in one: its command-frequency alarm, not a communication one).
    let faults = drive_faults(&rec);
    assert!(
        faults
            .iter()
            .all(|&(_, code)| code != 0x36 && code != 0x0861),
        "{faults:?}"
    );
}

/// Every EtherCAT cycle after the first few records the frame's DC phase error, and the loop
/// holds it near its target place in the SYNC0 cycle (median within 20 µs); the simulated
/// drives have no bus clock, so their cycles carry none.
fn assert_dc_phase_recorded(ec: &Recording, sim: &Recording) {
    let mut phase: Vec<i64> = ec
        .cycles
        .iter()
        .skip(10)
        .map(|c| {
            let e = c
                .dc_phase_error_ns
                .unwrap_or_else(|| panic!("cycle {} of the EtherCAT run has no DC phase", c.cycle));
            i64::from(e).abs()
        })
        .collect();
    assert!(phase.len() > 5000, "{} cycles", phase.len());
    phase.sort_unstable();
    let median = phase[phase.len() / 2];
    assert!(median < 20_000, "median |DC phase error| {median} ns");
    assert!(
        sim.cycles.iter().all(|c| c.dc_phase_error_ns.is_none()),
        "a sim cell recorded a DC phase"
    );
}

/// Runs the EtherCAT cell `ec_cfg` and the same cell on sim `sim_cfg`, and compares the drives'
/// response motion by motion, cycle by cycle; returns the EtherCAT recording.
fn compare_runs(
    ec_cfg: &std::path::Path,
    sim_cfg: &std::path::Path,
    dir: &std::path::Path,
) -> Recording {
    let out_ec = run(ec_cfg, &dir.join("ec.mcap"));
    assert!(
        out_ec.status.success(),
        "{}",
        String::from_utf8_lossy(&out_ec.stderr)
    );
    let out_sim = run(sim_cfg, &dir.join("sim.mcap"));
    assert!(
        out_sim.status.success(),
        "{}",
        String::from_utf8_lossy(&out_sim.stderr)
    );
    let ec = read_recording(&dir.join("ec.mcap"));
    let sim = read_recording(&dir.join("sim.mcap"));
    assert_dc_phase_recorded(&ec, &sim);
    // Motion by motion, from each one's start (when the planner starts the next motion is not
    // cycle-exact between two runs): the drives' response must be the same.
    let (se, ss) = (motion_starts(&ec), motion_starts(&sim));
    assert_eq!(se.len(), ss.len(), "both runs start the same motions");
    assert!(se.len() >= 7);
    for axis in ["x", "y", "z", "c"] {
        let mut worst = 0.0f64;
        let mut compared = 0usize;
        for m in 0..se.len() {
            let len = match (se.get(m + 1), ss.get(m + 1)) {
                (Some(ne), Some(ns)) => (ne - se[m]).min(ns - ss[m]),
                _ => 1000,
            };
            for k in 0..len {
                if let (Some(p), Some(q)) = (
                    position_at(&ec, axis, se[m] + k),
                    position_at(&sim, axis, ss[m] + k),
                ) {
                    worst = worst.max((p - q).abs());
                    compared += 1;
                }
            }
        }
        eprintln!("{axis}: {compared} cycles compared, largest difference {worst:.6}");
        assert!(compared > 4000, "{axis}: only {compared} cycles comparable");
        assert!(
            worst < 0.01,
            "{axis}: EtherCAT and sim differ by up to {worst}"
        );
        let (last_e, last_s) = (
            ec.axes[axis].last().unwrap(),
            sim.axes[axis].last().unwrap(),
        );
        assert!(
            (last_e.actual_position - last_s.actual_position).abs() < 0.01,
            "{axis}: final positions differ: {} vs {}",
            last_e.actual_position,
            last_s.actual_position
        );
    }
    ec
}

/// A link lost longer than the SyncManager watchdog (100 ms): the SubDevices behind it leave OP
/// for SAFE-OP with AL status code 001Bh when the link is back, and the master, which reads
/// every SubDevice's AL status in each cyclic frame, records it per axis (`al_status` events).
#[test]
fn a_link_lost_past_the_sm_watchdog_is_recorded_as_the_subdevices_al_status() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (out, rec) = run_with_wire_fault(
        "\n[[inject]]\nat_ms = 600\nfault = \"link_loss\"\naxis = \"z\"\nduration_ms = 150\n",
    );
    assert!(
        !out.status.success(),
        "the program must fail: the cell stops"
    );
    assert_stopped_by_the_watchdog(&rec, "link_loss", "z");
    let injected = rec
        .events
        .iter()
        .find(|e| e.kind == "fault_injected")
        .map(|e| e.cycle)
        .unwrap();
    let al: Vec<(&str, &str)> = rec
        .events
        .iter()
        .filter(|e| e.kind == "al_status")
        .map(|e| (e.axis.as_str(), e.detail.as_str()))
        .collect();
    let watchdog = "SAFE-OP, error 001Bh (sync manager watchdog)";
    assert_eq!(al, [("z", watchdog), ("c", watchdog)], "{:?}", rec.events);
    let first = rec
        .events
        .iter()
        .find(|e| e.kind == "al_status")
        .map(|e| e.cycle)
        .unwrap();
    // The link is back 150 ms after the loss on the link's clock, which moves with the loop's
    // cycles: seen with the first frame through.
    assert!(
        (injected + 150..=injected + 160).contains(&first),
        "seen with the first frame through, at {first} (link lost at {injected})"
    );
}

/// MR-J4-TM manual §4.1: a drive alarm injected on y (MR-J4-TM) during the move is recorded as an
/// `emergency` event of y with its code and error register, next to its `drive_fault`; the
/// alarm on x (MR-J3-T04, no CoE Emergency, MR-J3-T04 manual §1.7, §8.2.2, §8.2.3) is a `drive_fault` only.
#[test]
fn an_injected_drive_alarm_is_recorded_as_the_axis_emergency() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let (out, rec) = run_with_wire_fault(
        "\n[[inject]]\nat_ms = 300\nfault = \"drive_alarm\"\naxis = \"y\"\ncode = 0x2220\n\
         \n[[inject]]\nat_ms = 300\nfault = \"drive_alarm\"\naxis = \"x\"\ncode = 0x0032\n",
    );
    assert!(!out.status.success(), "the alarms stop the program");
    let emergencies: Vec<_> = rec
        .events
        .iter()
        .filter(|e| e.kind == "emergency")
        .map(|e| (e.axis.as_str(), e.value & 0xFF_FFFF, e.detail.as_str()))
        .collect();
    assert_eq!(
        emergencies,
        [(
            "y",
            0x01_2220,
            "error code 0x2220, error register 0x01, data 00 00 00 00 00"
        )],
        "{:?}",
        rec.events
    );
    let mut faults = drive_faults(&rec);
    faults.sort();
    assert_eq!(faults, [("x", 0x32), ("y", 0x2220)]);
    // Both read by the mailbox worker, off the RT thread, in the cycles after the alarm: the
    // Emergency when the cyclic frame saw SM1 full, 603Fh by the SDO posted at the fault edge.
    let injected = rec
        .events
        .iter()
        .find(|e| e.kind == "fault_injected")
        .map(|e| e.cycle)
        .unwrap();
    for kind in ["drive_fault", "emergency"] {
        let at = rec
            .events
            .iter()
            .find(|e| e.kind == kind && e.axis == "y")
            .map(|e| e.cycle)
            .unwrap();
        assert!(
            (injected + 1..injected + 500).contains(&at),
            "{kind} at {at}, alarm at {injected}"
        );
    }
}
