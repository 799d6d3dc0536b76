//! SDO Information through the mailbox framing, as a MainDevice sees it (ETG.1000.6 §5.6.3):
//! the values come from the manuals' tables (MR-J3-T04 manual §8.7 for the codes).

use super::*;

/// One SDO Information answer: its opcode and its data, fragments joined.
#[derive(Debug)]
struct Answer {
    opcode: u8,
    data: Vec<u8>,
    messages: usize,
}

impl Server {
    /// Sends SDO Information request `opcode` with `data`; the answer from SM1's messages.
    fn info(&mut self, opcode: u8, data: &[u8]) -> Answer {
        let mut req = vec![0u8; 128];
        let len = 6 + data.len();
        req[0..2].copy_from_slice(&(len as u16).to_le_bytes());
        req[5] = MAILBOX_TYPE_COE | 0x10;
        req[6..8].copy_from_slice(&(8u16 << 12).to_le_bytes());
        req[8] = opcode;
        req[12..12 + data.len()].copy_from_slice(data);
        let mut resp = vec![0u8; 128];
        assert!(serve(&mut self.ctx(), &req, &mut resp));
        let mut messages = vec![resp];
        messages.extend(self.fragments.drain(..));
        let mut answer = Answer {
            opcode: messages[0][8] & 0x7F,
            data: Vec::new(),
            messages: messages.len(),
        };
        for (k, m) in messages.iter().enumerate() {
            let len = usize::from(u16::from_le_bytes([m[0], m[1]]));
            assert_eq!(m[5] & 0x0F, MAILBOX_TYPE_COE);
            assert_eq!(u16::from_le_bytes([m[6], m[7]]) >> 12, 8, "CoE service 8");
            let last = k + 1 == messages.len();
            assert_eq!(m[8] & 0x80 == 0, last, "incomplete bit of message {k}");
            let left = u16::from_le_bytes([m[10], m[11]]);
            assert_eq!(usize::from(left), messages.len() - 1 - k, "fragments left");
            answer.data.extend_from_slice(&m[12..6 + len]);
        }
        answer
    }

    /// Get OD List of `list_type`: the indexes (or the counts of type 0).
    fn od_list(&mut self, list_type: u16) -> Vec<u16> {
        let a = self.info(1, &list_type.to_le_bytes());
        assert_eq!(a.opcode, 2, "{a:?}");
        assert_eq!(&a.data[..2], &list_type.to_le_bytes());
        a.data[2..]
            .chunks(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]))
            .collect()
    }

    /// Get Object Description: (data type, max sub-index, object code, name).
    fn object(&mut self, index: u16) -> Result<(u16, u8, u8, String), u32> {
        let a = self.info(3, &index.to_le_bytes());
        if a.opcode == 7 {
            return Err(u32::from_le_bytes(a.data[..4].try_into().unwrap()));
        }
        assert_eq!(a.opcode, 4);
        assert_eq!(&a.data[..2], &index.to_le_bytes());
        let name = String::from_utf8(a.data[6..].to_vec()).unwrap();
        Ok((
            u16::from_le_bytes([a.data[2], a.data[3]]),
            a.data[4],
            a.data[5],
            name,
        ))
    }

    /// Get Entry Description with `value_info`: (value info, type, bits, access, the rest).
    fn entry(&mut self, index: u16, sub: u8, value_info: u8) -> Result<Entry, u32> {
        let mut d = index.to_le_bytes().to_vec();
        d.extend_from_slice(&[sub, value_info]);
        let a = self.info(5, &d);
        if a.opcode == 7 {
            return Err(u32::from_le_bytes(a.data[..4].try_into().unwrap()));
        }
        assert_eq!(a.opcode, 6);
        assert_eq!(a.messages, 1, "one message, as SOEM reads it");
        let w = |at: usize| u16::from_le_bytes([a.data[at], a.data[at + 1]]);
        Ok(Entry {
            value_info: a.data[3],
            data_type: w(4),
            bits: w(6),
            access: w(8),
            rest: a.data[10..].to_vec(),
        })
    }
}

#[derive(Debug)]
struct Entry {
    value_info: u8,
    data_type: u16,
    bits: u16,
    access: u16,
    rest: Vec<u8>,
}

#[test]
fn the_od_list_of_the_mr_j4_tm_comes_in_fragments_and_names_what_the_manual_lists() {
    let mut s = Server::new(DriveModel::MrJ4TM);
    let all = s.od_list(1);
    for i in [
        0x1000, 0x1008, 0x1018, 0x1C00, 0x1C12, 0x1C13, 0x1C32, 0x1600, 0x1A00,
    ] {
        assert!(all.contains(&i), "{i:04X}h listed");
    }
    for i in [0x6040, 0x6041, 0x6060, 0x6064, 0x607A, 0x603F, 0x6502] {
        assert!(all.contains(&i), "{i:04X}h listed");
    }
    assert!(all.windows(2).all(|w| w[0] < w[1]), "ascending, once each");
    // A 128-byte mailbox holds 57 indexes after the list type: a 3-axis unit's list fragments,
    // and the fragments join to the same ascending list.
    let mut w3 = Server::new(DriveModel::MrJ5W3GN1);
    let a = w3.info(1, &1u16.to_le_bytes());
    assert!(a.messages >= 2, "{} messages", a.messages);
    let w3_all = w3.od_list(1);
    assert_eq!(w3_all.len(), (a.data.len() - 2) / 2);
    assert!(w3_all.windows(2).all(|w| w[0] < w[1]));
    assert!(w3_all.contains(&0x7041), "axis C's statusword");
    // List type 0 counts types 1–5; 2 and 3 are the mappable objects.
    let counts = s.od_list(0);
    let rx = s.od_list(2);
    let tx = s.od_list(3);
    assert_eq!(
        counts,
        [all.len() as u16, rx.len() as u16, tx.len() as u16, 0, 0]
    );
    assert!(rx.contains(&0x6040) && !rx.contains(&0x6041));
    assert!(tx.contains(&0x6041) && tx.contains(&0x6064) && !tx.contains(&0x6040));
}

#[test]
fn every_model_lists_every_entry_its_profile_declares_on_every_axis() {
    for &model in DriveModel::ALL {
        let mut s = Server::new(model);
        let all = s.od_list(1);
        let p = profile(model);
        for o in p.all_objects() {
            for slot in 0..p.axes_per_unit {
                let Some(index) = p.axis_object(o.index, slot) else {
                    continue;
                };
                assert!(all.contains(&index), "{model:?}: {index:04X}h listed");
                let e = s.entry(index, o.sub, 0x07);
                assert!(
                    e.is_ok(),
                    "{model:?}: {index:04X}h:{} described: {e:?}",
                    o.sub
                );
            }
        }
    }
}

#[test]
fn object_and_entry_descriptions_carry_the_cia_301_codes() {
    let mut s = Server::new(DriveModel::MrJ4TM);
    // 1018h: RECORD (9) of type IDENTITY (23h), sub-indexes 0–4.
    assert_eq!(s.object(0x1018), Ok((0x23, 4, 9, "Identity".into())));
    let vendor = s.entry(0x1018, 1, 0x07).unwrap();
    assert_eq!(
        (vendor.data_type, vendor.bits, vendor.access),
        (0x0007, 32, 0x07)
    );
    assert_eq!(vendor.rest, b"Vendor ID");
    // 6041h Statusword: VAR (7) UNSIGNED16, read in every state, TxPDO-mappable (bit 7).
    let (t, max_sub, code, name) = s.object(0x6041).unwrap();
    assert_eq!((t, max_sub, code), (0x0006, 0, 7));
    assert_eq!(name, p_name(DriveModel::MrJ4TM, 0x6041, 0));
    let sw = s.entry(0x6041, 0, 0x07).unwrap();
    assert_eq!((sw.data_type, sw.bits, sw.access), (0x0006, 16, 0x87));
    // 6040h Controlword: read-write in every state, RxPDO-mappable (bit 6).
    let cw = s.entry(0x6040, 0, 0x07).unwrap();
    assert_eq!((cw.data_type, cw.bits, cw.access), (0x0006, 16, 0x7F));
    // 607Ah Target position: INTEGER32.
    assert_eq!(s.entry(0x607A, 0, 0x07).unwrap().data_type, 0x0004);
    // 1C12h: ARRAY of UNSIGNED16; the MR-J4-TM's count is read-only (manual §5.1), sub 1
    // written in PRE-OP only (access 0Fh).
    assert_eq!(s.object(0x1C12).unwrap().2, 8);
    assert_eq!(s.entry(0x1C12, 0, 0x07).unwrap().access, 0x07);
    assert_eq!(s.entry(0x1C12, 1, 0x07).unwrap().access, 0x0F);
    // 1600h: RECORD of PDO_MAPPING (21h).
    assert_eq!(s.object(0x1600).unwrap().0, 0x21);
}

#[test]
fn unknown_objects_sub_indexes_and_list_types_get_the_manual_s_abort_codes() {
    // MR-J3-T04 manual §8.7: 0602 0000h unknown index, 0609 0011h unknown sub-index,
    // 0800 0000h an invalid list type or value info.
    let mut s = Server::new(DriveModel::MrJ3T04);
    assert_eq!(s.object(0x5FFF), Err(0x0602_0000));
    assert_eq!(s.entry(0x5FFF, 0, 0x07).map(|_| ()), Err(0x0602_0000));
    assert_eq!(s.entry(0x1018, 9, 0x07).map(|_| ()), Err(0x0609_0011));
    assert_eq!(s.entry(0x6041, 0, 0x80).map(|_| ()), Err(0x0800_0000));
    let a = s.info(1, &6u16.to_le_bytes());
    assert_eq!(
        (a.opcode, a.data[..4].to_vec()),
        (7, 0x0800_0000u32.to_le_bytes().to_vec())
    );
}

#[test]
fn the_mr_j3_t04_answers_only_the_lowest_of_default_minimum_and_maximum() {
    // 1C32h:02 Cycle time: default 500000 ns, range 500000–2000000 ns (manual §5.2).
    let mut j3 = Server::new(DriveModel::MrJ3T04);
    let e = j3.entry(0x1C32, 2, 0x70).unwrap();
    assert_eq!(e.value_info, 0x10, "default only (manual §8.7)");
    assert_eq!(&e.rest[..4], &500_000u32.to_le_bytes());
    assert_eq!(&e.rest[4..], b"Cycle time");
    let e = j3.entry(0x1C32, 2, 0x60).unwrap();
    assert_eq!(
        (e.value_info, &e.rest[..4]),
        (0x20, &500_000u32.to_le_bytes()[..])
    );
    // The J3's records carry the manual's type codes: 1C32h 29h (SYNC_PAR).
    assert_eq!(j3.object(0x1C32).unwrap().0, 0x29);
    // The generic drive answers each value asked for: 1C32h:02 default 1 ms, 125 µs–8 ms.
    let mut g = Server::new(DriveModel::GenericCia402);
    let e = g.entry(0x1C32, 2, 0x70).unwrap();
    assert_eq!(e.value_info, 0x70);
    let v: Vec<u32> = e.rest[..12]
        .chunks(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(v, [1_000_000, 125_000, 8_000_000]);
}

#[test]
fn a_multi_axis_unit_lists_each_axis_at_its_offset_index() {
    // MR-J5-G-N1 manual §1.5: axis B's CiA 402 objects at +800h, its mapping objects at +10h.
    let mut s = Server::new(DriveModel::MrJ5W2GN1);
    let all = s.od_list(1);
    for i in [
        0x6041, 0x6841, 0x6064, 0x6864, 0x1600, 0x1610, 0x1A00, 0x1A10,
    ] {
        assert!(all.contains(&i), "{i:04X}h listed");
    }
    assert!(!all.contains(&0x7041), "no axis C on a 2-axis unit");
    let b = s.entry(0x6841, 0, 0x07).unwrap();
    assert_eq!((b.data_type, b.access), (0x0006, 0x87));
    // 1C12h assigns one PDO per axis.
    assert_eq!(s.object(0x1C12).unwrap().1, 2);
}

#[test]
fn every_listed_entry_can_be_uploaded_or_is_refused_as_existing() {
    for model in [
        DriveModel::MrJ3T04,
        DriveModel::MrJetGN1,
        DriveModel::MrJ5W3GN1,
    ] {
        let mut s = Server::new(model);
        for index in s.od_list(1) {
            let (_, max_sub, _, _) = s.object(index).unwrap();
            for sub in 0..=max_sub {
                if s.entry(index, sub, 0x07).is_err() {
                    continue;
                }
                assert!(
                    !matches!(s.read(index, sub), Err(0x0602_0000 | 0x0609_0011)),
                    "{model:?} {index:04X}h:{sub} listed but not served"
                );
            }
        }
    }
}

#[test]
fn complete_access_is_refused_with_0601_0000() {
    // MR-J4-TM manual §4.1: "Complete Access is not supported".
    let mut s = Server::new(DriveModel::MrJ4TM);
    let mut req = vec![0u8; 128];
    req[0..2].copy_from_slice(&10u16.to_le_bytes());
    req[5] = MAILBOX_TYPE_COE | 0x10;
    req[6..8].copy_from_slice(&(2u16 << 12).to_le_bytes());
    req[8] = 0x40 | 0x10; // initiate upload, complete access
    req[9..11].copy_from_slice(&0x1C12u16.to_le_bytes());
    let mut resp = vec![0u8; 128];
    assert!(serve(&mut s.ctx(), &req, &mut resp));
    assert_eq!(
        u16::from_le_bytes([resp[6], resp[7]]) >> 12,
        2,
        "an abort is a request"
    );
    assert_eq!(resp[8], 0x80);
    assert_eq!(&resp[12..16], &0x0601_0000u32.to_le_bytes());
}

fn p_name(model: DriveModel, index: u16, sub: u8) -> String {
    profile(model).object(index, sub).unwrap().name.to_string()
}
