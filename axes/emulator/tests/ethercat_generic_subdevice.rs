//! A standard CiA 402 SubDevice of another vendor against the master (in-process emulator):
//! 1C32h:02 read-only or absent, no 60F4h, distributed clocks optional, required or absent.
//! What is optional is skipped with a warning where SYNC0 sets the cycle; what cannot work is
//! refused with an error that names the SubDevice, the axis and the object or AL status code.

use cellrt_cia402::pdo::{PdoLayout, RxPdo};
use cellrt_cia402::{
    profile, Controlword, CycleTime, Cycles, CyclicBus, DriveModel, FsaState, ModeOfOperation,
    PdoEntry, SharedProfile,
};
use cellrt_emulator::ethercat::{segment_of, InProcessLink};
use cellrt_emulator::ethercat::{CycleTimeObject, EmulatedDc, Segment, SubDeviceVariant};
use cellrt_emulator::{SimDrive, SimDriveParams};
use cellrt_ethercat::identity::ExpectedIdentity;
use cellrt_ethercat::master::{EthercatBus, EthercatError, SegmentConfig, SegmentDrive};
use cellrt_ethercat::register::AlState;

/// Bring-ups one at a time (ethercrab's bring-up timeouts run on the real clock).
static BRING_UP: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// The generic profile with an identity and a TxPDO without 60F4h (as `[axes.pdo] tx` gives it).
fn without_60f4() -> SharedProfile {
    let tx = [
        PdoEntry::object(0x6041, 0, 16),
        PdoEntry::object(0x6061, 0, 8),
        PdoEntry::padding(8),
        PdoEntry::object(0x6064, 0, 32),
        PdoEntry::object(0x606C, 0, 32),
        PdoEntry::object(0x603F, 0, 16),
    ];
    let p = profile(DriveModel::GenericCia402).with_identity(Some(0xCE11_0000), Some(0xCE11_0402));
    SharedProfile::new(p.with_pdo_maps(&p.pdo.rx.entries, &tx).unwrap())
}

const CYCLE_US: u32 = 1000;

/// Brings up one generic SubDevice presented as `variant`, the master with DC `dc`.
fn bring_up(variant: SubDeviceVariant, dc: bool) -> Result<EthercatBus, EthercatError> {
    let cycle = CycleTime::from_micros(CYCLE_US).unwrap();
    let p = without_60f4();
    let mut segment = Segment::new(vec![SimDrive::new(
        p.clone(),
        SimDriveParams::default(),
        cycle,
    )]);
    segment.station_mut(0).unwrap().present(variant);
    let config = SegmentConfig {
        cycle,
        drives: vec![SegmentDrive {
            axis: "x".into(),
            identity: ExpectedIdentity::of_profile(&p),
            profile: p,
            mode: ModeOfOperation::CyclicSyncPosition,
            amplifier: None,
            distributed_clocks: dc,
            fixed_pdo: Default::default(),
            startup_sdo: Vec::new(),
        }],
    };
    let _one = BRING_UP.lock().unwrap_or_else(|e| e.into_inner());
    EthercatBus::bring_up(config, Box::new(InProcessLink::new(segment)))
}

/// Enables the drive and moves it 2000 counts in csp (2 counts per cycle); returns the final
/// FSA state and the actual position.
fn enable_and_move(bus: &mut EthercatBus) -> (Option<FsaState>, i32) {
    let p = without_60f4();
    let (rxl, txl) = (PdoLayout::new(&p.pdo.rx), PdoLayout::new(&p.pdo.tx));
    let start = txl.decode_tx(bus.tx_image(0)).unwrap().position_actual;
    let mut target = start;
    for (n, cw) in [
        (50, Controlword::SHUTDOWN),
        (50, Controlword::SWITCH_ON),
        (100, Controlword::ENABLE_OPERATION),
        (1000, Controlword::ENABLE_OPERATION),
        (200, Controlword::ENABLE_OPERATION),
    ]
    .into_iter()
    .enumerate()
    .flat_map(|(phase, (n, cw))| std::iter::repeat_n((phase, cw), n))
    .map(|(phase, cw)| (phase == 3, cw))
    {
        if n {
            target += 2;
        }
        let rx = RxPdo {
            controlword: cw,
            mode: ModeOfOperation::CyclicSyncPosition.as_i8(),
            target_position: target,
            ..RxPdo::default()
        };
        rxl.encode_rx(&rx, bus.rx_image_mut(0)).unwrap();
        bus.exchange(Cycles(1)).unwrap();
        let _ = bus.deadline_correction_ns();
    }
    let tx = txl.decode_tx(bus.tx_image(0)).unwrap();
    assert_eq!(target - start, 2000);
    (tx.statusword.state(), tx.position_actual - start)
}

fn op(bus: &mut EthercatBus) -> AlState {
    segment_of(bus.link_mut()).unwrap().stations()[0].al_state()
}

#[test]
fn read_only_cycle_time_that_matches_and_no_60f4h_come_up_with_dc_on_and_off() {
    for dc in [true, false] {
        let variant = SubDeviceVariant {
            cycle_time: CycleTimeObject::ReadOnly(CYCLE_US * 1000),
            following_error_object: false,
            distributed_clocks: EmulatedDc::Optional,
            ..SubDeviceVariant::default()
        };
        let mut bus = bring_up(variant, dc).unwrap_or_else(|e| panic!("dc {dc}: {e}"));
        assert_eq!(op(&mut bus), AlState::Op, "dc {dc}");
        // The value already held: nothing written, nothing to warn about.
        assert!(bus.bring_up_warnings().is_empty(), "dc {dc}");
        let (state, moved) = enable_and_move(&mut bus);
        assert_eq!(state, Some(FsaState::OperationEnabled), "dc {dc}");
        assert_eq!(moved, 2000, "dc {dc}");
        assert_eq!(bus.counters().wkc_errors, 0, "dc {dc}");
        // Free-run: no SYNC0 grid, no phase error to report.
        assert_eq!(bus.dc_phase_error_ns().is_some(), dc, "dc {dc}");
    }
}

#[test]
fn a_refused_cycle_time_is_a_warning_under_sync0_and_an_error_in_free_run() {
    let other = SubDeviceVariant {
        cycle_time: CycleTimeObject::ReadOnly(2_000_000),
        ..SubDeviceVariant::default()
    };
    let bus = bring_up(other, true).expect("SYNC0 sets the cycle");
    let w = bus.bring_up_warnings();
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!(
        (w[0].sdo.index, w[0].sdo.sub, w[0].sdo.abort),
        (0x1C32, 2, 0x0601_0002)
    );
    assert_eq!((w[0].read, w[0].wanted), (Some(2_000_000), 1_000_000));
    assert_eq!(w[0].axis, "x");
    let text = w[0].to_string();
    assert!(
        text.contains("axis 'x'") && text.contains("1C32h:02"),
        "{text}"
    );

    let absent = SubDeviceVariant {
        cycle_time: CycleTimeObject::Absent,
        ..SubDeviceVariant::default()
    };
    let bus = bring_up(absent, true).expect("SYNC0 sets the cycle");
    let w = bus.bring_up_warnings();
    assert_eq!((w[0].sdo.abort, w[0].read), (0x0602_0000, None), "{w:?}");

    for variant in [other, absent] {
        let e = bring_up(variant, false).unwrap_err();
        assert!(matches!(e, EthercatError::CycleTimeNotSet { .. }), "{e}");
        let text = e.to_string();
        for part in [
            "SubDevice 0",
            "axis 'x'",
            "1C32h:02",
            "distributed_clocks = false",
        ] {
            assert!(text.contains(part), "{part:?} in {text}");
        }
    }
}

#[test]
fn dc_on_a_subdevice_without_dc_is_refused_by_name_and_dc_off_runs_it() {
    let absent = SubDeviceVariant {
        distributed_clocks: EmulatedDc::Absent,
        ..SubDeviceVariant::default()
    };
    let e = bring_up(absent, true).unwrap_err();
    let text = e.to_string();
    assert!(
        matches!(e, EthercatError::NoDistributedClocks { .. }),
        "{text}"
    );
    assert!(
        text.contains("axis 'x'") && text.contains("0008h"),
        "{text}"
    );
    let mut bus = bring_up(absent, false).expect("free-run");
    let (state, moved) = enable_and_move(&mut bus);
    assert_eq!((state, moved), (Some(FsaState::OperationEnabled), 2000));
}

#[test]
fn a_subdevice_that_needs_sync0_refuses_safe_op_in_free_run_and_the_error_says_why() {
    let required = SubDeviceVariant {
        distributed_clocks: EmulatedDc::Required,
        ..SubDeviceVariant::default()
    };
    let e = bring_up(required, false).unwrap_err();
    let EthercatError::StateRefused(r) = &e else {
        panic!("{e}");
    };
    assert_eq!((r.position, r.axis.as_str()), (0, "x"));
    assert_eq!(
        (r.requested, r.state, r.code),
        ("SAFE-OP", "PRE-OP", 0x0030)
    );
    assert_eq!(r.name, "generic CiA 402 drive", "the SII name");
    let text = e.to_string();
    for part in [
        "invalid DC SYNC configuration",
        "it refused no SDO",
        "likely cause: the drive needs (or rejects) SYNC0",
        "distributed_clocks",
    ] {
        assert!(text.contains(part), "{part:?} in {text}");
    }
    bring_up(required, true).expect("with SYNC0 it comes up");
}
