//! The simulated MR-JE-C (`cellrt_emulator::mr_je_c`) against the MR-JE-C manual: the FSA with
//! quick-stop option code 2, access rights and ranges with the transports' codes, the alarm
//! history and its reset, and the communication time-outs on a virtual clock.

use std::time::Duration;

use cellrt_cia402::fsa::FsaState;
use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams, Refusal, Transport};
use cellrt_fieldbus::modbus::ExceptionCode;
use cellrt_fieldbus::mr_je_c::{Alarm, ObjectId, SoftwareVersion, Value};
use cellrt_fieldbus::slmp::EndCode;

fn id(index: u16) -> ObjectId {
    ObjectId::new(index, 0)
}

fn ms(v: u64) -> Duration {
    Duration::from_millis(v)
}

fn drive() -> MrJeC {
    MrJeC::new(MrJeCParams::default())
}

fn cw(d: &mut MrJeC, word: u16, now: Duration) {
    d.write(id(0x6040), &Value::U16(word), now).unwrap();
}

fn enable(d: &mut MrJeC) {
    for word in [0x0006, 0x0007, 0x000F] {
        cw(d, word, Duration::ZERO);
    }
}

fn status(d: &MrJeC) -> u16 {
    match d.read(id(0x6041)).unwrap() {
        Value::U16(v) => v,
        other => panic!("{other:?}"),
    }
}

#[test]
fn power_on_defaults() {
    let d = drive();
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
    assert_eq!(d.read(id(0x1000)).unwrap(), Value::U32(0x0002_0192));
    assert_eq!(d.read(id(0x6061)).unwrap(), Value::I8(-20));
    assert_eq!(d.read(id(0x605A)).unwrap(), Value::I16(2));
    assert_eq!(d.read(id(0x6502)).unwrap(), Value::U32(0x000B_002D));
    assert_eq!(
        d.read(ObjectId::new(0x1A00, 1)).unwrap(),
        Value::U32(0x6061_0008)
    );
    // [Pr. PN02] 1000 ms, [Pr. PN10] and [Pr. PF46] off.
    assert_eq!(d.read(id(0x2582)).unwrap(), Value::U32(1000));
    assert_eq!(d.read(id(0x258A)).unwrap(), Value::U32(0));
    assert_eq!(d.read(id(0x22AE)).unwrap(), Value::U32(0));
    let a3 = MrJeC::new(MrJeCParams {
        software: SoftwareVersion::A3,
        ..Default::default()
    });
    assert_eq!(a3.read(id(0x6502)).unwrap(), Value::U32(0x2D));
    assert_eq!(a3.read(id(0x2D60)), Err(Refusal::NoIndex));
}

#[test]
fn fsa_to_operation_enabled_and_quick_stop_option_2() {
    let mut d = drive();
    enable(&mut d);
    assert_eq!(d.state(), FsaState::OperationEnabled);
    // MT-8: operation enabled, main power on, target reached.
    assert_eq!(status(&d), 0x0437);
    // Quick stop: Quick stop active, then Switch on disabled (option code 2, §7.6.2).
    cw(&mut d, 0x0002, ms(10));
    assert_eq!(d.state(), FsaState::QuickStopActive);
    assert_eq!(status(&d) & 0x6F, 0x07);
    d.tick(ms(20));
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
    // Enable Operation does not bring it back (no transition 16).
    cw(&mut d, 0x000F, ms(30));
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
}

#[test]
fn quick_stop_in_profile_torque_goes_straight_to_switch_on_disabled() {
    let mut d = drive();
    d.write(id(0x6060), &Value::I8(4), Duration::ZERO).unwrap();
    enable(&mut d);
    cw(&mut d, 0x0002, ms(1));
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
}

#[test]
fn servo_on_needs_main_power() {
    let mut d = MrJeC::new(MrJeCParams {
        main_power: false,
        ..Default::default()
    });
    enable(&mut d);
    assert_eq!(d.state(), FsaState::SwitchedOn);
    assert_eq!(status(&d) & 0x10, 0);
}

#[test]
fn modes_of_operation_display_follows_supported_modes() {
    let mut d = drive();
    d.write(id(0x6060), &Value::I8(-101), Duration::ZERO)
        .unwrap();
    assert_eq!(d.read(id(0x6061)).unwrap(), Value::I8(-101));
    let mut a3 = MrJeC::new(MrJeCParams {
        software: SoftwareVersion::A3,
        ..Default::default()
    });
    a3.write(id(0x6060), &Value::I8(-101), Duration::ZERO)
        .unwrap();
    assert_eq!(a3.read(id(0x6061)).unwrap(), Value::I8(-20));
}

#[test]
fn access_rights_and_ranges_give_the_transports_codes() {
    let mut d = drive();
    let t = Duration::ZERO;
    let cases: [(ObjectId, Value, Refusal, EndCode, ExceptionCode); 9] = [
        (
            id(0x6041),
            Value::U16(0),
            Refusal::ReadOnly,
            EndCode::ReadOnly,
            ExceptionCode::IllegalDataAddress,
        ),
        (
            id(0x6098),
            Value::I8(40),
            Refusal::AboveRange,
            EndCode::AboveRange,
            ExceptionCode::IllegalDataValue,
        ),
        (
            id(0x6098),
            Value::I8(-44),
            Refusal::BelowRange,
            EndCode::BelowRange,
            ExceptionCode::IllegalDataValue,
        ),
        (
            id(0x607A),
            Value::I32(1_000_000),
            Refusal::AboveRange,
            EndCode::AboveRange,
            ExceptionCode::IllegalDataValue,
        ),
        (
            id(0x605A),
            Value::I16(3),
            Refusal::AboveRange,
            EndCode::AboveRange,
            ExceptionCode::IllegalDataValue,
        ),
        // OV-18, OV-17.
        (
            ObjectId::new(0x607B, 1),
            Value::I32(0),
            Refusal::OutOfRange,
            EndCode::OutOfRange,
            ExceptionCode::IllegalDataValue,
        ),
        (
            id(0x2D52),
            Value::I16(1),
            Refusal::OutOfRange,
            EndCode::OutOfRange,
            ExceptionCode::IllegalDataValue,
        ),
        // 6067h: 0–65534 or 4294967295.
        (
            id(0x6067),
            Value::U32(65535),
            Refusal::OutOfRange,
            EndCode::OutOfRange,
            ExceptionCode::IllegalDataValue,
        ),
        // [Pr. PN02] 0–1000 ms.
        (
            id(0x2582),
            Value::U32(1001),
            Refusal::AboveRange,
            EndCode::AboveRange,
            ExceptionCode::IllegalDataValue,
        ),
    ];
    for (object, value, refusal, end, exception) in cases {
        let got = d.write(object, &value, t);
        assert_eq!(got, Err(refusal), "{object} = {value}");
        assert_eq!((refusal.end_code(), refusal.exception()), (end, exception));
    }
    assert_eq!(d.write(id(0x6067), &Value::U32(u32::MAX), t), Ok(()));
    assert_eq!(d.write(id(0x607A), &Value::I32(-999_999), t), Ok(()));
    assert_eq!(d.read(id(0x607A)).unwrap(), Value::I32(-999_999));
    assert_eq!(d.read(id(0x2A46)), Err(Refusal::WriteOnly));
    assert_eq!(d.read(id(0x5FFF)), Err(Refusal::NoIndex));
    assert_eq!(d.read(ObjectId::new(0x6041, 1)), Err(Refusal::NoSubIndex));
    // SLMP sizes: more or fewer bytes than the type.
    assert_eq!(
        d.write_le(id(0x6040), &[0, 0, 0, 0], t),
        Err(Refusal::TooLarge)
    );
    assert_eq!(d.write_le(id(0x6083), &[0, 0], t), Err(Refusal::TooSmall));
    assert_eq!(
        d.write_le(id(0x6041), &[0, 0, 0, 0], t),
        Err(Refusal::ReadOnly)
    );
}

#[test]
fn ethernet_timeout_raises_al_86_4_after_pn10_and_waits_after_a_reset() {
    let mut d = drive();
    d.write(id(0x258A), &Value::U32(2), Duration::ZERO).unwrap();
    enable(&mut d);
    d.received(Transport::ModbusTcp, ms(100));
    d.tick(ms(2099));
    assert_eq!(d.alarm(), None);
    d.tick(ms(2100));
    assert_eq!(d.alarm(), Some(Alarm::NETWORK_4));
    assert_eq!(d.state(), FsaState::Fault);
    assert_eq!(status(&d) & 0x4F, 0x08);
    assert_eq!(d.read(id(0x2A42)).unwrap(), Value::U16(0x8604));
    assert_eq!(d.read(id(0x2A41)).unwrap(), Value::U32(0x0086_0004));
    assert_eq!(d.read(id(0x603F)).unwrap(), Value::U16(0x1000));
    assert_eq!(d.read(id(0x1001)).unwrap(), Value::U8(1));
    assert_eq!(
        d.read(ObjectId::new(0x2A00, 1)).unwrap(),
        Value::U32(0x0086_0004)
    );
    assert_eq!(
        d.read(ObjectId::new(0x2A00, 3)).unwrap(),
        Value::U16(0x8604)
    );
    // Reset by 2A46h = 1EA5h (another value is ignored); disarmed until the next message.
    d.write(id(0x2A46), &Value::U16(1), ms(3000)).unwrap();
    assert_eq!(d.alarm(), Some(Alarm::NETWORK_4));
    d.write(id(0x2A46), &Value::U16(0x1EA5), ms(3000)).unwrap();
    assert_eq!((d.alarm(), d.state()), (None, FsaState::SwitchOnDisabled));
    d.tick(ms(60_000));
    assert_eq!(d.alarm(), None);
    // SLMP feeds the same time-out.
    d.received(Transport::Slmp, ms(60_000));
    d.tick(ms(62_000));
    assert_eq!(d.alarm(), Some(Alarm::NETWORK_4));
    assert_eq!(
        d.read(ObjectId::new(0x2A01, 1)).unwrap(),
        Value::U32(0x0086_0004)
    );
    // Reset by the controlword's fault-reset edge, then 2A40h = 1EA5h clears the history.
    cw(&mut d, 0x0000, ms(62_001));
    cw(&mut d, 0x0080, ms(62_002));
    assert_eq!(d.alarm(), None);
    d.write(id(0x2A40), &Value::U16(0x1EA5), ms(62_003))
        .unwrap();
    assert_eq!(d.read(ObjectId::new(0x2A00, 1)).unwrap(), Value::U32(0));
    assert!(d.history().get(0).is_none());
}

#[test]
fn the_off_defaults_leave_the_motor_running() {
    // PN10 = 0 and PF46 = 0 (defaults): a master that vanishes raises nothing.
    let mut d = drive();
    enable(&mut d);
    d.received(Transport::ModbusTcp, ms(0));
    d.received(Transport::Slmp, ms(0));
    d.received(Transport::ModbusRtu, ms(0));
    d.tick(Duration::from_secs(3600));
    assert_eq!((d.alarm(), d.state()), (None, FsaState::OperationEnabled));
    // An A3 drive has no [Pr. PN10] time-out at all.
    let mut a3 = MrJeC::new(MrJeCParams {
        software: SoftwareVersion::A3,
        ..Default::default()
    });
    a3.write(id(0x258A), &Value::U32(1), Duration::ZERO)
        .unwrap();
    a3.received(Transport::Slmp, ms(0));
    a3.tick(Duration::from_secs(10));
    assert_eq!(a3.alarm(), None);
}

#[test]
fn cclink_timeout_pn02_defaults_to_1000_ms() {
    let mut d = drive();
    // Not armed before the first cyclic frame.
    d.tick(Duration::from_secs(5));
    assert_eq!(d.alarm(), None);
    d.received(Transport::CcLink, ms(5000));
    d.tick(ms(5999));
    assert_eq!(d.alarm(), None);
    d.tick(ms(6000));
    assert_eq!(d.alarm(), Some(Alarm::NETWORK_1));
    assert_eq!(d.read(id(0x2A42)).unwrap(), Value::U16(0x8601));
    // PN02 = 0: off.
    let mut off = drive();
    off.write(id(0x2582), &Value::U32(0), Duration::ZERO)
        .unwrap();
    off.received(Transport::CcLink, ms(0));
    off.tick(Duration::from_secs(60));
    assert_eq!(off.alarm(), None);
}

#[test]
fn rtu_timeout_pf46_raises_al_8a_2() {
    let mut d = drive();
    d.write(id(0x22AE), &Value::U32(5), Duration::ZERO).unwrap();
    d.received(Transport::ModbusRtu, ms(1000));
    d.tick(ms(5999));
    assert_eq!(d.alarm(), None);
    d.tick(ms(6000));
    assert_eq!(d.alarm(), Some(Alarm::MODBUS_RTU_TIMEOUT));
    assert_eq!(d.read(id(0x2A42)).unwrap(), Value::U16(0x8A02));
    assert_eq!(Alarm::MODBUS_RTU_TIMEOUT.to_string(), "AL. 8A.2");
}

/// [Pr. PN23] (`*KAA`, 1–7200 s, 3600 s) takes effect at power-on; by default the drive closes a
/// silent Modbus/TCP connection after 28800 s (MR-JE-C manual §5.2.3: "3600 [s] × 8 times").
#[test]
fn pn23_keep_alive_takes_effect_at_power_on() {
    let mut d = drive();
    assert_eq!(d.keep_alive().interval, Duration::from_secs(3600));
    assert_eq!(d.keep_alive().close_after(), Duration::from_secs(28_800));
    d.write(id(0x2597), &Value::U32(10), ms(0)).unwrap();
    assert_eq!(d.keep_alive().interval, Duration::from_secs(3600));
    // Saved to the EEPROM (1010h:4 "save", §7.4.4), then the power cycle loads it.
    let save = Value::U32(0x6576_6173);
    d.write(ObjectId::new(0x1010, 4), &save, ms(0)).unwrap();
    d.tick(Duration::from_secs(60));
    d.power_cycle();
    assert_eq!(d.keep_alive().interval, Duration::from_secs(10));
    assert_eq!(d.keep_alive().close_after(), Duration::from_secs(80));
    for refused in [0, 7201] {
        assert!(d.write(id(0x2597), &Value::U32(refused), ms(0)).is_err());
    }
}

/// OV-7, OV-8 (§7.3): 6086h −1 and 6088h 0 are fixed (the same value is taken, another is out
/// of range), 60A9h is FEB44700h; OV-15, OV-16: the manual's examples of 100Ah and 2D33h, the
/// simulated unit's defaults.
#[test]
fn ov_7_8_15_16_fixed_profile_types_si_velocity_and_texts() {
    let mut d = drive();
    let t = Duration::ZERO;
    assert_eq!(d.read(id(0x6086)).unwrap(), Value::I16(-1));
    assert_eq!(d.read(id(0x6088)).unwrap(), Value::I16(0));
    assert_eq!(d.read(id(0x60A9)).unwrap(), Value::U32(0xFEB4_4700));
    d.write(id(0x6086), &Value::I16(-1), t).unwrap();
    assert_eq!(
        d.write(id(0x6086), &Value::I16(0), t),
        Err(Refusal::AboveRange)
    );
    assert_eq!(
        d.write(id(0x6088), &Value::I16(1), t),
        Err(Refusal::AboveRange)
    );
    let text = |index| d.read(id(index)).unwrap().to_le();
    assert_eq!(text(0x100A), b" BCD-B46W750 A4 ");
    assert_eq!(text(0x2D33), b"123456789012    ");
}
