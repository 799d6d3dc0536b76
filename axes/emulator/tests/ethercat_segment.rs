//! The EtherCAT backend against the in-process SubDevice emulator: bring-up of a segment of
//! each EtherCAT model to OP through ethercrab, PDO layouts read back by SDO, the cyclic
//! exchange, identity and cycle-time refusals, and the clean and dirty shutdowns.

mod mailbox_common;

use cellrt_cia402::pdo::{PdoLayout, RxPdo};
use cellrt_cia402::{
    profile, AcyclicBus, Controlword, CycleTime, Cycles, CyclicBus, DriveModel, FaultInjection,
    FsaState, ModeOfOperation, SharedProfile,
};
use cellrt_emulator::ethercat::Segment;
use cellrt_emulator::ethercat::{segment_of, InProcessLink};
use cellrt_emulator::{SimDrive, SimDriveParams};
use cellrt_ethercat::identity::ExpectedIdentity;
use cellrt_ethercat::master::{EthercatBus, EthercatError, SegmentConfig, SegmentDrive};
use cellrt_ethercat::register::{AlState, AlStatus};

const MODELS: [DriveModel; 5] = [
    DriveModel::MrJ3T04,
    DriveModel::MrJ4TM,
    DriveModel::MrJetGN1,
    DriveModel::MrJ5GN1,
    DriveModel::GenericCia402,
];

/// The identity a generic CiA 402 drive is given here, as a cell config's `[axes.ethercat]`
/// would (placeholders in the style of the emulator's, not a vendor's values).
const GENERIC_VENDOR: u32 = 0xCE11_0000;
const GENERIC_PRODUCT: u32 = 0xCE11_0402;

/// The profile of `m` as a cell config gives it: the generic CiA 402 model with the identity
/// the config names (the model has none of its own), the others as they are.
fn prof(m: DriveModel) -> SharedProfile {
    match m {
        DriveModel::GenericCia402 => SharedProfile::new(
            profile(m).with_identity(Some(GENERIC_VENDOR), Some(GENERIC_PRODUCT)),
        ),
        _ => profile(m).shared(),
    }
}

fn segment(models: &[DriveModel], cycle: CycleTime) -> Segment {
    Segment::new(
        models
            .iter()
            .map(|&m| SimDrive::new(prof(m), SimDriveParams::default(), cycle))
            .collect(),
    )
}

fn config(models: &[DriveModel], cycle: CycleTime) -> SegmentConfig {
    SegmentConfig {
        cycle,
        drives: models
            .iter()
            .enumerate()
            .map(|(i, &m)| SegmentDrive {
                axis: format!("a{i}"),
                profile: prof(m),
                identity: ExpectedIdentity::of_profile(&prof(m)),
                mode: ModeOfOperation::CyclicSyncPosition,
                amplifier: None,
                distributed_clocks: true,
                fixed_pdo: Default::default(),
                startup_sdo: Vec::new(),
            })
            .collect(),
    }
}

/// Bring-ups one at a time: ethercrab's bring-up timeouts (EEPROM, mailbox) run on the real
/// clock, and a dozen tests bringing segments up side by side on a loaded 2-CPU machine can
/// starve one of them past a timeout. The cyclic exchange after it runs on the virtual clock.
static BRING_UP: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn bring_up_one(
    config: SegmentConfig,
    link: Box<dyn cellrt_ethercat::master::Link>,
) -> Result<EthercatBus, EthercatError> {
    let _one = BRING_UP.lock().unwrap_or_else(|e| e.into_inner());
    EthercatBus::bring_up(config, link)
}

fn bring_up(models: &[DriveModel]) -> EthercatBus {
    let cycle = CycleTime::from_micros(1000).unwrap();
    let link = InProcessLink::new(segment(models, cycle));
    bring_up_one(config(models, cycle), Box::new(link)).expect("bring-up")
}

fn stations(bus: &mut EthercatBus) -> &Segment {
    segment_of(bus.link_mut())
        .map(|s| &*s)
        .expect("in-process link")
}

#[test]
fn a_segment_of_each_ethercat_model_comes_up_to_op() {
    let mut bus = bring_up(&MODELS);
    assert_eq!(bus.axis_count(), MODELS.len());
    for (i, st) in stations(&mut bus).stations().iter().enumerate() {
        assert_eq!(st.al_state(), AlState::Op, "station {i}");
        assert_eq!(st.al_status_code(), 0, "station {i}");
        assert_eq!(st.station_address(), 0x1000 + i as u16);
    }
    for (axis, m) in MODELS.iter().enumerate() {
        let p = profile(*m);
        assert_eq!(bus.rx_image_mut(axis).len(), p.pdo.rx.byte_len());
        assert_eq!(bus.tx_image(axis).len(), p.pdo.tx.byte_len());
    }
}

#[test]
fn pdo_layouts_read_back_by_sdo_equal_the_profiles() {
    let mut bus = bring_up(&MODELS);
    for (axis, m) in MODELS.iter().enumerate() {
        let p = profile(*m);
        for map in [&p.pdo.rx, &p.pdo.tx] {
            let n = bus.sdo_upload(axis, map.index, 0).unwrap();
            assert_eq!(n as usize, map.entries.len(), "{m:?} {:#06x}:00", map.index);
            for (i, e) in map.entries.iter().enumerate() {
                let w = bus.sdo_upload(axis, map.index, i as u8 + 1).unwrap() as u32;
                assert_eq!(w, e.mapping_word(), "{m:?} {:#06x}:{:02}", map.index, i + 1);
            }
        }
        assert_eq!(
            bus.sdo_upload(axis, 0x1C12, 1).unwrap() as u16,
            p.pdo.rx.index
        );
        assert_eq!(
            bus.sdo_upload(axis, 0x1C13, 1).unwrap() as u16,
            p.pdo.tx.index
        );
    }
}

/// Runs `cycles` exchanges commanding `cw` to every axis (holding position, counter + 1 each
/// cycle); returns the FSA state of each axis after the last one.
fn run(
    bus: &mut EthercatBus,
    models: &[DriveModel],
    cycles: u32,
    cw: Controlword,
    counter: &mut u8,
) -> Vec<Option<FsaState>> {
    let layouts: Vec<(PdoLayout, PdoLayout)> = models
        .iter()
        .map(|m| {
            (
                PdoLayout::new(&profile(*m).pdo.rx),
                PdoLayout::new(&profile(*m).pdo.tx),
            )
        })
        .collect();
    for _ in 0..cycles {
        *counter = counter.wrapping_add(1);
        for (axis, (rxl, txl)) in layouts.iter().enumerate() {
            let tx = txl.decode_tx(bus.tx_image(axis)).unwrap();
            let rx = RxPdo {
                controlword: cw,
                mode: ModeOfOperation::CyclicSyncPosition.as_i8(),
                target_position: tx.position_actual,
                counter: *counter,
                ..RxPdo::default()
            };
            rxl.encode_rx(&rx, bus.rx_image_mut(axis)).unwrap();
        }
        bus.exchange(Cycles(1)).unwrap();
        // As the RT loop does: keep the cycle aligned to the SYNC0 grid.
        let _ = bus.deadline_correction_ns();
    }
    layouts
        .iter()
        .enumerate()
        .map(|(axis, (_, txl))| {
            txl.decode_tx(bus.tx_image(axis))
                .unwrap()
                .statusword
                .state()
        })
        .collect()
}

fn enable(bus: &mut EthercatBus, models: &[DriveModel], counter: &mut u8) -> Vec<Option<FsaState>> {
    run(bus, models, 50, Controlword::SHUTDOWN, counter);
    run(bus, models, 50, Controlword::SWITCH_ON, counter);
    run(bus, models, 300, Controlword::ENABLE_OPERATION, counter)
}

#[test]
fn the_cyclic_exchange_enables_every_drive_through_the_emulated_segment() {
    let mut bus = bring_up(&MODELS);
    let mut counter = 0;
    let states = enable(&mut bus, &MODELS, &mut counter);
    assert_eq!(states, vec![Some(FsaState::OperationEnabled); MODELS.len()]);
    assert_eq!(bus.counters().wkc_errors, 0);
    assert_eq!(bus.counters().frames, 400);
}

#[test]
fn clean_shutdown_leaves_no_alarm_and_a_dirty_one_raises_each_models_leaving_op_alarm() {
    let mut bus = bring_up(&MODELS);
    let mut counter = 0;
    enable(&mut bus, &MODELS, &mut counter);
    // Clean: Shutdown by controlword (Ready to switch on), then PRE-OP.
    let states = run(&mut bus, &MODELS, 20, Controlword::SHUTDOWN, &mut counter);
    assert_eq!(states, vec![Some(FsaState::ReadyToSwitchOn); MODELS.len()]);
    bus.leave_op().expect("every SubDevice in PRE-OP");
    for st in stations(&mut bus).stations() {
        assert_eq!(st.al_state(), AlState::PreOp);
        assert_eq!(st.drive().alarm(), None, "{}", st.drive().profile().name);
    }

    // Dirty: leaving OP while Operation enabled.
    let mut bus = bring_up(&MODELS);
    enable(&mut bus, &MODELS, &mut counter);
    bus.leave_op().expect("PRE-OP");
    for st in stations(&mut bus).stations() {
        let p = st.drive().profile();
        assert_eq!(
            st.drive().alarm(),
            Some(p.comm.leave_op_alarm),
            "{}",
            p.name
        );
    }
}

#[test]
fn a_drive_whose_identity_is_not_its_configured_model_is_refused_by_name() {
    let cycle = CycleTime::from_micros(1000).unwrap();
    // The wire has an MR-J4-TM where the config says MR-J3-T04.
    let link = InProcessLink::new(segment(&[DriveModel::MrJ5GN1, DriveModel::MrJ4TM], cycle));
    let e = bring_up_one(
        config(&[DriveModel::MrJ5GN1, DriveModel::MrJ3T04], cycle),
        Box::new(link),
    )
    .unwrap_err();
    assert!(
        matches!(e, EthercatError::Identity { position: 1, .. }),
        "{e}"
    );
    let text = e.to_string();
    assert!(
        text.contains("axis 'a1'") && text.contains("mr-j3-t04") && text.contains("0x00000201"),
        "{text}"
    );

    let link = InProcessLink::new(segment(&[DriveModel::MrJ5GN1], cycle));
    let e = bring_up_one(
        config(&[DriveModel::MrJ5GN1, DriveModel::MrJ5GN1], cycle),
        Box::new(link),
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            EthercatError::Count {
                expected: 2,
                found: 1
            }
        ),
        "{e}"
    );
}

#[test]
fn a_cycle_time_the_model_does_not_allow_is_refused_before_bring_up() {
    // MR-J3-T04 runs 0.5, 1 and 2 ms only (MR-J3-T04 manual §1.1, §1.3, §8.4.2, §5.1).
    let cycle = CycleTime::from_micros(250).unwrap();
    let link = InProcessLink::new(segment(&[DriveModel::MrJ3T04], cycle));
    let e = bring_up_one(config(&[DriveModel::MrJ3T04], cycle), Box::new(link)).unwrap_err();
    assert!(matches!(e, EthercatError::CycleTime { .. }), "{e}");
    assert!(
        e.to_string().contains("250 µs") && e.to_string().contains("axis 'a0'"),
        "{e}"
    );
}

#[test]
fn lost_frames_raise_the_drives_communication_alarm_and_count_on_the_master() {
    let models = [DriveModel::MrJ3T04];
    let mut bus = bring_up(&models);
    let mut counter = 0;
    assert_eq!(
        enable(&mut bus, &models, &mut counter),
        vec![Some(FsaState::OperationEnabled)]
    );
    // MR-J3-T04: AL.36 after about 7 ms without RxPDO (MR-J3-T04 manual §8.5, §8.6); 20 frames lost.
    assert!(bus.link_mut().drop_frames(20));
    for _ in 0..20 {
        assert_eq!(
            bus.exchange(Cycles(1)),
            Err(cellrt_cia402::BusError::FrameLost)
        );
    }
    assert_eq!(bus.counters().lost, 20);
    let states = run(
        &mut bus,
        &models,
        1,
        Controlword::ENABLE_OPERATION,
        &mut counter,
    );
    assert_eq!(states, vec![Some(FsaState::Fault)]);
    let alarm = stations(&mut bus).stations()[0].drive().alarm();
    assert_eq!(alarm, Some(0x36), "AL.36");
}

/// A mapping other than the model's default, as a cell configuration gives it: the master writes
/// it by SDO, the emulated drive takes it at SAFE-OP, and the process data follow it
/// (MR-J3-T04 TV-PDO-1 (docs/test-vectors.md)'s csv-only RxPDO; a shortened MR-J5-G-N1 TxPDO).
#[test]
fn a_variable_mapping_is_written_taken_by_the_drive_and_exchanged() {
    use cellrt_cia402::PdoEntry;
    let cycle = CycleTime::from_micros(1000).unwrap();
    let models = [DriveModel::MrJ3T04, DriveModel::MrJ5GN1];
    let j3 = profile(DriveModel::MrJ3T04);
    let j3_rx = [
        PdoEntry::object(0x2020, 0, 8),
        PdoEntry::padding(8),
        PdoEntry::object(0x6040, 0, 16),
        PdoEntry::object(0x2001, 0, 16),
        PdoEntry::object(0x60FF, 0, 32),
    ];
    let j5 = profile(DriveModel::MrJ5GN1);
    let j5_tx: Vec<PdoEntry> = j5
        .pdo
        .tx
        .entries
        .iter()
        .copied()
        .filter(|e| matches!(e.index, 0x6041 | 0x6064 | 0x606C | 0x6061))
        .collect();
    let profiles = [
        SharedProfile::new(j3.with_pdo_maps(&j3_rx, &j3.pdo.tx.entries).unwrap()),
        SharedProfile::new(j5.with_pdo_maps(&j5.pdo.rx.entries, &j5_tx).unwrap()),
    ];
    let mut cfg = config(&models, cycle);
    for (d, p) in cfg.drives.iter_mut().zip(profiles.clone()) {
        d.profile = p;
        d.mode = ModeOfOperation::CyclicSyncVelocity;
    }
    let link = InProcessLink::new(segment(&models, cycle));
    let mut bus = bring_up_one(cfg, Box::new(link)).expect("bring-up");
    assert_eq!(bus.rx_image_mut(0).len(), 10);
    assert_eq!(bus.tx_image(1).len(), 2 + 4 + 4 + 1);
    for (axis, p) in profiles.iter().enumerate() {
        assert_eq!(
            stations(&mut bus).stations()[axis].drive().profile().pdo.rx,
            p.pdo.rx,
            "axis {axis} runs the written RxPDO"
        );
        for map in [&p.pdo.rx, &p.pdo.tx] {
            let n = bus.sdo_upload(axis, map.index, 0).unwrap();
            assert_eq!(n as usize, map.entries.len());
            for (i, e) in map.entries.iter().enumerate() {
                let w = bus.sdo_upload(axis, map.index, i as u8 + 1).unwrap() as u32;
                assert_eq!(w, e.mapping_word());
            }
        }
    }
    // Enable both in csv and turn them at 100 r/min-ish for 200 ms: the drives decode the
    // remapped images (60FFh at byte 6 of the J3's 10-byte RxPDO).
    let layouts: Vec<(PdoLayout, PdoLayout)> = profiles
        .iter()
        .map(|p| (PdoLayout::new(&p.pdo.rx), PdoLayout::new(&p.pdo.tx)))
        .collect();
    let mut counter = 0u8;
    let mut step = |bus: &mut EthercatBus, cw: Controlword, velocity: i32| {
        counter = counter.wrapping_add(1);
        for (axis, (rxl, _)) in layouts.iter().enumerate() {
            let rx = RxPdo {
                controlword: cw,
                mode: ModeOfOperation::CyclicSyncVelocity.as_i8(),
                target_velocity: velocity,
                counter,
                ..RxPdo::default()
            };
            rxl.encode_rx(&rx, bus.rx_image_mut(axis)).unwrap();
        }
        bus.exchange(Cycles(1)).unwrap();
    };
    for (cw, n) in [
        (Controlword::SHUTDOWN, 50),
        (Controlword::SWITCH_ON, 50),
        (Controlword::ENABLE_OPERATION, 300),
    ] {
        for _ in 0..n {
            step(&mut bus, cw, 0);
        }
    }
    let read = |bus: &EthercatBus| -> Vec<_> {
        layouts
            .iter()
            .enumerate()
            .map(|(axis, (_, txl))| txl.decode_tx(bus.tx_image(axis)).unwrap())
            .collect()
    };
    let before = read(&bus);
    for tx in &before {
        assert_eq!(tx.statusword.state(), Some(FsaState::OperationEnabled));
    }
    for _ in 0..200 {
        step(&mut bus, Controlword::ENABLE_OPERATION, 100_000);
    }
    let after = read(&bus);
    for (axis, (b, a)) in before.iter().zip(&after).enumerate() {
        assert!(
            a.position_actual > b.position_actual + 100 && a.velocity_actual > 0,
            "axis {axis} turned: {b:?} -> {a:?}"
        );
        assert_eq!(a.statusword.state(), Some(FsaState::OperationEnabled));
    }
    assert_eq!(bus.counters().wkc_errors, 0);
}

/// Distributed clocks: every cyclic frame reads the reference clock's system time, and the
/// master moves its cycle so that the frame passes 1/8 cycle after SYNC0 — at once on the first
/// reading, then by a bounded share of the error (a late frame is pulled back gradually).
#[test]
fn the_cycle_is_aligned_to_the_dc_sync0_grid() {
    let cycle = CycleTime::from_micros(1000).unwrap();
    let mut bus = bring_up(&MODELS);
    assert_eq!(bus.dc_phase_error_ns(), None, "no cyclic frame yet");
    let run = |bus: &mut EthercatBus, n: usize| -> Vec<i64> {
        (0..n)
            .map(|_| {
                bus.exchange(Cycles(1)).unwrap();
                bus.deadline_correction_ns()
            })
            .collect()
    };
    // SYNC0 starts 10 ms after the DC set-up; by 30 cycles the master has locked on.
    let corrections = run(&mut bus, 30);
    let e = bus.dc_phase_error_ns().expect("locked");
    assert!(e.abs() < 1_000, "phase error after lock-in: {e} ns");
    // The phase the master starts at is not the same from run to run (a run under load once
    // started 2.3 µs from the grid): the first reading moves the cycle by whatever it is.
    assert!(
        corrections.iter().any(|&c| c != 0),
        "the first reading moved the cycle: {corrections:?}"
    );
    // A frame 300 µs late (the RT thread was held up): the error shows it, and the master pulls
    // its cycle back by at most 2 % of a cycle per frame, without missing a SYNC0.
    bus.link_mut().advance(300_000);
    let mut corrections = run(&mut bus, 1);
    let e = bus.dc_phase_error_ns().unwrap();
    assert!(
        (e - 300_000).abs() < 1_000,
        "the late frame's phase error: {e}"
    );
    corrections.extend(run(&mut bus, 200));
    assert!(corrections
        .iter()
        .all(|c| c.abs() <= cycle.as_nanos() as i64 / 50));
    assert!(
        corrections.iter().sum::<i64>() < -290_000,
        "{corrections:?}"
    );
    let e = bus.dc_phase_error_ns().unwrap();
    assert!(e.abs() < 5_000, "phase error after the pull-back: {e} ns");
    assert_eq!(bus.counters().lost, 0);
    for (i, st) in stations(&mut bus).stations().iter().enumerate() {
        assert_eq!(
            st.drive().tx_pdo().error_code,
            0,
            "station {i}: no SYNC0 missed"
        );
    }
}

/// A segment of generic CiA 402 drives (`drive = "cia402"`): each comes up to OP with the
/// identity its config gives (1018h read back by SDO), a drive of another vendor or product is
/// refused by name, and a custom mapping (a csv RxPDO carrying the touch-probe function 60B8h,
/// a TxPDO with the digital inputs 60FDh) is written, taken and exchanged.
#[test]
fn generic_cia402_drives_come_up_with_the_configured_identity_and_mapping() {
    use cellrt_cia402::PdoEntry;
    let cycle = CycleTime::from_micros(500).unwrap();
    let generic = profile(DriveModel::GenericCia402);
    let models = [DriveModel::GenericCia402, DriveModel::GenericCia402];
    let rx = [
        PdoEntry::object(0x6040, 0, 16),
        PdoEntry::object(0x6060, 0, 8),
        PdoEntry::padding(8),
        PdoEntry::object(0x60FF, 0, 32),
        PdoEntry::object(0x60B8, 0, 16),
    ];
    let tx = [
        PdoEntry::object(0x6041, 0, 16),
        PdoEntry::object(0x6061, 0, 8),
        PdoEntry::padding(8),
        PdoEntry::object(0x6064, 0, 32),
        PdoEntry::object(0x606C, 0, 32),
        PdoEntry::object(0x60FD, 0, 32),
        PdoEntry::object(0x603F, 0, 16),
    ];
    let remapped = SharedProfile::new(
        prof(DriveModel::GenericCia402)
            .with_pdo_maps(&rx, &tx)
            .unwrap(),
    );
    assert_eq!(remapped.vendor_id(), Some(GENERIC_VENDOR));
    // The config: axis 0 on the default maps, axis 1 remapped, both in csv.
    let mut cfg = config(&models, cycle);
    cfg.drives[1].profile = remapped.clone();
    for d in &mut cfg.drives {
        d.mode = ModeOfOperation::CyclicSyncVelocity;
    }
    let link = InProcessLink::new(segment(&models, cycle));
    let mut bus = EthercatBus::bring_up(cfg.clone(), Box::new(link)).expect("bring-up");
    for (i, st) in stations(&mut bus).stations().iter().enumerate() {
        assert_eq!(st.al_state(), AlState::Op, "station {i}");
        assert_eq!(st.identity().vendor_id, GENERIC_VENDOR);
        assert_eq!(st.identity().product_code, GENERIC_PRODUCT);
    }
    for axis in 0..2 {
        assert_eq!(
            bus.sdo_upload(axis, 0x1018, 1).unwrap() as u32,
            GENERIC_VENDOR
        );
        assert_eq!(
            bus.sdo_upload(axis, 0x1018, 2).unwrap() as u32,
            GENERIC_PRODUCT
        );
        // 6502h: hm, csp, csv, cst.
        assert_eq!(bus.sdo_upload(axis, 0x6502, 0).unwrap(), 0x3A0);
    }
    assert_eq!(bus.rx_image_mut(0).len(), generic.pdo.rx.byte_len());
    assert_eq!(bus.rx_image_mut(1).len(), 2 + 1 + 1 + 4 + 2);
    assert_eq!(bus.tx_image(1).len(), 2 + 1 + 1 + 4 + 4 + 4 + 2);
    assert_eq!(
        stations(&mut bus).stations()[1].drive().profile().pdo.rx,
        remapped.pdo.rx,
        "axis 1 runs the written RxPDO"
    );
    for (i, e) in remapped.pdo.tx.entries.iter().enumerate() {
        let w = bus.sdo_upload(1, 0x1A00, i as u8 + 1).unwrap() as u32;
        assert_eq!(w, e.mapping_word());
    }
    // Enabled and turned in csv through both layouts.
    let layouts: Vec<(PdoLayout, PdoLayout)> = [prof(DriveModel::GenericCia402), remapped.clone()]
        .iter()
        .map(|p| (PdoLayout::new(&p.pdo.rx), PdoLayout::new(&p.pdo.tx)))
        .collect();
    let step = |bus: &mut EthercatBus, cw: Controlword, velocity: i32| {
        for (axis, (rxl, _)) in layouts.iter().enumerate() {
            let rx = RxPdo {
                controlword: cw,
                mode: ModeOfOperation::CyclicSyncVelocity.as_i8(),
                target_velocity: velocity,
                ..RxPdo::default()
            };
            rxl.encode_rx(&rx, bus.rx_image_mut(axis)).unwrap();
        }
        bus.exchange(Cycles(1)).unwrap();
    };
    for (cw, n) in [
        (Controlword::SHUTDOWN, 50),
        (Controlword::SWITCH_ON, 50),
        (Controlword::ENABLE_OPERATION, 300),
    ] {
        for _ in 0..n {
            step(&mut bus, cw, 0);
        }
    }
    let read =
        |bus: &EthercatBus, axis: usize| layouts[axis].1.decode_tx(bus.tx_image(axis)).unwrap();
    let before: Vec<_> = (0..2).map(|a| read(&bus, a)).collect();
    for _ in 0..200 {
        step(&mut bus, Controlword::ENABLE_OPERATION, 100_000);
    }
    for (axis, b) in before.iter().enumerate() {
        let a = read(&bus, axis);
        assert_eq!(b.statusword.state(), Some(FsaState::OperationEnabled));
        assert_eq!(a.mode_display, 9, "axis {axis}: 6061h = csv");
        assert!(
            a.position_actual > b.position_actual + 100 && a.velocity_actual > 0,
            "axis {axis} turned: {b:?} -> {a:?}"
        );
    }
    assert_eq!(bus.counters().wkc_errors, 0);
    // Leaving OP while enabled: the generic leaving-OP code, 8100h.
    bus.leave_op().expect("PRE-OP");
    for st in stations(&mut bus).stations() {
        assert_eq!(st.drive().alarm(), Some(0x8100));
    }

    // Another vendor's drive where the config names this identity: refused by name.
    let mut wrong = cfg.clone();
    wrong.drives[1].identity = ExpectedIdentity {
        vendor_id: 0x0000_0002,
        product_code: Some(GENERIC_PRODUCT),
    };
    let link = InProcessLink::new(segment(&models, cycle));
    let e = EthercatBus::bring_up(wrong, Box::new(link)).unwrap_err();
    assert!(
        matches!(e, EthercatError::Identity { position: 1, .. }),
        "{e}"
    );
    let text = e.to_string();
    assert!(
        text.contains("axis 'a1'") && text.contains("cia402") && text.contains("0xce110000"),
        "{text}"
    );
    // The same vendor, another product: refused too.
    let mut wrong = cfg;
    wrong.drives[0].identity.product_code = Some(GENERIC_PRODUCT + 1);
    let link = InProcessLink::new(segment(&models, cycle));
    let e = EthercatBus::bring_up(wrong, Box::new(link)).unwrap_err();
    assert!(
        matches!(e, EthercatError::Identity { position: 0, .. }),
        "{e}"
    );
}

// Wire faults of the emulated segment (issue "Networked drives over EtherCAT": drop, delay or
// corrupt frames or single datagrams, lose the link), on a segment of the four Mitsubishi models.

/// The Mitsubishi EtherCAT models, one each, in line order.
const MITSUBISHI: [DriveModel; 4] = [
    DriveModel::MrJ3T04,
    DriveModel::MrJ4TM,
    DriveModel::MrJetGN1,
    DriveModel::MrJ5GN1,
];

use cellrt_cia402::BusError;
use cellrt_ethercat::register as reg;

/// The alarm `model`'s communication check raises for lost process data.
fn loss_alarm(model: DriveModel) -> u16 {
    profile(model).comm.check.loss_alarm()
}

/// The drives' alarms.
fn alarms(bus: &mut EthercatBus) -> Vec<Option<u16>> {
    stations(bus)
        .stations()
        .iter()
        .map(|s| s.drive().alarm())
        .collect()
}

/// Per station: the register byte at `addr`.
fn registers(bus: &mut EthercatBus, addr: u16) -> Vec<u8> {
    stations(bus)
        .stations()
        .iter()
        .map(|s| s.register(addr))
        .collect()
}

/// Runs `n` exchanges holding the last outputs; returns their results.
fn exchanges(bus: &mut EthercatBus, n: usize) -> Vec<Result<(), BusError>> {
    (0..n)
        .map(|_| {
            let r = bus.exchange(Cycles(1));
            let _ = bus.deadline_correction_ns();
            r
        })
        .collect()
}

fn enabled(models: &[DriveModel]) -> (EthercatBus, u8) {
    enabled_with(models, InProcessLink::new)
}

fn enabled_with(
    models: &[DriveModel],
    link: impl FnOnce(Segment) -> InProcessLink,
) -> (EthercatBus, u8) {
    let cycle = CycleTime::from_micros(1000).unwrap();
    let link = link(segment(models, cycle));
    let mut bus = bring_up_one(config(models, cycle), Box::new(link)).expect("bring-up");
    let mut counter = 0;
    assert_eq!(
        enable(&mut bus, models, &mut counter),
        vec![Some(FsaState::OperationEnabled); models.len()]
    );
    (bus, counter)
}

/// Every axis' RxPDO: Operation enabled in csp at position 0, with the incremental `counter`.
fn hold_enabled_at_zero(bus: &mut EthercatBus, layouts: &[PdoLayout], counter: u8) {
    for (axis, l) in layouts.iter().enumerate() {
        let rx = RxPdo {
            controlword: Controlword::ENABLE_OPERATION,
            mode: ModeOfOperation::CyclicSyncPosition.as_i8(),
            target_position: 0,
            counter,
            ..RxPdo::default()
        };
        l.encode_rx(&rx, bus.rx_image_mut(axis)).unwrap();
    }
}

fn missed_sync0(bus: &mut EthercatBus) -> Vec<u64> {
    stations(bus)
        .stations()
        .iter()
        .map(|s| s.missed_sync0())
        .collect()
}

#[test]
fn a_frame_delay_below_the_timeout_arrives_late_and_past_sync0_is_applied_a_cycle_late() {
    let models = [DriveModel::MrJ3T04];
    // 300 µs: inside the cycle's margin before SYNC0, nothing visible.
    let (mut bus, _) = enabled(&models);
    assert!(bus.link_mut().delay_frames(300_000, 20));
    assert!(exchanges(&mut bus, 20).iter().all(Result::is_ok));
    assert_eq!(bus.counters().lost, 0);
    assert_eq!(missed_sync0(&mut bus), [0]);

    // 900 µs with a 1 ms timeout: the frames come back, but each reaches the drive after the
    // SYNC0 it was meant for: the first delayed frame leaves one SYNC0 without data, the
    // others are applied one cycle late; when the delay ends the first undelayed frame lands
    // before the same SYNC0 as the last delayed one and waits for the next.
    let (mut bus, mut counter) = enabled_with(&models, |s| {
        InProcessLink::with_frame_timeout(s, std::time::Duration::from_millis(1))
    });
    assert!(bus.link_mut().delay_frames(900_000, 20));
    assert!(exchanges(&mut bus, 20).iter().all(Result::is_ok));
    assert_eq!(bus.counters().lost, 0);
    assert_eq!(missed_sync0(&mut bus), [1]);
    let states = run(
        &mut bus,
        &models,
        50,
        Controlword::ENABLE_OPERATION,
        &mut counter,
    );
    assert_eq!(states, vec![Some(FsaState::OperationEnabled)]);
    assert_eq!(alarms(&mut bus), [None]);
    assert_eq!(missed_sync0(&mut bus), [1]);

    // The same delay against the default 500 µs timeout: lost at the master every cycle (the
    // drive still takes them, late).
    let (mut bus, _) = enabled(&models);
    assert!(bus.link_mut().delay_frames(900_000, 20));
    let r = exchanges(&mut bus, 20);
    assert!(r.iter().all(|r| *r == Err(BusError::FrameLost)), "{r:?}");
    assert_eq!(bus.counters().lost, 20);
    assert_eq!(missed_sync0(&mut bus), [1]);
    assert!(exchanges(&mut bus, 5).iter().all(Result::is_ok));
}

#[test]
fn a_corrupted_frame_is_not_processed_behind_the_bad_link_counts_rx_errors_and_is_lost() {
    let (mut bus, mut counter) = enabled(&MITSUBISHI);
    let before: Vec<u64> = stations(&mut bus)
        .stations()
        .iter()
        .map(|s| s.exchanges())
        .collect();
    // Bit errors on the link between SubDevice 1 and SubDevice 2 for 20 frames.
    assert!(bus.link_mut().corrupt_frames(2, 20));
    let r = exchanges(&mut bus, 20);
    assert!(r.iter().all(|r| *r == Err(BusError::FrameLost)), "{r:?}");
    assert_eq!(bus.counters().lost, 20);
    let done: Vec<u64> = stations(&mut bus)
        .stations()
        .iter()
        .zip(&before)
        .map(|(s, b)| s.exchanges() - b)
        .collect();
    assert_eq!(done, [20, 20, 0, 0], "stations in front still process it");
    // Invalid frame counter port 0: only the station behind the bad link; the one after it
    // counts the marked frame as forwarded on port 0; on the way back every station with a
    // station behind it counts it forwarded on port 1.
    assert_eq!(registers(&mut bus, reg::RX_ERROR_COUNTER), [0, 0, 20, 0]);
    assert_eq!(registers(&mut bus, reg::RX_ERROR_COUNTER + 2), [0; 4]);
    assert_eq!(
        registers(&mut bus, reg::FORWARDED_RX_ERROR_COUNTER),
        [0, 0, 0, 20]
    );
    assert_eq!(
        registers(&mut bus, reg::FORWARDED_RX_ERROR_COUNTER + 1),
        [20, 20, 20, 0]
    );
    // The drives behind it lost 20 frames: their communication alarms; the others run on.
    run(
        &mut bus,
        &MITSUBISHI,
        1,
        Controlword::ENABLE_OPERATION,
        &mut counter,
    );
    assert_eq!(
        alarms(&mut bus),
        [
            None,
            None,
            Some(loss_alarm(MITSUBISHI[2])),
            Some(loss_alarm(MITSUBISHI[3]))
        ]
    );
    // Counters saturate at FFh.
    assert!(bus.link_mut().corrupt_frames(0, 300));
    let _ = exchanges(&mut bus, 300);
    assert_eq!(registers(&mut bus, reg::RX_ERROR_COUNTER), [255, 0, 20, 0]);
    assert_eq!(
        registers(&mut bus, reg::FORWARDED_RX_ERROR_COUNTER),
        [0, 255, 255, 255]
    );
    assert_eq!(bus.counters().lost, 320);
}

#[test]
fn a_dropped_datagram_returns_the_frame_with_working_counter_zero() {
    let (mut bus, mut counter) = enabled(&MITSUBISHI);
    let before = bus.counters();
    assert!(bus.link_mut().drop_datagrams(20));
    let r = exchanges(&mut bus, 20);
    assert!(
        r.iter().all(|r| *r
            == Err(BusError::WorkingCounter {
                expected: 12,
                found: 0
            })),
        "{r:?}"
    );
    assert_eq!(bus.counters().wkc_errors - before.wkc_errors, 20);
    assert_eq!(bus.counters().lost, 0);
    run(
        &mut bus,
        &MITSUBISHI,
        1,
        Controlword::ENABLE_OPERATION,
        &mut counter,
    );
    let expected: Vec<Option<u16>> = MITSUBISHI.iter().map(|&m| Some(loss_alarm(m))).collect();
    assert_eq!(alarms(&mut bus), expected);
}

#[test]
fn a_lost_link_shows_in_dl_status_stops_frames_behind_it_and_comes_back() {
    let link_bits = reg::DL_LINK_PORT0 | reg::DL_COMM_PORT0;
    let port1_bits = reg::DL_LINK_PORT1 | reg::DL_COMM_PORT1;
    let dl = |bus: &mut EthercatBus| -> Vec<u16> {
        stations(bus)
            .stations()
            .iter()
            .map(|s| s.register16(reg::DL_STATUS))
            .collect()
    };

    // The master's own link (the default): every frame lost, every drive alarms.
    let models = [DriveModel::MrJ3T04, DriveModel::MrJ4TM];
    let (mut bus, mut counter) = enabled(&models);
    let up = dl(&mut bus);
    assert!(bus.link_mut().lose_link(0, 20));
    assert_eq!(dl(&mut bus)[0] & link_bits, 0, "port 0 link down");
    assert_eq!(dl(&mut bus)[1], up[1]);
    let r = exchanges(&mut bus, 20);
    assert!(r.iter().all(|r| *r == Err(BusError::FrameLost)), "{r:?}");
    assert_eq!(dl(&mut bus), up, "the link is back after 20 frames");
    assert_eq!(registers(&mut bus, reg::LOST_LINK_COUNTER), [1, 0]);
    run(
        &mut bus,
        &models,
        1,
        Controlword::ENABLE_OPERATION,
        &mut counter,
    );
    // MR-J3-T04 AL.36 (about 7 ms without RxPDO), MR-J4-TM AL. 86.1.
    assert_eq!(alarms(&mut bus), [Some(0x36), Some(0x0861)]);

    // Further down the line: the SubDevice in front closes its port 1 and returns the frame
    // with its own working counter only.
    let (mut bus, mut counter) = enabled(&MITSUBISHI);
    let up = dl(&mut bus);
    assert!(bus.link_mut().lose_link(2, 20));
    let down = dl(&mut bus);
    assert_eq!(down[1] & port1_bits, 0);
    assert_ne!(down[1] & reg::DL_LOOP_PORT1, 0, "port 1 closed");
    assert_eq!(down[2] & link_bits, 0);
    assert_eq!((down[0], down[3]), (up[0], up[3]));
    let r = exchanges(&mut bus, 20);
    assert!(
        r.iter().all(|r| *r
            == Err(BusError::WorkingCounter {
                expected: 12,
                found: 6
            })),
        "{r:?}"
    );
    assert_eq!(dl(&mut bus), up);
    assert_eq!(
        registers(&mut bus, reg::LOST_LINK_COUNTER + 1),
        [0, 1, 0, 0]
    );
    assert_eq!(registers(&mut bus, reg::LOST_LINK_COUNTER), [0, 0, 1, 0]);
    run(
        &mut bus,
        &MITSUBISHI,
        1,
        Controlword::ENABLE_OPERATION,
        &mut counter,
    );
    assert_eq!(
        alarms(&mut bus),
        [
            None,
            None,
            Some(loss_alarm(MITSUBISHI[2])),
            Some(loss_alarm(MITSUBISHI[3]))
        ]
    );
    assert!(!bus.link_mut().lose_link(4, 1), "no SubDevice 4");
    assert!(!bus.link_mut().corrupt_frames(4, 1));
}

/// An overrun of the master's RT loop on an in-process segment: with the link excusing host
/// stalls (what `cellrt run` uses for `interface = "in-process"`) the skipped cycles are time for
/// the drives, not missed SYNC0s, so no drive counts a lost frame or faults; without it (the
/// emulator on a network) the same stall is missed SYNC0s at every station.
#[test]
fn an_in_process_segment_excusing_host_stalls_runs_the_drives_on() {
    for excuse in [true, false] {
        let (mut bus, mut counter) = enabled_with(&MODELS, |s| {
            let link = InProcessLink::new(s);
            if excuse {
                link.excusing_host_stalls()
            } else {
                link
            }
        });
        let layouts: Vec<PdoLayout> = MODELS
            .iter()
            .map(|m| PdoLayout::new(&profile(*m).pdo.rx))
            .collect();
        for k in 0..40 {
            counter = counter.wrapping_add(1);
            hold_enabled_at_zero(&mut bus, &layouts, counter);
            // Every tenth cycle the loop overran by four cycles.
            let elapsed = if k % 10 == 9 { Cycles(5) } else { Cycles(1) };
            bus.exchange(elapsed).unwrap();
        }
        let missed = missed_sync0(&mut bus);
        if excuse {
            assert_eq!(missed, vec![0; MODELS.len()]);
            assert_eq!(alarms(&mut bus), vec![None; MODELS.len()]);
        } else {
            assert!(missed.iter().all(|m| *m == 16), "{missed:?}");
        }
    }
}

/// Host stalls excused before a frame reaches the drives add up: an overrun, a frame lost on the
/// wire, another overrun, and the drives count exactly the one lost frame as a missed SYNC0
/// (what `cellrt drive-sim --excuse-host-stalls` relies on, gap by gap between frames).
#[test]
fn host_stalls_excused_around_a_lost_frame_add_up_and_the_lost_frame_still_counts() {
    let (mut bus, mut counter) =
        enabled_with(&MODELS, |s| InProcessLink::new(s).excusing_host_stalls());
    let layouts: Vec<PdoLayout> = MODELS
        .iter()
        .map(|m| PdoLayout::new(&profile(*m).pdo.rx))
        .collect();
    let before = missed_sync0(&mut bus);
    for (k, elapsed) in [1, 5, 5, 1].into_iter().enumerate() {
        counter = counter.wrapping_add(1);
        hold_enabled_at_zero(&mut bus, &layouts, counter);
        if k == 1 {
            assert!(bus.link_mut().drop_frames(1));
        }
        let _ = bus.exchange(Cycles(elapsed));
    }
    let missed: Vec<u64> = missed_sync0(&mut bus)
        .iter()
        .zip(&before)
        .map(|(m, b)| m - b)
        .collect();
    assert_eq!(missed, vec![1; MODELS.len()]);
}

/// The process-data watchdog and the master's AL status monitoring: a link lost for longer
/// than the SyncManager watchdog (0420h × 0400h: 100 ms by default) leaves the SubDevices
/// behind it without output writes; the first frame through afterwards finds their watchdog
/// expired (0440h bit 0 clear, 0442h counted), and they are in SAFE-OP with AL status code
/// 001Bh. The master reads every SubDevice's AL status in each cyclic frame and reports it per
/// axis. A shorter loss leaves every SubDevice in OP.
#[test]
fn a_link_lost_past_the_sm_watchdog_drops_the_subdevices_behind_it_to_safe_op_and_the_master_sees_it(
) {
    let (mut bus, _) = enabled(&MITSUBISHI);
    let op = AlStatus::from_registers(AlState::Op as u16, 0);
    assert_eq!(
        (0..4).map(|a| bus.al_status(a)).collect::<Vec<_>>(),
        vec![Some(op); 4],
        "every SubDevice in OP, read by the cyclic frame"
    );
    assert_eq!(
        stations(&mut bus).stations()[0].pd_watchdog_ns(),
        100_000_000,
        "the ESC's reset values: 1000 × 100 µs"
    );

    // 50 ms: within the watchdog.
    assert!(bus.link_mut().lose_link(2, 50));
    let _ = exchanges(&mut bus, 60);
    assert_eq!(
        (0..4).map(|a| bus.al_status(a)).collect::<Vec<_>>(),
        vec![Some(op); 4]
    );
    assert_eq!(registers(&mut bus, reg::SM_WATCHDOG_COUNTER), [0, 0, 0, 0]);

    // 150 ms: the stations behind the link expire.
    assert!(bus.link_mut().lose_link(2, 150));
    let r = exchanges(&mut bus, 151);
    let watchdog = AlStatus::from_registers(
        AlState::SafeOp as u16 | u16::from(reg::AL_ERROR_INDICATION),
        reg::al_code::SM_WATCHDOG,
    );
    assert_eq!(
        (0..4).map(|a| bus.al_status(a)).collect::<Vec<_>>(),
        vec![Some(op), Some(op), Some(watchdog), Some(watchdog)]
    );
    assert_eq!(
        watchdog.describe(),
        "SAFE-OP, error 001Bh (sync manager watchdog)"
    );
    assert_eq!(AlStatus::decode(watchdog.encode()), watchdog);
    assert_eq!(registers(&mut bus, reg::SM_WATCHDOG_COUNTER), [0, 0, 1, 1]);
    assert_eq!(registers(&mut bus, reg::SM_WATCHDOG_STATUS), [1, 1, 0, 0]);
    // In SAFE-OP the two stations no longer write their outputs: 2 × 2 of the working
    // counter's 12 are missing.
    assert_eq!(
        r.last(),
        Some(&Err(BusError::WorkingCounter {
            expected: 12,
            found: 8
        }))
    );
    let states: Vec<AlState> = stations(&mut bus)
        .stations()
        .iter()
        .map(|s| s.al_state())
        .collect();
    assert_eq!(
        states,
        [AlState::Op, AlState::Op, AlState::SafeOp, AlState::SafeOp]
    );
}

/// MR-J4-TM manual §4.1: an alarm of an MR-J4-TM in OP is a CoE Emergency; the master sees SM1
/// full in its cyclic frame, reads it and names the axis and the 603Fh code; an SDO read of
/// 603Fh afterwards, and one with an Emergency still waiting in SM1, both succeed (ethercrab
/// 0.7.1 would panic on reading an Emergency as its SDO response, or silently discard it when
/// clearing SM1). The MR-J3-T04 next to it sends none (MR-J3-T04 manual §1.7, §8.2.2, §8.2.3).
#[test]
fn an_alarm_in_op_is_an_emergency_of_its_axis_and_sdo_reads_still_work() {
    use cellrt_cia402::bus::MailboxNotice;
    use cellrt_ethercat::emergency::Emergency;
    let models = [DriveModel::MrJ3T04, DriveModel::MrJ4TM];
    let (mut bus, _) = enabled(&models);
    assert!(
        mailbox_common::no_notice_within(&mut bus, 5),
        "no alarm, no notice"
    );
    let code = profile(DriveModel::MrJ4TM).limits.following_error_alarm;
    assert!(bus.inject_alarm(1, code));
    assert!(bus.inject_alarm(0, profile(DriveModel::MrJ3T04).limits.following_error_alarm));
    assert!(exchanges(&mut bus, 1)[0].is_ok());
    assert_eq!(
        mailbox_common::await_notices(&mut bus, 1).pop(),
        Some(MailboxNotice::Emergency {
            axis: 1,
            emergency: Emergency::of_alarm(code, 0)
        })
    );
    assert!(
        mailbox_common::no_notice_within(&mut bus, 10),
        "the J3 sends none"
    );
    assert_eq!(bus.sdo_upload(1, 0x603F, 0), Ok(i64::from(code)));
    // A second alarm: its Emergency waits in SM1 when the fault edge's SDO read comes.
    let second = code.wrapping_add(1);
    segment_of(bus.link_mut())
        .and_then(|s| s.station_mut(1))
        .expect("station 1")
        .drive_mut()
        .inject_alarm(second);
    assert!(exchanges(&mut bus, 1)[0].is_ok());
    assert_eq!(
        bus.sdo_upload(1, 0x603F, 0).ok().map(|v| v as u16),
        Some(second)
    );
    assert_eq!(
        bus.take_mailbox_notice(),
        Some(MailboxNotice::Emergency {
            axis: 1,
            emergency: Emergency::of_alarm(second, 0)
        })
    );
    assert_eq!(bus.take_mailbox_notice(), None);
    assert!(exchanges(&mut bus, 5).iter().all(Result::is_ok));
    assert_eq!(bus.mailbox_notices_dropped(), 0);
}

/// An alarm raised with no cyclic frame in between goes out as an Emergency ahead of the SDO
/// response the master is waiting for (the drive's firmware sends it when the alarm occurs).
/// ethercrab 0.7.1 failed the SDO on it or panicked (vendor/ethercrab/CELLRT-PATCHES.md); now
/// the SDO meets an Emergency error, the master records it for the axis and repeats the SDO,
/// which reads the alarm's 603Fh (the first request's late response is read from SM1 and
/// discarded as such). A download (6085h) likewise.
#[test]
fn an_emergency_where_the_sdo_response_should_be_is_recorded_and_the_sdo_repeated() {
    use cellrt_cia402::bus::MailboxNotice;
    let models = [DriveModel::MrJ4TM, DriveModel::MrJ5GN1];
    let (mut bus, _) = enabled(&models);
    fn drive(bus: &mut EthercatBus, n: usize) -> &mut SimDrive {
        segment_of(bus.link_mut())
            .and_then(|s| s.station_mut(n))
            .expect("station")
            .drive_mut()
    }
    let code = profile(DriveModel::MrJ5GN1).limits.following_error_alarm;
    drive(&mut bus, 1).inject_alarm(code);
    assert_eq!(bus.sdo_upload(1, 0x603F, 0), Ok(i64::from(code)));
    match bus.take_mailbox_notice() {
        Some(MailboxNotice::Emergency { axis, emergency }) => {
            assert_eq!((axis, emergency.error_code), (1, code));
        }
        other => panic!("expected the J5's Emergency, got {other:?}"),
    }
    // The response to the first request came after the Emergency; the repeat found it in SM1.
    assert_eq!(
        bus.take_mailbox_notice(),
        Some(MailboxNotice::Discarded {
            axis: 1,
            mailbox_type: 3,
            service: 3
        }),
        "the first request's SDO response (CoE, service 3) is read and discarded"
    );
    let code = profile(DriveModel::MrJ4TM).limits.following_error_alarm;
    drive(&mut bus, 0).inject_alarm(code);
    // 6085h Quick stop deceleration: the repeated download is the one that takes effect.
    let decel: u32 = 123_456;
    assert_eq!(bus.sdo_download(0, 0x6085, 0, &decel.to_le_bytes()), Ok(()));
    match bus.take_mailbox_notice() {
        Some(MailboxNotice::Emergency { axis, emergency }) => {
            assert_eq!((axis, emergency.error_code), (0, code));
        }
        other => panic!("expected the J4-TM's Emergency, got {other:?}"),
    }
    assert_eq!(bus.sdo_upload(0, 0x6085, 0), Ok(i64::from(decel)));
    assert!(matches!(
        bus.take_mailbox_notice(),
        Some(MailboxNotice::Discarded { axis: 0, .. })
    ));
    // The cyclic exchange goes on; no Emergency twice.
    assert!(exchanges(&mut bus, 5).iter().all(Result::is_ok));
    while let Some(n) = bus.take_mailbox_notice() {
        assert!(
            !matches!(n, MailboxNotice::Emergency { .. }),
            "one Emergency per alarm: {n:?}"
        );
    }
}

/// Bus diagnostics, read by the mailbox worker while the cyclic exchange goes on: the
/// corruption injected in front of SubDevice 2 shows as its port-0 invalid frames and as
/// forwarded errors behind and on the way back, the master's lost frames beside them.
#[test]
fn bus_diagnostics_show_the_port_of_the_bad_link() {
    let (mut bus, _) = enabled(&MITSUBISHI);
    let diag = bus.diagnostics();
    let lost_before = bus.counters().lost;
    assert!(bus.link_mut().corrupt_frames(2, 20));
    let _ = exchanges(&mut bus, 20);
    diag.request();
    let end = std::time::Instant::now() + std::time::Duration::from_secs(5);
    let reading = loop {
        if let Some(r) = diag.take() {
            break r;
        }
        assert!(std::time::Instant::now() < end, "no diagnostics reading");
        let _ = bus.exchange(Cycles(1));
        std::thread::sleep(std::time::Duration::from_micros(200));
    };
    let s = &reading.subdevices;
    assert_eq!(s.len(), 4);
    assert!(
        s.iter()
            .all(|d| d.answered && d.al_state == "OP" && !d.al_error),
        "{s:?}"
    );
    let col = |f: fn(&cellrt_ethercat::master::SubDeviceDiag) -> u8| -> Vec<u8> {
        s.iter().map(f).collect()
    };
    assert_eq!(col(|d| d.ports[0].invalid_frames), [0, 0, 20, 0]);
    assert_eq!(col(|d| d.ports[0].forwarded_errors), [0, 0, 0, 20]);
    assert_eq!(col(|d| d.ports[1].forwarded_errors), [20, 20, 20, 0]);
    assert_eq!(col(|d| d.ports[1].invalid_frames), [0; 4]);
    // Links: port 0 everywhere, port 1 up to the last SubDevice.
    assert!(s.iter().all(|d| d.ports[0].link));
    assert_eq!(
        s.iter().map(|d| d.ports[1].link).collect::<Vec<_>>(),
        [true, true, true, false]
    );
    assert_eq!(reading.frames_lost - lost_before, 20);
    assert!(reading.frames >= 20);
}

/// A drive's dictionary read by SDO Information on the mailbox worker while the cyclic
/// exchange goes on: the walk takes one exchange per pass of the worker, so an SDO the RT loop
/// posts after the request is answered long before the walk ends; an axis the segment does not
/// have is answered as such.
#[test]
fn the_mailbox_worker_walks_a_dictionary_by_sdo_information_beside_the_loops_sdos() {
    use cellrt_cia402::bus::{SdoOutcome, SdoRequest};
    use cellrt_ethercat::master::NoSdoInformation;
    let mut bus = bring_up(&[DriveModel::MrJ4TM]);
    let reader = bus.dictionary_reader();
    assert!(reader.request(0));
    let status = SdoRequest::Upload {
        index: 0x6041,
        sub: 0,
    };
    assert_eq!(bus.post_sdo(0, status), Ok(()));
    let end = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let mut sdo_first = None;
    let reading = loop {
        if let Some(r) = reader.take() {
            break r;
        }
        if sdo_first.is_none() {
            sdo_first = bus.take_sdo(0);
        }
        assert!(std::time::Instant::now() < end, "no dictionary");
        let _ = exchanges(&mut bus, 1);
        std::thread::sleep(std::time::Duration::from_micros(100));
    };
    assert!(
        matches!(sdo_first, Some(SdoOutcome::Uploaded(_))),
        "the loop's SDO waited for the walk: {sdo_first:?}"
    );
    assert_eq!(reading.axis, 0);
    let entries = reading
        .entries
        .expect("the MR-J4-TM offers SDO Information");
    let find = |index: u16, sub: u8| entries.iter().find(|e| (e.index, e.sub) == (index, sub));
    let s = find(0x6041, 0).expect("6041h:00");
    assert_eq!(
        (s.name.as_str(), s.data_type.as_str(), s.bits),
        ("Statusword", "UNSIGNED16", Some(16))
    );
    assert!((1..=4).all(|sub| find(0x1018, sub).is_some()));
    assert!(find(0x2FFF, 0).is_none());
    assert!(reader.request(7));
    let reading = loop {
        if let Some(r) = reader.take() {
            break r;
        }
        assert!(std::time::Instant::now() < end, "no answer for axis 7");
        let _ = exchanges(&mut bus, 1);
    };
    assert_eq!(reading.entries, Err(NoSdoInformation::UnknownAxis(7)));
}

/// A SubDevice whose SII's CoE details do not offer SDO Information (bit 1) is not asked: the
/// reading says so, and the cell lists the profile's dictionary instead.
#[test]
fn a_subdevice_without_sdo_information_in_its_sii_is_not_asked_for_its_dictionary() {
    use cellrt_ethercat::master::NoSdoInformation;
    let mut p = profile(DriveModel::MrJ4TM).clone();
    p.comm.sdo_info.offered = false;
    let p = SharedProfile::new(p);
    let cycle = CycleTime::from_micros(1000).unwrap();
    let drive = SimDrive::new(p.clone(), SimDriveParams::default(), cycle);
    let mut config = config(&[DriveModel::MrJ4TM], cycle);
    config.drives[0].profile = p;
    let link = InProcessLink::new(Segment::new(vec![drive]));
    let mut bus = bring_up_one(config, Box::new(link)).expect("bring-up");
    let reader = bus.dictionary_reader();
    assert!(reader.request(0));
    let end = std::time::Instant::now() + std::time::Duration::from_secs(10);
    let reading = loop {
        if let Some(r) = reader.take() {
            break r;
        }
        assert!(std::time::Instant::now() < end, "no answer");
        let _ = exchanges(&mut bus, 1);
    };
    assert_eq!(reading.entries, Err(NoSdoInformation::NotOffered));
}
