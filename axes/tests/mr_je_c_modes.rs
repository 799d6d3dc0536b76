//! The simulated MR-JE-C's motor in hm, jg, tq, pt and idx, driven through object writes as a
//! client drives it (MR-JE-C manual §7.3, §7.5.9, §7.6.2–§7.6.4): 6060h, 6040h 06h/07h/0Fh,
//! the mode's objects, then ticks of the virtual clock.

use std::time::Duration;

use cellrt_axes::cia402::fsa::FsaState;
use cellrt_axes::mr_je_c::emulator::{MrJeC, MrJeCParams, Refusal};
use cellrt_axes::mr_je_c::{ObjectId, SoftwareVersion, Value};

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
