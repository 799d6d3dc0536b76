//! The MR-JE-C emulator on loopback sockets against our clients (Modbus/TCP, SLMP over UDP and
//! TCP, typed object access) and against an independent client (pymodbus, via
//! `CELLRT_PYTHON`; says SKIPPED without one outside CI): object access, refusals with the
//! transport's codes, connection limits, and AL. 86.4 when the client stops.

use std::io::{Read, Write};
use std::net::{IpAddr, Ipv4Addr, TcpStream};
use std::process::Command;
use std::time::Duration;

use cellrt_cia402::controlword::Controlword as Cw;
use cellrt_emulator::mr_je_c::server::{Ports, Server};
use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams};
use cellrt_fieldbus::modbus::client::TcpClient;
use cellrt_fieldbus::modbus::ExceptionCode;
use cellrt_fieldbus::mr_je_c::access::typed::{
    Controlword, CurrentAlarm, ModesOfOperationDisplay, ResetAlarm, Statusword, TargetPosition,
};
use cellrt_fieldbus::mr_je_c::{AccessError, Alarm, ObjectAccess, ObjectId, OverModbus, Value};
use cellrt_fieldbus::slmp::client::{FrameType, SlmpClient};
use cellrt_fieldbus::slmp::EndCode;

const LOOPBACK: IpAddr = IpAddr::V4(Ipv4Addr::LOCALHOST);
const ANY: Ports = Ports::ANY;
const TIMEOUT: Duration = Duration::from_secs(2);

fn server() -> Server {
    Server::start(MrJeC::new(MrJeCParams::default()), LOOPBACK, ANY).unwrap()
}

fn modbus(s: &Server) -> OverModbus {
    let client = TcpClient::connect(s.modbus_tcp, TIMEOUT).unwrap();
    OverModbus::new(client, Default::default())
}

/// The same checks through any transport.
fn power_up_and_move_targets(drive: &mut impl ObjectAccess) {
    for w in [0x0006, 0x0007, 0x000F] {
        drive.write::<Controlword>(Cw(w)).unwrap();
    }
    assert_eq!(drive.read::<Statusword>().unwrap().0, 0x0437);
    drive.write::<TargetPosition>(-123_456).unwrap();
    assert_eq!(drive.read::<TargetPosition>().unwrap(), -123_456);
    assert_eq!(drive.read::<ModesOfOperationDisplay>().unwrap(), -20);
    // A sub-index of a record.
    let vendor = drive.read_object(ObjectId::new(0x1018, 1)).unwrap();
    assert_eq!(vendor, Value::U32(2));
    let max = ObjectId::new(0x607D, 2);
    drive.write_object(max, &Value::I32(5000)).unwrap();
    assert_eq!(drive.read_object(max).unwrap(), Value::I32(5000));
    assert_eq!(
        drive.read_object(ObjectId::new(0x607D, 1)).unwrap(),
        Value::I32(0)
    );
    // Not an object of the dictionary: refused before anything is sent.
    assert!(matches!(
        drive.read_object(ObjectId::new(0x5FFF, 0)),
        Err(AccessError::Unknown(..))
    ));
    assert!(matches!(
        drive.write_object(ObjectId::new(0x6040, 0), &Value::U32(1)),
        Err(AccessError::Type { .. })
    ));
}

#[test]
fn modbus_tcp_client_against_the_emulator() {
    let s = server();
    let mut drive = modbus(&s);
    power_up_and_move_targets(&mut drive);
    let refused = |r: Result<(), AccessError>| match r {
        Err(AccessError::Exception { code, .. }) => code,
        other => panic!("{other:?}"),
    };
    let ro = drive.write_object(ObjectId::new(0x6041, 0), &Value::U16(0));
    assert_eq!(refused(ro), ExceptionCode::IllegalDataAddress);
    let range = drive.write_object(ObjectId::new(0x6098, 0), &Value::I8(40));
    assert_eq!(refused(range), ExceptionCode::IllegalDataValue);
    // The 1010h record with sub 1 = "save" (subs 0, 2–5 carried as read).
    drive
        .write_object(ObjectId::new(0x1010, 1), &Value::U32(0x6576_6173))
        .unwrap();
    assert_eq!(
        s.drive().read(ObjectId::new(0x607A, 0)).unwrap(),
        Value::I32(-123_456)
    );
}

#[test]
fn slmp_clients_against_the_emulator() {
    let s = server();
    for (name, mut drive) in [
        (
            "UDP 4E",
            SlmpClient::udp(s.slmp_udp, FrameType::E4, TIMEOUT).unwrap(),
        ),
        (
            "UDP 3E",
            SlmpClient::udp(s.slmp_udp, FrameType::E3, TIMEOUT).unwrap(),
        ),
        (
            "TCP 4E",
            SlmpClient::tcp(s.slmp_tcp, FrameType::E4, TIMEOUT).unwrap(),
        ),
    ] {
        power_up_and_move_targets(&mut drive);
        match drive.write_object(ObjectId::new(0x6041, 0), &Value::U16(0)) {
            Err(AccessError::EndCode { code, .. }) => assert_eq!(code, EndCode::ReadOnly, "{name}"),
            other => panic!("{name}: {other:?}"),
        }
        match drive.write_object(ObjectId::new(0x607B, 1), &Value::I32(0)) {
            Err(AccessError::EndCode { code, .. }) => {
                assert_eq!(code, EndCode::OutOfRange, "{name}")
            }
            other => panic!("{name}: {other:?}"),
        }
        assert_eq!(
            drive.model().unwrap(),
            ("MR-JE-20C".to_string(), 0),
            "{name}"
        );
    }
}

/// Whether the server closed `stream` (a read gives EOF or a reset).
fn closed(stream: &mut TcpStream) -> bool {
    stream.set_read_timeout(Some(TIMEOUT)).unwrap();
    let mut b = [0u8; 16];
    matches!(stream.read(&mut b), Ok(0) | Err(_))
}

#[test]
fn connection_limits() {
    let s = server();
    // Modbus/TCP: three connections; the fourth is closed; a freed place is taken again.
    let mut three: Vec<OverModbus> = (0..3).map(|_| modbus(&s)).collect();
    std::thread::sleep(Duration::from_millis(100));
    let mut fourth = TcpStream::connect(s.modbus_tcp).unwrap();
    assert!(closed(&mut fourth), "a fourth Modbus/TCP connection");
    for d in &mut three {
        assert_eq!(d.read::<CurrentAlarm>().unwrap(), None);
    }
    drop(three.pop());
    std::thread::sleep(Duration::from_millis(100));
    let mut again = modbus(&s);
    assert_eq!(again.read::<CurrentAlarm>().unwrap(), None);
    // SLMP over TCP: one connection.
    let mut first = SlmpClient::tcp(s.slmp_tcp, FrameType::E4, TIMEOUT).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    let mut second = TcpStream::connect(s.slmp_tcp).unwrap();
    let _ = second.write_all(&[0x50, 0x00]);
    assert!(closed(&mut second), "a second SLMP TCP connection");
    assert_eq!(first.read::<CurrentAlarm>().unwrap(), None);
}

#[test]
fn al_86_4_when_the_modbus_client_stops() {
    let s = server();
    let mut drive = modbus(&s);
    // [Pr. PN10] = 1 s.
    drive
        .write_object(ObjectId::new(0x258A, 0), &Value::U32(1))
        .unwrap();
    let last = s.now();
    drop(drive);
    let end = last + Duration::from_secs(20);
    while s.drive().alarm().is_none() && s.now() < end {
        std::thread::sleep(Duration::from_millis(20));
    }
    let raised = s.now();
    assert_eq!(s.drive().alarm(), Some(Alarm::NETWORK_4));
    assert!(
        raised - last >= Duration::from_secs(1),
        "{:?}",
        raised - last
    );
    // A new client sees it and resets it.
    let mut drive = modbus(&s);
    assert_eq!(
        drive.read::<CurrentAlarm>().unwrap(),
        Some(Alarm::NETWORK_4)
    );
    drive.write::<ResetAlarm>(ResetAlarm::KEY).unwrap();
    assert_eq!(drive.read::<CurrentAlarm>().unwrap(), None);
}

#[test]
fn pymodbus_client_against_the_emulator() {
    let Some(python) =
        cellrt_test_support::python::pymodbus("pymodbus_client_against_the_emulator")
    else {
        return;
    };
    let s = server();
    let out = Command::new(python)
        .arg(cellrt_test_support::python::script("modbus_client.py"))
        .arg(s.modbus_tcp.port().to_string())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "pymodbus client: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        s.drive().read(ObjectId::new(0x607A, 0)).unwrap(),
        Value::I32(100_000)
    );
}

/// The SLMP monitoring timer (MR-JE-C manual §2.4.2): a drive that takes 600 ms to process a
/// request discards the answer to a client that waits 400 ms (timer 0001h, 0.25 s) and answers
/// one that waits 5 s (timer 0014h); a raw 4E request with timer 0000h ("wait until done") is
/// answered too.
#[test]
fn an_answer_the_monitoring_timer_outlives_is_discarded() {
    let params = MrJeCParams {
        slmp_processing_time: Duration::from_millis(600),
        ..MrJeCParams::default()
    };
    let s = Server::start(MrJeC::new(params), LOOPBACK, ANY).unwrap();
    let short = Duration::from_millis(400);
    let mut impatient = SlmpClient::udp(s.slmp_udp, FrameType::E4, short).unwrap();
    assert!(matches!(
        impatient.read::<Statusword>(),
        Err(AccessError::Timeout(_))
    ));
    let mut patient = SlmpClient::udp(s.slmp_udp, FrameType::E4, Duration::from_secs(5)).unwrap();
    assert_eq!(patient.read::<Statusword>().unwrap().0 & 0x4F, 0x40);
    // SL-3 with the timer 0000h: upload 6064h.
    let socket = std::net::UdpSocket::bind((Ipv4Addr::LOCALHOST, 0)).unwrap();
    socket
        .set_read_timeout(Some(Duration::from_secs(5)))
        .unwrap();
    let request = [
        0x54, 0x00, 0x34, 0x12, 0x00, 0x00, 0x00, 0xFF, 0xFF, 0x03, 0x00, 0x0C, 0x00, 0x00, 0x00,
        0x20, 0x40, 0x01, 0x00, 0x64, 0x60, 0x00, 0x00, 0x00, 0x00,
    ];
    socket.send_to(&request, s.slmp_udp).unwrap();
    let mut answer = [0u8; 64];
    let (n, _) = socket.recv_from(&mut answer).unwrap();
    assert_eq!(
        &answer[..4],
        &[0xD4, 0x00, 0x34, 0x12],
        "{:02X?}",
        &answer[..n]
    );
    assert_eq!(&answer[13..15], &[0x00, 0x00], "end code");
}
