//! EtherCAT targets: frames and datagrams, the emulated segment receiving any frame, the
//! emulated CoE server, the master's SM1 mailbox decoder, the SII walk of a scan, ESI XML.

use cellrt_cia402::cycles::CycleTime;
use cellrt_cia402::{profile, DriveModel};
use cellrt_emulator::ethercat::coe::{self, CoeContext, PdoConfig, SegmentedUpload};
use cellrt_emulator::ethercat::{Segment, SubDeviceVariant};
use cellrt_emulator::{SimDrive, SimDriveParams};
use cellrt_ethercat::emergency::MailboxMessage;
use cellrt_ethercat::frame;
use cellrt_ethercat::identity::SubDeviceIdentity;
use cellrt_ethercat::master::scan;
use cellrt_ethercat::register::AlState;

use crate::pieces;
use crate::sii_link::FuzzedEsc;

/// The emulated drives of the segment and CoE targets: a 2-axis unit and a 1-axis drive.
fn drives(model: DriveModel) -> Vec<SimDrive> {
    let p = profile(model);
    (0..p.axes_per_unit)
        .map(|_| {
            SimDrive::new(
                p,
                SimDriveParams::default(),
                CycleTime::from_micros(1000).expect("1 ms is a cycle time"),
            )
        })
        .collect()
}

/// A frame as the master reads it back: header check, datagram walk, working counters.
pub fn frame(data: &[u8]) {
    let _ = frame::check_frame(data);
    for span in frame::datagrams(data).flatten() {
        let _ = frame::wkc(data, &span);
    }
}

/// Frames from the wire into the emulated segment (a 2-axis and a 1-axis EtherCAT drive).
pub fn emulator(data: &[u8]) {
    let mut units = vec![drives(DriveModel::MrJ5W2GN1), drives(DriveModel::MrJ5GN1)];
    let mut segment = Segment::of_units(std::mem::take(&mut units)).expect("a valid segment");
    let mut now_ns = 0;
    for piece in pieces(data) {
        let mut buf = piece.to_vec();
        let _ = segment.process(&mut buf, now_ns);
        now_ns += 1_000_000;
    }
}

/// Mailbox requests (SM0) into the emulated CoE server of a 2-axis drive; the first byte picks
/// the AL state.
pub fn coe_server(data: &[u8]) {
    let Some((&state, data)) = data.split_first() else {
        return;
    };
    let mut drives = drives(DriveModel::MrJ5W2GN1);
    let mut pdo = PdoConfig::new(&drives);
    let identity = SubDeviceIdentity::of_profile(drives[0].profile());
    let (mut counter, mut upload) = (0u8, SegmentedUpload::default());
    let mut fragments = std::collections::VecDeque::new();
    let variant = SubDeviceVariant::default();
    let al_state = match state % 3 {
        0 => AlState::PreOp,
        1 => AlState::SafeOp,
        _ => AlState::Op,
    };
    let mut response = [0u8; 128];
    for request in pieces(data) {
        let mut ctx = CoeContext {
            drives: &mut drives,
            identity,
            al_state,
            pdo: &mut pdo,
            counter: &mut counter,
            upload: &mut upload,
            variant: &variant,
            esi: None,
            info_fragments: &mut fragments,
        };
        let _ = coe::serve(&mut ctx, request, &mut response);
    }
}

/// The master's decoder of a SubDevice's SM1 mailbox (CoE Emergency or other).
pub fn mailbox_message(data: &[u8]) {
    let _ = MailboxMessage::decode(data);
}

/// A `bus scan` against SubDevices whose registers and SII EEPROM are the input.
pub fn sii_scan(data: &[u8]) {
    let _ = scan::scan(&mut FuzzedEsc::new(data));
}

/// An ESI XML file.
pub fn esi_xml(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = cellrt_ethercat::esi::parse(text);
    }
}
