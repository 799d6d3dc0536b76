//! Profile position mode (pp) of the simulated drives and the master-side mode change into csp:
//! MR-J4-TM TV-9 (docs/test-vectors.md), MR-J5-G-N1 TV-10 (docs/test-vectors.md), MR-JET-G-N1 TV-7 (docs/test-vectors.md), and pp basics on
//! MR-J5 / MR-JET (SDO-set 6081h/6083h/6084h, trapezoid, handshake, relative, set-point modes).

mod common;

use cellrt_cia402::profiles::mr_j4_tm;
use cellrt_cia402::{
    Controlword, CycleTime, Cycles, DriveModel, FsaState, ModeOfOperation, ModeSwitch,
    ModeSwitchError, ModeSwitchParams, ModeSwitchPhase, ModeSwitchProgress, RxPdo, TxPdo,
};
use cellrt_emulator::motion::profile_position::{
    PositionUnit, PpParams, SET_POINT_ACKNOWLEDGE, TARGET_REACHED,
};
use cellrt_emulator::sim::drive::SimMotor;
use cellrt_emulator::sim::sdo::SdoAbort;
use cellrt_emulator::{SimDrive, SimDriveParams};
use common::{drive, enabled};

/// One cycle, with 606Ch replaced by the plant's speed in counts/s: with the
/// [`MOTOR_COUNTS_PER_REV`] motor one 0.01 r/min LSB of 6081h is one count/s, so these tests
/// judge speeds in counts/s.
fn exchange(d: &mut SimDrive, rx: &RxPdo) -> TxPdo {
    let mut tx = common::exchange(d, rx);
    tx.velocity_actual = counts_per_s(d);
    tx
}

/// The plant's speed in counts/s.
fn counts_per_s(d: &SimDrive) -> i32 {
    d.plant().velocity().round() as i32
}

use cellrt_test_support::counting_alloc::{thread_heap_calls, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// The drive's zero speed (PC07) in these tests, counts/s.
const ZERO_SPEED: f64 = 10.0;

/// A motor of 6000 counts/rev: 6081h in 0.01 r/min (MR-J4-TM manual §4.2; the default unit of
/// MR-JET / MR-J5) is then 1 count/s per LSB (100 r/min = 10000 counts/s).
const MOTOR_COUNTS_PER_REV: f64 = 6_000.0;

fn params(pp: PpParams) -> SimDriveParams {
    SimDriveParams {
        zero_speed: ZERO_SPEED,
        motor: SimMotor {
            counts_per: Some(MOTOR_COUNTS_PER_REV),
            ..SimMotor::default()
        },
        pp,
        ..SimDriveParams::default()
    }
}

/// pp parameters whose 6083h/6084h time constants refer to `speed` counts/s.
fn pp_ref(speed: f64) -> PpParams {
    PpParams {
        time_constant_speed: Some(speed),
        ..PpParams::default()
    }
}

/// An MR-J4-TM with PA01 = `___2` (pp/pv/tq/hm, 1601h) at 1 ms.
fn j4_profile_mode(p: SimDriveParams) -> SimDrive {
    SimDrive::new(
        mr_j4_tm::ModeGroup::Profile.profile(),
        p,
        CycleTime::from_micros(1000).unwrap(),
    )
}

/// A pp RxPDO.
fn pp(cw: u16, target: i32) -> RxPdo {
    RxPdo {
        mode: ModeOfOperation::ProfilePosition.as_i8(),
        controlword: Controlword(cw),
        target_position: target,
        ..RxPdo::default()
    }
}

/// Boots and enables with `base` (its controlword replaced).
fn enable_with(d: &mut SimDrive, base: RxPdo) {
    for cw in [0u16, 0, 0, 0x06, 0x07, 0x0F] {
        exchange(
            d,
            &RxPdo {
                controlword: Controlword(cw),
                ..base
            },
        );
    }
    assert_eq!(d.state(), FsaState::OperationEnabled);
}

fn sw(tx: &TxPdo, bit: u16) -> bool {
    tx.statusword.0 & bit != 0
}

/// What a run of cycles saw.
#[derive(Debug, Default)]
struct Run {
    cycles: u32,
    peak_velocity: i32,
    reached: bool,
    /// Consecutive cycles (ending at the first bit 10) with |6064h − target| ≤ window.
    window_run: u32,
    /// Bit 12 was 1 in every cycle before bit 10.
    ack_while_moving: bool,
    last: TxPdo,
}

/// Sends `rx` until bit 10 (or `max` cycles); tracks the window and bit 12 against `target`.
fn run_until_reached(d: &mut SimDrive, rx: &RxPdo, target: i32, window: i32, max: u32) -> Run {
    let mut r = Run {
        ack_while_moving: true,
        ..Run::default()
    };
    let mut in_window = 0;
    for _ in 0..max {
        let tx = exchange(d, rx);
        r.cycles += 1;
        r.peak_velocity = r.peak_velocity.max(tx.velocity_actual.abs());
        if (tx.position_actual.wrapping_sub(target)).abs() <= window {
            in_window += 1;
        } else {
            in_window = 0;
        }
        r.last = tx;
        if sw(&tx, TARGET_REACHED) {
            r.reached = true;
            r.window_run = in_window;
            break;
        }
        r.ack_while_moving &= sw(&tx, SET_POINT_ACKNOWLEDGE);
    }
    r
}

// ---------------------------------------------------------------- MR-J4-TM TV-9

/// TV-9 step 0: 6060h = 1, OE, 607Ah = 100000, 6081h = 10000, 6083h = 6084h = 100 ms, all in
/// the 1601h RxPDO of the PA01 `___2` group. The time constants refer to 10000 counts/s here,
/// so the ramps are 100 ms long.
fn tv_9_drive(unit: PositionUnit) -> (SimDrive, RxPdo) {
    let mut d = j4_profile_mode(SimDriveParams {
        position_unit: unit,
        ..params(pp_ref(10_000.0))
    });
    let base = RxPdo {
        profile_velocity: 10_000,
        profile_acceleration: 100,
        profile_deceleration: 100,
        ..pp(0x000F, 100_000)
    };
    enable_with(&mut d, base);
    assert_eq!(d.tx_pdo().mode_display, 1, "PA01 ___2 starts in pp");
    assert_eq!(d.tx_pdo().position_actual, 0);
    (d, base)
}

fn with_cw(base: RxPdo, cw: u16) -> RxPdo {
    RxPdo {
        controlword: Controlword(cw),
        ..base
    }
}

#[test]
fn tv_9_pp_single_set_point_mr_j4_tm() {
    let (mut d, base) = tv_9_drive(PositionUnit::Pulse);
    // 6068h (not in 1601h) by SDO: 50 ms, longer than the motor's settling inside the window,
    // so bit 10 shows the window time (the default is `PpParams::position_window_time_ms`).
    d.sdo_download(0x6068, 0, &50u16.to_le_bytes()).unwrap();
    // Step 1: 0x003F, absolute single set-point: bit 12 = 1, motion starts.
    let tx = exchange(&mut d, &with_cw(base, 0x003F));
    assert!(sw(&tx, SET_POINT_ACKNOWLEDGE), "bit 12 at the set-point");
    assert!(!sw(&tx, TARGET_REACHED));
    for _ in 0..20 {
        exchange(&mut d, &with_cw(base, 0x003F));
    }
    assert!(counts_per_s(&d) > 0, "motion started");
    // Step 2: bit 4 = 0; positioning continues with bit 12 = 1 (Mitsubishi's wording, §4.7).
    let r = run_until_reached(&mut d, &with_cw(base, 0x002F), 100_000, 100, 20_000);
    // Step 3: bit 10 = 1 and bit 12 = 0 once |6064h − 607Ah| ≤ 6067h for 6068h.
    assert!(r.reached, "{r:?}");
    assert!(r.ack_while_moving, "bit 12 stayed 1 while positioning");
    assert!(
        !sw(&r.last, SET_POINT_ACKNOWLEDGE),
        "bit 12 = 0 on completion"
    );
    assert!((r.last.position_actual - 100_000).abs() <= 100);
    assert!(
        r.window_run >= 50,
        "in the window for 6068h = 50 ms first: {}",
        r.window_run
    );
    // The drive's profile: 6081h caps the speed, so 100000 counts take about 10 s.
    assert!(r.peak_velocity <= 10_050, "{}", r.peak_velocity);
    assert!(r.peak_velocity >= 9_900, "{}", r.peak_velocity);
    assert!((10_000..10_450).contains(&(r.cycles + 21)), "{}", r.cycles);
    assert!(d.alarm().is_none() && d.warning().is_none());
}

#[test]
fn tv_9_relative_in_degree_raises_al_f4_8_without_motion_mr_j4_tm() {
    // Step 4: 0x007F (relative) with PT01 = degree → AL. F4.8, no motion.
    let (mut d, base) = tv_9_drive(PositionUnit::Degree);
    for _ in 0..300 {
        let tx = exchange(&mut d, &with_cw(base, 0x007F));
        assert_eq!(tx.position_actual, 0, "no motion");
        assert!(!sw(&tx, SET_POINT_ACKNOWLEDGE), "no positioning started");
    }
    assert_eq!(d.warning(), Some(mr_j4_tm::AL_F4_8));
    assert!(d.tx_pdo().statusword.warning(), "statusword bit 7");
    assert_eq!(d.state(), FsaState::OperationEnabled, "a warning, no fault");
    // An absolute set-point is still accepted and clears the warning.
    exchange(&mut d, &with_cw(base, 0x002F));
    let r = run_until_reached(&mut d, &with_cw(base, 0x003F), 100_000, 100, 20_000);
    assert!(r.reached && d.warning().is_none());
    // The same relative word in pulse units moves by 607Ah: the refusal is the degree rule.
    let (mut p, base) = tv_9_drive(PositionUnit::Pulse);
    let r = run_until_reached(&mut p, &with_cw(base, 0x007F), 100_000, 100, 20_000);
    assert!(r.reached && p.warning().is_none(), "{r:?}");
}

#[test]
fn tv_9_halt_stops_per_605dh_and_target_reached_at_zero_velocity_mr_j4_tm() {
    let (mut d, base) = tv_9_drive(PositionUnit::Pulse);
    exchange(&mut d, &with_cw(base, 0x003F));
    for _ in 0..2_000 {
        exchange(&mut d, &with_cw(base, 0x002F));
    }
    assert!((counts_per_s(&d) - 10_000).abs() < 100);
    // Step 5: 0x013F during the move: decelerate with 6084h (605Dh default, 100 ms from
    // 10000 counts/s); bit 10 = 0 while decelerating, 1 once 606Ch = 0.
    let mut stop_cycles = None;
    let mut v_at_50ms = 0;
    for k in 1..=1_000 {
        let tx = exchange(&mut d, &with_cw(base, 0x013F));
        if k == 50 {
            v_at_50ms = tx.velocity_actual;
        }
        if tx.velocity_actual != 0 {
            assert!(
                !sw(&tx, TARGET_REACHED),
                "cycle {k}: decelerating, bit 10 = 0"
            );
        } else if stop_cycles.is_none() {
            stop_cycles = Some(k);
        }
        if stop_cycles.is_some() && sw(&tx, TARGET_REACHED) {
            break;
        }
    }
    let stop = stop_cycles.expect("the axis stops");
    assert!(
        (3_000..=7_500).contains(&v_at_50ms),
        "a ramp, not a sudden stop: {v_at_50ms}"
    );
    assert!((95..400).contains(&stop), "{stop} cycles");
    let tx = *d.tx_pdo();
    assert!(sw(&tx, TARGET_REACHED) && tx.velocity_actual == 0);
    assert!(
        tx.position_actual < 100_000 - 1_000,
        "halted short of 607Ah"
    );
    // Releasing HALT resumes the positioning (CiA 402).
    let r = run_until_reached(&mut d, &with_cw(base, 0x002F), 100_000, 100, 20_000);
    assert!(r.reached, "{r:?}");
    assert!((r.last.position_actual - 100_000).abs() <= 100);
}

#[test]
fn mr_j4_tm_pa01_groups_are_exclusive() {
    // Default PA01 (cyclic group): pp is refused, 6061h stays 8.
    let mut c = drive(DriveModel::MrJ4TM, 1000, params(PpParams::default()));
    enabled(&mut c);
    let pos = c.tx_pdo().position_actual;
    for _ in 0..20 {
        assert_eq!(exchange(&mut c, &pp(0x0F, pos)).mode_display, 8);
    }
    // PA01 ___2: csp is refused; 6081h is in the RxPDO, so not writable by SDO (0601 0006h).
    let (mut d, base) = tv_9_drive(PositionUnit::Pulse);
    let tx = exchange(
        &mut d,
        &RxPdo {
            mode: 8,
            ..with_cw(base, 0x0F)
        },
    );
    assert_eq!(tx.mode_display, 1);
    assert_eq!(
        d.sdo_download(0x6081, 0, &5_000u32.to_le_bytes()),
        Err(SdoAbort::MAPPED_TO_RXPDO)
    );
    assert_eq!(d.sdo_upload(0x6081, 0), Ok(10_000), "read from the RxPDO");
}

// ---------------------------------------------------------------- pp basics, MR-J5 / MR-JET

/// Enables in csp, writes 6081h/6083h/6084h by SDO (not in the default 1600h) and switches to
/// pp at standstill. Ramps: 6083h = 200 ms, 6084h = 100 ms to 100000 counts/s.
fn pp_drive(model: DriveModel) -> SimDrive {
    let mut d = drive(model, 1000, params(pp_ref(100_000.0)));
    enabled(&mut d);
    for (index, v) in [(0x6081u16, 50_000u32), (0x6083, 200), (0x6084, 100)] {
        d.sdo_download(index, 0, &v.to_le_bytes()).unwrap();
        assert_eq!(d.sdo_upload(index, 0), Ok(i64::from(v)));
    }
    let pos = d.tx_pdo().position_actual;
    for _ in 0..10 {
        exchange(&mut d, &pp(0x0F, pos));
    }
    assert_eq!(d.tx_pdo().mode_display, 1, "{model}: pp at standstill");
    d
}

fn pp_basics(model: DriveModel) {
    let mut d = pp_drive(model);
    let p0 = d.tx_pdo().position_actual;
    // Absolute move with the SDO profile: accelerate at 500000 counts/s² to 50000 counts/s.
    let target = p0 + 200_000;
    let tx = exchange(&mut d, &pp(0x1F, target));
    assert!(sw(&tx, SET_POINT_ACKNOWLEDGE), "{model}");
    let mut v = [0i32; 120];
    for slot in v.iter_mut() {
        *slot = exchange(&mut d, &pp(0x0F, target)).velocity_actual;
    }
    // 50 ms into the ramp the profile is at 25000 counts/s (the plant lags about 11 ms).
    assert!((17_000..=26_000).contains(&v[49]), "{model}: {}", v[49]);
    assert!(v[115] > 45_000, "{model}: {}", v[115]);
    let r = run_until_reached(&mut d, &pp(0x0F, target), target, 100, 10_000);
    assert!(r.reached && r.ack_while_moving, "{model}: {r:?}");
    assert!(
        (49_000..=50_300).contains(&r.peak_velocity),
        "{model}: {r:?}"
    );
    assert!(!sw(&r.last, SET_POINT_ACKNOWLEDGE));
    assert!((r.last.position_actual - target).abs() <= 100);

    // Relative (bit 6): −50000 from the previous target.
    exchange(&mut d, &pp(0x4F, -50_000));
    let r = run_until_reached(&mut d, &pp(0x5F, -50_000), target - 50_000, 100, 10_000);
    assert!(r.reached, "{model}: {r:?}");
    assert!((r.last.position_actual - (target - 50_000)).abs() <= 100);

    // Single set-point (bit 5 = 1): a new target mid-move replaces the move at once.
    let base = d.tx_pdo().position_actual;
    let far = base + 300_000;
    let near = base + 60_000;
    exchange(&mut d, &pp(0x0F, far));
    exchange(&mut d, &pp(0x3F, far));
    for _ in 0..500 {
        exchange(&mut d, &pp(0x2F, far));
    }
    exchange(&mut d, &pp(0x3F, near));
    let r = run_until_reached(&mut d, &pp(0x2F, near), near, 100, 10_000);
    assert!(r.reached, "{model}: {r:?}");
    assert!((r.last.position_actual - near).abs() <= 100, "{model}");

    // Set of set-points (bit 5 = 0): the next move waits for the current one to finish.
    let a = near + 30_000;
    let b = near + 60_000;
    exchange(&mut d, &pp(0x0F, a));
    exchange(&mut d, &pp(0x1F, a));
    for _ in 0..100 {
        exchange(&mut d, &pp(0x0F, a));
    }
    exchange(&mut d, &pp(0x1F, b));
    // Near the first set-point the speed drops far below 6081h (a queued move starts from
    // standstill); an immediate change would pass it at 50000 counts/s.
    let mut slowest_near_a = i32::MAX;
    for _ in 0..10_000 {
        let tx = exchange(&mut d, &pp(0x0F, b));
        if (tx.position_actual - a).abs() <= 3_000 {
            slowest_near_a = slowest_near_a.min(tx.velocity_actual.abs());
        }
        if sw(&tx, TARGET_REACHED) {
            break;
        }
    }
    assert!(
        slowest_near_a < 10_000,
        "{model}: stopped at the first set-point: {slowest_near_a}"
    );
    assert!((d.tx_pdo().position_actual - b).abs() <= 100, "{model}");
    assert!(d.alarm().is_none(), "{model}");
}

#[test]
fn pp_basics_mr_j5_g_n1() {
    pp_basics(DriveModel::MrJ5GN1);
    pp_basics(DriveModel::MrJ5W2GN1);
}

#[test]
fn pp_basics_mr_jet_g_n1() {
    pp_basics(DriveModel::MrJetGN1);
}

#[test]
fn pp_set_point_needs_the_edge_after_the_mode_switch() {
    // OMS bits are ignored until the switch has finished: bit 4 already 1 is not an edge.
    let mut d = drive(DriveModel::MrJ5GN1, 1000, params(PpParams::default()));
    enabled(&mut d);
    let p0 = d.tx_pdo().position_actual;
    for _ in 0..200 {
        exchange(&mut d, &pp(0x1F, p0 + 50_000));
    }
    assert_eq!(d.tx_pdo().mode_display, 1);
    assert_eq!(d.tx_pdo().position_actual, p0, "no set-point taken");
    exchange(&mut d, &pp(0x0F, p0 + 50_000));
    let r = run_until_reached(&mut d, &pp(0x1F, p0 + 50_000), p0 + 50_000, 100, 20_000);
    assert!(r.reached, "{r:?}");
}

// ---------------------------------------------------------------- entering csp (master side)

/// A J5/JET in pp that has finished a move to `p0 + 100000`; returns the drive and that target.
fn after_pp_move(model: DriveModel) -> (SimDrive, i32) {
    let mut d = pp_drive(model);
    let target = d.tx_pdo().position_actual + 100_000;
    exchange(&mut d, &pp(0x1F, target));
    let r = run_until_reached(&mut d, &pp(0x0F, target), target, 100, 10_000);
    assert!(r.reached, "{r:?}");
    for _ in 0..200 {
        exchange(&mut d, &pp(0x0F, target));
    }
    assert_eq!(counts_per_s(&d), 0);
    (d, target)
}

/// One cycle of the master: the old mode's (pp) commands, then the mode-switch override.
struct SwitchLog {
    /// (6060h sent, 607Ah sent, 6064h, 6061h after the exchange) per cycle.
    cycles: Vec<(i8, i32, i32, i8)>,
    csp_target: Option<i32>,
    start_position: i32,
}

fn switch_to_csp(d: &mut SimDrive, pp_target: i32, offset: i32) -> SwitchLog {
    let params = ModeSwitchParams {
        timeout: Cycles(5_000),
        zero_speed: ZERO_SPEED as u32,
    };
    let mut s = ModeSwitch::for_profile(
        d.profile(),
        ModeOfOperation::CyclicSyncPosition,
        offset,
        params,
    )
    .unwrap();
    let mut log = SwitchLog {
        cycles: Vec::new(),
        csp_target: None,
        start_position: d.tx_pdo().position_actual,
    };
    for _ in 0..6_000 {
        // The gate in counts/s like the rest of these pp tests (`exchange`).
        let mut tx = *d.tx_pdo();
        tx.velocity_actual = counts_per_s(d);
        let mut rx = pp(0x0F, pp_target);
        match s.update(&tx, &mut rx).unwrap() {
            ModeSwitchProgress::Done { csp_target } => {
                log.csp_target = csp_target;
                return log;
            }
            ModeSwitchProgress::Pending(_) => {}
        }
        let after = exchange(d, &rx);
        log.cycles.push((
            rx.mode,
            rx.target_position,
            tx.position_actual,
            after.mode_display,
        ));
    }
    panic!("no Done: {:?}", log.cycles);
}

/// The rule ordering and the 6061h transition in `log`.
fn check_ordering(log: &SwitchLog, offset: i32) {
    let first8 = log
        .cycles
        .iter()
        .position(|c| c.0 == 8)
        .expect("6060h = 8 sent");
    assert!(first8 >= 1, "607Ah is set a cycle before 6060h = 8");
    let (mode, target, pos, _) = log.cycles[first8 - 1];
    assert_eq!(mode, 1, "the cycle before still sends pp");
    assert_eq!(
        target,
        pos - offset,
        "607Ah = 6064h − 60B0h before 6060h = 8"
    );
    for &(m, t, p, _) in &log.cycles[first8..] {
        assert_eq!(m, 8);
        assert_eq!(t, p - offset);
    }
    let displays: Vec<i8> = log.cycles.iter().map(|c| c.3).collect();
    let switch = displays.iter().position(|&m| m == 8).expect("6061h = 8");
    assert!(switch >= first8, "6061h follows the request");
    assert!(displays[..switch].iter().all(|&m| m == 1), "{displays:?}");
    assert!(displays[switch..].iter().all(|&m| m == 8), "{displays:?}");
}

/// Holds csp at `target` for 300 cycles; returns the largest |6064h − start|.
fn hold_csp(d: &mut SimDrive, target: i32, start: i32) -> i32 {
    let mut worst = 0;
    for _ in 0..300 {
        let tx = exchange(
            d,
            &RxPdo {
                mode: 8,
                controlword: Controlword(0x0F),
                target_position: target,
                ..RxPdo::default()
            },
        );
        worst = worst.max((tx.position_actual - start).abs());
    }
    worst
}

#[test]
fn tv_10_entering_csp_mr_j5_g_n1() {
    let offset: i32 = 3_000;
    let (mut d, pp_target) = after_pp_move(DriveModel::MrJ5GN1);
    d.sdo_download(0x60B0, 0, &offset.to_le_bytes()).unwrap();
    let log = switch_to_csp(&mut d, pp_target, offset);
    check_ordering(&log, offset);
    let start = log.start_position;
    let handed = log.csp_target.unwrap();
    assert!((handed - (d.tx_pdo().position_actual - offset)).abs() <= 1);
    let worst = hold_csp(&mut d, handed, start);
    assert!(worst <= 2, "no jump entering csp: {worst} counts");
    assert!(d.alarm().is_none());
    assert_eq!(d.tx_pdo().mode_display, 8);

    // The rule matters: a master that sends 607Ah = 6064h (60B0h ignored) moves the motor by
    // 60B0h on entering csp.
    let (mut n, _) = after_pp_move(DriveModel::MrJ5GN1);
    n.sdo_download(0x60B0, 0, &offset.to_le_bytes()).unwrap();
    let start = n.tx_pdo().position_actual;
    let worst = hold_csp(&mut n, start, start);
    assert!(worst >= offset - 10, "naive switch jumps: {worst}");
}

#[test]
fn tv_7_entering_csp_from_pp_mr_jet_g_n1() {
    let (mut d, pp_target) = after_pp_move(DriveModel::MrJetGN1);
    // 60B0h = 0 and 607Ah = P (the TV's reading of "update 607Ah and 60B0h to 6064h").
    d.sdo_download(0x60B0, 0, &0i32.to_le_bytes()).unwrap();
    let p = d.tx_pdo().position_actual;
    let log = switch_to_csp(&mut d, pp_target, 0);
    check_ordering(&log, 0);
    assert_eq!(log.csp_target, Some(p));
    // The pp values (6060h = 1, its 607Ah) were kept until the Prepare cycle.
    assert_eq!(log.cycles[0].0, 1);
    let worst = hold_csp(&mut d, p, p);
    assert!(worst <= 2, "no jump: {worst}");
    assert!(d.alarm().is_none());
}

#[test]
fn mode_switch_waits_for_the_zero_speed_gate() {
    // Requested during a pp move: 6060h stays 1 until |606Ch| ≤ zero speed, then csp without
    // a jump at the final position.
    let mut d = pp_drive(DriveModel::MrJ5GN1);
    let target = d.tx_pdo().position_actual + 100_000;
    exchange(&mut d, &pp(0x1F, target));
    for _ in 0..300 {
        exchange(&mut d, &pp(0x0F, target));
    }
    assert!(counts_per_s(&d) > 40_000);
    let log = switch_to_csp(&mut d, target, 0);
    let waited = log.cycles.iter().take_while(|c| c.0 == 1).count();
    assert!(waited > 500, "waited for the move to end: {waited}");
    for &(m, _, p, _) in &log.cycles {
        if m == 8 {
            assert!(
                (p - target).abs() <= 100,
                "requested only at the target: {p}"
            );
        }
    }
    check_ordering(&log, 0);
    let start = d.tx_pdo().position_actual;
    assert!(hold_csp(&mut d, log.csp_target.unwrap(), start) <= 2);
}

#[test]
fn mode_switch_times_out_when_the_drive_gates_and_reports_bad_input() {
    // The master's zero speed above the drive's: it requests while moving, the drive keeps
    // 6061h = 1, the switch fails after the timeout and withdraws the request.
    let mut d = pp_drive(DriveModel::MrJetGN1);
    let target = d.tx_pdo().position_actual + 1_000_000;
    exchange(&mut d, &pp(0x1F, target));
    for _ in 0..300 {
        exchange(&mut d, &pp(0x0F, target));
    }
    let mut s = ModeSwitch::new(
        ModeOfOperation::CyclicSyncPosition,
        0,
        ModeSwitchParams {
            timeout: Cycles(50),
            zero_speed: 1_000_000,
        },
    )
    .unwrap();
    let mut err = None;
    for _ in 0..100 {
        let tx = *d.tx_pdo();
        let mut rx = pp(0x0F, target);
        match s.update(&tx, &mut rx) {
            Ok(_) => {
                exchange(&mut d, &rx);
            }
            Err(e) => {
                assert_eq!(rx.mode, 1, "request withdrawn");
                err = Some(e);
                break;
            }
        }
    }
    match err {
        Some(ModeSwitchError::Timeout { display, phase, .. }) => {
            assert_eq!(display, 1);
            assert_eq!(phase, ModeSwitchPhase::Requested);
        }
        e => panic!("{e:?}"),
    }
    assert_eq!(d.tx_pdo().mode_display, 1, "the drive's gate held");

    // Unsupported mode: a clear error, no switch object.
    let w2 = cellrt_cia402::profile(DriveModel::MrJ5W2GN1);
    let e = ModeSwitch::for_profile(
        w2,
        ModeOfOperation::ProfileVelocity,
        0,
        ModeSwitchParams::default(),
    )
    .unwrap_err();
    assert_eq!(
        e,
        ModeSwitchError::Unsupported {
            to: ModeOfOperation::ProfileVelocity
        }
    );
    assert!(e.to_string().contains("pv"), "{e}");

    // A fault during the switch ends it at once.
    let (mut f, t) = after_pp_move(DriveModel::MrJ5GN1);
    let mut s = ModeSwitch::new(
        ModeOfOperation::CyclicSyncPosition,
        0,
        ModeSwitchParams::default(),
    )
    .unwrap();
    f.inject_alarm(0x0123);
    for _ in 0..5 {
        exchange(&mut f, &pp(0x0F, t));
    }
    let mut rx = pp(0x0F, t);
    assert_eq!(
        s.update(&{ *f.tx_pdo() }, &mut rx),
        Err(ModeSwitchError::Fault {
            to: ModeOfOperation::CyclicSyncPosition
        })
    );
}

#[test]
fn pp_and_the_mode_switch_are_allocation_free() {
    let (mut d, pp_target) = after_pp_move(DriveModel::MrJ5GN1);
    d.sdo_download(0x60B0, 0, &1_000i32.to_le_bytes()).unwrap();
    let (mut j4, base) = tv_9_drive(PositionUnit::Degree);
    let mut s = ModeSwitch::new(
        ModeOfOperation::CyclicSyncPosition,
        1_000,
        ModeSwitchParams::default(),
    )
    .unwrap();
    let before = thread_heap_calls();
    // A pp move with HALT and the refused relative word on the MR-J4-TM...
    exchange(&mut j4, &with_cw(base, 0x003F));
    for k in 0..3_000 {
        let cw = match k {
            1_000..=1_500 => 0x012F,
            2_000 => 0x007F,
            _ => 0x002F,
        };
        exchange(&mut j4, &with_cw(base, cw));
    }
    // ...and the switch into csp on the MR-J5.
    let mut done = false;
    for _ in 0..100 {
        let tx = *d.tx_pdo();
        let mut rx = pp(0x0F, pp_target);
        if let ModeSwitchProgress::Done { .. } = s.update(&tx, &mut rx).unwrap() {
            done = true;
            break;
        }
        exchange(&mut d, &rx);
    }
    assert_eq!(thread_heap_calls() - before, 0);
    assert!(done);
    assert_eq!(j4.warning(), Some(mr_j4_tm::AL_F4_8));
}
