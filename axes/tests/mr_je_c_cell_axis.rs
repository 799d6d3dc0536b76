//! An MR-JE-C axis of a cell on its own thread against the emulator on loopback, over each
//! transport: power on, a pp move to the target (the drive's position there, Target reached),
//! a pv velocity and halt, a homing, a tq torque within the speed limit and its halt; a cut link stops the axis by the master's watchdog and the drive by
//! its own time-out (AL. 86.4 from [Pr. PN10], AL. 86.1 from [Pr. PN02]).

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::time::{Duration, Instant};

use cellrt_axes::cclink_ief_basic::io_thread::CyclicIo;
use cellrt_axes::cclink_ief_basic::master::{GroupMaster, MasterParams};
use cellrt_axes::modbus::client::TcpClient;
use cellrt_axes::modbus::serial::{LineSettings, RtuClient};
use cellrt_axes::mr_je_c::cell::{
    AxisCommand, AxisControl, AxisHandle, AxisThread, CyclicDriveIo, DriveIo, ObjectIo,
    StopReaction, Stopped,
};
use cellrt_axes::mr_je_c::emulator::rs485::Rs485Line;
use cellrt_axes::mr_je_c::emulator::server::{Ports, Server};
use cellrt_axes::mr_je_c::emulator::{MrJeC, MrJeCParams};
use cellrt_axes::mr_je_c::parameters::{PN02, PN10};
use cellrt_axes::mr_je_c::{Alarm, ObjectId, OverModbus, Value};
use cellrt_axes::slmp::client::{FrameType, SlmpClient};
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
    ok: impl Fn(&cellrt_axes::mr_je_c::cell::AxisFeedback) -> bool,
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

#[test]
fn cclink_axis_moves_and_a_cut_link_raises_al_86_1() {
    let s = server();
    let local = SocketAddr::new(LOOPBACK, 0);
    let master = GroupMaster::new(local, s.cclink, &[LOOPBACK], MasterParams::default()).unwrap();
    let slmp = SlmpClient::udp(s.slmp_udp, FrameType::E4, TIMEOUT).unwrap();
    let mut slmp = ObjectIo::new(slmp);
    let io = CyclicDriveIo::new(
        CyclicIo::new(master),
        Some(Box::new(move |id, v| slmp.write_object(id, v))),
    );
    // [Pr. PN02] 100 ms.
    let t = moves(
        Box::new(io),
        &[(ObjectId::new(PN02.index(), 0), Value::U32(100))],
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
