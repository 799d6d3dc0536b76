//! The CoE mailbox server of an emulated drive (ETG.1000.6 §5.6): SDO upload (expedited and
//! normal) and download (expedited and normal) with CiA 301 abort codes. The communication
//! objects (1000h, 1008h, 1018h, 1C12h/1C13h, the PDO mapping objects) are served here; every
//! other object is the simulated drive's own SDO surface (`sim::sdo`), so abort codes such as
//! MR-J4-TM's 0609 0030h for 1C32h:03 (mr-j4-tm.md §12 TV-10) come from the drive model.

use crate::ethercat::identity::SubDeviceIdentity;
use crate::ethercat::register::AlState;
use crate::pdo::objects::ERROR_CODE;
use crate::pdo::PdoMap;
use crate::sim::drive::SimDrive;
use crate::sim::sdo::SdoAbort;

/// Mailbox header bytes (length, address, channel/priority, type/counter).
pub const MAILBOX_HEADER_LEN: usize = 6;
/// Mailbox type CoE.
pub const MAILBOX_TYPE_COE: u8 = 3;
/// CoE service: SDO request.
const SERVICE_SDO_REQUEST: u16 = 2;
/// CoE service: SDO response.
const SERVICE_SDO_RESPONSE: u16 = 3;
/// 1000h Device type: CiA 402 (0192h), servo drive (additional information 0002h).
pub const DEVICE_TYPE: u32 = 0x0002_0192;
/// 0504 0001h Client/server command specifier not valid or unknown.
pub const ABORT_BAD_COMMAND: SdoAbort = SdoAbort(0x0504_0001);
/// 0800 0022h Data cannot be transferred because of the present device state.
pub const ABORT_DEVICE_STATE: SdoAbort = SdoAbort(0x0800_0022);
/// 0604 0043h General parameter incompatibility: a PDO mapping the emulator cannot serve.
pub const ABORT_PARAMETER_INCOMPATIBLE: SdoAbort = SdoAbort(0x0604_0043);
/// 0601 0000h for complete access, which the SII does not advertise.
const ABORT_UNSUPPORTED: SdoAbort = SdoAbort::UNSUPPORTED_ACCESS;

/// 1C32h SM2 synchronisation; sub 2 the cycle time.
const SM2_SYNC: u16 = 0x1C32;
/// 1C33h SM3 synchronisation; sub 2 follows 1C32h:02.
const SM3_SYNC: u16 = 0x1C33;

/// The station-level state the CoE server needs besides the drive.
#[derive(Debug)]
pub struct CoeContext<'a> {
    /// The drive behind the station.
    pub drive: &'a mut SimDrive,
    /// 1018h.
    pub identity: SubDeviceIdentity,
    /// The AL state (PDO configuration only in PRE-OP).
    pub al_state: AlState,
    /// The station's PDO assignment and mapping, as written by the master.
    pub pdo: &'a mut PdoConfig,
    /// The mailbox counter of the last response (1..=7).
    pub counter: &'a mut u8,
}

/// The PDO assignment (1C12h/1C13h) and mapping (16xxh/1Axxh) objects of a station. The
/// emulated drive runs its profile's default maps, so a mapping can be rewritten (count to 0,
/// entries, count last) but must end equal to the default; anything else is refused with
/// 0604 0043h when the count is written (a documented emulator limit).
#[derive(Debug, Clone)]
pub struct PdoConfig {
    rx: PdoObject,
    tx: PdoObject,
    /// 1C12h:00 / 1C13h:00 counts (0 while being rewritten).
    assign_counts: [u8; 2],
}

#[derive(Debug, Clone)]
struct PdoObject {
    map: PdoMap,
    count: u8,
    words: Vec<u32>,
}

impl PdoObject {
    fn new(map: PdoMap) -> Self {
        let words: Vec<u32> = map.entries.iter().map(|e| e.mapping_word()).collect();
        PdoObject {
            map,
            count: words.len() as u8,
            words,
        }
    }

    fn default_words(&self) -> impl Iterator<Item = u32> + '_ {
        self.map.entries.iter().map(|e| e.mapping_word())
    }
}

impl PdoConfig {
    /// The defaults of the drive's profile.
    pub fn new(rx: PdoMap, tx: PdoMap) -> Self {
        PdoConfig {
            rx: PdoObject::new(rx),
            tx: PdoObject::new(tx),
            assign_counts: [1, 1],
        }
    }

    /// True if the RxPDO and TxPDO are assigned and mapped (what SAFE-OP requires).
    pub fn complete(&self) -> bool {
        self.assign_counts == [1, 1]
            && usize::from(self.rx.count) == self.rx.map.entries.len()
            && usize::from(self.tx.count) == self.tx.map.entries.len()
    }

    fn object(&mut self, index: u16) -> Option<&mut PdoObject> {
        if index == self.rx.map.index {
            Some(&mut self.rx)
        } else if index == self.tx.map.index {
            Some(&mut self.tx)
        } else {
            None
        }
    }
}

/// A value to upload: up to 64 bytes of little-endian data.
type Value = Vec<u8>;

fn upload(ctx: &mut CoeContext<'_>, index: u16, sub: u8) -> Result<Value, SdoAbort> {
    let u8v = |v: u8| vec![v];
    let u16v = |v: u16| v.to_le_bytes().to_vec();
    let u32v = |v: u32| v.to_le_bytes().to_vec();
    let profile = ctx.drive.profile();
    match (index, sub) {
        (0x1000, 0) => return Ok(u32v(DEVICE_TYPE)),
        (0x1000, _) | (0x1008, 1..) => return Err(SdoAbort::NO_SUBINDEX),
        (0x1008, 0) => return Ok(profile.name.as_bytes().to_vec()),
        (0x1018, 0) => return Ok(u8v(4)),
        (0x1018, 1) => return Ok(u32v(ctx.identity.vendor_id)),
        (0x1018, 2) => return Ok(u32v(ctx.identity.product_code)),
        (0x1018, 3) => return Ok(u32v(ctx.identity.revision)),
        (0x1018, 4) => return Ok(u32v(ctx.identity.serial)),
        (0x1018, _) => return Err(SdoAbort::NO_SUBINDEX),
        (0x1C12 | 0x1C13, s) => {
            let i = usize::from(index == 0x1C13);
            let map = if i == 0 {
                ctx.pdo.rx.map
            } else {
                ctx.pdo.tx.map
            };
            return match s {
                0 => Ok(u8v(ctx.pdo.assign_counts[i])),
                1 => Ok(u16v(map.index)),
                _ => Err(SdoAbort::NO_SUBINDEX),
            };
        }
        (SM3_SYNC, 2) => return upload(ctx, SM2_SYNC, 2),
        // 603Fh Error code: mandatory in CiA 402, served live where the model's table and
        // TxPDO leave it out (MR-JET-G-N1, MR-J5-G-N1).
        (ERROR_CODE, 0) if profile.object(ERROR_CODE, 0).is_none() => {
            return Ok(u16v(ctx.drive.tx_pdo().error_code))
        }
        _ => {}
    }
    if let Some(obj) = ctx.pdo.object(index) {
        return match sub {
            0 => Ok(u8v(obj.count)),
            s if usize::from(s) <= obj.words.len() => Ok(u32v(obj.words[usize::from(s) - 1])),
            _ => Err(SdoAbort::NO_SUBINDEX),
        };
    }
    let value = ctx.drive.sdo_upload(index, sub)?;
    let bits = profile
        .rx_pdo
        .entries
        .iter()
        .chain(profile.tx_pdo.entries)
        .find(|e| e.index == index && e.sub == sub)
        .map(|e| e.bits)
        .or_else(|| profile.object(index, sub).and_then(|o| o.data_type.bits()))
        .unwrap_or(32);
    let n = usize::from(bits.div_ceil(8)).clamp(1, 8);
    Ok(value.to_le_bytes()[..n].to_vec())
}

fn download(ctx: &mut CoeContext<'_>, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
    let word = |d: &[u8]| {
        let mut b = [0u8; 4];
        let n = d.len().min(4);
        b[..n].copy_from_slice(&d[..n]);
        u32::from_le_bytes(b)
    };
    match index {
        0x1000 | 0x1008 | 0x1018 => return Err(SdoAbort::READ_ONLY),
        0x1C12 | 0x1C13 => {
            if ctx.al_state != AlState::PreOp {
                return Err(ABORT_DEVICE_STATE);
            }
            let i = usize::from(index == 0x1C13);
            let own = if i == 0 {
                ctx.pdo.rx.map.index
            } else {
                ctx.pdo.tx.map.index
            };
            return match sub {
                0 if data.len() != 1 => Err(SdoAbort::TOO_LONG),
                0 if data[0] > 1 => Err(SdoAbort::VALUE_RANGE),
                0 => {
                    ctx.pdo.assign_counts[i] = data[0];
                    Ok(())
                }
                1 if ctx.pdo.assign_counts[i] != 0 => Err(SdoAbort::UNSUPPORTED_ACCESS),
                1 if word(data) as u16 != own => Err(ABORT_PARAMETER_INCOMPATIBLE),
                1 => Ok(()),
                _ => Err(SdoAbort::NO_SUBINDEX),
            };
        }
        SM3_SYNC => return Err(SdoAbort::READ_ONLY),
        SM2_SYNC if sub == 2 => {
            let ns = word(data);
            if !super::allows_cycle_ns(ctx.drive.profile(), ns) {
                return Err(SdoAbort::VALUE_RANGE);
            }
        }
        _ => {}
    }
    let pre_op = ctx.al_state == AlState::PreOp;
    if let Some(obj) = ctx.pdo.object(index) {
        if !pre_op {
            return Err(ABORT_DEVICE_STATE);
        }
        return match sub {
            0 => {
                let n = usize::from(data[0]);
                if n != 0
                    && (n != obj.map.entries.len()
                        || !obj.default_words().eq(obj.words.iter().copied()))
                {
                    return Err(ABORT_PARAMETER_INCOMPATIBLE);
                }
                obj.count = data[0];
                Ok(())
            }
            _ if obj.count != 0 => Err(SdoAbort::UNSUPPORTED_ACCESS),
            s if usize::from(s) > crate::pdo::MAX_LAYOUT_ENTRIES => Err(SdoAbort::NO_SUBINDEX),
            s => {
                let at = usize::from(s) - 1;
                if obj.words.len() <= at {
                    obj.words.resize(at + 1, 0);
                }
                obj.words[at] = word(data);
                Ok(())
            }
        };
    }
    ctx.drive.sdo_download(index, sub, data)
}

/// Handles one mailbox request in `request` (the SM0 buffer) and writes the response into
/// `response` (the SM1 buffer). Returns false if the request needs no response (an abort
/// from the master, or not CoE).
pub fn serve(ctx: &mut CoeContext<'_>, request: &[u8], response: &mut [u8]) -> bool {
    if request.len() < MAILBOX_HEADER_LEN + 2 {
        return false;
    }
    let len = usize::from(u16::from_le_bytes([request[0], request[1]]));
    if request[5] & 0x0F != MAILBOX_TYPE_COE {
        return false;
    }
    let body = &request[MAILBOX_HEADER_LEN..(MAILBOX_HEADER_LEN + len).min(request.len())];
    if body.len() < 2 + 4 || u16::from_le_bytes([body[0], body[1]]) >> 12 != SERVICE_SDO_REQUEST {
        return false;
    }
    let cmd = body[2];
    let index = u16::from_le_bytes([body[3], body[4]]);
    let sub = body[5];
    let data = &body[6..];
    let ccs = cmd >> 5;
    if ccs == 4 {
        return false;
    }
    let complete_access = cmd & 0x10 != 0;
    let mut out = [0u8; 10];
    out[3..5].copy_from_slice(&index.to_le_bytes());
    out[5] = sub;
    let payload: Result<Option<Value>, SdoAbort> = if complete_access && ccs != 3 && ccs != 0 {
        Err(ABORT_UNSUPPORTED)
    } else {
        match ccs {
            1 => {
                let expedited = cmd & 0x02 != 0;
                let sized = cmd & 0x01 != 0;
                let value: Option<&[u8]> = if expedited {
                    let n = if sized {
                        4 - usize::from((cmd >> 2) & 3)
                    } else {
                        4
                    };
                    data.get(..n)
                } else {
                    data.get(..4).and_then(|s| {
                        let n = u32::from_le_bytes([s[0], s[1], s[2], s[3]]) as usize;
                        data.get(4..4 + n)
                    })
                };
                match value {
                    None => Err(SdoAbort::TOO_SHORT),
                    Some(v) => download(ctx, index, sub, v).map(|()| {
                        out[2] = 0x60;
                        None
                    }),
                }
            }
            2 => upload(ctx, index, sub).map(Some),
            _ => Err(ABORT_BAD_COMMAND),
        }
    };
    let body_len = match payload {
        Ok(None) => 6,
        Ok(Some(v)) if v.len() <= 4 => {
            out[2] = 0x43 | (((4 - v.len()) as u8) << 2);
            out[6..6 + v.len()].copy_from_slice(&v);
            10
        }
        Ok(Some(v)) => {
            let room = response.len().saturating_sub(MAILBOX_HEADER_LEN + 10);
            if v.len() > room {
                write_abort(&mut out, SdoAbort::TOO_LONG);
                10
            } else {
                out[2] = 0x41;
                out[6..10].copy_from_slice(&(v.len() as u32).to_le_bytes());
                let start = MAILBOX_HEADER_LEN + 10;
                response[start..start + v.len()].copy_from_slice(&v);
                10 + v.len()
            }
        }
        Err(abort) => {
            write_abort(&mut out, abort);
            10
        }
    };
    let body_len = body_len.max(10);
    out[0..2].copy_from_slice(&(SERVICE_SDO_RESPONSE << 12).to_le_bytes());
    response[0..2].copy_from_slice(&(body_len as u16).to_le_bytes());
    response[2..5].fill(0);
    *ctx.counter = if *ctx.counter >= 7 {
        1
    } else {
        *ctx.counter + 1
    };
    response[5] = MAILBOX_TYPE_COE | (*ctx.counter << 4);
    let head = MAILBOX_HEADER_LEN;
    response[head..head + 10].copy_from_slice(&out);
    true
}

fn write_abort(out: &mut [u8; 10], abort: SdoAbort) {
    out[2] = 0x80;
    out[6..10].copy_from_slice(&abort.0.to_le_bytes());
}
