//! The simulated MR-JE-C's CC-Link IE Field Basic cyclic link (docs/test-vectors.md, mr-je-c.md
//! §13.4 CB-0 … CB-6, SL-9 … SL-11): connection, CSR/SSR, RWw import, RWr from 1A00h, master
//! duplication, AL. 86.1 on the virtual clock; and our cyclic master against the emulator on
//! loopback, allocating nothing per exchange; a drive on Table 2.3 (positioning modes) run
//! through a point table by our encoder of that table.

use std::net::{IpAddr, Ipv4Addr};
use std::time::Duration;

use cellrt_cia402::fsa::FsaState;
use cellrt_emulator::mr_je_c::cyclic::CyclicLink;
use cellrt_emulator::mr_je_c::server::{Ports, Server};
use cellrt_emulator::mr_je_c::{slmp, MrJeC, MrJeCParams};
use cellrt_fieldbus::cclink_ief_basic::master::{CyclicMaster, MasterParams};
use cellrt_fieldbus::cclink_ief_basic::{
    bit, set_bit, CyclicRequest, CyclicResponse, EndCode, StationData, READY_BIT,
};
use cellrt_fieldbus::mr_je_c::{Alarm, ObjectId, SoftwareVersion, Value};
use cellrt_test_support::counting_alloc::{thread_heap_calls, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

const MASTER: u32 = 0xC0A8_03FA;
const DRIVE: u32 = 0xC0A8_0301;

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

fn ms(v: u64) -> Duration {
    Duration::from_millis(v)
}

/// A request of `master` to the drive: transmission bit, RWw words (6060h, 6040h) and CSR.
fn request(
    master: u32,
    sequence: u16,
    transmit: bool,
    mode: u8,
    cw: u16,
    csr: bool,
) -> CyclicRequest {
    let mut station = [StationData::default(); 16];
    station[0].slave_id = DRIVE;
    station[0].words[0] = mode;
    station[0].words[2..4].copy_from_slice(&cw.to_le_bytes());
    set_bit(&mut station[0].bits, READY_BIT, csr);
    CyclicRequest {
        protocol_version: 2,
        unit_info: 1,
        clock_ms: 0,
        master_id: master,
        group: 1,
        sequence,
        timeout_ms: 50,
        parallel_off_count: 3,
        parameter_no: 1,
        transmission: u16::from(transmit),
        stations: 1,
        station,
    }
}

struct Bench {
    drive: MrJeC,
    link: CyclicLink,
}

impl Bench {
    fn new() -> Bench {
        Bench {
            drive: MrJeC::new(MrJeCParams::default()),
            link: CyclicLink::default(),
        }
    }

    fn send(&mut self, r: &CyclicRequest, now: Duration) -> Option<CyclicResponse> {
        self.link.answer(&mut self.drive, r, DRIVE, true, now)
    }
}

fn ssr(r: &CyclicResponse) -> bool {
    bit(&r.station.bits, READY_BIT)
}

#[test]
fn connection_and_the_ready_handshake() {
    let mut b = Bench::new();
    // CB-0: a fresh drive drops a first request with the transmission bit on...
    assert!(b
        .send(&request(MASTER, 1, true, 1, 6, true), ms(0))
        .is_none());
    // ...and answers one with it off: zero data, end code 0.
    let r = b
        .send(&request(MASTER, 2, false, 1, 6, true), ms(10))
        .unwrap();
    assert_eq!(
        (r.end_code, r.station.words, r.station.bits),
        (EndCode::Normal, [0; 64], [0; 8])
    );
    // CB-1: transmitting, CSR off: SSR off, RWw not imported.
    let r = b
        .send(&request(MASTER, 3, true, 1, 6, false), ms(20))
        .unwrap();
    assert!(!ssr(&r));
    assert_eq!(
        b.drive.read(ObjectId::new(0x6060, 0)).unwrap(),
        Value::I8(0)
    );
    // CB-2: CSR on: RWw imported, SSR on within the exchange; 6061h and 6041h in RWr.
    for (k, cw) in [6u16, 7, 0xF].into_iter().enumerate() {
        let r = b
            .send(
                &request(MASTER, 4 + k as u16, true, 1, cw, true),
                ms(30 + 10 * k as u64),
            )
            .unwrap();
        assert!(ssr(&r));
    }
    assert_eq!(b.drive.state(), FsaState::OperationEnabled);
    let r = b
        .send(&request(MASTER, 0x1234, true, 1, 0xF, true), ms(70))
        .unwrap();
    assert_eq!(&r.station.words[..4], &[0x01, 0x00, 0x37, 0x04]);
    // CB-6: the sequence number and group are echoed.
    assert_eq!((r.sequence, r.group), (0x1234, 1));
    // CB-3: another master gets CFE0h and no data.
    let r = b
        .send(&request(MASTER + 1, 9, true, 1, 0, true), ms(80))
        .unwrap();
    assert_eq!(
        (r.end_code, r.station.words),
        (EndCode::MasterDuplication, [0; 64])
    );
    assert_eq!(b.drive.state(), FsaState::OperationEnabled);
    // CB-4: transmission off: zero data, SSR off.
    let r = b
        .send(&request(MASTER, 10, false, 1, 0xF, true), ms(90))
        .unwrap();
    assert_eq!((r.station.words, ssr(&r)), ([0; 64], false));
}

#[test]
fn response_mapping_is_locked_while_ssr_is_on() {
    let mut b = Bench::new();
    let frame = |s: &str| hex(s);
    let sl9 = frame("50 00 00 FF FF 03 00 0D 00 00 00 20 40 02 00 00 1A 00 00 01 00 00");
    let sl10 = frame("50 00 00 FF FF 03 00 10 00 00 00 20 40 02 00 00 1A 01 00 04 00 10 00 41 60");
    let count1 = frame("50 00 00 FF FF 03 00 0D 00 00 00 20 40 02 00 00 1A 00 00 01 00 01");
    b.send(&request(MASTER, 0, false, 0, 0, false), ms(0))
        .unwrap();
    b.send(&request(MASTER, 1, true, 0, 0, true), ms(10))
        .unwrap();
    // SL-11: SSR on: CCC7h.
    assert_eq!(
        slmp::answer_frame(&mut b.drive, &sl10, ms(15)),
        Some(frame(
            "D0 00 00 FF FF 03 00 0B 00 C7 CC 00 FF FF 03 00 20 40 02 00"
        ))
    );
    // CSR off, then SL-9, SL-10 and 1A00h:0 = 1: RWr starts with the statusword.
    b.send(&request(MASTER, 2, true, 0, 0, false), ms(20))
        .unwrap();
    for f in [&sl9, &sl10, &count1] {
        let r = slmp::answer_frame(&mut b.drive, f, ms(25)).unwrap();
        assert_eq!(&r[9..11], &[0, 0], "{r:02X?}");
    }
    let r = b
        .send(&request(MASTER, 3, true, 0, 6, true), ms(30))
        .unwrap();
    assert_eq!(&r.station.words[..4], &[0x31, 0x00, 0x00, 0x00]);
    // Unmappable (1018h:1) or beyond 64 bytes: CCCBh / CCCCh.
    b.send(&request(MASTER, 4, true, 0, 6, false), ms(40))
        .unwrap();
    let mut w = |sub: u8, v: u32| b_write(&mut b.drive, sub, v);
    assert_eq!(w(0, 0), None);
    assert_eq!(w(1, 0x1018_0120), None);
    assert_eq!(w(0, 1), Some([0xCB, 0xCC]));
    for sub in 1..=17 {
        assert_eq!(w(sub, 0x6064_0020), None);
    }
    assert_eq!(w(0, 17), Some([0xCC, 0xCC]));
}

/// An SLMP download of 1A00h:`sub` = `v` (sub 0 U8, the others U32); the end code if
/// abnormal.
fn b_write(drive: &mut MrJeC, sub: u8, v: u32) -> Option<[u8; 2]> {
    let data = if sub == 0 {
        vec![v as u8]
    } else {
        v.to_le_bytes().to_vec()
    };
    let mut f = hex("50 00 00 FF FF 03 00 00 00 00 00 20 40 02 00 00 1A 00 00 00 00");
    f[7] = 12 + data.len() as u8;
    f[17] = sub;
    f[19] = data.len() as u8;
    f.extend(data);
    let r = slmp::answer_frame(drive, &f, ms(50)).unwrap();
    (r[9..11] != [0, 0]).then(|| [r[9], r[10]])
}

#[test]
fn al_86_1_after_pn02_and_the_master_lost_after_its_supervision_time() {
    let mut b = Bench::new();
    b.send(&request(MASTER, 0, false, 0, 0, false), ms(0))
        .unwrap();
    b.send(&request(MASTER, 1, true, 0, 6, true), ms(10))
        .unwrap();
    b.drive.tick(ms(1009));
    assert_eq!(b.drive.alarm(), None);
    b.drive.tick(ms(1010));
    assert_eq!(b.drive.alarm(), Some(Alarm::NETWORK_1));
    // 150 ms of silence dropped the master: another one may connect (bit off first).
    assert!(b
        .send(&request(MASTER + 1, 1, true, 0, 0, true), ms(2000))
        .is_none());
    let r = b
        .send(&request(MASTER + 1, 2, false, 0, 0, false), ms(2010))
        .unwrap();
    assert_eq!(r.end_code, EndCode::Normal);
}

/// The emulator on loopback and our master of it.
fn on_loopback() -> (Server, CyclicMaster) {
    let ip = IpAddr::V4(Ipv4Addr::LOCALHOST);
    let any = Ports::ANY;
    let s = Server::start(MrJeC::new(MrJeCParams::default()), ip, any).unwrap();
    let p = MasterParams {
        response_timeout: Duration::from_secs(2),
        ..Default::default()
    };
    let m = CyclicMaster::new((ip, 0).into(), s.cclink, p).unwrap();
    (s, m)
}

#[test]
fn our_master_against_the_emulator_on_loopback() {
    let (s, mut m) = on_loopback();
    let mut rww = [0u8; 64];
    let mut ry = [0u8; 8];
    let r = m.exchange(false, &rww, &ry).unwrap();
    assert!(!bit(&r.station.bits, READY_BIT));
    rww[0] = 1;
    set_bit(&mut ry, READY_BIT, true);
    for cw in [6u16, 7, 0xF] {
        rww[2..4].copy_from_slice(&cw.to_le_bytes());
        let r = m.exchange(true, &rww, &ry).unwrap();
        assert!(bit(&r.station.bits, READY_BIT), "SSR");
    }
    let r = m.exchange(true, &rww, &ry).unwrap();
    assert_eq!(&r.station.words[..4], &[0x01, 0x00, 0x37, 0x04]);
    assert_eq!(m.stale, 0);
    // The master stops: AL. 86.1 after [Pr. PN02] (1000 ms), judged on the emulator's clock.
    let last = s.now();
    drop(m);
    while s.drive().alarm().is_none() && s.now() < last + Duration::from_secs(20) {
        std::thread::sleep(ms(20));
    }
    assert_eq!(s.drive().alarm(), Some(Alarm::NETWORK_1));
    assert!(s.now() - last >= ms(1000));
}

#[test]
fn cyclic_exchanges_are_allocation_free() {
    // Issue 18: the cyclic client never allocates per cycle (counted on this thread).
    let (_s, mut m) = on_loopback();
    let (mut rww, mut ry) = ([0u8; 64], [0u8; 8]);
    m.exchange(false, &rww, &ry).unwrap();
    set_bit(&mut ry, READY_BIT, true);
    rww[0] = 1;
    rww[2] = 6;
    m.exchange(true, &rww, &ry).unwrap();
    let before = thread_heap_calls();
    let mut ready = 0;
    for k in 0..200u16 {
        rww[4] = k as u8;
        let r = m.exchange(true, &rww, &ry).unwrap();
        ready += usize::from(bit(&r.station.bits, READY_BIT));
    }
    assert_eq!(
        thread_heap_calls() - before,
        0,
        "heap calls in 200 exchanges"
    );
    assert_eq!(ready, 200);
}

/// A group master sent to one drive's address: that station answers, the other (no drive at
/// 127.0.0.9) stays empty; a group of 0 or 17 stations is refused.
#[test]
fn a_group_master_collects_the_stations_that_answer() {
    use cellrt_fieldbus::cclink_ief_basic::master::{GroupMaster, MasterError};
    use cellrt_fieldbus::cclink_ief_basic::MAX_STATIONS;
    let ip = IpAddr::V4(Ipv4Addr::LOCALHOST);
    let s = Server::start(MrJeC::new(MrJeCParams::default()), ip, Ports::ANY).unwrap();
    // The absent station's wait (300 ms) stays well within the drive's supervision time
    // (1000 ms × 3), which would otherwise drop the master between the exchanges.
    let p = MasterParams {
        response_timeout: Duration::from_millis(300),
        timeout_ms: 1000,
        ..Default::default()
    };
    let absent = IpAddr::V4(Ipv4Addr::new(127, 0, 0, 9));
    let mut m = GroupMaster::new((ip, 0).into(), s.cclink, &[ip, absent], p).unwrap();
    let mut responses = [None; MAX_STATIONS];
    assert_eq!(m.exchange(0, &mut responses).unwrap(), 1);
    assert_eq!(responses[0].unwrap().station.slave_id, 0x7F00_0001);
    assert!(responses[1].is_none());
    assert_eq!(m.exchange(0b01, &mut responses).unwrap(), 1);
    assert_eq!(responses[0].unwrap().end_code, EndCode::Normal);
    for n in [0, 17] {
        let many = vec![ip; n];
        assert!(matches!(
            GroupMaster::new((ip, 0).into(), s.cclink, &many, p),
            Err(MasterError::Stations(k)) if k == n
        ));
    }
}

/// The link's cycle as the I/O thread runs it: the station is connected by a first request
/// that does not transmit to it, then takes RWw with CSR (6060h = 1, controlword 0006h) and
/// answers SSR; 200 cycles allocate nothing on the cycling thread.
#[test]
fn the_link_cycle_connects_the_station_and_allocates_nothing() {
    use cellrt_fieldbus::cclink_ief_basic::io_thread::{CyclicIo, StationCommand};
    use cellrt_fieldbus::cclink_ief_basic::master::GroupMaster;
    let ip = IpAddr::V4(Ipv4Addr::LOCALHOST);
    let s = Server::start(MrJeC::new(MrJeCParams::default()), ip, Ports::ANY).unwrap();
    let p = MasterParams {
        response_timeout: Duration::from_secs(2),
        ..Default::default()
    };
    let mut io = CyclicIo::new(GroupMaster::new((ip, 0).into(), s.cclink, &[ip], p).unwrap());
    let link = io.handle();
    let mut c = StationCommand {
        transmit: true,
        ..Default::default()
    };
    set_bit(&mut c.ry, READY_BIT, true);
    c.rww[0] = 1;
    c.rww[2] = 6;
    link.command(0, c);
    io.cycle().unwrap();
    let f = link.feedback(0).unwrap();
    assert!(f.connected && f.answered == 1, "{f:?}");
    assert!(!bit(&f.rx, READY_BIT), "not transmitted to yet: no SSR");
    io.cycle().unwrap();
    assert!(bit(&link.feedback(0).unwrap().rx, READY_BIT), "SSR");
    let before = thread_heap_calls();
    for _ in 0..200 {
        io.cycle().unwrap();
    }
    assert_eq!(thread_heap_calls() - before, 0, "heap calls in 200 cycles");
    let f = link.feedback(0).unwrap();
    assert_eq!((f.cycles, f.answered, f.missed_in_row), (202, 202, 0));
    assert_eq!(
        s.drive().read(ObjectId::new(0x6060, 0)).unwrap().as_i64(),
        Some(1)
    );
}

/// On its own thread: the link runs at its period; when the drive goes away the feedback
/// counts the cycles missed in a row (what the controller's watchdog judges).
#[test]
fn the_link_thread_runs_and_counts_missed_answers() {
    use cellrt_fieldbus::cclink_ief_basic::io_thread::CyclicIo;
    use cellrt_fieldbus::cclink_ief_basic::master::GroupMaster;
    let ip = IpAddr::V4(Ipv4Addr::LOCALHOST);
    let s = Server::start(MrJeC::new(MrJeCParams::default()), ip, Ports::ANY).unwrap();
    let p = MasterParams {
        response_timeout: ms(20),
        timeout_ms: 1000,
        ..Default::default()
    };
    let io = CyclicIo::new(GroupMaster::new((ip, 0).into(), s.cclink, &[ip], p).unwrap());
    let thread = io.spawn(ms(10)).unwrap();
    let wait = |what: &str, done: &dyn Fn() -> bool| {
        let end = std::time::Instant::now() + Duration::from_secs(20);
        while !done() {
            assert!(std::time::Instant::now() < end, "{what}");
            std::thread::sleep(ms(10));
        }
    };
    let f = || thread.handle.feedback(0).unwrap();
    wait("20 answers", &|| f().answered >= 20);
    assert!(f().connected);
    s.stop();
    wait("3 misses in a row", &|| f().missed_in_row >= 3);
    assert!(!f().connected);
    drop(thread);
}

/// A request carrying `rww` with CSR on.
fn request_with(sequence: u16, rww: [u8; 64]) -> CyclicRequest {
    let mut r = request(MASTER, sequence, true, 0, 0, true);
    r.station[0].words = rww;
    r
}

/// Manual Table 2.3 at both ends: our encoder's RWw (6060h = −101, 2D60h = 2, 6081h …) is
/// imported by the emulated drive through its own table of devices; the point table runs and
/// the default Table 2.3 response mapping (20 entries) answers the completed table and its M
/// code where our decoder reads them.
#[test]
fn a_point_table_runs_over_the_devices_of_table_2_3() {
    use cellrt_emulator::mr_je_c::cyclic::{LinkLayout, POSITIONING_MAPPING};
    use cellrt_fieldbus::mr_je_c::cell::{PositioningCommand, PositioningFeedback};
    let mut b = Bench::new();
    b.drive = MrJeC::new(MrJeCParams {
        link_layout: LinkLayout::Positioning,
        ..MrJeCParams::default()
    });
    assert_eq!(b.drive.mapping(), POSITIONING_MAPPING.to_vec());
    let table = |sub| ObjectId::new(0x2802, sub);
    for (sub, v) in [(1, 393_216), (2, 60_000), (3, 100), (4, 100), (7, 12)] {
        b.drive.write(table(sub), &Value::I32(v), ms(0)).unwrap();
    }
    let mut cmd = PositioningCommand {
        mode: -101,
        target_point_table: 2,
        ..PositioningCommand::default()
    };
    assert!(b
        .send(&request(MASTER, 1, false, 0, 0, false), ms(0))
        .is_some());
    let mut t = 10;
    let mut exchange = |b: &mut Bench, cmd: &PositioningCommand| {
        let r = b.send(&request_with(t as u16, cmd.rww()), ms(t)).unwrap();
        b.drive.tick(ms(t));
        t += 10;
        PositioningFeedback::from_rwr(&r.station.words)
    };
    for cw in [0x06, 0x07, 0x0F, 0x1F] {
        cmd.controlword = cw;
        exchange(&mut b, &cmd);
    }
    assert_eq!(b.drive.state(), FsaState::OperationEnabled);
    assert_eq!(
        b.drive.read(ObjectId::new(0x2D60, 0)).unwrap(),
        Value::I16(2),
        "2D60h from RWwn05"
    );
    let mut f = exchange(&mut b, &cmd);
    assert_eq!((f.mode, f.point_demand), (-101, 2));
    for _ in 0..200 {
        f = exchange(&mut b, &cmd);
        if f.point_actual == 2 {
            break;
        }
    }
    // Three revolutions at 600 r/min: 0.3 s and the ramps, within the 2 s run. The table
    // completes with the command; the motor is then still its droop (RWrn06, 60F4h) short,
    // within Position window 6067h (100).
    assert_eq!((f.point_actual, f.m_code), (2, 12), "{f:?}");
    assert_eq!(f.position + f.following_error, 393_216, "{f:?}");
    assert!((1..=100).contains(&f.following_error), "{f:?}");
    // Target reached only after Position window time 6068h (10 ms): not in the answer that
    // first shows the completed table, in the one 10 ms later, with the motor at the target.
    assert_eq!(f.statusword & (1 << 10), 0, "{f:?}");
    let f = exchange(&mut b, &cmd);
    assert_eq!(f.statusword & (1 << 10), 1 << 10);
    assert_eq!((f.position, f.following_error), (393_216, 0), "{f:?}");
}

/// The devices of Table 2.2 our master does not command carry their objects' initial values
/// (MR-JE-C manual §7.3): 60E0h/60E1h 10000 (1000.0 %), 2D20h 50000 (500.00 r/min); the
/// others 0. The drive takes every device each cycle: 0 in 60E0h would leave the motor no
/// torque.
#[test]
fn the_devices_we_do_not_command_carry_the_manuals_initial_values() {
    use cellrt_fieldbus::mr_je_c::cell::uncommanded_rww;
    let rww = uncommanded_rww(SoftwareVersion::A4);
    let word = |device: usize| u16::from_le_bytes([rww[2 * device], rww[2 * device + 1]]);
    assert_eq!((word(0x14), word(0x15)), (10_000, 10_000), "60E0h, 60E1h");
    assert_eq!(
        u32::from_le_bytes(rww[18..22].try_into().unwrap()),
        50_000,
        "2D20h in RWwn09-0A"
    );
    let others: u32 = [0x02, 0x03, 0x04, 0x0B, 0x12, 0x13, 0x17, 0x18, 0x19]
        .iter()
        .map(|&d| u32::from(word(d)))
        .sum();
    assert_eq!(others, 0);
    // The emulated drive takes them: an import of this block leaves 60E0h at 10000.
    let mut b = Bench::new();
    assert!(b
        .send(&request(MASTER, 1, false, 0, 0, false), ms(0))
        .is_some());
    b.send(&request_with(2, rww), ms(10)).unwrap();
    assert_eq!(
        b.drive.read(ObjectId::new(0x60E0, 0)).unwrap(),
        Value::U16(10_000)
    );
}
