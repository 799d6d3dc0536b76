//! Multi-axis amplifiers (MR-J5W2/W3-G-N1) as one EtherCAT SubDevice each, against the
//! in-process emulator (MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4): bring-up to OP, the per-axis PDO mapping objects
//! read back by SDO at the offset indexes, TV-2 (axis B enabled, axis A untouched), TV-6/TV-7
//! (0.125 ms refused, a J5W3 at 0.25 ms with 72 bytes of RxPDO), TV-8 (pv/tq refused), and the
//! refusal of inconsistent amplifier labels and slots.

mod mailbox_common;

use cellrt_cia402::pdo::{PdoLayout, RxPdo};
use cellrt_cia402::profiles::mr_j5_g_n1::axis_index;
use cellrt_cia402::{
    profile, AcyclicBus, Controlword, CycleTime, Cycles, CyclicBus, DriveModel, FaultInjection,
    FsaState, ModeOfOperation,
};
use cellrt_emulator::ethercat::Segment;
use cellrt_emulator::ethercat::{segment_of, InProcessLink};
use cellrt_emulator::{SimDrive, SimDriveParams};
use cellrt_ethercat::identity::{emulator_product_code, ExpectedIdentity};
use cellrt_ethercat::master::{
    AmplifierSlot, EthercatBus, EthercatError, SegmentConfig, SegmentDrive,
};
use cellrt_ethercat::register::AlState;

/// One axis of the test cell: its model and, on a multi-axis unit, (label, slot).
type AxisSpec = (DriveModel, Option<(&'static str, u8)>);

/// A J5W2 with both axes and a J5W3 with all three.
const UNITS: [AxisSpec; 5] = [
    (DriveModel::MrJ5W2GN1, Some(("w2", 0))),
    (DriveModel::MrJ5W2GN1, Some(("w2", 1))),
    (DriveModel::MrJ5W3GN1, Some(("w3", 0))),
    (DriveModel::MrJ5W3GN1, Some(("w3", 1))),
    (DriveModel::MrJ5W3GN1, Some(("w3", 2))),
];

fn config(axes: &[AxisSpec], cycle: CycleTime) -> SegmentConfig {
    SegmentConfig {
        cycle,
        drives: axes
            .iter()
            .enumerate()
            .map(|(i, &(m, amp))| SegmentDrive {
                axis: format!("a{i}"),
                profile: profile(m).into(),
                identity: ExpectedIdentity::of_profile(profile(m)),
                mode: ModeOfOperation::CyclicSyncPosition,
                amplifier: amp.map(|(label, slot)| AmplifierSlot {
                    label: label.into(),
                    slot,
                }),
                distributed_clocks: true,
                fixed_pdo: Default::default(),
                startup_sdo: Vec::new(),
            })
            .collect(),
    }
}

/// The emulated segment `config` describes: one station per SubDevice, every slot a drive.
fn segment(config: &SegmentConfig) -> Segment {
    let units = config
        .stations()
        .expect("a consistent cell")
        .iter()
        .map(|st| {
            st.slots
                .iter()
                .map(|_| SimDrive::new(st.model, SimDriveParams::default(), config.cycle))
                .collect()
        })
        .collect();
    Segment::of_units(units).expect("whole units")
}

/// Bring-ups one at a time (ethercrab's bring-up timeouts run on the real clock).
static BRING_UP: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn bring_up_config(config: SegmentConfig) -> Result<EthercatBus, EthercatError> {
    let _one = BRING_UP.lock().unwrap_or_else(|e| e.into_inner());
    let link = InProcessLink::new(segment(&config));
    EthercatBus::bring_up(config, Box::new(link))
}

fn bring_up(axes: &[AxisSpec], cycle_us: u32) -> EthercatBus {
    let cycle = CycleTime::from_micros(cycle_us).unwrap();
    bring_up_config(config(axes, cycle)).expect("bring-up")
}

fn stations(bus: &mut EthercatBus) -> &Segment {
    segment_of(bus.link_mut())
        .map(|s| &*s)
        .expect("in-process link")
}

/// Runs `cycles` exchanges commanding `cws[axis]` (holding position); returns each axis' FSA
/// state after the last one.
fn run(
    bus: &mut EthercatBus,
    axes: &[AxisSpec],
    cycles: u32,
    cws: &[Controlword],
) -> Vec<FsaState> {
    let layouts: Vec<(PdoLayout, PdoLayout)> = axes
        .iter()
        .map(|(m, _)| {
            (
                PdoLayout::new(&profile(*m).pdo.rx),
                PdoLayout::new(&profile(*m).pdo.tx),
            )
        })
        .collect();
    for _ in 0..cycles {
        for (axis, (rxl, txl)) in layouts.iter().enumerate() {
            let tx = txl.decode_tx(bus.tx_image(axis)).unwrap();
            let rx = RxPdo {
                controlword: cws[axis],
                mode: ModeOfOperation::CyclicSyncPosition.as_i8(),
                target_position: tx.position_actual,
                ..RxPdo::default()
            };
            rxl.encode_rx(&rx, bus.rx_image_mut(axis)).unwrap();
        }
        bus.exchange(Cycles(1)).unwrap();
        let _ = bus.deadline_correction_ns();
    }
    layouts
        .iter()
        .enumerate()
        .map(|(axis, (_, txl))| {
            let sw = txl.decode_tx(bus.tx_image(axis)).unwrap().statusword;
            sw.state().expect("a decodable statusword")
        })
        .collect()
}

fn enable(bus: &mut EthercatBus, axes: &[AxisSpec], enabled: &[bool]) -> Vec<FsaState> {
    let cw = |c: Controlword| -> Vec<Controlword> {
        enabled
            .iter()
            .map(|&e| if e { c } else { Controlword(0) })
            .collect()
    };
    run(bus, axes, 50, &cw(Controlword::SHUTDOWN));
    run(bus, axes, 50, &cw(Controlword::SWITCH_ON));
    run(bus, axes, 300, &cw(Controlword::ENABLE_OPERATION))
}

/// TV-7: the J5W3 at 0.25 ms with the default 1st RxPDO on every axis (3 × 24 = 72 bytes) is
/// accepted; the J5W2 and J5W3 are one SubDevice each, with their own identity.
#[test]
fn a_j5w2_and_a_j5w3_come_up_to_op_as_one_subdevice_each() {
    let mut bus = bring_up(&UNITS, 250);
    assert_eq!(bus.axis_count(), 5);
    let segment = stations(&mut bus);
    assert_eq!(segment.stations().len(), 2);
    for (st, (model, axes)) in segment
        .stations()
        .iter()
        .zip([(DriveModel::MrJ5W2GN1, 2), (DriveModel::MrJ5W3GN1, 3)])
    {
        assert_eq!(st.al_state(), AlState::Op);
        assert_eq!(st.al_status_code(), 0);
        assert_eq!(st.identity().product_code, emulator_product_code(model));
        assert_eq!(st.drives().len(), axes);
    }
    for axis in 0..5 {
        assert_eq!(bus.rx_image_mut(axis).len(), 24);
        assert_eq!(bus.tx_image(axis).len(), 24);
    }
    let states = enable(&mut bus, &UNITS, &[true; 5]);
    assert_eq!(states, vec![FsaState::OperationEnabled; 5]);
    assert_eq!(bus.counters().wkc_errors, 0);
}

/// A mixed line: a 1-axis drive, a J5W2 whose axes are not next to each other in the config,
/// a J5W3 with one slot used, another 1-axis drive.
#[test]
fn a_mixed_segment_of_single_and_multi_axis_drives_comes_up_and_enables() {
    let axes: [AxisSpec; 5] = [
        (DriveModel::MrJ3T04, None),
        (DriveModel::MrJ5W2GN1, Some(("w2", 1))),
        (DriveModel::MrJ5W3GN1, Some(("w3", 0))),
        (DriveModel::MrJ5W2GN1, Some(("w2", 0))),
        (DriveModel::MrJ5GN1, None),
    ];
    let mut bus = bring_up(&axes, 1000);
    assert_eq!(stations(&mut bus).stations().len(), 4);
    let states = enable(&mut bus, &axes, &[true; 5]);
    assert_eq!(states, vec![FsaState::OperationEnabled; 5]);
    // Axis a1 is slot 1 (B) of the J5W2 at station 1, a3 its slot 0 (A); the J5W3's unused
    // slots B and C stay in Switch on disabled.
    let segment = stations(&mut bus);
    let w2 = &segment.stations()[1];
    assert_eq!(w2.drives()[0].state(), FsaState::OperationEnabled);
    assert_eq!(w2.drives()[1].state(), FsaState::OperationEnabled);
    let w3 = &segment.stations()[2];
    assert_eq!(w3.drives()[0].state(), FsaState::OperationEnabled);
    for d in &w3.drives()[1..] {
        assert_eq!(d.state(), FsaState::SwitchOnDisabled);
    }
}

/// §1.5: each axis' mapping objects at +10h carry the axis-A objects at +800h (CiA 402) and
/// +1000h (manufacturer); 1C12h/1C13h assign one PDO per axis [inferred].
#[test]
fn pdo_layouts_read_back_by_sdo_sit_at_the_offset_indexes() {
    let mut bus = bring_up(&UNITS, 1000);
    let p = profile(DriveModel::MrJ5W3GN1);
    for (axis, slot) in [(2usize, 0u8), (3, 1), (4, 2)] {
        for map in [&p.pdo.rx, &p.pdo.tx] {
            let index = axis_index(map.index, slot).unwrap();
            assert_eq!(index, map.index + 0x10 * u16::from(slot));
            // Read on axis A's station object, by the offset index itself.
            let n = bus.sdo_upload(2, index, 0).unwrap();
            assert_eq!(n as usize, map.entries.len(), "{index:#06x}:00");
            for (i, e) in map.entries.iter().enumerate() {
                let w = bus.sdo_upload(2, index, i as u8 + 1).unwrap() as u32;
                let at = if e.is_padding() {
                    *e
                } else {
                    cellrt_cia402::PdoEntry {
                        index: axis_index(e.index, slot).unwrap(),
                        ..*e
                    }
                };
                assert_eq!(w, at.mapping_word(), "{index:#06x}:{:02}", i + 1);
            }
            // The per-axis API reads the same object by its axis-A index.
            assert_eq!(bus.sdo_upload(axis, map.index, 0).unwrap(), n);
        }
    }
    assert_eq!(
        bus.sdo_upload(2, 0x6840, 0).unwrap(),
        bus.sdo_upload(3, 0x6040, 0).unwrap()
    );
    for (assign, base) in [(0x1C12, 0x1600), (0x1C13, 0x1A00)] {
        assert_eq!(bus.sdo_upload(2, assign, 0).unwrap(), 3);
        for slot in 0..3u16 {
            let idx = bus.sdo_upload(2, assign, slot as u8 + 1).unwrap();
            assert_eq!(idx as u16, base + 0x10 * slot);
        }
        assert_eq!(bus.sdo_upload(0, assign, 0).unwrap(), 2, "the J5W2");
    }
}

/// TV-2: axis B of a J5W2 enabled through 6840h/6841h while axis A (6040h) stays in Switch on
/// disabled; leaving OP re-initialises both (one ESM per station, §2.1).
#[test]
fn tv_2_axis_b_of_a_j5w2_is_enabled_and_axis_a_is_untouched() {
    let axes = &UNITS[..2];
    let mut bus = bring_up(axes, 1000);
    let states = enable(&mut bus, axes, &[false, true]);
    assert_eq!(
        states,
        vec![FsaState::SwitchOnDisabled, FsaState::OperationEnabled]
    );
    // 6841h by SDO (axis B's statusword at its offset index) against the PDO.
    let sw_b = bus.sdo_upload(1, 0x6041, 0).unwrap() as u16;
    assert_eq!(sw_b & 0x006F, 0x0027, "6841h: Operation enabled");
    let sw_a = bus.sdo_upload(0, 0x6041, 0).unwrap() as u16;
    assert_eq!(sw_a & 0x004F, 0x0040, "6041h: Switch on disabled");
    {
        let w2 = &stations(&mut bus).stations()[0];
        assert_eq!(w2.drives()[0].state(), FsaState::SwitchOnDisabled);
        assert_eq!(w2.drives()[1].state(), FsaState::OperationEnabled);
    }
    bus.leave_op().expect("PRE-OP");
    let w2 = &stations(&mut bus).stations()[0];
    assert_eq!(w2.al_state(), AlState::PreOp);
    for d in w2.drives() {
        assert_ne!(d.state(), FsaState::OperationEnabled);
    }
    let p = profile(DriveModel::MrJ5W2GN1);
    assert_eq!(w2.drives()[0].alarm(), None, "axis A was not switched on");
    assert_eq!(w2.drives()[1].alarm(), Some(p.comm.leave_op_alarm));
}

/// TV-8: pv on a J5W2 axis is refused in the RxPDO (6861h keeps csp) and by the master's
/// configuration check.
#[test]
fn tv_8_pv_and_tq_are_refused_on_a_multi_axis_unit() {
    let axes = &UNITS[..2];
    let mut bus = bring_up(axes, 1000);
    enable(&mut bus, axes, &[true, true]);
    let rxl = PdoLayout::new(&profile(DriveModel::MrJ5W2GN1).pdo.rx);
    let txl = PdoLayout::new(&profile(DriveModel::MrJ5W2GN1).pdo.tx);
    for _ in 0..50 {
        let tx = txl.decode_tx(bus.tx_image(1)).unwrap();
        let rx = RxPdo {
            controlword: Controlword::ENABLE_OPERATION,
            mode: ModeOfOperation::ProfileVelocity.as_i8(),
            target_position: tx.position_actual,
            ..RxPdo::default()
        };
        rxl.encode_rx(&rx, bus.rx_image_mut(1)).unwrap();
        bus.exchange(Cycles(1)).unwrap();
    }
    let tx = txl.decode_tx(bus.tx_image(1)).unwrap();
    assert_eq!(
        tx.mode_display,
        ModeOfOperation::CyclicSyncPosition.as_i8(),
        "6861h keeps csp"
    );

    let cycle = CycleTime::from_micros(1000).unwrap();
    for mode in [
        ModeOfOperation::ProfileVelocity,
        ModeOfOperation::ProfileTorque,
    ] {
        let mut cfg = config(axes, cycle);
        cfg.drives[1].mode = mode;
        let e = bring_up_config(cfg).unwrap_err();
        assert!(matches!(e, EthercatError::Mode { .. }), "{e}");
        let text = e.to_string();
        assert!(
            text.contains("axis 'a1'") && text.contains(mode.as_str()),
            "{text}"
        );
    }
}

/// TV-6: the J5W2/W3 do not run 0.125 ms; the master refuses it before bring-up, naming the axis.
#[test]
fn tv_6_a_125_us_cycle_is_refused_for_a_multi_axis_unit() {
    let cycle = CycleTime::from_micros(125).unwrap();
    let cfg = config(&UNITS, cycle);
    let e = EthercatBus::bring_up(cfg, Box::new(InProcessLink::new(Segment::new(Vec::new()))))
        .unwrap_err();
    assert!(matches!(e, EthercatError::CycleTime { .. }), "{e}");
    assert!(
        e.to_string().contains("axis 'a0'") && e.to_string().contains("125 µs"),
        "{e}"
    );
}

/// Labels and slots that do not describe units are refused by name.
#[test]
fn inconsistent_amplifier_labels_and_slots_are_refused_by_name() {
    let cycle = CycleTime::from_micros(1000).unwrap();
    let cases: [(&[AxisSpec], &str); 3] = [
        (
            &[
                (DriveModel::MrJ5W2GN1, Some(("u", 0))),
                (DriveModel::MrJ5W2GN1, Some(("u", 0))),
            ],
            "already axis 'a0'",
        ),
        (
            &[
                (DriveModel::MrJ5W2GN1, Some(("u", 0))),
                (DriveModel::MrJ5W3GN1, Some(("u", 1))),
            ],
            "is a mr-j5w2-g-n1, not a mr-j5w3-g-n1",
        ),
        (&[(DriveModel::MrJ5W2GN1, Some(("u", 2)))], "slots 0..=1"),
    ];
    for (axes, reason) in cases {
        let e = config(axes, cycle).stations().unwrap_err();
        assert!(matches!(e, EthercatError::Amplifier { .. }), "{e}");
        let text = e.to_string();
        assert!(
            text.contains(reason) && text.contains("amplifier"),
            "{text}"
        );
    }
}

/// MR-J5-G-N1 manual §5, §1.5: an alarm of axis B of a J5W2 (and of axis C of a J5W3) is an
/// Emergency of that axis: the code is the axis' 603Fh (at its offset index 683Fh / 703Fh),
/// the slot is named in manufacturer byte 0 (cellrt's emulator layout); the SDO read of the
/// axis' 603Fh after it succeeds.
#[test]
fn an_alarm_of_axis_b_or_c_is_an_emergency_of_that_axis() {
    use cellrt_cia402::bus::MailboxNotice;
    use cellrt_ethercat::emergency::Emergency;
    let mut bus = bring_up(&UNITS, 1000);
    enable(&mut bus, &UNITS, &[true; 5]);
    let code = profile(DriveModel::MrJ5W2GN1).limits.following_error_alarm;
    assert!(bus.inject_alarm(1, code));
    assert!(bus.inject_alarm(4, code.wrapping_add(2)));
    run(&mut bus, &UNITS, 1, &[Controlword::ENABLE_OPERATION; 5]);
    let mut got = mailbox_common::await_notices(&mut bus, 2);
    got.sort_by_key(|n| format!("{n:?}"));
    let mut want = vec![
        MailboxNotice::Emergency {
            axis: 1,
            emergency: Emergency::of_alarm(code, 1),
        },
        MailboxNotice::Emergency {
            axis: 4,
            emergency: Emergency::of_alarm(code.wrapping_add(2), 2),
        },
    ];
    want.sort_by_key(|n| format!("{n:?}"));
    assert_eq!(got, want);
    assert!(mailbox_common::no_notice_within(&mut bus, 10));
    assert_eq!(
        bus.sdo_upload(1, 0x603F, 0).ok().map(|v| v as u16),
        Some(code)
    );
    assert_eq!(
        bus.sdo_upload(4, 0x603F, 0).ok().map(|v| v as u16),
        Some(code.wrapping_add(2))
    );
    assert_eq!(
        bus.sdo_upload(0, 0x603F, 0).ok().map(|v| v as u16),
        Some(0),
        "axis A has no alarm"
    );
}

/// An alarm of axis B raised just before an SDO to axis A of the same J5W2: the Emergency
/// comes where A's SDO response should be, and is still recorded for axis B (the slot it
/// names, with its manufacturer bytes, which the patched ethercrab passes on); A's read is
/// repeated and succeeds.
#[test]
fn an_emergency_of_axis_b_met_by_an_sdo_of_axis_a_is_axis_bs() {
    use cellrt_cia402::bus::MailboxNotice;
    use cellrt_ethercat::emergency::Emergency;
    let mut bus = bring_up(&UNITS, 1000);
    let code = profile(DriveModel::MrJ5W2GN1).limits.following_error_alarm;
    segment_of(bus.link_mut())
        .and_then(|s| s.station_mut(0))
        .and_then(|st| st.drive_at_mut(1))
        .expect("the J5W2's axis B")
        .inject_alarm(code);
    assert_eq!(
        bus.sdo_upload(0, 0x603F, 0).ok().map(|v| v as u16),
        Some(0),
        "axis A has no alarm"
    );
    assert_eq!(
        bus.take_mailbox_notice(),
        Some(MailboxNotice::Emergency {
            axis: 1,
            emergency: Emergency::of_alarm(code, 1),
        })
    );
}
