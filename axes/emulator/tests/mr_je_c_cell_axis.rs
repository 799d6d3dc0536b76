//! An MR-JE-C axis of a cell on its own thread against the emulator on loopback, over each
//! transport: power on, a pp move to the target (the drive's position there, Target reached),
//! a pv velocity and halt, a homing, a tq torque within the speed limit and its halt, point
//! tables, a jog and a station in the positioning modes; a cut link stops the axis by the
//! master's watchdog and the drive by its own time-out (AL. 86.4 from [Pr. PN10], AL. 86.1
//! from [Pr. PN02]).

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::time::{Duration, Instant};

use cellrt_emulator::mr_je_c::cyclic::LinkLayout;
use cellrt_emulator::mr_je_c::rs485::Rs485Line;
use cellrt_emulator::mr_je_c::server::{Ports, Server};
use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams};
use cellrt_fieldbus::cclink_ief_basic::io_thread::CyclicIo;
use cellrt_fieldbus::cclink_ief_basic::master::{GroupMaster, MasterParams};
use cellrt_fieldbus::modbus::client::TcpClient;
use cellrt_fieldbus::modbus::serial::{LineSettings, RtuClient};
use cellrt_fieldbus::mr_je_c::cell::{
    AxisCommand, AxisControl, AxisHandle, AxisThread, CyclicDriveIo, DeviceTable, DriveIo,
    ObjectIo, PositioningMode, StopReaction, Stopped,
};
use cellrt_fieldbus::mr_je_c::parameters::{PN02, PN10, PT28};
use cellrt_fieldbus::mr_je_c::{Alarm, ObjectId, OverModbus, Value};
use cellrt_fieldbus::slmp::client::{FrameType, SlmpClient};
use serialport::TTYPort;

const LOOPBACK: IpAddr = IpAddr::V4(Ipv4Addr::LOCALHOST);
const TIMEOUT: Duration = Duration::from_millis(200);
const PERIOD: Duration = Duration::from_millis(10);

fn server() -> Server {
    Server::start(MrJeC::new(MrJeCParams::default()), LOOPBACK, Ports::ANY).unwrap()
}

fn wait(
    h: &AxisHandle,
    what: &str,
    ok: impl Fn(&cellrt_fieldbus::mr_je_c::cell::AxisFeedback) -> bool,
) {
    let end = Instant::now() + Duration::from_secs(10);
    while Instant::now() < end {
        if ok(&h.feedback()) {
            return;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    panic!("{what}: {:?}", h.feedback());
}

/// The drive's alarm once raised, waiting at most 5 s.
fn alarm_within_5_s(s: &Server) -> Option<Alarm> {
    let end = Instant::now() + Duration::from_secs(5);
    while s.drive().alarm().is_none() && Instant::now() < end {
        std::thread::sleep(Duration::from_millis(20));
    }
    s.drive().alarm()
}

/// Power on, a pp move of 2 revolutions, a pv velocity, halt.
fn moves(io: Box<dyn DriveIo>, params: &[(ObjectId, Value)]) -> AxisThread {
    let control = AxisControl::new(5, StopReaction::QuickStop);
    let t = AxisThread::start("x", io, params, control, PERIOD).unwrap();
    let h = t.handle.clone();
    assert!(h.command(AxisCommand::PowerOn));
    wait(&h, "enabled", |f| f.enabled);
    h.command(AxisCommand::Move {
        target: 262_144,
        velocity: 120_000,
        acceleration_ms: 200,
        deceleration_ms: 200,
    });
    wait(&h, "pp move done", |f| f.done == 1);
    let f = h.feedback();
    assert_eq!(f.failed, 0);
    assert!((f.inputs.position - 262_144).abs() <= 100, "{f:?}");
    assert!(f.inputs.statusword & (1 << 10) != 0);
    h.command(AxisCommand::Velocity {
        velocity: -60_000,
        acceleration_ms: 100,
        deceleration_ms: 100,
    });
    wait(&h, "at speed", |f| f.done == 2);
    // Reached within the velocity window 606Dh (2000 = 20 r/min, its initial value).
    let v = h.feedback().inputs.velocity;
    assert!((v + 60_000).abs() <= 2000, "{v}");
    h.command(AxisCommand::Halt);
    wait(&h, "halted", |f| f.done == 3 && f.inputs.velocity == 0);
    // hm with the drive's default method 37: the home (607Ch = 0) where the motor stands.
    assert_ne!(h.feedback().inputs.position, 0);
    assert!(h.command(AxisCommand::Home));
    wait(&h, "homed", |f| f.done == 4);
    let f = h.feedback();
    assert_eq!((f.failed, f.inputs.position), (0, 0), "{f:?}");
    assert_eq!(
        f.inputs.statusword & 0x3400,
        0x1400,
        "Homing attained, Target reached"
    );
    // tq: 10 % at 100 %/s, the speed held at 300 r/min by 2D20h: the ramp's job ends after
    // its time (0.1 s), the motor runs up to the limit and no further; Halt ramps the torque
    // to 0 (the job ends after that ramp) and friction stops the motor.
    assert!(h.command(AxisCommand::Torque {
        torque: 100,
        slope: 1000,
        velocity_limit: 30_000,
    }));
    wait(&h, "torque ramp done", |f| f.done == 5);
    wait(&h, "at the speed limit", |f| f.inputs.velocity >= 29_000);
    for _ in 0..10 {
        let v = h.feedback().inputs.velocity;
        assert!(v <= 30_000, "2D20h holds the speed: {v}");
        std::thread::sleep(PERIOD);
    }
    assert!(h.command(AxisCommand::Halt));
    wait(&h, "torque halted", |f| f.done == 6);
    wait(&h, "stopped by friction", |f| f.inputs.velocity == 0);
    assert_eq!(h.feedback().failed, 0);
    t
}

#[test]
fn modbus_tcp_axis_moves_and_a_cut_link_stops_it() {
    let s = server();
    let client = TcpClient::connect(s.modbus_tcp, TIMEOUT).unwrap();
    let io = Box::new(ObjectIo::new(OverModbus::new(client, Default::default())));
    // [Pr. PN10] 1 s: AL. 86.4 one second after the last message.
    let t = moves(io, &[(ObjectId::new(PN10.index(), 0), Value::U32(1))]);
    let h = t.handle.clone();
    s.cut_link(true);
    wait(&h, "watchdog", |f| {
        f.stopped == Some(Stopped::CommunicationLost(5))
    });
    assert_eq!(alarm_within_5_s(&s), Some(Alarm::NETWORK_4));
}

#[test]
fn slmp_udp_axis_moves() {
    let s = server();
    let client = SlmpClient::udp(s.slmp_udp, FrameType::E4, TIMEOUT).unwrap();
    let t = moves(Box::new(ObjectIo::new(client)), &[]);
    assert_eq!(t.handle.feedback().missed, 0);
}

/// A method the emulated drive does not run (6098h = 35, listed in 60E3h but not emulated):
/// Homing error (bit 13), the job fails and the axis stays enabled.
#[test]
fn a_homing_error_fails_the_home_job() {
    let s = server();
    let client = SlmpClient::udp(s.slmp_udp, FrameType::E4, TIMEOUT).unwrap();
    let io = Box::new(ObjectIo::new(client));
    let method = [(ObjectId::new(0x6098, 0), Value::I8(35))];
    let control = AxisControl::new(5, StopReaction::QuickStop);
    let t = AxisThread::start("x", io, &method, control, PERIOD).unwrap();
    let h = t.handle.clone();
    assert!(h.command(AxisCommand::PowerOn));
    wait(&h, "enabled", |f| f.enabled);
    assert!(h.command(AxisCommand::Home));
    wait(&h, "homing failed", |f| f.failed == 1);
    let f = h.feedback();
    assert_eq!((f.done, f.stopped), (0, None), "{f:?}");
    assert!(f.enabled && f.inputs.statusword & (1 << 13) != 0, "{f:?}");
}

/// The cyclic exchange with `s`'s drive, start-up writes by SLMP beside it.
fn cclink_io(s: &Server) -> CyclicDriveIo {
    let local = SocketAddr::new(LOOPBACK, 0);
    let master = GroupMaster::new(local, s.cclink, &[LOOPBACK], MasterParams::default()).unwrap();
    let slmp = SlmpClient::udp(s.slmp_udp, FrameType::E4, TIMEOUT).unwrap();
    let mut slmp = ObjectIo::new(slmp);
    CyclicDriveIo::new(
        CyclicIo::new(master),
        Some(Box::new(move |id, v| slmp.write_object(id, v))),
    )
}

#[test]
fn cclink_axis_moves_and_a_cut_link_raises_al_86_1() {
    let s = server();
    let io = cclink_io(&s);
    // [Pr. PN02] 1000 ms: long enough that a stall of this (loaded) machine during the moves
    // is not taken for a lost master (the emulator's clock is wall time over sockets).
    let t = moves(
        Box::new(io),
        &[(ObjectId::new(PN02.index(), 0), Value::U32(1000))],
    );
    s.cut_link(true);
    wait(&t.handle, "watchdog", |f| f.stopped.is_some());
    assert_eq!(alarm_within_5_s(&s), Some(Alarm::NETWORK_1));
}

#[test]
fn modbus_rtu_axis_moves_over_a_pty() {
    let (master, slave) = TTYPort::pair().expect("a pseudo-terminal");
    let drive = MrJeC::on_rs485_line(MrJeCParams::default(), 3);
    let line = Rs485Line::start(vec![drive], Box::new(master), LineSettings::default()).unwrap();
    let client = RtuClient::new(Box::new(slave), LineSettings::default(), 3, TIMEOUT).unwrap();
    let t = moves(
        Box::new(ObjectIo::new(OverModbus::new(client, Default::default()))),
        &[],
    );
    assert_eq!(t.handle.feedback().missed, 0);
    drop(t);
    line.stop();
}

/// Point tables 1 and 2 (2801h/2802h: position, speed 0.01 r/min, ramps ms) and [Pr. PT28]
/// = 8 stations, written at start-up.
fn positioning_parameters() -> Vec<(ObjectId, Value)> {
    let mut p = Vec::new();
    for (index, position, speed, ramp) in [
        (0x2801, 262_144, 120_000, 200),
        (0x2802, -131_072, 60_000, 100),
    ] {
        p.push((ObjectId::new(index, 1), Value::I32(position)));
        p.push((ObjectId::new(index, 2), Value::I32(speed)));
        p.push((ObjectId::new(index, 3), Value::I32(ramp)));
        p.push((ObjectId::new(index, 4), Value::I32(ramp)));
    }
    p.push((ObjectId::new(PT28.index(), 0), Value::U32(8)));
    p
}

/// pt: tables 1 and 2 run to their positions (Target reached, within 100 pos units), table 2
/// again where the axis stands ends too; jg in reverse runs at 6081h until Halt; idx turns to
/// station 3 (6064h in stations).
fn positions(io: Box<dyn DriveIo>) {
    let control = AxisControl::new(5, StopReaction::QuickStop)
        .starting_in_positioning(PositioningMode::PointTable);
    let t = AxisThread::start("x", io, &positioning_parameters(), control, PERIOD).unwrap();
    let h = t.handle.clone();
    assert!(h.command(AxisCommand::PowerOn));
    wait(&h, "enabled", |f| f.enabled);
    for (n, (table, at)) in [(1, 262_144), (2, -131_072), (2, -131_072)]
        .into_iter()
        .enumerate()
    {
        assert!(h.command(AxisCommand::PointTable { table }));
        wait(&h, "point table done", |f| f.done == n as u32 + 1);
        let f = h.feedback();
        assert_eq!(f.failed, 0, "{f:?}");
        assert!(
            (f.inputs.position - at).abs() <= 100,
            "table {table}: {f:?}"
        );
        assert!(f.inputs.statusword & (1 << 10) != 0);
    }
    assert!(h.command(AxisCommand::Jog {
        velocity: 60_000,
        reverse: true,
        acceleration_ms: 100,
        deceleration_ms: 100,
    }));
    wait(&h, "jogging in reverse", |f| f.inputs.velocity <= -59_000);
    assert!(h.command(AxisCommand::Halt));
    wait(&h, "jog halted", |f| f.done == 5 && f.inputs.velocity == 0);
    assert!(h.command(AxisCommand::Station {
        station: 3,
        velocity: 60_000,
        acceleration_ms: 100,
        deceleration_ms: 100,
    }));
    wait(&h, "station reached", |f| f.done == 6);
    let f = h.feedback();
    assert_eq!((f.failed, f.inputs.position), (0, 3), "{f:?}");
}

#[test]
fn slmp_axis_runs_point_tables_a_jog_and_a_station() {
    let s = server();
    let client = SlmpClient::udp(s.slmp_udp, FrameType::E4, TIMEOUT).unwrap();
    positions(Box::new(ObjectIo::new(client)));
}

/// The same over the cyclic link with the devices of Table 2.3 on both ends.
#[test]
fn cclink_axis_runs_point_tables_on_the_devices_of_table_2_3() {
    let params = MrJeCParams {
        link_layout: LinkLayout::Positioning,
        ..MrJeCParams::default()
    };
    let s = Server::start(MrJeC::new(params), LOOPBACK, Ports::ANY).unwrap();
    positions(Box::new(
        cclink_io(&s).with_devices(DeviceTable::Positioning),
    ));
}

/// The feed override reaches the drive: a move started at 50 % carries half its 6081h, a new
/// override mid-move sends the new one, at 0 % the motor stands under Halt with the move not
/// ended, and released it arrives. The move (4 revolutions at 30 r/min, 8 s) outlasts any
/// stall of a loaded machine between its start and the hold.
#[test]
fn the_feed_override_scales_the_profile_velocity_the_drive_gets() {
    let s = server();
    let client = SlmpClient::udp(s.slmp_udp, FrameType::E4, TIMEOUT).unwrap();
    let control = AxisControl::new(5, StopReaction::QuickStop);
    let t = AxisThread::start("x", Box::new(ObjectIo::new(client)), &[], control, PERIOD).unwrap();
    let h = t.handle.clone();
    let speed = || s.drive().read(ObjectId::new(0x6081, 0)).unwrap().as_i64();
    assert!(h.command(AxisCommand::PowerOn));
    wait(&h, "enabled", |f| f.enabled);
    assert!(h.command(AxisCommand::Override { permille: 500 }));
    assert!(h.command(AxisCommand::Move {
        target: 524_288,
        velocity: 6_000,
        acceleration_ms: 100,
        deceleration_ms: 100,
    }));
    wait(&h, "moving", |f| f.inputs.velocity > 0);
    assert_eq!(speed(), Some(3_000));
    assert!(h.command(AxisCommand::Override { permille: 0 }));
    wait(&h, "held", |f| f.inputs.velocity == 0);
    for _ in 0..20 {
        std::thread::sleep(PERIOD);
        assert_eq!(h.feedback().done, 0, "a held move does not end");
    }
    assert!(h.command(AxisCommand::Override { permille: 1000 }));
    wait(&h, "arrived", |f| f.done == 1);
    assert_eq!(speed(), Some(6_000));
    let f = h.feedback();
    assert!((f.inputs.position - 524_288).abs() <= 100, "{f:?}");
    assert_eq!(f.failed, 0);
}
