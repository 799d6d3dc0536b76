//! SII EEPROM images generated from a drive profile (ETG.2010): identity, mailbox
//! configuration, and the Strings, General, FMMU, SyncManager, TxPDO, RxPDO and DC categories a
//! MainDevice reads to bring the SubDevice up, consistent with the model's ESI
//! (`configs/esi/`, written from the same profile).

use super::layout::StationLayout;
use cellrt_cia402::pdo::{PdoEntry, PdoMap};
use cellrt_cia402::profiles::DriveProfile;
use cellrt_ethercat::identity::SubDeviceIdentity;
use cellrt_ethercat::register::DC_ASSIGN_ACTIVATE_SYNC0;

/// One PDO as the SII lists it: its mapping object and entries (on a multi-axis unit at the
/// axis' offset indexes, MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SiiPdo {
    /// The mapping object index (1600h, 1610h…).
    pub index: u16,
    /// The mapped entries.
    pub entries: Vec<PdoEntry>,
}

impl SiiPdo {
    /// `map` of `profile` as axis `slot` of the unit carries it.
    pub fn of_slot(profile: &DriveProfile, map: &PdoMap, slot: u8) -> Self {
        let at = |index: u16| profile.axis_object(index, slot).unwrap_or(index);
        SiiPdo {
            index: at(map.index),
            entries: map
                .entries
                .iter()
                .map(|e| {
                    if e.is_padding() {
                        *e
                    } else {
                        PdoEntry {
                            index: at(e.index),
                            ..*e
                        }
                    }
                })
                .collect(),
        }
    }
}

/// Category codes (ETG.2010 Table 4).
mod category {
    pub const STRINGS: u16 = 10;
    pub const GENERAL: u16 = 30;
    pub const FMMU: u16 = 40;
    pub const SYNC_MANAGER: u16 = 41;
    pub const TX_PDO: u16 = 50;
    pub const RX_PDO: u16 = 51;
    pub const DC: u16 = 60;
    pub const END: u16 = 0xFFFF;
}

/// Mailbox protocols word bit for CoE (ETG.2010 Table 2).
const MAILBOX_COE: u16 = 0x0004;
/// General category CoE details (ETG.2010 Table 4): SDO, PDO assign, PDO config; bit 5
/// (complete access) stays clear: "Complete Access is not supported" (MR-J4-TM manual §4.1,
/// MR-J3-T04 manual §8.5; the MR-J5-G-N1 and MR-JET-G-N1 manuals' service lists (§5) omit it).
const COE_DETAILS: u8 = 0x01 | 0x04 | 0x08;
/// CoE details bit 1: SDO Information.
const COE_DETAILS_SDO_INFO: u8 = 0x02;
/// The word address where the categories start.
const FIRST_CATEGORY_WORD: usize = 0x40;
/// EEPROM size word 003Eh: size in kbit − 1 (a 32 kbit device).
const SIZE_KBIT_MINUS_1: u16 = 31;

/// Builds the EEPROM image, in bytes, of a SubDevice with `identity`, `name` and `layout`,
/// listing `rx_pdos` and `tx_pdos` (one per axis of a multi-axis unit, in axis order); `sdo_info`:
/// the CoE details say SDO Information is offered.
pub fn image(
    identity: SubDeviceIdentity,
    sdo_info: bool,
    name: &str,
    layout: &StationLayout,
    rx_pdos: &[SiiPdo],
    tx_pdos: &[SiiPdo],
) -> Vec<u8> {
    let mut words = vec![0u16; FIRST_CATEGORY_WORD];
    let put32 = |w: &mut Vec<u16>, at: usize, v: u32| {
        w[at] = v as u16;
        w[at + 1] = (v >> 16) as u16;
    };
    put32(&mut words, 0x08, identity.vendor_id);
    put32(&mut words, 0x0A, identity.product_code);
    put32(&mut words, 0x0C, identity.revision);
    put32(&mut words, 0x0E, identity.serial);
    words[0x18] = layout.mailbox_out.start;
    words[0x19] = layout.mailbox_out.len;
    words[0x1A] = layout.mailbox_in.start;
    words[0x1B] = layout.mailbox_in.len;
    words[0x1C] = MAILBOX_COE;
    words[0x3E] = SIZE_KBIT_MINUS_1;
    let mut bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();

    // Strings: 1 = device name, 2 = "RxPDO", 3 = "TxPDO", 4 = the DC operation mode's name.
    let strings = [name, "RxPDO", "TxPDO", DC_OP_MODE_NAME];
    let mut s = vec![strings.len() as u8];
    for t in strings {
        let t = &t.as_bytes()[..t.len().min(255)];
        s.push(t.len() as u8);
        s.extend_from_slice(t);
    }
    push_category(&mut bytes, category::STRINGS, &s);

    let mut general = [0u8; 32];
    // Order number and name string index: the emulated drive's order number is its name.
    general[2] = 1;
    general[3] = 1;
    general[5] = COE_DETAILS | if sdo_info { COE_DETAILS_SDO_INFO } else { 0 };
    push_category(&mut bytes, category::GENERAL, &general);

    // FMMU usage: 0 outputs, 1 inputs, 2 SyncManager status.
    push_category(&mut bytes, category::FMMU, &[1, 2, 3, 0]);

    let mut sms = Vec::new();
    for sm in layout.sync_managers() {
        sms.extend_from_slice(&sm.start.to_le_bytes());
        sms.extend_from_slice(&sm.len.to_le_bytes());
        sms.extend_from_slice(&[sm.control, 0, 1, sm.usage as u8]);
    }
    push_category(&mut bytes, category::SYNC_MANAGER, &sms);

    for pdo in tx_pdos {
        push_category(&mut bytes, category::TX_PDO, &pdo_category(pdo, 3, 3));
    }
    for pdo in rx_pdos {
        push_category(&mut bytes, category::RX_PDO, &pdo_category(pdo, 2, 2));
    }
    push_category(&mut bytes, category::DC, &dc_op_mode());
    bytes.extend_from_slice(&category::END.to_le_bytes());
    bytes.extend_from_slice(&[0, 0]);
    bytes
}

/// The name of the one DC operation mode, as the ESI's `Dc/OpMode/Name`.
const DC_OP_MODE_NAME: &str = "DC";

/// The DC category's one operation mode (ETG.2010 Table 18, 24 bytes): SYNC0 at one bus cycle
/// (cycle time 0, factor 1), no shift, no SYNC1, the ESI's `AssignActivate`.
fn dc_op_mode() -> [u8; 24] {
    let mut m = [0u8; 24];
    // Cycle time SYNC0, shift SYNC0, shift SYNC1 (bytes 0–11): 0; SYNC1 cycle factor: 0.
    m[14..16].copy_from_slice(&DC_ASSIGN_ACTIVATE_SYNC0.to_le_bytes());
    m[16..18].copy_from_slice(&1i16.to_le_bytes());
    m[18] = 4;
    m
}

/// `image` without its DC category: a SubDevice whose ESC has no distributed clocks.
pub fn without_dc(image: &[u8]) -> Vec<u8> {
    let mut out = image[..2 * FIRST_CATEGORY_WORD].to_vec();
    let mut at = 2 * FIRST_CATEGORY_WORD;
    while at + 4 <= image.len() {
        let code = u16::from_le_bytes([image[at], image[at + 1]]);
        let words = usize::from(u16::from_le_bytes([image[at + 2], image[at + 3]]));
        let end = (at + 4 + 2 * words).min(image.len());
        if code != category::DC {
            out.extend_from_slice(&image[at..end]);
        }
        if code == category::END {
            break;
        }
        at = end;
    }
    out
}

/// One PDO with its entries (ETG.2010 Table 14/15), assigned to SyncManager `sm`.
fn pdo_category(map: &SiiPdo, sm: u8, name: u8) -> Vec<u8> {
    let mut v = Vec::new();
    v.extend_from_slice(&map.index.to_le_bytes());
    v.extend_from_slice(&[map.entries.len() as u8, sm, 0, name, 0, 0]);
    for e in &map.entries {
        v.extend_from_slice(&e.index.to_le_bytes());
        v.extend_from_slice(&[e.sub, 0, 0, e.bits as u8, 0, 0]);
    }
    v
}

fn push_category(bytes: &mut Vec<u8>, code: u16, data: &[u8]) {
    let words = data.len().div_ceil(2);
    bytes.extend_from_slice(&code.to_le_bytes());
    bytes.extend_from_slice(&(words as u16).to_le_bytes());
    bytes.extend_from_slice(data);
    if data.len() % 2 == 1 {
        bytes.push(0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::profiles::{profile, DriveModel};

    fn word(img: &[u8], w: usize) -> u16 {
        u16::from_le_bytes([img[2 * w], img[2 * w + 1]])
    }

    #[test]
    fn identity_mailbox_and_categories_sit_where_etg2010_puts_them() {
        let p = profile(DriveModel::MrJ3T04);
        let id = SubDeviceIdentity::of_profile(p);
        let layout = StationLayout::of_profile(p);
        let img = image(
            id,
            p.comm.sdo_info.offered,
            p.name,
            &layout,
            &[SiiPdo::of_slot(p, &p.pdo.rx, 0)],
            &[SiiPdo::of_slot(p, &p.pdo.tx, 0)],
        );
        assert_eq!(word(&img, 0x08), 0x0A1E);
        assert_eq!(word(&img, 0x0A), 0x0102);
        assert_eq!(word(&img, 0x18), layout.mailbox_out.start);
        assert_eq!(word(&img, 0x1C), MAILBOX_COE);
        // Walk the categories to the SyncManager one.
        let mut w = FIRST_CATEGORY_WORD;
        let mut seen = Vec::new();
        loop {
            let code = word(&img, w);
            seen.push(code);
            if code == category::END {
                break;
            }
            if code == category::GENERAL {
                // CoE details (general byte 5): SDO, SDO Information, PDO assign and
                // configuration; no complete access (MR-J3-T04 manual §8.5).
                assert_eq!(img[2 * (w + 2) + 5], 0x0F);
            }
            if code == category::SYNC_MANAGER {
                assert_eq!(word(&img, w + 1), 16, "four 8-byte SyncManagers");
                assert_eq!(word(&img, w + 2 + 4 * 2 + 1), p.pdo.rx.byte_len() as u16);
            }
            w += 2 + usize::from(word(&img, w + 1));
        }
        assert_eq!(seen, [10, 30, 40, 41, 50, 51, 60, 0xFFFF]);
        // Without distributed clocks the DC category goes, the rest stays.
        let no_dc = without_dc(&img);
        assert_eq!(no_dc.len(), img.len() - 4 - 24);
        assert_eq!(&no_dc[..no_dc.len() - 4], &img[..no_dc.len() - 4]);
    }

    /// The DC category agrees with the model's shipped ESI: its one `Dc/OpMode` (name,
    /// `AssignActivate`, SYNC0 at one bus cycle).
    #[test]
    fn the_dc_category_is_the_esi_s_op_mode() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/esi/mr-j4-tm.xml");
        let esi = cellrt_ethercat::esi::load(&path).unwrap().remove(0);
        let op = &esi.dc_opmodes[0];
        let m = dc_op_mode();
        assert_eq!(op.name, DC_OP_MODE_NAME);
        assert_eq!(
            op.assign_activate,
            u32::from(u16::from_le_bytes([m[14], m[15]]))
        );
        assert!(op.uses_sync0());
        let sync0 = op.sync0.expect("CycleTimeSync0");
        assert_eq!((sync0.ns, sync0.factor), (0, Some(1)));
        assert_eq!(u32::from_le_bytes(m[0..4].try_into().unwrap()), sync0.ns);
        assert_eq!(i16::from_le_bytes([m[16], m[17]]), 1);
    }
}
