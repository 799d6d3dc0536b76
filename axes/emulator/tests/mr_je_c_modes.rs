//! The simulated MR-JE-C's motor in hm, jg, tq, pt and idx, driven through object writes as a
//! client drives it (MR-JE-C manual §7.3, §7.5.9, §7.6.2–§7.6.4): 6060h, 6040h 06h/07h/0Fh,
//! the mode's objects, then ticks of the virtual clock.

use std::time::Duration;

use cellrt_cia402::fsa::FsaState;
use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams, Refusal};
use cellrt_fieldbus::mr_je_c::{ObjectId, SoftwareVersion, Value};

fn id(index: u16) -> ObjectId {
    ObjectId::new(index, 0)
}

fn ms(v: u64) -> Duration {
    Duration::from_millis(v)
}

fn cw(d: &mut MrJeC, word: u16, now: Duration) {
    d.write(id(0x6040), &Value::U16(word), now).unwrap();
}

/// 6060h = `mode`, then 06h, 07h, 0Fh.
fn enabled_in(mode: i8) -> MrJeC {
    let mut d = MrJeC::new(MrJeCParams::default());
    d.write(id(0x6060), &Value::I8(mode), Duration::ZERO)
        .unwrap();
    for word in [0x0006, 0x0007, 0x000F] {
        cw(&mut d, word, Duration::ZERO);
    }
    d
}

fn int(d: &MrJeC, o: ObjectId) -> i64 {
    d.read(o).unwrap().as_i64().unwrap()
}

fn status(d: &MrJeC) -> i64 {
    int(d, id(0x6041))
}

#[test]
fn hm_method_37_sets_home_where_the_motor_stands() {
    let mut d = enabled_in(1);
    d.write(id(0x607A), &Value::I32(131_072), ms(0)).unwrap();
    d.write(id(0x6081), &Value::U32(60_000), ms(0)).unwrap();
    cw(&mut d, 0x1F, ms(0));
    d.tick(ms(1000));
    assert_eq!(int(&d, id(0x6064)), 131_072);
    assert_eq!(
        int(&d, id(0x2D12)) & (1 << 15),
        0,
        "S_ZP2 off before homing"
    );
    d.write(id(0x6060), &Value::I8(6), ms(1000)).unwrap();
    assert_eq!(int(&d, id(0x6098)), 37, "the default method");
    cw(&mut d, 0x0F, ms(1000));
    assert_eq!(status(&d) & 0x3400, 1 << 10, "homing not started");
    cw(&mut d, 0x1F, ms(1001));
    assert_eq!(
        int(&d, id(0x6064)),
        0,
        "6064h reads the home position 607Ch"
    );
    assert_eq!(
        status(&d) & 0x3400,
        (1 << 12) | (1 << 10),
        "homing attained"
    );
    assert_eq!(int(&d, id(0x2D15)) & (1 << 7), 1 << 7, "S_ZP");
    assert_eq!(int(&d, id(0x2D12)) & (1 << 15), 1 << 15, "S_ZP2");
    cw(&mut d, 0x07, ms(1002));
    assert_eq!(int(&d, id(0x2D15)) & (1 << 7), 0, "S_ZP off at servo-off");
    assert_eq!(int(&d, id(0x2D12)) & (1 << 15), 1 << 15, "S_ZP2 kept");
}

#[test]
fn hm_method_range_list_and_methods_not_emulated() {
    let mut d = enabled_in(6);
    assert_eq!(
        d.write(id(0x6098), &Value::I8(40), ms(0)),
        Err(Refusal::AboveRange)
    );
    assert_eq!(
        d.write(id(0x6098), &Value::I8(-44), ms(0)),
        Err(Refusal::BelowRange)
    );
    assert_eq!(int(&d, ObjectId::new(0x60E3, 0)), 40);
    assert_eq!(int(&d, ObjectId::new(0x60E3, 1)), 37);
    let a3 = MrJeC::new(MrJeCParams {
        software: SoftwareVersion::A3,
        ..Default::default()
    });
    assert_eq!(int(&a3, ObjectId::new(0x60E3, 0)), 39);
    d.write(id(0x6098), &Value::I8(-43), ms(0)).unwrap();
    cw(&mut d, 0x1F, ms(1));
    assert_eq!(status(&d) & 0x3400, (1 << 13) | (1 << 10), "homing error");
    assert_eq!(int(&d, id(0x2D12)) & (1 << 15), 0);
}

#[test]
fn jg_runs_at_6081h_while_bit_4_is_on_a4_only() {
    let mut d = enabled_in(-100);
    assert_eq!(int(&d, id(0x6061)), -100);
    d.write(id(0x6081), &Value::U32(120_000), ms(0)).unwrap();
    d.write(id(0x6083), &Value::U32(100), ms(0)).unwrap();
    d.write(id(0x6084), &Value::U32(100), ms(0)).unwrap();
    cw(&mut d, 0x1F, ms(0));
    d.tick(ms(20));
    assert_eq!(int(&d, id(0x606C)), 60_000, "100 ms to 3000 r/min");
    d.tick(ms(100));
    assert_eq!(int(&d, id(0x606C)), 120_000);
    assert_eq!(status(&d) & (1 << 10), 0);
    cw(&mut d, 0x0F, ms(100));
    d.tick(ms(140));
    assert_eq!(int(&d, id(0x606C)), 0);
    // Target reached once the Position window time 6068h (10 ms) has passed.
    assert_eq!(status(&d) & (1 << 10), 0);
    d.tick(ms(150));
    assert_eq!(status(&d) & (1 << 10), 1 << 10);
    assert!(int(&d, id(0x6064)) > 0);

    let mut a3 = MrJeC::new(MrJeCParams {
        software: SoftwareVersion::A3,
        ..Default::default()
    });
    a3.write(id(0x6060), &Value::I8(-100), ms(0)).unwrap();
    assert_eq!(int(&a3, id(0x6061)), -20, "jg needs SW A4");
}

#[test]
fn tq_torque_follows_6071h_with_6087h_and_2d20h_limits_the_speed() {
    let mut d = enabled_in(4);
    d.write(id(0x6087), &Value::U32(10_000), ms(0)).unwrap();
    d.write(id(0x6071), &Value::I16(-1000), ms(0)).unwrap();
    d.tick(ms(50));
    assert_eq!(int(&d, id(0x6074)), -500, "1000.0 %/s for 50 ms");
    d.tick(ms(300));
    assert_eq!(int(&d, id(0x6074)), -1000);
    assert_eq!(
        int(&d, id(0x606C)),
        -50_000,
        "the 2D20h default 500.00 r/min"
    );
    assert_eq!(
        int(&d, id(0x6077)),
        -30,
        "the plant's friction holds the speed"
    );
    d.write(id(0x60E1), &Value::U16(200), ms(300)).unwrap();
    d.tick(ms(400));
    assert_eq!(
        int(&d, id(0x6074)),
        -200,
        "60E1h limits the negative torque"
    );
    cw(&mut d, 0x0002, ms(400));
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
    assert_eq!(int(&d, id(0x606C)), 0, "dynamic brake");
    assert_eq!(int(&d, id(0x6074)), 0);
}

#[test]
fn pt_runs_the_table_2d60h_selects_and_reports_it() {
    let mut d = enabled_in(-101);
    let table = |sub| ObjectId::new(0x2807, sub);
    d.write(table(1), &Value::I32(262_144), ms(0)).unwrap();
    d.write(table(2), &Value::I32(120_000), ms(0)).unwrap();
    d.write(table(3), &Value::I32(50), ms(0)).unwrap();
    d.write(table(4), &Value::I32(50), ms(0)).unwrap();
    d.write(table(7), &Value::I32(0x63), ms(0)).unwrap();
    d.write(id(0x2D60), &Value::I16(7), ms(0)).unwrap();
    assert_eq!(int(&d, id(0x2D68)), 7, "2D60h while stopped");
    cw(&mut d, 0x1F, ms(0));
    d.tick(ms(10));
    assert_eq!(int(&d, id(0x606C)), 60_000, "50 ms to 3000 r/min");
    assert_eq!(int(&d, id(0x2D68)), 7);
    assert_eq!(int(&d, id(0x2D69)), 0);
    d.tick(ms(1000));
    assert_eq!(int(&d, id(0x6064)), 262_144);
    assert_eq!(int(&d, id(0x2D69)), 7);
    assert_eq!(int(&d, id(0x2D6A)), 0x63);
    d.tick(ms(1010));
    assert_eq!(status(&d) & (1 << 10), 1 << 10, "after 6068h");

    // 2DD1h: speed, acceleration and deceleration from table 2 (1 ms to 3000 r/min).
    let two = |sub| ObjectId::new(0x2802, sub);
    d.write(two(2), &Value::I32(30_000), ms(1010)).unwrap();
    d.write(two(3), &Value::I32(1), ms(1010)).unwrap();
    d.write(two(4), &Value::I32(1), ms(1010)).unwrap();
    d.write(id(0x2DD1), &Value::I16(2), ms(1010)).unwrap();
    d.write(table(1), &Value::I32(0), ms(1010)).unwrap();
    cw(&mut d, 0x0F, ms(1010));
    cw(&mut d, 0x1F, ms(1010));
    d.tick(ms(1020));
    assert_eq!(int(&d, id(0x606C)), -30_000);
}

#[test]
fn idx_turns_to_the_station_2d60h_names_in_pt28_stations() {
    let mut d = enabled_in(1);
    d.write(id(0x607A), &Value::I32(262_144), ms(0)).unwrap();
    cw(&mut d, 0x1F, ms(0));
    d.tick(ms(2000));
    assert_eq!(int(&d, id(0x6064)), 262_144, "two revolutions");
    d.write(ObjectId::new(0x249C, 0), &Value::U32(4), ms(2000))
        .unwrap();
    d.write(id(0x6060), &Value::I8(-103), ms(2000)).unwrap();
    assert_eq!(
        int(&d, ObjectId::new(0x6092, 1)),
        4,
        "6092h:1 is PT28 in idx"
    );
    assert_eq!(
        int(&d, id(0x6064)),
        0,
        "8 stations from the start reads station 0"
    );
    d.write(id(0x6081), &Value::U32(60_000), ms(2000)).unwrap();
    d.write(id(0x2D60), &Value::I16(3), ms(2000)).unwrap();
    cw(&mut d, 0x0F, ms(2000));
    cw(&mut d, 0x11F, ms(2000));
    d.tick(ms(2010));
    assert_eq!(
        int(&d, id(0x606C)),
        -60_000,
        "0 → 3 of 4 goes backwards; halt is disabled"
    );
    assert_eq!(int(&d, id(0x2D68)), 3);
    d.tick(ms(2500));
    assert_eq!(int(&d, id(0x6064)), 3);
    assert_eq!(int(&d, id(0x2D69)), 3);
    assert_eq!(int(&d, id(0x2D6A)), 0);
    d.tick(ms(2510));
    assert_eq!(status(&d) & (1 << 10), 1 << 10, "after 6068h");
}

/// Quick stop, option code 2 (§7.6.2, §7.3 6085h): from 1500 r/min with 6085h = 200 ms (a time
/// constant from the rated 3000 r/min) the motor decelerates for 100 ms, covering 1.25
/// revolutions, in Quick stop active, then Switch on disabled; 6085h = 0 runs at 100 ms.
#[test]
fn quick_stop_decelerates_with_6085h_then_switch_on_disabled() {
    for (qs_ms, stop_ms) in [(200u32, 100u64), (0, 50)] {
        let mut d = enabled_in(3);
        d.write(id(0x6085), &Value::U32(qs_ms), ms(0)).unwrap();
        d.write(id(0x6083), &Value::U32(0), ms(0)).unwrap();
        d.write(id(0x60FF), &Value::I32(150_000), ms(0)).unwrap();
        d.tick(ms(10));
        assert_eq!(int(&d, id(0x606C)), 150_000);
        let from = int(&d, id(0x6064));
        cw(&mut d, 0x0002, ms(10));
        assert_eq!(d.state(), FsaState::QuickStopActive);
        for t in 1..=stop_ms / 2 {
            d.tick(ms(10 + t));
        }
        assert_eq!(d.state(), FsaState::QuickStopActive, "6085h = {qs_ms}");
        assert_eq!(int(&d, id(0x606C)), 75_000, "half way down");
        for t in 1..=stop_ms + 1 {
            d.tick(ms(10 + stop_ms / 2 + t));
        }
        assert_eq!(d.state(), FsaState::SwitchOnDisabled, "6085h = {qs_ms}");
        assert_eq!(int(&d, id(0x606C)), 0);
        // 25 rev/s ramped to 0 over the stop: half of 25 × stop revolutions (less half a 1 ms
        // step's worth of the ramp: the motor model steps at its end velocity).
        let travel = (int(&d, id(0x6064)) - from) as f64 / 131_072.0;
        let expect = 25.0 * stop_ms as f64 / 1000.0 / 2.0;
        assert!(
            (travel - expect).abs() < 0.02,
            "{travel} rev, 6085h = {qs_ms}"
        );
    }
}

/// Ticks of 1 ms from `from` to `to` ms; `f` after each.
fn each_ms(d: &mut MrJeC, from: u64, to: u64, mut f: impl FnMut(&MrJeC, u64)) {
    for t in from..=to {
        d.tick(ms(t));
        f(d, t);
    }
}

/// 6081h 600 r/min, 6083h/6084h 100 ms (from and to 3000 r/min).
fn at_600_rpm(d: &mut MrJeC) {
    d.write(id(0x6081), &Value::U32(60_000), ms(0)).unwrap();
    d.write(id(0x6083), &Value::U32(100), ms(0)).unwrap();
    d.write(id(0x6084), &Value::U32(100), ms(0)).unwrap();
}

/// A pp move to `target` at 600 r/min, started at 0 ms.
fn start_pp(d: &mut MrJeC, target: i32) {
    d.write(id(0x607A), &Value::I32(target), ms(0)).unwrap();
    at_600_rpm(d);
    cw(d, 0x1F, ms(0));
    cw(d, 0x0F, ms(0));
}

/// The motor model's droop (MR-JE-C manual §7.3 60F4h, 2B03h) with the default position loop
/// gain Kp = 1000 rad/s: jg at 600 r/min with 6092h:1 = 10000 pos units per revolution runs
/// the command at 10 rev/s × 10000 = 100000 pos units/s, so the droop settles at
/// 100000 / 1000 = 100 pos units (60F4h), 100 × 131072 / 10000 = 1310.72 ≈ 1311 encoder pulses
/// (2B03h). 60F4h over Modbus/TCP object access as well (low word first). Once the jog has
/// stopped the droop decays and Target reached comes.
#[test]
fn jg_droop_at_a_constant_speed_is_the_speed_over_the_loop_gain() {
    use cellrt_emulator::mr_je_c::modbus;
    use cellrt_fieldbus::modbus::{Query, Reply, WordOrder};
    let mut d = enabled_in(-100);
    d.write(ObjectId::new(0x6092, 1), &Value::U32(10_000), ms(0))
        .unwrap();
    at_600_rpm(&mut d);
    cw(&mut d, 0x1F, ms(0));
    each_ms(&mut d, 1, 100, |_, _| {});
    assert_eq!(int(&d, id(0x606C)), 60_000);
    assert_eq!(int(&d, id(0x60F4)), 100);
    assert_eq!(int(&d, id(0x2B03)), 1311);
    let mut out = Vec::new();
    let query = Query::Read {
        address: 0x60F4,
        registers: 2,
    };
    let reply = modbus::answer(&mut d, &query, WordOrder::LowFirst, ms(100), &mut out);
    assert_eq!(reply, Reply::Read(&[0x00, 0x64, 0x00, 0x00]));
    cw(&mut d, 0x0F, ms(100));
    each_ms(&mut d, 101, 150, |_, _| {});
    assert_eq!((int(&d, id(0x60F4)), int(&d, id(0x2B03))), (0, 0));
    assert_eq!(status(&d) & (1 << 10), 1 << 10);
}

/// A pp move of 3 revolutions at 600 r/min (10 rev/s × 131072 = 1310720 pos units/s: a
/// steady droop of 1310.72 with Kp = 1000 rad/s), each ms: when 60F4h is first over 1000 and
/// when Statusword bit 13 first comes on (§7.3 6065h: on once the droop has been over 6065h for
/// 6066h), with 6065h = `window`.
fn following_error_times(window: Option<u32>) -> (Option<u64>, Option<u64>, u16) {
    let mut d = enabled_in(1);
    if let Some(w) = window {
        d.write(id(0x6065), &Value::U32(w), ms(0)).unwrap();
    }
    d.write(id(0x6066), &Value::U16(10), ms(0)).unwrap();
    start_pp(&mut d, 3 * 131_072);
    let (mut over, mut bit13) = (None, None);
    each_ms(&mut d, 1, 500, |d, t| {
        if over.is_none() && int(d, id(0x60F4)) > 1000 {
            over = Some(t);
        }
        if bit13.is_none() && status(d) & (1 << 13) != 0 {
            bit13 = Some(t);
        }
    });
    (over, bit13, status(&d) as u16)
}

#[test]
fn bit_13_after_the_droop_exceeds_6065h_for_6066h() {
    let (over, bit13, end) = following_error_times(Some(1000));
    let over = over.expect("the droop passes 1000 while accelerating");
    assert_eq!(
        bit13,
        Some(over + 10),
        "6066h = 10 ms after the droop passed 1000"
    );
    assert_eq!(
        end & 0x2400,
        1 << 10,
        "bit 13 off again once the move has ended"
    );
    let (over, bit13, end) = following_error_times(None);
    assert!(over.is_some());
    assert_eq!(
        bit13, None,
        "the default 6065h (12582912) is never exceeded"
    );
    assert_eq!(end & 0x2400, 1 << 10);
    let (_, bit13, _) = following_error_times(Some(u32::MAX));
    assert_eq!(bit13, None, "6065h = 4294967295: always off");
}

/// [Pr. PC03] (2103h) from the parameter store: a pp move of one revolution reaches its target
/// PC03 = 200 ms later than the trapezoid (within one tick of 1 ms).
#[test]
fn pc03_delays_target_reached_by_its_time() {
    let reached_at = |pc03: u32| {
        let mut d = enabled_in(1);
        d.write(id(0x2103), &Value::U32(pc03), ms(0)).unwrap();
        start_pp(&mut d, 131_072);
        let mut at = None;
        each_ms(&mut d, 1, 1000, |d, t| {
            if at.is_none() && status(d) & (1 << 10) != 0 {
                at = Some(t);
            }
        });
        assert_eq!(int(&d, id(0x6064)), 131_072);
        at.expect("reached")
    };
    let (trapezoid, s) = (reached_at(0), reached_at(200));
    assert!(
        (199..=201).contains(&(s - trapezoid)),
        "{trapezoid} ms, {s} ms"
    );
    // 5000 ms is the top of the setting range: a larger value is refused, not run at 5000.
    let mut d = enabled_in(1);
    assert!(d.write(id(0x2103), &Value::U32(5000), ms(0)).is_ok());
    assert!(d.write(id(0x2103), &Value::U32(5001), ms(0)).is_err());
    assert_eq!(int(&d, id(0x2103)), 5000);
}

/// OV-19 (§7.3 2B01h): the cumulative feedback pulses count the encoder (131 072 pulses a
/// revolution), homing leaves them alone, 00001EA5h clears them and another value is refused.
#[test]
fn ov_19_cumulative_feedback_pulses_count_and_clear() {
    let mut d = enabled_in(1);
    d.write(id(0x607A), &Value::I32(131_072), ms(0)).unwrap();
    d.write(id(0x6081), &Value::U32(60_000), ms(0)).unwrap();
    cw(&mut d, 0x1F, ms(0));
    d.tick(ms(1000));
    assert_eq!(int(&d, id(0x2B01)), 131_072);
    // Home where the motor stands (method 37): 6064h reads 0, the encoder's count stays.
    d.write(id(0x6060), &Value::I8(6), ms(1000)).unwrap();
    cw(&mut d, 0x0F, ms(1000));
    cw(&mut d, 0x1F, ms(1001));
    assert_eq!(int(&d, id(0x6064)), 0);
    assert_eq!(int(&d, id(0x2B01)), 131_072);
    assert_eq!(
        d.write(id(0x2B01), &Value::I32(5), ms(1002)),
        Err(Refusal::OutOfRange)
    );
    assert_eq!(int(&d, id(0x2B01)), 131_072);
    d.write(id(0x2B01), &Value::I32(0x1EA5), ms(1002)).unwrap();
    assert_eq!(int(&d, id(0x2B01)), 0);
    // Half a revolution back in pp: −65 536 since the clear.
    d.write(id(0x6060), &Value::I8(1), ms(1003)).unwrap();
    d.write(id(0x607A), &Value::I32(-65_536), ms(1003)).unwrap();
    cw(&mut d, 0x0F, ms(1003));
    cw(&mut d, 0x1F, ms(1004));
    d.tick(ms(3000));
    assert_eq!(int(&d, id(0x6064)), -65_536);
    assert_eq!(int(&d, id(0x2B01)), -65_536);
}

/// The jog of `d` (jg, 6081h = 600 r/min) started at `t` ms.
fn jog(d: &mut MrJeC, t: u64) {
    d.write(id(0x6081), &Value::U32(60_000), ms(t)).unwrap();
    cw(d, 0x1F, ms(t));
}

/// OV-20 (§6.2): 2D50h ← 1 starts the one-touch tuning; 2D51h climbs while the motor runs and
/// reads 100 at the end, 2D50h returns to 0 and 2D54h reads 0000h (finished normally). The
/// emulator's tuning takes `one_touch_tuning_time` (5 s) of motion.
#[test]
fn ov_20_one_touch_tuning_runs_while_the_motor_moves_and_returns_to_0() {
    let mut d = enabled_in(-100);
    jog(&mut d, 0);
    d.tick(ms(500));
    d.write(id(0x2D50), &Value::U8(1), ms(500)).unwrap();
    assert_eq!(int(&d, id(0x2D50)), 1, "running");
    d.tick(ms(3000));
    let half = int(&d, id(0x2D51));
    assert_eq!(half, 50, "2.5 s of 5 s");
    assert_eq!(int(&d, id(0x2D50)), 1);
    d.tick(ms(5499));
    assert_eq!(int(&d, id(0x2D51)), 99);
    d.tick(ms(5500));
    assert_eq!(int(&d, id(0x2D51)), 100);
    assert_eq!(int(&d, id(0x2D50)), 0, "auto-returns to 0");
    assert_eq!(int(&d, id(0x2D54)), 0x0000, "finished normally");
}

/// §6.2's error codes: 2D52h = 1EA5h cancels (C000h), the servo going off ends it (C002h), a
/// start in tq is a control mode error (C003h); each reads 100 % and 2D50h = 0. A standing motor
/// does not advance the tuning.
#[test]
fn one_touch_tuning_stop_servo_off_and_control_mode_errors() {
    let mut d = enabled_in(-100);
    d.write(id(0x2D50), &Value::U8(2), ms(0)).unwrap();
    d.tick(ms(2000));
    assert_eq!(int(&d, id(0x2D51)), 0, "no motion, no progress");
    d.write(id(0x2D52), &Value::I16(0x1EA5), ms(2000)).unwrap();
    let ended = |d: &MrJeC| {
        (
            int(d, id(0x2D50)),
            int(d, id(0x2D51)),
            int(d, id(0x2D54)) as u16,
        )
    };
    assert_eq!(ended(&d), (0, 100, 0xC000));
    d.write(id(0x2D50), &Value::U8(3), ms(2000)).unwrap();
    cw(&mut d, 0x07, ms(2001));
    d.tick(ms(2002));
    assert_eq!(ended(&d), (0, 100, 0xC002));
    let mut tq = enabled_in(4);
    tq.write(id(0x2D50), &Value::U8(1), ms(0)).unwrap();
    assert_eq!(ended(&tq), (0, 100, 0xC003));
}
