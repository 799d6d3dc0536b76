//! The simulated drive's side of the CC-Link IE Field Basic cyclic link (MR-JE-C manual §2.2.1,
//! §2.3.2, §2.5.1; the connection rules of a conformant slave as the extract records them from
//! an open implementation): a master is accepted from a request whose transmission bit for the
//! drive's station is off, another master gets end code CFE0h, a master silent for its
//! supervision time (timeout × count) is dropped. While the master transmits to the station and
//! sets CSR (RY(n+3)F), the drive imports RWw into the objects of the manual's Table 2.2
//! (profile mode) or Table 2.3 (positioning modes; [`LinkLayout`]) and answers SSR
//! (RX(n+3)F); RWr is built from the 1A00h mapping. Every
//! request refreshes [Pr. PN02]'s time-out; the sequence number and group are echoed.

use std::time::Duration;

use super::{MrJeC, Transport};
use cellrt_fieldbus::cclink_ief_basic::{
    bit, set_bit, CyclicRequest, CyclicResponse, EndCode, StationData, READY_BIT,
};
use cellrt_fieldbus::mr_je_c::objects::ObjectId;
use cellrt_fieldbus::mr_je_c::value::Value;

/// Which of the manual's RWw/RWr tables the drive's link devices follow (§2.3.2): Table 2.2
/// "position/speed/torque control mode, profile mode, and home position return mode", or
/// Table 2.3 "pt/idx/jg/hm". The manual ties them to the operation mode by those titles only
/// (hm is in both) and does not say whether 6060h or [Pr. PA01] chooses; the emulator takes
/// the layout as a unit parameter, fixed like [Pr. PA01] (a named choice,
/// [`super::MrJeCParams::link_layout`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinkLayout {
    /// Table 2.2: the standard control modes, profile mode and homing.
    #[default]
    Profile,
    /// Table 2.3: the positioning modes (point table, indexer, jog) and homing.
    Positioning,
}

/// Text that names no link layout.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("link layout {0:?}: expected profile (Table 2.2) or positioning (Table 2.3)")]
pub struct ParseLinkLayoutError(pub String);

impl std::str::FromStr for LinkLayout {
    type Err = ParseLinkLayoutError;

    /// `profile` or `positioning` (also `2.2` / `2.3`, the manual's table numbers).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "profile" | "2.2" => Ok(LinkLayout::Profile),
            "positioning" | "2.3" => Ok(LinkLayout::Positioning),
            _ => Err(ParseLinkLayoutError(s.to_string())),
        }
    }
}

impl std::fmt::Display for LinkLayout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LinkLayout::Profile => "Table 2.2 (profile)",
            LinkLayout::Positioning => "Table 2.3 (positioning)",
        })
    }
}

impl LinkLayout {
    /// RWw → objects: (device, object).
    pub fn rww(self) -> &'static [(usize, u16)] {
        match self {
            LinkLayout::Profile => &RWW_PROFILE,
            LinkLayout::Positioning => &RWW_POSITIONING,
        }
    }

    /// The response mapping 1A00h:1… after power-on (§7.4.6: "Table 2.2 and Table 2.3").
    pub fn default_mapping(self) -> &'static [u32] {
        match self {
            LinkLayout::Profile => &DEFAULT_MAPPING,
            LinkLayout::Positioning => &POSITIONING_MAPPING,
        }
    }
}

/// RWw → objects, manual Table 2.2 (profile, P/S/T and homing modes): (device, object).
/// 32-bit objects take two devices, the low word first; 6060h is the low byte of RWwn00.
const RWW_PROFILE: [(usize, u16); 19] = [
    (0x00, 0x6060),
    (0x01, 0x6040),
    (0x02, 0x2D01),
    (0x03, 0x2D02),
    (0x04, 0x2D03),
    (0x05, 0x607A),
    (0x07, 0x60FF),
    (0x09, 0x2D20),
    (0x0B, 0x6071),
    (0x0C, 0x6081),
    (0x0E, 0x6083),
    (0x10, 0x6084),
    (0x12, 0x6087),
    (0x14, 0x60E0),
    (0x15, 0x60E1),
    (0x17, 0x60B8),
    (0x18, 0x60F2),
    (0x19, 0x2D05),
    (0x1A, 0x0000),
];

/// RWw → objects, manual Table 2.3 (pt, idx, jg, hm): the profile velocity and ramps, the
/// target point table 2D60h and target speed No. 2DD1h (16-bit) instead of the targets.
const RWW_POSITIONING: [(usize, u16); 11] = [
    (0x00, 0x6060),
    (0x01, 0x6040),
    (0x02, 0x2D01),
    (0x03, 0x2D02),
    (0x04, 0x2D03),
    (0x05, 0x2D60),
    (0x06, 0x6081),
    (0x08, 0x6083),
    (0x0A, 0x6084),
    (0x0C, 0x60B8),
    (0x0D, 0x2DD1),
];

/// The response mapping of Table 2.3's RWr column as the extract reconstructs it (20 entries,
/// 46 bytes = RWrn00…RWrn16: the raw table's objects with 32-bit ones on two devices, 8-bit
/// ones padded to a word).
pub const POSITIONING_MAPPING: [u32; 20] = [
    0x6061_0008,
    0x0000_0008,
    0x6041_0010,
    0x6064_0020,
    0x606C_0020,
    0x60F4_0020,
    0x6077_0010,
    0x2D11_0010,
    0x2D12_0010,
    0x2D13_0010,
    0x2D15_0010,
    0x2D17_0010,
    0x2D68_0010,
    0x2D69_0010,
    0x2D6A_0008,
    0x0000_0008,
    0x2A42_0010,
    0x60B9_0010,
    0x60BA_0020,
    0x60BB_0020,
];

/// The default response mapping 1A00h:1–15 (the extract's reconstruction of the garbled
/// Table 2.2 RWr column: 15 entries, 40 bytes, sub 1 = 60610008h as the manual gives).
pub const DEFAULT_MAPPING: [u32; 15] = [
    0x6061_0008,
    0x0000_0008,
    0x6041_0010,
    0x6064_0020,
    0x606C_0020,
    0x60F4_0020,
    0x6077_0010,
    0x2D11_0010,
    0x2D12_0010,
    0x2D13_0010,
    0x2A42_0010,
    0x60B9_0010,
    0x60BA_0020,
    0x60BB_0020,
    0x2C12_0120,
];

/// The connected master.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Master {
    id: u32,
    last: Duration,
    lost_after: Duration,
}

/// The drive's end of the cyclic link.
#[derive(Debug, Clone, Default)]
pub struct CyclicLink {
    master: Option<Master>,
}

impl CyclicLink {
    /// The response to `request` at `now` for a drive whose IP (slave ID) is `own`; `None`:
    /// dropped without an answer. RWw is imported only if the master may `operate` (the
    /// operation specification IP, §5.2.3); RY, and so the CSR/SSR handshake, always is.
    pub fn answer(
        &mut self,
        drive: &mut MrJeC,
        request: &CyclicRequest,
        own: u32,
        operate: bool,
        now: Duration,
    ) -> Option<CyclicResponse> {
        let k = request.station_of(own)?;
        if let Some(m) = self.master {
            if now.saturating_sub(m.last) > m.lost_after {
                self.master = None;
                drive.set_cyclic_ready(false);
            }
        }
        let mut response = CyclicResponse {
            protocol_version: request.protocol_version,
            end_code: EndCode::Normal,
            vendor_code: 0,
            model_code: 0,
            equipment_version: 0,
            unit_info: 1,
            error_code: 0,
            local_info: 0,
            group: request.group,
            sequence: request.sequence,
            station: StationData {
                slave_id: own,
                ..StationData::default()
            },
        };
        let transmitting = request.transmitting(k);
        match self.master {
            None if transmitting => return None,
            None => {
                self.connect(request, now);
                return Some(response);
            }
            Some(m) if m.id != request.master_id => {
                response.end_code = EndCode::MasterDuplication;
                return Some(response);
            }
            Some(_) => self.connect(request, now),
        }
        drive.received(Transport::CcLink, now);
        if !transmitting {
            drive.set_cyclic_ready(false);
            return Some(response);
        }
        let data = &request.station[k - 1];
        let csr = bit(&data.bits, READY_BIT);
        drive.set_cyclic_ready(csr);
        if csr {
            if operate {
                import(drive, &data.words, now);
            }
            response.station.words = export(drive);
            set_bit(&mut response.station.bits, READY_BIT, true);
        }
        Some(response)
    }

    fn connect(&mut self, request: &CyclicRequest, now: Duration) {
        self.master = Some(Master {
            id: request.master_id,
            last: now,
            lost_after: Duration::from_millis(u64::from(request.master_lost_after_ms())),
        });
    }
}

/// Writes RWw into the objects; a value an object refuses is not taken.
fn import(drive: &mut MrJeC, words: &[u8; 64], now: Duration) {
    let sw = drive.params().software;
    let layout = drive.params().link_layout;
    for &(device, index) in layout.rww().iter().filter(|(_, i)| *i != 0) {
        let id = ObjectId::new(index, 0);
        let Ok((_, row)) = cellrt_fieldbus::mr_je_c::access::lookup(id, sw) else {
            continue;
        };
        let at = 2 * device;
        let bytes = &words[at..at + row.ty.bytes().min(64 - at)];
        if let Some(v) = Value::from_le(row.ty, bytes) {
            let unchanged = drive.read(id).is_ok_and(|old| old == v);
            if !unchanged || index == 0x6040 {
                let _ = drive.write(id, &v, now);
            }
        }
    }
}

/// RWr from the 1A00h mapping: each entry's value in its bit size, gaps as zeros.
fn export(drive: &MrJeC) -> [u8; 64] {
    let mut out = [0u8; 64];
    let mut at = 0;
    for entry in drive.mapping() {
        let bytes = (entry & 0xFF) as usize / 8;
        let id = ObjectId::new((entry >> 16) as u16, (entry >> 8) as u8);
        if id.index != 0 {
            if let Ok(v) = drive.read(id) {
                let le = v.to_le();
                let n = bytes.min(le.len()).min(64 - at);
                out[at..at + n].copy_from_slice(&le[..n]);
            }
        }
        at = (at + bytes).min(64);
    }
    out
}
