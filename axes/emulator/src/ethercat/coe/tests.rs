//! The emulated CoE server: SDO services, segmented transfers and the PDO mapping objects.

use super::*;
use crate::sim::drive::SimDriveParams;
use cellrt_cia402::cycles::CycleTime;
use cellrt_cia402::profiles::{profile, DriveModel};

mod info;

/// A drive of `model` behind a CoE server in `al_state`.
struct Server {
    drives: Vec<SimDrive>,
    pdo: PdoConfig,
    al_state: AlState,
    counter: u8,
    upload: SegmentedUpload,
    variant: crate::ethercat::SubDeviceVariant,
    fragments: std::collections::VecDeque<Vec<u8>>,
}

impl Server {
    fn new(model: DriveModel) -> Self {
        let p = profile(model);
        let drives: Vec<SimDrive> = (0..p.axes_per_unit)
            .map(|_| {
                SimDrive::new(
                    p,
                    SimDriveParams::default(),
                    CycleTime::from_micros(1000).unwrap(),
                )
            })
            .collect();
        Server {
            pdo: PdoConfig::new(&drives),
            drives,
            al_state: AlState::PreOp,
            counter: 0,
            upload: SegmentedUpload::default(),
            variant: Default::default(),
            fragments: Default::default(),
        }
    }

    fn ctx(&mut self) -> CoeContext<'_> {
        let identity = SubDeviceIdentity::of_profile(self.drives[0].profile());
        CoeContext {
            drives: &mut self.drives,
            identity,
            al_state: self.al_state,
            pdo: &mut self.pdo,
            counter: &mut self.counter,
            upload: &mut self.upload,
            variant: &self.variant,
            esi: None,
            info_fragments: &mut self.fragments,
        }
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), u32> {
        download(&mut self.ctx(), index, sub, data).map_err(|e| e.0)
    }

    fn write_u32(&mut self, index: u16, sub: u8, v: u32) -> Result<(), u32> {
        self.write(index, sub, &v.to_le_bytes())
    }

    fn read(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, u32> {
        upload(&mut self.ctx(), index, sub).map_err(|e| e.0)
    }
}

/// MR-J3-T04 TV-PDO-1 (docs/test-vectors.md): remap the RxPDO for csv only, with the listed abort codes.
#[test]
fn tv_pdo_1_csv_only_remap_by_sdo_and_its_abort_codes() {
    let mut s = Server::new(DriveModel::MrJ3T04);
    // An SDO write to 6040h while the (default) RxPDO maps it: 0601 0000h.
    assert_eq!(s.write(0x6040, 0, &[0x06, 0x00]), Err(0x0601_0000));
    // Entries while the mapping is valid (locked): 0601 0000h.
    assert_eq!(s.write_u32(0x1614, 1, 0x6040_0010), Err(0x0601_0000));
    assert_eq!(s.write(0x1614, 0, &[0]), Ok(()));
    for (sub, word) in [
        (1, 0x2020_0008),
        (2, 0x0000_0008),
        (3, 0x6040_0010),
        (4, 0x2001_0010),
        (5, 0x60FF_0020),
    ] {
        assert_eq!(s.write_u32(0x1614, sub, word), Ok(()), "1614h:{sub}");
    }
    // Mapping 6041h into 1614h: 0604 0041h (and the entry is not taken).
    assert_eq!(s.write_u32(0x1614, 6, 0x6041_0010), Err(0x0604_0041));
    assert_eq!(s.write(0x1614, 0, &[5]), Ok(()));
    assert_eq!(s.read(0x1614, 0), Ok(vec![5]));
    assert_eq!(s.read(0x1614, 5), Ok(0x60FF_0020u32.to_le_bytes().to_vec()));
    // Writing 1614h:06 now (locked): 0601 0000h.
    assert_eq!(s.write_u32(0x1614, 6, 0x60E0_0010), Err(0x0601_0000));
    // The mapping is 10 bytes: counter, gap, controlword, controlword2, target velocity.
    let j3 = s.drives[0].profile();
    let (rx, _) = s.pdo.mapping(j3, 0);
    let p = j3.with_pdo_maps(&rx, &j3.pdo.tx.entries);
    let p = p.expect("the TV-PDO-1 mapping is valid");
    assert_eq!(p.pdo.rx.byte_len(), 10);
    assert_eq!(p.pdo.rx.offset_of(0x2020, 0), Some(0));
    assert_eq!(p.pdo.rx.offset_of(0x6040, 0), Some(2));
    assert_eq!(p.pdo.rx.offset_of(0x2001, 0), Some(4));
    assert_eq!(p.pdo.rx.offset_of(0x60FF, 0), Some(6));
    // A mapping totalling 32 bytes: 0604 0042h, and the count stays 0.
    assert_eq!(s.write(0x1614, 0, &[0]), Ok(()));
    for sub in 1..=8 {
        assert_eq!(s.write_u32(0x1614, sub, 0x607A_0020), Ok(()));
    }
    assert_eq!(s.write(0x1614, 0, &[8]), Err(0x0604_0042));
    assert_eq!(s.read(0x1614, 0), Ok(vec![0]));
    // More than 15 entries do not exist.
    assert_eq!(s.write_u32(0x1614, 16, 0x6040_0010), Err(0x0609_0011));
}

/// MR-J3-T04 TV-IC-5 (docs/test-vectors.md) rows 3 and 4: 1C32h:02 takes only the three cycles, only in PRE-OP,
/// and never again once SAFE-OP has been reached (mapping likewise, §4.4).
#[test]
fn tv_ic_5_cycle_time_writes_and_the_freeze_after_safe_op() {
    let mut s = Server::new(DriveModel::MrJ3T04);
    assert_eq!(s.write_u32(0x1C32, 2, 1_500_000), Err(0x0609_0030));
    assert_eq!(s.write_u32(0x1C32, 2, 1_000_000), Ok(()));
    // The assignment is read-only on this drive (§4.3).
    assert_eq!(s.write(0x1C12, 0, &[0]), Err(0x0601_0002));
    s.al_state = AlState::SafeOp;
    s.pdo.reached_safe_op();
    assert_eq!(s.write_u32(0x1C32, 2, 1_000_000), Err(0x0601_0002));
    assert_eq!(s.write(0x1614, 0, &[0]), Err(0x0601_0002));
    s.al_state = AlState::PreOp;
    assert_eq!(s.write_u32(0x1C32, 2, 1_000_000), Err(0x0601_0002));
    assert_eq!(s.write(0x1614, 0, &[0]), Err(0x0601_0002));
}

/// MR-J4-TM TV-10 (docs/test-vectors.md), last row: 1600h:0 in SAFE-OP/OP is refused (0800 0022h assumed,
/// [D]); in PRE-OP it is taken. The count of 1C12h is read-only (§5.1).
#[test]
fn tv_10_mapping_writes_outside_pre_op_mr_j4_tm() {
    let mut s = Server::new(DriveModel::MrJ4TM);
    for state in [AlState::SafeOp, AlState::Op] {
        s.al_state = state;
        assert_eq!(s.write(0x1600, 0, &[0]), Err(0x0800_0022), "{state:?}");
    }
    s.al_state = AlState::PreOp;
    assert_eq!(s.write(0x1C12, 0, &[0]), Err(0x0601_0002));
    assert_eq!(s.write(0x1C12, 1, &0x1600u16.to_le_bytes()), Ok(()));
    assert_eq!(s.write(0x1600, 0, &[0]), Ok(()));
    // The family answers an object it cannot map with 0604 0043h.
    assert_eq!(s.write_u32(0x1600, 1, 0x6041_0010), Err(0x0604_0043));
}

/// MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4 on a J5W3: the mapping objects of axis B/C at +10h carry the axis'
/// objects at +800h (an axis-A object is not mappable there); 1C12h sub n assigns axis n's
/// object; TV-6: 1C32h:02 = 0.125 ms refused (0609 0030h, the spec's natural code), 0.25 ms
/// taken by every axis; per-axis objects routed to the axis' drive.
#[test]
fn a_j5w3_serves_each_axis_at_its_offset_indexes() {
    let mut s = Server::new(DriveModel::MrJ5W3GN1);
    assert_eq!(s.drives.len(), 3);
    assert_eq!(s.read(0x1610, 0), Ok(vec![10]));
    assert_eq!(s.read(0x1620, 3), Ok(0x7040_0010u32.to_le_bytes().to_vec()));
    assert_eq!(s.read(0x1A10, 3), Ok(0x6841_0010u32.to_le_bytes().to_vec()));
    assert_eq!(s.read(0x1630, 0), Err(0x0602_0000), "no axis D");
    assert_eq!(s.write(0x1610, 0, &[0]), Ok(()));
    let not_mappable = Err(profile(DriveModel::MrJ5W3GN1).pdo.rules.not_mappable_abort);
    assert_eq!(s.write_u32(0x1610, 1, 0x6040_0010), not_mappable);
    assert_eq!(s.write_u32(0x1610, 1, 0x7040_0010), not_mappable);
    assert_eq!(s.write_u32(0x1610, 1, 0x6840_0010), Ok(()));
    assert_eq!(s.write(0x1610, 0, &[1]), Ok(()));
    let (rx, _) = s.pdo.mapping(profile(DriveModel::MrJ5W3GN1), 1);
    assert_eq!(rx, vec![PdoEntry::object(0x6040, 0, 16)]);

    assert_eq!(s.write(0x1C12, 0, &[0]), Ok(()));
    assert_eq!(
        s.write(0x1C12, 2, &0x1600u16.to_le_bytes()),
        Err(0x0604_0043)
    );
    assert_eq!(s.write(0x1C12, 2, &0x1610u16.to_le_bytes()), Ok(()));
    assert_eq!(
        s.write(0x1C12, 4, &0x1630u16.to_le_bytes()),
        Err(0x0609_0011)
    );
    assert_eq!(s.write(0x1C12, 0, &[4]), Err(0x0609_0030));
    assert_eq!(s.write(0x1C12, 0, &[3]), Ok(()));
    assert_eq!(s.read(0x1C12, 3), Ok(0x1620u16.to_le_bytes().to_vec()));

    assert_eq!(s.write_u32(0x1C32, 2, 125_000), Err(0x0609_0030));
    assert_eq!(s.write_u32(0x1C32, 2, 250_000), Ok(()));
    for d in &s.drives {
        assert_eq!(d.sdo_upload(0x1C32, 2), Ok(250_000));
    }
    // 7060h (axis C's modes of operation) reaches axis C's drive only: it is mapped there.
    assert_eq!(s.write(0x7060, 0, &[1]), Err(0x0601_0006));
    assert_eq!(s.read(0x7041, 0), Ok(vec![0, 0]));
}

/// A CoE SDO request in a mailbox: `cmd`, index, sub-index, then `data`.
fn request(cmd: u8, index: u16, sub: u8) -> Vec<u8> {
    let mut r = vec![0u8; MAILBOX_HEADER_LEN + 10];
    r[0..2].copy_from_slice(&10u16.to_le_bytes());
    r[5] = MAILBOX_TYPE_COE;
    r[6..8].copy_from_slice(&(SERVICE_SDO_REQUEST << 12).to_le_bytes());
    r[8] = cmd;
    r[9..11].copy_from_slice(&index.to_le_bytes());
    r[11] = sub;
    r
}

/// An upload longer than the mailbox goes in segments: the initiate response gives the size,
/// each segment request (toggle alternating) the next part, the last one flagged; a wrong
/// toggle aborts with 0503 0000h, a segment request without an upload with 0504 0001h.
#[test]
fn long_uploads_are_segmented() {
    let mut s = Server::new(DriveModel::MrJ3T04);
    let name = s.drives[0].profile().name.as_bytes().to_vec();
    // A 32-byte mailbox: 16 bytes of data fit a normal response, the name does not.
    let mut rsp = vec![0u8; 32];
    assert!(serve(&mut s.ctx(), &request(0x40, 0x1008, 0), &mut rsp));
    assert_eq!(rsp[8], 0x41, "normal upload, size indicated");
    assert_eq!(
        u16::from_le_bytes([rsp[0], rsp[1]]),
        10,
        "no data in the initiate"
    );
    assert_eq!(
        u32::from_le_bytes([rsp[12], rsp[13], rsp[14], rsp[15]]) as usize,
        name.len()
    );
    let mut got = Vec::new();
    let mut toggle = false;
    loop {
        let mut rsp = vec![0u8; 32];
        assert!(serve(
            &mut s.ctx(),
            &request(0x60 | (u8::from(toggle) << 4), 0, 0),
            &mut rsp
        ));
        let cmd = rsp[8];
        assert_eq!(cmd >> 5, 0, "upload segment response");
        assert_eq!(cmd & 0x10 != 0, toggle);
        let mut n = usize::from(u16::from_le_bytes([rsp[0], rsp[1]])) - 3;
        if n == 7 {
            n -= usize::from((cmd >> 1) & 7);
        }
        got.extend_from_slice(&rsp[9..9 + n]);
        if cmd & 1 != 0 {
            break;
        }
        toggle = !toggle;
        assert!(got.len() < 100, "the upload ends");
    }
    assert_eq!(got, name);
    let abort = |rsp: &[u8]| u32::from_le_bytes([rsp[12], rsp[13], rsp[14], rsp[15]]);
    // No upload in progress any more.
    let mut rsp = vec![0u8; 32];
    assert!(serve(&mut s.ctx(), &request(0x60, 0, 0), &mut rsp));
    assert_eq!((rsp[8], abort(&rsp)), (0x80, 0x0504_0001));
    // A toggle bit that does not alternate.
    assert!(serve(&mut s.ctx(), &request(0x40, 0x1008, 0), &mut rsp));
    assert!(serve(&mut s.ctx(), &request(0x70, 0, 0), &mut rsp));
    assert_eq!((rsp[8], abort(&rsp)), (0x80, 0x0503_0000));
}

#[test]
fn a_variant_without_60f4h_refuses_to_map_it_and_a_read_only_cycle_time_its_write() {
    use crate::ethercat::{CycleTimeObject, SubDeviceVariant};
    let mut s = Server::new(DriveModel::GenericCia402);
    s.variant = SubDeviceVariant {
        cycle_time: CycleTimeObject::ReadOnly(1_000_000),
        following_error_object: false,
        ..SubDeviceVariant::default()
    };
    s.write(0x1A00, 0, &[0]).unwrap();
    // CiA 301 0604 0041h (the generic profile's not-mappable abort) for 60F4h; 6064h maps.
    assert_eq!(
        s.write(0x1A00, 1, &0x60F4_0020u32.to_le_bytes()),
        Err(0x0604_0041)
    );
    s.write(0x1A00, 1, &0x6064_0020u32.to_le_bytes()).unwrap();
    assert_eq!(s.write(0x60F4, 0, &[0; 4]), Err(0x0602_0000));
    assert_eq!(
        s.write(0x1C32, 2, &1_000_000u32.to_le_bytes()),
        Err(0x0601_0002)
    );
}

#[test]
fn an_abort_is_framed_as_an_sdo_request_and_an_answer_as_a_response() {
    // ETG.1000.6 §5.6.2.7.1: Abort SDO Transfer goes as CoE service 2 (SDO request); SOEM takes
    // an abort framed as service 3 (SDO response) for data and fails (PacketError).
    let mut s = Server::new(DriveModel::MrJ4TM);
    let service = |rsp: &[u8]| u16::from_le_bytes([rsp[6], rsp[7]]) >> 12;
    let abort = |rsp: &[u8]| u32::from_le_bytes([rsp[12], rsp[13], rsp[14], rsp[15]]);
    let mut rsp = vec![0u8; 32];
    assert!(serve(&mut s.ctx(), &request(0x40, 0x5FFF, 0), &mut rsp));
    assert_eq!((service(&rsp), rsp[8]), (SERVICE_SDO_REQUEST, 0x80));
    assert_eq!(abort(&rsp), 0x0602_0000, "no such object");
    assert!(serve(&mut s.ctx(), &request(0x40, 0x1000, 0), &mut rsp));
    assert_eq!((service(&rsp), rsp[8] & 0xE0), (SERVICE_SDO_RESPONSE, 0x40));
    // The abort of a segmented upload out of step, too.
    assert!(serve(&mut s.ctx(), &request(0x60, 0, 0), &mut rsp));
    assert_eq!(
        (service(&rsp), abort(&rsp)),
        (SERVICE_SDO_REQUEST, 0x0504_0001)
    );
}

#[test]
fn the_objects_the_manuals_list_are_served() {
    // 1C00h (ETG.1000.6; MR-J3-T04 manual §8.3.2): four sync managers, mailbox out/in, outputs,
    // inputs; read-only.
    let mut s = Server::new(DriveModel::MrJ3T04);
    assert_eq!(s.read(0x1C00, 0), Ok(vec![4]));
    assert_eq!(s.read(0x1C00, 3), Ok(vec![3]));
    assert_eq!(s.read(0x1C00, 5), Err(0x0609_0011));
    assert_eq!(s.write(0x1C00, 1, &[2]), Err(0x0601_0002));
    // MR-J3-T04 §8.2.2: 1C32h:01 = 2, 1C32h:06 = 166666 ns, 1C33h:09 = 0; 100Ah listed.
    assert_eq!(s.read(0x1C32, 1), Ok(2u16.to_le_bytes().to_vec()));
    assert_eq!(s.read(0x1C32, 6), Ok(166_666u32.to_le_bytes().to_vec()));
    assert_eq!(s.read(0x1C33, 9), Ok(0u32.to_le_bytes().to_vec()));
    assert_eq!(
        s.read(0x100A, 0),
        Ok(emulated_software_version().into_bytes())
    );
    // MR-J4-TM §7.3: 12 entries, 0025h supported, calc-and-copy 222722 / 306055 ns; either
    // shift time is refused with 0609 0030h.
    let mut s = Server::new(DriveModel::MrJ4TM);
    assert_eq!(s.read(0x1C32, 0), Ok(vec![12]));
    assert_eq!(s.read(0x1C33, 4), Ok(0x0025u16.to_le_bytes().to_vec()));
    assert_eq!(s.read(0x1C32, 6), Ok(222_722u32.to_le_bytes().to_vec()));
    assert_eq!(s.read(0x1C33, 6), Ok(306_055u32.to_le_bytes().to_vec()));
    assert_eq!(s.write_u32(0x1C33, 3, 0), Err(0x0609_0030));
    assert_eq!(s.write_u32(0x1C32, 3, 0), Err(0x0609_0030));
    // The master selects DC SYNC0 (ETG.1020: 2) and reads it back.
    assert_eq!(s.write(0x1C32, 1, &2u16.to_le_bytes()), Ok(()));
    assert_eq!(s.read(0x1C32, 1), Ok(2u16.to_le_bytes().to_vec()));
    // An array or record the table lists from sub-index 1 answers sub-index 0 with its highest
    // sub-index (CiA 301 §7.4.3): 607Dh software position limit, subs 1–2.
    assert_eq!(s.read(0x607D, 0), Ok(vec![2]));
    assert_eq!(s.read(0x6041, 1), Err(0x0609_0011));
}
