//! The per-cycle calls allocate nothing (docs/architecture.md "Rules of the RT thread" 1).

use cellrt_cia402::{
    profile, AxisMaster, CycleTime, Cycles, CyclicBus, DriveModel, FaultInjection, MasterParams,
    MasterRequest, RxPdo,
};
use cellrt_emulator::{SimBus, SimDrive, SimDriveParams};

use cellrt_test_support::counting_alloc::{thread_heap_calls, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn steady_state_cycle_is_allocation_free() {
    let p = profile(DriveModel::MrJ5GN1);
    let ct = CycleTime::from_micros(1000).unwrap();
    let drives = (0..3)
        .map(|_| SimDrive::new(p, SimDriveParams::default(), ct))
        .collect();
    let mut bus = SimBus::new(drives);
    let params = MasterParams {
        fault_reset_hold: p.fault_reset_hold(ct),
        transition_timeout: Cycles(100),
    };
    let mut masters = [
        AxisMaster::new(params),
        AxisMaster::new(params),
        AxisMaster::new(params),
    ];
    for m in &mut masters {
        m.request(MasterRequest::Enable);
    }
    let before = thread_heap_calls();
    for k in 0..10_000i32 {
        if k == 5_000 {
            bus.drive_mut(1).inject_alarm(0x0123);
        }
        for (axis, m) in masters.iter_mut().enumerate() {
            let tx = p.pdo.tx.decode_tx(bus.tx_image(axis)).unwrap();
            let cw = m.update(tx.statusword);
            let rx = RxPdo {
                mode: 8,
                controlword: cw,
                target_position: if m.is_enabled() {
                    k * 100
                } else {
                    tx.position_actual
                },
                ..RxPdo::default()
            };
            p.pdo.rx.encode_rx(&rx, bus.rx_image_mut(axis)).unwrap();
        }
        bus.exchange(Cycles(1)).unwrap();
    }
    assert_eq!(thread_heap_calls() - before, 0);
    assert!(masters[0].is_enabled());
}

#[test]
fn every_model_on_one_bus_with_counter_and_injections_is_allocation_free() {
    use cellrt_cia402::IncrementalCounter;
    let ct = CycleTime::from_micros(1000).unwrap();
    let drives: Vec<SimDrive> = DriveModel::ALL
        .iter()
        .map(|m| SimDrive::new(profile(*m), SimDriveParams::default(), ct))
        .collect();
    let n = drives.len();
    let mut bus = SimBus::new(drives);
    let mut masters: Vec<AxisMaster> = (0..n)
        .map(|i| AxisMaster::for_profile(bus.drive(i).profile(), ct, Cycles(200)))
        .collect();
    let mut counters: Vec<IncrementalCounter> = (0..n)
        .map(|_| {
            IncrementalCounter::new(cellrt_cia402::profiles::mr_j3_t04::MASTER_COUNTER_CHECK, 0)
        })
        .collect();
    for m in &mut masters {
        m.request(MasterRequest::Enable);
    }
    let profiles: Vec<_> = (0..n).map(|a| bus.drive(a).profile().clone()).collect();
    let before = thread_heap_calls();
    for k in 0..10_000i32 {
        match k {
            3_000 => {
                bus.inject_rx_loss(0, 1);
                bus.inject_counter_corruption(3, 2);
            }
            6_000 => masters[2].set_halt(true),
            6_500 => masters[2].set_halt(false),
            _ => {}
        }
        for axis in 0..n {
            let p = &profiles[axis];
            let tx = p.pdo.tx.decode_tx(bus.tx_image(axis)).unwrap();
            let _ = counters[axis].check_rx(p.comm.check.tx_counter(&tx));
            let m = &mut masters[axis];
            let cw = m.update(tx.statusword);
            let rx = RxPdo {
                mode: 8,
                controlword: cw,
                target_position: if m.is_enabled() {
                    tx.position_actual.wrapping_add(50)
                } else {
                    tx.position_actual
                },
                counter: counters[axis].next_tx(),
                ..RxPdo::default()
            };
            p.pdo.rx.encode_rx(&rx, bus.rx_image_mut(axis)).unwrap();
        }
        bus.exchange(Cycles(1)).unwrap();
    }
    assert_eq!(thread_heap_calls() - before, 0);
    assert!(masters[1].is_enabled());
}

#[test]
fn the_ethercat_cyclic_exchange_is_allocation_free() {
    use cellrt_cia402::ModeOfOperation;
    use cellrt_emulator::ethercat::InProcessLink;
    use cellrt_emulator::ethercat::Segment;
    use cellrt_ethercat::identity::ExpectedIdentity;
    use cellrt_ethercat::master::{EthercatBus, SegmentConfig, SegmentDrive};

    let ct = CycleTime::from_micros(1000).unwrap();
    let models = [DriveModel::MrJ3T04, DriveModel::MrJ5GN1];
    let segment = Segment::new(
        models
            .iter()
            .map(|&m| SimDrive::new(profile(m), SimDriveParams::default(), ct))
            .collect(),
    );
    let config = SegmentConfig {
        cycle: ct,
        drives: models
            .iter()
            .map(|&m| SegmentDrive {
                axis: m.as_str().into(),
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
    let mut bus = EthercatBus::bring_up(config, Box::new(InProcessLink::new(segment))).unwrap();
    let layouts: Vec<_> = models
        .iter()
        .map(|&m| cellrt_cia402::pdo::PdoLayout::new(&profile(m).pdo.rx))
        .collect();
    bus.exchange(Cycles(1)).unwrap();
    let before = thread_heap_calls();
    let mut errors = 0;
    let mut emergencies = 0;
    for k in 0..2_000u32 {
        // An alarm of the MR-J5-G-N1: its CoE Emergency is in SM1, the cyclic frame sees it
        // full, `take_mailbox_notice` hands the read to the mailbox worker and the exchange
        // carries the worker's frame, as in the RT loop.
        if k == 1500 {
            assert!(bus.inject_alarm(1, 0x2010));
        }
        while let Some(n) = bus.take_mailbox_notice() {
            if let cellrt_cia402::bus::MailboxNotice::Emergency { axis: 1, emergency } = n {
                emergencies += usize::from(emergency.error_code == 0x2010);
            }
        }
        // The emulated segment's wire faults, 5 frames each.
        let link = bus.link_mut();
        match k {
            200 => assert!(link.delay_frames(900_000, 5)),
            400 => assert!(link.corrupt_frames(1, 5)),
            600 => assert!(link.drop_datagrams(5)),
            800 => assert!(link.lose_link(1, 5)),
            1000 => assert!(link.lose_link(0, 5)),
            1200 => assert!(link.stall_subdevice(0, 5)),
            _ => {}
        }
        for (axis, l) in layouts.iter().enumerate() {
            let rx = RxPdo {
                counter: k as u8,
                ..RxPdo::default()
            };
            l.encode_rx(&rx, bus.rx_image_mut(axis)).unwrap();
        }
        if bus.exchange(Cycles(1)).is_err() {
            errors += 1;
        }
        // The RT loop takes the DC alignment every cycle.
        let _ = bus.deadline_correction_ns();
        // After the alarm, give the worker (another thread) time to hand its frame over.
        if k >= 1500 && emergencies == 0 {
            std::thread::sleep(std::time::Duration::from_micros(300));
        }
    }
    assert!(bus.dc_phase_error_ns().is_some(), "DC alignment ran");
    assert_eq!(
        thread_heap_calls() - before,
        0,
        "master frame, DC alignment, SM1 status and Emergency read, emulated segment and drives"
    );
    assert_eq!(errors, 30, "every faulty frame an error");
    assert_eq!(
        emergencies, 1,
        "the alarm's Emergency was read on the cyclic path"
    );
}

/// A multi-axis station (MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4) on the cyclic path: the master splits the PDI per
/// axis and the emulated J5W3 runs each axis' drive on its part of the process data, without
/// allocating; two of its three slots used, beside a 1-axis drive; the axes enabled, then the
/// SubDevice stalled and its link lost for 5 frames each.
#[test]
fn the_ethercat_cyclic_exchange_of_a_multi_axis_station_is_allocation_free() {
    use cellrt_cia402::{Controlword, ModeOfOperation};
    use cellrt_emulator::ethercat::InProcessLink;
    use cellrt_emulator::ethercat::Segment;
    use cellrt_ethercat::identity::ExpectedIdentity;
    use cellrt_ethercat::master::{AmplifierSlot, EthercatBus, SegmentConfig, SegmentDrive};

    let ct = CycleTime::from_micros(1000).unwrap();
    let axes = [
        (DriveModel::MrJ5W3GN1, Some(2u8)),
        (DriveModel::MrJ5GN1, None),
        (DriveModel::MrJ5W3GN1, Some(0u8)),
    ];
    let config = SegmentConfig {
        cycle: ct,
        drives: axes
            .iter()
            .enumerate()
            .map(|(i, &(m, slot))| SegmentDrive {
                axis: format!("a{i}"),
                profile: profile(m).into(),
                identity: ExpectedIdentity::of_profile(profile(m)),
                mode: ModeOfOperation::CyclicSyncPosition,
                amplifier: slot.map(|slot| AmplifierSlot {
                    label: "w3".into(),
                    slot,
                }),
                distributed_clocks: true,
                fixed_pdo: Default::default(),
                startup_sdo: Vec::new(),
            })
            .collect(),
    };
    let units = config
        .stations()
        .unwrap()
        .iter()
        .map(|st| {
            st.slots
                .iter()
                .map(|_| SimDrive::new(st.model, SimDriveParams::default(), ct))
                .collect()
        })
        .collect();
    let segment = Segment::of_units(units).unwrap();
    let mut bus = EthercatBus::bring_up(config, Box::new(InProcessLink::new(segment))).unwrap();
    let layouts: Vec<_> = axes
        .iter()
        .map(|&(m, _)| {
            (
                cellrt_cia402::pdo::PdoLayout::new(&profile(m).pdo.rx),
                cellrt_cia402::pdo::PdoLayout::new(&profile(m).pdo.tx),
            )
        })
        .collect();
    bus.exchange(Cycles(1)).unwrap();
    let before = thread_heap_calls();
    let mut errors = 0;
    for k in 0..2_000u32 {
        let link = bus.link_mut();
        match k {
            1200 => assert!(link.stall_subdevice(0, 5)),
            1400 => assert!(link.lose_link(1, 5)),
            _ => {}
        }
        let cw = match k {
            0..=49 => Controlword::SHUTDOWN,
            50..=99 => Controlword::SWITCH_ON,
            _ => Controlword::ENABLE_OPERATION,
        };
        for (axis, (rxl, txl)) in layouts.iter().enumerate() {
            let tx = txl.decode_tx(bus.tx_image(axis)).unwrap();
            let rx = RxPdo {
                controlword: cw,
                mode: ModeOfOperation::CyclicSyncPosition.as_i8(),
                target_position: tx.position_actual,
                ..RxPdo::default()
            };
            rxl.encode_rx(&rx, bus.rx_image_mut(axis)).unwrap();
        }
        if bus.exchange(Cycles(1)).is_err() {
            errors += 1;
        }
        let _ = bus.deadline_correction_ns();
        if k == 1000 {
            for (axis, (_, txl)) in layouts.iter().enumerate() {
                let sw = txl.decode_tx(bus.tx_image(axis)).unwrap().statusword;
                assert_eq!(
                    sw.state(),
                    Some(cellrt_cia402::FsaState::OperationEnabled),
                    "axis {axis}"
                );
            }
        }
    }
    assert_eq!(
        thread_heap_calls() - before,
        0,
        "master PDI split, multi-axis station and its drives"
    );
    assert_eq!(errors, 10, "every faulty frame an error");
}

/// The simulated MR-JE-C's tick allocates nothing, with [Pr. PC03]'s S-pattern filter (its ring
/// buffer is sized once, when the drive is built) and the droop of the motor model running.
#[test]
fn mr_je_c_emulator_ticks_are_allocation_free_with_the_s_pattern() {
    use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams};
    use cellrt_fieldbus::mr_je_c::{ObjectId, Value};
    use std::time::Duration;
    let mut d = MrJeC::new(MrJeCParams::default());
    let at = Duration::ZERO;
    for (index, v) in [
        (0x2103, Value::U32(100)),
        (0x6060, Value::I8(1)),
        (0x607A, Value::I32(4 * 131_072)),
        (0x6081, Value::U32(60_000)),
    ] {
        d.write(ObjectId::new(index, 0), &v, at).unwrap();
    }
    for word in [0x06u16, 0x07, 0x0F, 0x1F, 0x0F] {
        d.write(ObjectId::new(0x6040, 0), &Value::U16(word), at)
            .unwrap();
    }
    d.tick(Duration::from_millis(1));
    let before = thread_heap_calls();
    for t in 2..2000 {
        d.tick(Duration::from_micros(t * 1000 - 500));
        d.tick(Duration::from_millis(t));
    }
    assert_eq!(thread_heap_calls() - before, 0);
    assert_eq!(
        d.read(ObjectId::new(0x6064, 0)).unwrap(),
        Value::I32(4 * 131_072)
    );
}
