//! Process-data round trip of the EtherCAT backend against the in-process emulated segment of
//! four drives (one of each EtherCAT model): the master builds the LRW frame, the segment
//! processes it and runs the four simulated drives, the master checks the working counter and
//! copies the inputs. Target (issue 7): p50 ≤ 10 µs. Run: `cargo bench -p cellrt-axes --bench ethercat`.

use criterion::{criterion_group, criterion_main, Criterion};

use cellrt_cia402::{profile, CycleTime, Cycles, CyclicBus, DriveModel, ModeOfOperation};
use cellrt_emulator::ethercat::InProcessLink;
use cellrt_emulator::ethercat::Segment;
use cellrt_emulator::{SimDrive, SimDriveParams};
use cellrt_ethercat::identity::ExpectedIdentity;
use cellrt_ethercat::master::{EthercatBus, SegmentConfig, SegmentDrive};

fn bus(models: &[DriveModel]) -> EthercatBus {
    let ct = CycleTime::from_micros(1000).unwrap();
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
    EthercatBus::bring_up(config, Box::new(InProcessLink::new(segment))).expect("bring-up")
}

fn round_trip(c: &mut Criterion) {
    let models = [
        DriveModel::MrJ3T04,
        DriveModel::MrJ4TM,
        DriveModel::MrJetGN1,
        DriveModel::MrJ5GN1,
    ];
    let mut b = bus(&models);
    c.bench_function("ethercat_in_process_4_drives_exchange", |bench| {
        bench.iter(|| b.exchange(Cycles(1)).expect("exchange"))
    });
}

criterion_group!(benches, round_trip);
criterion_main!(benches);
