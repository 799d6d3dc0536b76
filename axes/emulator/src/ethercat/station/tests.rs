//! The emulated station's mailbox: Emergencies in SM1 next to SDO responses.

use super::*;
use crate::ethercat::coe;
use crate::sim::drive::SimDriveParams;
use cellrt_cia402::cycles::CycleTime;
use cellrt_cia402::profiles::{profile, DriveModel};
use cellrt_ethercat::emergency::{CoeEmergency, Emergency, MailboxMessage, EMERGENCY_MAILBOX_LEN};

/// A station of `model` (every axis of the unit) in PRE-OP, its mailboxes configured.
fn pre_op(model: DriveModel) -> Station {
    let p = profile(model);
    let drives = (0..p.axes_per_unit)
        .map(|_| {
            let cycle = CycleTime::from_micros(1000).expect("1 ms");
            SimDrive::new(p, SimDriveParams::default(), cycle)
        })
        .collect();
    let mut s = Station::unit(drives, 0, 1).expect("one drive per axis");
    let (o, i) = (s.layout.mailbox_out, s.layout.mailbox_in);
    for (n, sm) in [(0u8, o), (1, i)] {
        let mut r = [0u8; 8];
        r[0..2].copy_from_slice(&sm.start.to_le_bytes());
        r[2..4].copy_from_slice(&sm.len.to_le_bytes());
        r[4] = sm.control;
        r[6] = 1;
        s.physical(Command::Fpwr, reg::sync_manager(n), &mut r, 0);
    }
    s.physical(
        Command::Fpwr,
        reg::AL_CONTROL,
        &mut [AlState::PreOp as u8, 0],
        0,
    );
    assert_eq!(s.al_state(), AlState::PreOp);
    s
}

fn sm1_full(s: &mut Station) -> bool {
    let mut b = [0u8];
    s.physical(Command::Fprd, reg::sync_manager(1) + 5, &mut b, 0);
    b[0] & SM_FULL != 0
}

/// Reads the whole SM1 buffer (which empties it).
fn read_sm1(s: &mut Station) -> Vec<u8> {
    let mb = s.layout.mailbox_in;
    let mut b = vec![0u8; usize::from(mb.len)];
    s.physical(Command::Fprd, mb.start, &mut b, 0);
    b
}

/// Writes an SDO upload request of `index:00` into SM0.
fn request_upload(s: &mut Station, index: u16) {
    let mb = s.layout.mailbox_out;
    let mut r = vec![0u8; usize::from(mb.len)];
    r[0..2].copy_from_slice(&10u16.to_le_bytes());
    r[5] = coe::MAILBOX_TYPE_COE;
    r[6..8].copy_from_slice(&(2u16 << 12).to_le_bytes());
    r[8] = 0x40;
    r[9..11].copy_from_slice(&index.to_le_bytes());
    s.physical(Command::Fpwr, mb.start, &mut r, 0);
}

/// MR-J4-TM manual §4.1: an alarm is reported by CoE Emergency: at the drive's next cycle SM1
/// holds it (error code = 603Fh, error register 01h, slot 0), and reading it empties SM1.
#[test]
fn an_mr_j4_tm_alarm_is_an_emergency_in_sm1() {
    let mut s = pre_op(DriveModel::MrJ4TM);
    assert!(!sm1_full(&mut s));
    let code = s.drive().profile().comm.leave_op_alarm;
    s.drive_mut().inject_alarm(code);
    s.watch_alarms();
    assert!(sm1_full(&mut s));
    let got = read_sm1(&mut s);
    let mut want = [0u8; EMERGENCY_MAILBOX_LEN];
    Emergency::of_alarm(code, 0).encode(1, &mut want);
    assert_eq!(&got[..EMERGENCY_MAILBOX_LEN], &want);
    assert_eq!(&got[8..11], &[code as u8, (code >> 8) as u8, 0x01]);
    assert!(!sm1_full(&mut s), "read, and nothing else to send");
    // The same alarm still latched is not reported again.
    s.watch_alarms();
    assert!(!sm1_full(&mut s));
}

/// MR-J3-T04 manual §1.7, §8.2.2, §8.2.3: the MR-J3-T04 sends no CoE Emergency (PDO only).
#[test]
fn an_mr_j3_t04_alarm_sends_no_emergency() {
    let mut s = pre_op(DriveModel::MrJ3T04);
    s.drive_mut().inject_alarm(0x3400);
    s.watch_alarms();
    assert!(!sm1_full(&mut s));
    assert_eq!(s.emergencies_queued(), 0);
}

/// Two alarms on a J5W2 (axes A and B) and an SDO request before the master read SM1:
/// the Emergencies come first, in order, each naming its slot with the axis' code, then
/// the SDO response; none is lost or overwritten.
#[test]
fn an_sdo_request_behind_queued_emergencies_still_gets_its_response() {
    let mut s = pre_op(DriveModel::MrJ5W2GN1);
    s.drive_at_mut(0).expect("axis A").inject_alarm(0x1010);
    s.drive_at_mut(1).expect("axis B").inject_alarm(0x2020);
    s.watch_alarms();
    assert!(sm1_full(&mut s));
    assert_eq!(s.emergencies_queued(), 1);
    request_upload(&mut s, 0x1000);
    let first = MailboxMessage::decode(&read_sm1(&mut s));
    assert_eq!(
        first,
        MailboxMessage::Emergency(Emergency::of_alarm(0x1010, 0))
    );
    assert!(sm1_full(&mut s), "the next message follows at once");
    let second = MailboxMessage::decode(&read_sm1(&mut s));
    assert_eq!(
        second,
        MailboxMessage::Emergency(Emergency::of_alarm(0x2020, 1))
    );
    let third = read_sm1(&mut s);
    assert_eq!(
        MailboxMessage::decode(&third),
        MailboxMessage::Other {
            mailbox_type: 3,
            service: 3
        }
    );
    assert_eq!(third[8], 0x43, "expedited upload response");
    assert_eq!(u16::from_le_bytes([third[9], third[10]]), 0x1000);
    assert_eq!(
        u32::from_le_bytes([third[12], third[13], third[14], third[15]]),
        coe::DEVICE_TYPE
    );
    // Counters 1, 2, 3 in the order written.
    assert_eq!(third[5] >> 4, 3);
    assert!(!sm1_full(&mut s));
    assert_eq!(s.emergencies_lost(), 0);
}

/// More alarms than [`EMERGENCY_QUEUE`] holds while SM1 is occupied: the excess is counted.
#[test]
fn a_full_emergency_queue_counts_what_it_drops() {
    let mut s = pre_op(DriveModel::MrJ4TM);
    for k in 0..(EMERGENCY_QUEUE as u16 + 3) {
        s.drive_mut().inject_alarm(0x1000 + k);
        s.watch_alarms();
    }
    assert_eq!(s.emergencies_queued(), EMERGENCY_QUEUE);
    assert_eq!(s.emergencies_lost(), 2);
}
