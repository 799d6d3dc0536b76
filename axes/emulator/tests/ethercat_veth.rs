//! The EtherCAT backend over real raw sockets: a veth pair, the emulator on one end (with a
//! scheduled frame delay), the MainDevice on the other. Needs root (CAP_NET_ADMIN for the pair, CAP_NET_RAW for the
//! sockets) and `ip` from iproute2; says so plainly and skips where either is missing.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use cellrt_cia402::{profile, CycleTime, Cycles, CyclicBus, DriveModel, ModeOfOperation};
use cellrt_emulator::ethercat::{wire, FaultSchedule, ScheduledFault, Segment, WireFault};
use cellrt_emulator::{SimDrive, SimDriveParams};
use cellrt_ethercat::identity::ExpectedIdentity;
use cellrt_ethercat::master::{EthercatBus, RawSocketLink, SegmentConfig, SegmentDrive};
use cellrt_ethercat::raw_socket::RawSocket;
use cellrt_test_support::veth::VethPair;

/// The tests of this file one at a time: each sets up a veth pair (`ip`, RTNL) and paces a
/// real-time loop, which the other's set-up would disturb.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[test]
fn a_segment_on_a_veth_pair_comes_up_and_exchanges_over_raw_sockets() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|p| p.into_inner());
    // SAFETY: geteuid has no preconditions.
    if unsafe { libc::geteuid() } != 0 {
        eprintln!("SKIPPED: the veth EtherCAT test needs root (CAP_NET_ADMIN, CAP_NET_RAW)");
        return;
    }
    let Some(pair) = VethPair::create("crtveth0") else {
        eprintln!("SKIPPED: cannot create a veth pair (is iproute2 installed?)");
        return;
    };
    exchange_over(&pair);
}

/// One bring-up and 200 paced exchanges. The emulator excuses gaps in the frames as stalls of
/// this (loaded) machine (`HostStalls::Excused`), so a drive alarms only for frames it lost;
/// the master waits up to 200 ms for each frame, so a held-back emulator loses none.
fn exchange_over(pair: &VethPair) {
    let ct = CycleTime::from_micros(1000).unwrap();
    let models = [
        DriveModel::MrJ3T04,
        DriveModel::MrJ4TM,
        DriveModel::MrJetGN1,
        DriveModel::MrJ5GN1,
    ];
    let mut segment = Segment::new(
        models
            .iter()
            .map(|&m| SimDrive::new(profile(m), SimDriveParams::default(), ct))
            .collect(),
    );
    // Frames 100 µs late for 50 cycles from cycle 100: held by the emulator while it serves
    // on, returned well within the master's timeout.
    let mut faults = FaultSchedule::new(
        vec![ScheduledFault {
            cycle: 100,
            fault: WireFault::FrameDelay {
                delay_ns: 100_000,
                frames: 50,
            },
        }],
        ct,
        models.len(),
    )
    .unwrap();
    let socket = RawSocket::open(&pair.peer()).expect("emulator socket");
    let stop = Arc::new(AtomicBool::new(false));
    let stop2 = stop.clone();
    let emulator = std::thread::spawn(move || {
        // As `cellrt drive-sim` does: the drives' end answers at once (as root).
        cellrt_test_support::sched::fifo(81);
        let stats = wire::serve(
            &socket,
            &mut segment,
            &mut faults,
            wire::HostStalls::Excused {
                cycle: ct.as_duration(),
            },
            &stop2,
        )
        .expect("serve");
        (stats, segment)
    });
    let link = RawSocketLink::open(pair.name(), Duration::from_millis(200)).expect("master socket");
    let config = SegmentConfig {
        cycle: ct,
        drives: models
            .iter()
            .enumerate()
            .map(|(i, &m)| SegmentDrive {
                axis: format!("a{i}"),
                profile: profile(m).into(),
                identity: ExpectedIdentity::of_profile(profile(m)),
                mode: ModeOfOperation::CyclicSyncPosition,
                amplifier: None,
                distributed_clocks: true,
                fixed_pdo: Default::default(),
                startup_sdo: Vec::new(),
            })
            .collect(),
    };
    let mut bus = EthercatBus::bring_up(config, Box::new(link)).expect("bring-up over veth");
    // The paced loop as the RT thread runs (after bring-up: the mailbox worker it starts
    // stays SCHED_OTHER), until the attempt ends.
    let _fifo = cellrt_test_support::sched::Fifo::enter(80);
    // Paced at the 1 ms cycle and aligned to the DC SYNC0 grid as the RT loop is (the
    // correction taken every cycle): the emulated drives take one frame per SYNC0. Unaligned,
    // a frame near a SYNC0 edge plus the 100 µs delay below missed SYNC0s (AL.36 on the J3).
    let start = std::time::Instant::now();
    let mut last = start;
    let mut max_gap = Duration::ZERO;
    let mut shift_ns = 0i64;
    for k in 1..=200u32 {
        bus.exchange(Cycles(1)).expect("exchange");
        let now = std::time::Instant::now();
        max_gap = max_gap.max(now - last);
        last = now;
        shift_ns += bus.deadline_correction_ns();
        let next_ns = i64::from(k) * 1_000_000 + shift_ns;
        let next = start + Duration::from_nanos(next_ns.max(0) as u64);
        std::thread::sleep(next.saturating_duration_since(std::time::Instant::now()));
    }
    bus.leave_op().expect("PRE-OP");
    assert_eq!(bus.counters().lost, 0);
    assert_eq!(bus.counters().wkc_errors, 0);
    stop.store(true, Ordering::Release);
    let (stats, segment) = emulator.join().unwrap();
    assert!(stats.frames >= 200, "{stats:?}");
    assert_eq!((stats.delayed, stats.lost), (50, 0), "{stats:?}");
    assert_eq!(stats.injected.frame_delay, 1, "{stats:?}");
    let emulator_gap = Duration::from_nanos(stats.max_gap_ns);
    for st in segment.stations() {
        assert_eq!(
            st.drive().alarm(),
            None,
            "{} (SYNC0 edges missed {}; longest gap: master loop {max_gap:?}, emulator {emulator_gap:?})",
            st.drive().profile().name,
            st.missed_sync0()
        );
        assert!(st.exchanges() >= 190, "{}", st.exchanges());
    }
}

/// A BRD of the ESC type register (0000h) from `source`: returns the reply's working counter
/// and its source MAC, or `None` when nothing came back within 200 ms.
fn broadcast_read(socket: &RawSocket, source: [u8; 6], index: u8) -> Option<(u16, [u8; 6])> {
    use cellrt_ethercat::frame::{self, Command, FrameBuilder};
    let mut buf = [0u8; 128];
    let mut b = FrameBuilder::new(&mut buf, source);
    let span = b.push(Command::Brd, index, 0, &[0; 2]).unwrap();
    let len = b.finish();
    socket.send(&buf[..len]).unwrap();
    let deadline = std::time::Instant::now() + Duration::from_millis(200);
    loop {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        let n = socket.recv(&mut buf, left).unwrap()?;
        if n > span.wkc_offset + 1 && buf[span.header_offset + 1] == index {
            let mac = buf[6..12].try_into().unwrap();
            return Some((frame::wkc(&buf, &span), mac));
        }
    }
}

#[test]
fn a_maindevice_is_served_whatever_its_source_mac() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|p| p.into_inner());
    // SAFETY: geteuid has no preconditions.
    if unsafe { libc::geteuid() } != 0 {
        eprintln!("SKIPPED: the veth EtherCAT test needs root (CAP_NET_ADMIN, CAP_NET_RAW)");
        return;
    }
    let Some(pair) = VethPair::create("crtveth1") else {
        eprintln!("SKIPPED: cannot create a veth pair (is iproute2 installed?)");
        return;
    };
    let ct = CycleTime::from_micros(1000).unwrap();
    let mut segment = Segment::new(
        (0..3)
            .map(|_| SimDrive::new(profile(DriveModel::MrJ4TM), SimDriveParams::default(), ct))
            .collect(),
    );
    let mut faults = FaultSchedule::new(Vec::new(), ct, 3).unwrap();
    let socket = RawSocket::open(&pair.peer()).expect("emulator socket");
    let stop = Arc::new(AtomicBool::new(false));
    let stop2 = stop.clone();
    let emulator = std::thread::spawn(move || {
        wire::serve(
            &socket,
            &mut segment,
            &mut faults,
            wire::HostStalls::Counted,
            &stop2,
        )
        .expect("serve")
    });
    let master = RawSocket::open(pair.name()).expect("master socket");
    // A software MainDevice's locally administered address (SOEM-based tools send from such
    // ones), and a universally administered one: both reach every ESC; the replies come back
    // marked as an ESC marks them, and the master's socket never mistakes its own frame for one.
    for (k, source) in [
        [0xCA, 0xDE, 0xCA, 0xDE, 0xDE, 0xFF],
        [0x00, 0x1B, 0x21, 1, 2, 3],
    ]
    .into_iter()
    .enumerate()
    {
        let (wkc, mac) = broadcast_read(&master, source, 0x40 + k as u8)
            .unwrap_or_else(|| panic!("no reply to a frame from {source:02X?}"));
        assert_eq!(wkc, 3, "every station read the register");
        assert_eq!(mac[0], source[0] | 0x02, "the reply's source is marked");
        assert_eq!(mac[1..], source[1..]);
    }
    stop.store(true, Ordering::Release);
    let stats = emulator.join().unwrap();
    assert_eq!(stats.frames, 2, "{stats:?}");
}
