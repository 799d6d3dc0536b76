//! The RT executive driven directly through its real inputs: commands on the hand-off queue and
//! setpoint blocks on the iceoryx2 service. Bad blocks are refused with the reason and nothing
//! moves; an underrun stops the cell; the cell refuses motion until reset and moves after it.

use std::path::Path;
use std::sync::atomic::Ordering;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::handoff::{self, CellCommand, CellState, EventKind, EventRecord, HostEnd};
use cellrt_runtime::host::cell_bus::sim_bus;
use cellrt_runtime::rt::executive::{Executive, RtStats};
use cellrt_runtime::rt::setpoint_stream::SetpointStream;
use cellrt_runtime::services::{self, SetpointPublisher};
use cellrt_runtime::setpoints::{AxisSetpoint, SetpointHeader, FLAG_LAST};

const COUNTS_PER_MM: f64 = 1000.0;

/// Cycles between reading the cell's cycle and a block's start: ample for a test thread that a
/// loaded machine delays (a block that arrives after its start is refused as late).
const LEAD: u64 = 1000;

/// A one-axis cell named uniquely per test (`tag`) and process.
fn cell_with(tag: &str, extra: &str) -> CellConfig {
    let text = format!(
        r#"
[cell]
name = "exec-{tag}-{}"
cycle_time_us = 1000
[watchdogs]
max_consecutive_overruns = 0
[[axes]]
name = "x"
drive = "mr-j5-g-n1"
motor = {{ counts_per_rev = 10000 }}  # position counts per motor revolution (10 mm lead)
counts_per_unit = 1000
limits = {{ position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }}
sim = {{ initial_position = 100.0 }}
{extra}
"#,
        std::process::id()
    );
    CellConfig::parse(Path::new("exec.toml"), &text).unwrap()
}

struct Rig {
    handoff: HostEnd,
    rt: Option<JoinHandle<RtStats>>,
    publisher: SetpointPublisher,
    _node: iceoryx2::node::Node<iceoryx2::prelude::ipc::Service>,
    events: Vec<EventRecord>,
}

impl Rig {
    fn start(cell: &CellConfig) -> Rig {
        let n = cell.axes.on_loop().len();
        let (h, handoff) = handoff::new(n, 1000, handoff::PerCycleRecords::Skipped);
        let node = services::node(&cell.name, "test").unwrap();
        let publisher = services::setpoint_publisher(&node, &cell.name, n).unwrap();
        let c = cell.clone();
        let rt = std::thread::spawn(move || {
            let node = services::node(&c.name, "rt").unwrap();
            let sub = services::setpoint_subscriber(&node, &c.name).unwrap();
            Executive::new(&c, sim_bus(&c), SetpointStream::new(sub), h, None).run()
        });
        Rig {
            handoff,
            rt: Some(rt),
            publisher,
            _node: node,
            events: Vec::new(),
        }
    }

    fn command(&self, c: CellCommand) {
        self.handoff.send_command(c).unwrap();
    }

    fn drain(&mut self) {
        while let Some(e) = self.handoff.pop_event() {
            self.events.push(e);
        }
    }

    fn wait_state(&mut self, s: CellState) {
        let end = Instant::now() + Duration::from_secs(10);
        while self.handoff.status().state() != s {
            assert!(
                Instant::now() < end,
                "never {s:?}, is {:?}",
                self.handoff.status().state()
            );
            std::thread::sleep(Duration::from_millis(1));
        }
        self.drain();
    }

    fn wait_cycles(&mut self, n: u64) {
        let until = self.handoff.status().cycle() + n;
        self.wait_until(until);
    }

    fn wait_until(&mut self, cycle: u64) {
        while self.handoff.status().cycle() < cycle {
            std::thread::sleep(Duration::from_millis(1));
        }
        self.drain();
    }

    /// Waits until motion `id` has finished and the cell is idle again.
    fn wait_motion_done(&mut self, id: u32) {
        let end = Instant::now() + Duration::from_secs(5);
        let done = |r: &Rig| r.handoff.status().motion_done.load(Ordering::Acquire);
        while done(self) != id {
            assert!(Instant::now() < end, "motion {id} never finished");
            std::thread::sleep(Duration::from_millis(1));
        }
        self.wait_state(CellState::Idle);
    }

    fn hold_mm(&self) -> f64 {
        self.handoff.status().hold(0) / COUNTS_PER_MM
    }

    fn cycle(&self) -> u64 {
        self.handoff.status().cycle()
    }

    /// Publishes one block of `positions` (mm) starting at `start`.
    fn publish(&self, motion_id: u32, start: u64, positions: &[f64], last: bool) {
        let rows: Vec<Vec<f64>> = positions.iter().map(|&p| vec![p]).collect();
        self.publish_rows(motion_id, start, &rows, last);
    }

    /// Publishes one block of per-cycle rows of positions (mm), one per axis.
    fn publish_rows(&self, motion_id: u32, start: u64, rows: &[Vec<f64>], last: bool) {
        let axes = rows[0].len();
        let mut sp = Vec::with_capacity(rows.len() * axes);
        for (k, row) in rows.iter().enumerate() {
            for (i, p) in row.iter().enumerate() {
                let prev = if k == 0 { *p } else { rows[k - 1][i] };
                sp.push(AxisSetpoint {
                    position: p * COUNTS_PER_MM,
                    velocity: (p - prev) * COUNTS_PER_MM / 1e-3,
                    torque: 0.0,
                });
            }
        }
        let mut s = self.publisher.loan_slice_uninit(sp.len()).unwrap();
        *s.user_header_mut() = SetpointHeader {
            motion_id,
            flags: if last { FLAG_LAST } else { 0 },
            start_cycle: start,
            cycles: rows.len() as u32,
            axis_count: axes as u32,
        };
        s.write_from_slice(&sp).send().unwrap();
    }

    /// Publishes a valid ramp move of `blocks` full blocks from the hold position, 0.01 mm per
    /// cycle (10 mm/s); the last block is flagged only if `complete`.
    fn publish_move(&self, motion_id: u32, start: u64, blocks: usize, complete: bool) -> f64 {
        let mut p = self.hold_mm();
        for b in 0..blocks {
            let row: Vec<f64> = (0..16)
                .map(|_| {
                    p += 0.01;
                    p
                })
                .collect();
            self.publish(
                motion_id,
                start + 16 * b as u64,
                &row,
                complete && b + 1 == blocks,
            );
        }
        p
    }

    fn rejections(&self) -> Vec<i64> {
        self.events
            .iter()
            .filter(|e| e.kind == EventKind::SetpointRejected)
            .map(|e| e.value)
            .collect()
    }

    fn stop(mut self) -> RtStats {
        self.command(CellCommand::PowerOff);
        self.wait_state(CellState::Disabled);
        self.command(CellCommand::Quit);
        self.rt.take().unwrap().join().unwrap()
    }
}

#[test]
fn bad_blocks_are_refused_underrun_stops_and_motion_waits_for_reset() {
    // A wide start slip: the test thread, stalled on a loaded machine, publishes late itself.
    let cell = cell_with("refusals", "[setpoints]\nmax_start_slip_ms = 1000");
    let mut rig = Rig::start(&cell);
    rig.command(CellCommand::PowerOn);
    rig.wait_state(CellState::Idle);
    let home = rig.hold_mm();
    assert!(
        (home - 100.0).abs() < 0.01,
        "holds at its start position: {home}"
    );

    // A block that jumps 5 mm in one cycle (5000 mm/s > 100 mm/s): refused, nothing moves.
    let start = rig.cycle() + LEAD;
    rig.publish(1, start, &[home + 5.0; 16], true);
    rig.wait_until(start + 60);
    assert_eq!(rig.rejections(), vec![2], "velocity_step"); // RejectReason::VelocityStep
    assert_eq!(rig.handoff.status().state(), CellState::Idle);
    assert_eq!(rig.hold_mm(), home);
    // The motion never started, and the status says so (its planner stops waiting for it).
    assert_eq!(rig.handoff.status().motion_id.load(Ordering::Acquire), 0);
    assert_eq!(
        rig.handoff.status().motion_refused.load(Ordering::Acquire),
        1
    );
    // Its later blocks are dropped without a rejection each.
    let start = rig.cycle() + LEAD;
    rig.publish(1, start, &[home; 16], true);
    rig.wait_until(start + 20);
    assert_eq!(rig.rejections(), vec![2]);
    assert!(
        !rig.events
            .iter()
            .any(|e| e.kind == EventKind::MotionStarted),
        "a refused motion does not start from a later block"
    );
    assert_eq!(rig.handoff.status().state(), CellState::Idle);

    // A first block more than `max_start_slip_ms` (1000 cycles) late: refused.
    rig.publish(2, rig.cycle() - 2000, &[home; 16], true);
    rig.wait_cycles(20);
    assert_eq!(rig.rejections(), vec![2, 1], "late_block");
    assert_eq!(rig.hold_mm(), home);
    assert_eq!(
        rig.handoff.status().motion_refused.load(Ordering::Acquire),
        2
    );

    // A block outside the position range: refused.
    let start = rig.cycle() + LEAD;
    rig.publish(3, start, &[600.0; 16], true);
    rig.wait_until(start + 60);
    assert_eq!(rig.rejections().len(), 3);
    assert_eq!(rig.hold_mm(), home);

    // A motion whose stream ends without its last block: underrun, controlled stop, Stopped.
    let start = rig.cycle() + LEAD;
    rig.publish_move(4, start, 3, false);
    rig.wait_state(CellState::Stopped);
    assert!(rig.events.iter().any(|e| e.kind == EventKind::Underrun));
    let stopped_at = rig.hold_mm();
    assert!(stopped_at > home, "it had moved before the underrun");

    // Stopped: a valid motion is refused (not accepted) and nothing moves.
    let start = rig.cycle() + LEAD;
    rig.publish_move(5, start, 2, true);
    rig.wait_until(start + 100);
    assert_eq!(rig.handoff.status().state(), CellState::Stopped);
    assert_eq!(*rig.rejections().last().unwrap(), 6, "not_accepting");
    assert_eq!(rig.hold_mm(), stopped_at);

    // After reset the same kind of motion runs to its end.
    rig.command(CellCommand::Reset);
    rig.wait_state(CellState::Idle);
    let start = rig.cycle() + LEAD;
    let target = rig.publish_move(6, start, 3, true);
    rig.wait_motion_done(6);
    assert!(
        (rig.hold_mm() - target).abs() < 1e-9,
        "{} vs {target}",
        rig.hold_mm()
    );

    // A first block less late than that: the motion starts from rest when it arrives, and every
    // block of it is due as many cycles after the cycle it names.
    let late = rig.cycle() - 30;
    let target = rig.publish_move(7, late, 3, true);
    rig.wait_motion_done(7);
    let slip: Vec<i64> = rig
        .events
        .iter()
        .filter(|e| e.kind == EventKind::StartSlipped)
        .map(|e| e.value)
        .collect();
    assert_eq!(slip.len(), 1, "{:?}", rig.events);
    assert!((30..=1000).contains(&slip[0]), "slip {slip:?}");
    assert_eq!(
        i64::from(rig.handoff.status().motion_slip.load(Ordering::Acquire)),
        slip[0]
    );
    let started = rig
        .events
        .iter()
        .find(|e| e.kind == EventKind::MotionStarted && e.value == 7)
        .unwrap()
        .cycle;
    assert_eq!(started, late + slip[0] as u64);
    assert!(
        (rig.hold_mm() - target).abs() < 1e-9,
        "{} vs {target}",
        rig.hold_mm()
    );

    let stats = rig.stop();
    assert_eq!(stats.counters.underruns, 1);
    assert_eq!(stats.counters.rejected_setpoints, 3);
    assert_eq!(stats.final_state, CellState::Disabled);
}

#[test]
fn a_faulted_cell_needs_reset_and_power_on_before_it_moves_again() {
    // The drive raises an alarm 300 ms after the loop starts.
    let cell = cell_with(
        "b",
        "[[inject]]\nat_ms = 300\nfault = \"drive_alarm\"\naxis = \"x\"\ncode = 0x2220",
    );
    let mut rig = Rig::start(&cell);
    rig.command(CellCommand::PowerOn);
    rig.wait_state(CellState::Idle);
    rig.wait_state(CellState::Faulted);
    assert!(rig.events.iter().any(|e| e.kind == EventKind::DriveFault));

    // Faulted: power on is refused, motion is refused.
    rig.command(CellCommand::PowerOn);
    let start = rig.cycle() + LEAD;
    rig.publish_move(1, start, 2, true);
    rig.wait_until(start + 80);
    assert_eq!(rig.handoff.status().state(), CellState::Faulted);
    assert!(rig
        .events
        .iter()
        .any(|e| e.kind == EventKind::CommandRefused));
    assert_eq!(*rig.rejections().last().unwrap(), 6, "not_accepting");

    // Reset: the fault is acknowledged (held fault reset) and the cell ends Disabled.
    rig.command(CellCommand::Reset);
    rig.wait_state(CellState::Disabled);
    rig.command(CellCommand::PowerOn);
    rig.wait_state(CellState::Idle);
    let start = rig.cycle() + LEAD;
    let target = rig.publish_move(2, start, 2, true);
    rig.wait_motion_done(2);
    assert!((rig.hold_mm() - target).abs() < 1e-9);
    let stats = rig.stop();
    assert_eq!(stats.counters.faults, 1);
}

/// A two-axis cell whose second axis (`y`) is not powered.
fn two_axis_cell(tag: &str) -> CellConfig {
    cell_with(
        tag,
        r#"
[[axes]]
name = "y"
drive = "mr-j5-g-n1"
motor = { counts_per_rev = 10000 }  # position counts per motor revolution (10 mm lead)
counts_per_unit = 1000
limits = { position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }
sim = { initial_position = 50.0 }
"#,
    )
}

fn enabled(rig: &Rig, axis: usize) -> bool {
    let sw = rig.handoff.status().live[axis]
        .statusword
        .load(Ordering::Relaxed);
    cellrt_cia402::statusword::Statusword(sw).state()
        == Some(cellrt_cia402::fsa::FsaState::OperationEnabled)
}

fn powered(rig: &Rig, axis: usize) -> bool {
    rig.handoff.status().live[axis]
        .powered
        .load(Ordering::Relaxed)
}

#[test]
fn single_axes_power_on_and_off_and_an_unpowered_axis_takes_no_motion() {
    let cell = two_axis_cell("p");
    let mut rig = Rig::start(&cell);

    // MC_Power on x only: the cell is idle with x enabled and y still disabled.
    rig.command(CellCommand::PowerOnAxis(0));
    rig.wait_state(CellState::Idle);
    rig.wait_cycles(20);
    assert!(enabled(&rig, 0) && powered(&rig, 0));
    assert!(!enabled(&rig, 1) && !powered(&rig, 1));

    // x moves while y holds: accepted, x arrives, y stays put.
    let y = rig.handoff.status().hold(1) / COUNTS_PER_MM;
    let mut x = rig.hold_mm();
    let start = rig.cycle() + LEAD;
    for b in 0..2u64 {
        let rows: Vec<Vec<f64>> = (0..16)
            .map(|_| {
                x += 0.01;
                vec![x, y]
            })
            .collect();
        rig.publish_rows(1, start + 16 * b, &rows, b == 1);
    }
    rig.wait_motion_done(1);
    assert!((rig.hold_mm() - x).abs() < 1e-9);
    assert_eq!(rig.handoff.status().hold(1) / COUNTS_PER_MM, y);

    // Motion of the unpowered y: refused (axis_not_powered), the cell stops; y never moved.
    let start = rig.cycle() + LEAD;
    let rows: Vec<Vec<f64>> = (1..=16).map(|k| vec![x, y + 0.01 * k as f64]).collect();
    rig.publish_rows(2, start, &rows, true);
    rig.wait_state(CellState::Stopped);
    assert_eq!(*rig.rejections().last().unwrap(), 9, "axis_not_powered");
    assert!(rig
        .events
        .iter()
        .any(|e| e.kind == EventKind::SetpointRejected && e.axis == 1));
    assert!((rig.handoff.status().hold(1) / COUNTS_PER_MM - y).abs() < 1e-3);

    // Reset: idle again with x still powered and y still not.
    rig.command(CellCommand::Reset);
    rig.wait_state(CellState::Idle);
    assert!(enabled(&rig, 0) && !enabled(&rig, 1));

    // Power y on as well, then power x off: the cell stays idle on y alone.
    rig.command(CellCommand::PowerOnAxis(1));
    let end = Instant::now() + Duration::from_secs(5);
    while !enabled(&rig, 1) {
        assert!(Instant::now() < end, "y never reached operation enabled");
        std::thread::sleep(Duration::from_millis(1));
    }
    rig.wait_cycles(5);
    rig.wait_state(CellState::Idle);
    assert!(rig
        .events
        .iter()
        .any(|e| e.kind == EventKind::CellState && e.value == CellState::Enabling as i64));
    assert!(enabled(&rig, 0) && enabled(&rig, 1));
    rig.command(CellCommand::PowerOffAxis(0));
    let end = Instant::now() + Duration::from_secs(5);
    while enabled(&rig, 0) {
        assert!(Instant::now() < end, "x never left operation enabled");
        std::thread::sleep(Duration::from_millis(1));
    }
    rig.wait_cycles(20);
    assert_eq!(rig.handoff.status().state(), CellState::Idle);
    assert!(enabled(&rig, 1) && !powered(&rig, 0));

    // An axis index the cell lacks is refused, nothing changes.
    rig.command(CellCommand::PowerOnAxis(7));
    rig.wait_cycles(20);
    assert!(rig
        .events
        .iter()
        .any(|e| e.kind == EventKind::CommandRefused && e.axis == 7));
    assert_eq!(rig.handoff.status().state(), CellState::Idle);

    // The last powered axis off: the cell powers off.
    rig.command(CellCommand::PowerOffAxis(1));
    rig.wait_state(CellState::Disabled);
    assert!(!enabled(&rig, 0) && !enabled(&rig, 1));
    rig.command(CellCommand::Quit);
    rig.rt.take().unwrap().join().unwrap();
}

/// A planner lost while the cell is idle (between its motions): a motion whose blocks it had
/// already published does not start from the buffer (they are refused, not accepting), and
/// motions start again once a planner is back.
#[test]
fn no_motion_starts_while_the_planner_is_lost() {
    let cell = cell_with("planner-lost", "");
    let mut rig = Rig::start(&cell);
    rig.command(CellCommand::PowerOn);
    rig.wait_state(CellState::Idle);
    let home = rig.hold_mm();
    rig.command(CellCommand::PlannerLost);
    let start = rig.cycle() + LEAD;
    rig.publish_move(1, start, 2, true);
    rig.wait_until(start + 100);
    assert_eq!(rig.handoff.status().state(), CellState::Idle);
    assert_eq!(rig.hold_mm(), home, "nothing moved");
    assert!(
        !rig.events
            .iter()
            .any(|e| e.kind == EventKind::MotionStarted),
        "{:?}",
        rig.events
    );
    assert!(rig.rejections().iter().all(|&r| r == 6), "not_accepting");
    assert!(!rig.rejections().is_empty());
    rig.command(CellCommand::PlannerConnected);
    let start = rig.cycle() + LEAD;
    let target = rig.publish_move(2, start, 2, true);
    rig.wait_motion_done(2);
    assert!((rig.hold_mm() - target).abs() < 1e-9);
    rig.stop();
}

/// An overrun that skips past a motion's end still leaves the axis at the motion's final
/// setpoint: the RT loop stalls 100 ms (injected at 1530 ms) inside the last block of a motion
/// due at cycles 1500–1548, and the motion ends on its target, not on the row before the stall
/// (on a loaded machine this failed by the rows the stall skipped).
#[test]
fn an_overrun_past_the_end_of_a_motion_still_applies_its_final_setpoint() {
    let cell = cell_with(
        "skip",
        "[[inject]]\nat_ms = 1530\nfault = \"stall\"\nduration_ms = 100",
    );
    let mut rig = Rig::start(&cell);
    rig.command(CellCommand::PowerOn);
    rig.wait_state(CellState::Idle);
    assert!(
        rig.cycle() < 1400,
        "the rig came up late: cycle {}",
        rig.cycle()
    );
    let target = rig.publish_move(1, 1500, 3, true);
    rig.wait_motion_done(1);
    assert!(
        rig.events
            .iter()
            .any(|e| e.kind == EventKind::Overrun && (1500..1548).contains(&e.cycle)),
        "the stall fell inside the motion: {:?}",
        rig.events
    );
    assert!(
        (rig.hold_mm() - target).abs() < 1e-9,
        "{} vs {target}",
        rig.hold_mm()
    );
    rig.stop();
}

/// What a late cycle does with the deadlines it missed (`rt.missed_deadlines`): the RT loop
/// stalls 100 ms at cycle 300. Skipped (the default), the cell's clock keeps wall time and
/// about 100 cycle numbers are never executed; stretched, every cycle number is executed and
/// the cell's clock falls behind. Either way the missed deadlines are counted.
#[test]
fn a_stall_skips_its_cycles_by_default_and_stretches_the_cells_clock_when_asked() {
    for (policy, extra) in [
        ("skip", ""),
        ("stretch", "[rt]\nmissed_deadlines = \"stretch\"\n"),
    ] {
        let cell = cell_with(
            &format!("missed-{policy}"),
            &format!("{extra}[[inject]]\nat_ms = 300\nfault = \"stall\"\nduration_ms = 100"),
        );
        let mut rig = Rig::start(&cell);
        rig.command(CellCommand::PowerOn);
        rig.wait_state(CellState::Idle);
        rig.wait_until(500);
        let stats = rig.stop();
        let executed = stats.counters.cycles;
        let unexecuted = stats.final_cycle + 1 - executed;
        assert!(
            stats.counters.overruns >= 90,
            "{policy}: {} missed deadlines counted",
            stats.counters.overruns
        );
        match policy {
            "skip" => assert!(
                unexecuted >= 90 && unexecuted == stats.counters.overruns,
                "skip: {unexecuted} cycle numbers not executed, {} overruns",
                stats.counters.overruns
            ),
            _ => assert_eq!(unexecuted, 0, "stretch: no cycle number is skipped"),
        }
    }
}
