//! `bus scan` against the emulated segment: the master's SII walk reads each SubDevice's
//! identity, name, mailbox protocols and DC support, and leaves every station as it found it.

use cellrt_cia402::{profile, CycleTime, DriveModel};
use cellrt_emulator::ethercat::{segment_of, EmulatedDc, InProcessLink, Segment, SubDeviceVariant};
use cellrt_emulator::{SimDrive, SimDriveParams};
use cellrt_ethercat::identity::SubDeviceIdentity;
use cellrt_ethercat::master::scan::{mailbox_protocol_names, scan};
use cellrt_ethercat::register::AlState;

#[test]
fn a_scan_of_the_emulated_segment_reads_each_subdevice_and_changes_nothing() {
    let cycle = CycleTime::from_micros(1000).unwrap();
    let models = [DriveModel::MrJ4TM, DriveModel::MrJ5GN1];
    let mut segment = Segment::new(
        models
            .iter()
            .map(|&m| SimDrive::new(profile(m), SimDriveParams::default(), cycle))
            .collect(),
    );
    segment.station_mut(1).unwrap().present(SubDeviceVariant {
        distributed_clocks: EmulatedDc::Absent,
        ..Default::default()
    });
    let mut link = InProcessLink::new(segment);
    let found = scan(&mut link).unwrap();
    assert_eq!(found.len(), 2);
    for (i, (d, m)) in found.iter().zip(models).enumerate() {
        let p = profile(m);
        assert_eq!(d.position, i);
        assert_eq!(d.identity, SubDeviceIdentity::of_profile(p), "{m:?}");
        assert_eq!(d.name, p.name);
        assert_eq!(d.al.state, Some(AlState::Init));
        assert_eq!(mailbox_protocol_names(d.mailbox_protocols), ["CoE"]);
    }
    assert_eq!((found[0].dc, found[1].dc), (true, false));
    let seg = segment_of(&mut link).unwrap();
    for st in seg.stations() {
        assert_eq!(st.al_state(), AlState::Init);
        assert_eq!(st.station_address(), 0, "no address was set");
    }
}
