//! The SubDevices on a link, read without configuring anything (`cellrt bus scan`): their
//! number by a broadcast read, then each one by its position (auto-increment addressing, so
//! no station address is set): identity, name, mailbox protocols from its SII EEPROM
//! (ETG.2010), AL status and code (ETG.1000.6 §6.4), and DC support (ESC feature register).

use super::al_state::{read_al_status, read_registers};
use super::group::MASTER_MAC;
use super::link::{Link, LinkError, Retrying};
use crate::frame::{self, Command, FrameBuilder};
use crate::identity::SubDeviceIdentity;
use crate::register::{self as reg, AlStatus};

/// Bytes of the frame buffer a scan uses.
const FRAME_BUF: usize = 1536;
/// SII words read at most while walking the categories (a 32 kbit EEPROM has 2048).
const MAX_SII_WORDS: u16 = 2048;
/// First category word (ETG.2010 Table 1: the categories follow the 64-word header).
const FIRST_CATEGORY_WORD: u16 = 0x40;
/// SII control (0502h) bit 8: read; bit 15: busy; bit 6: 8-byte reads.
const SII_READ: u16 = 0x0100;
const SII_BUSY: u16 = 0x8000;
const SII_READ_8: u16 = 0x0040;
/// Times a scan frame is sent again when its return does not come in time (a loaded host or
/// emulator may answer late; every datagram of a scan is a read or a repeatable request).
const SCAN_RETRIES: usize = 3;
/// Polls of the SII busy bit before a read counts as failed.
const SII_POLLS: usize = 100;
/// ESC feature register (0008h) bit 2: distributed clocks.
const FEATURE_DC: u16 = 0x0004;

/// One SubDevice as a scan found it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScannedSubDevice {
    /// Position in the line (0 = next to the master).
    pub position: usize,
    /// Vendor, product code, revision and serial from the SII (words 08h–0Fh).
    pub identity: SubDeviceIdentity,
    /// The device name from the SII (General category's name string); empty where none.
    pub name: String,
    /// AL status and code.
    pub al: AlStatus,
    /// Mailbox protocols word of the SII (word 1Ch, ETG.2010 Table 2).
    pub mailbox_protocols: u16,
    /// The ESC has distributed clocks.
    pub dc: bool,
}

/// The mailbox protocols of SII word 1Ch by name (ETG.2010 Table 2).
pub fn mailbox_protocol_names(word: u16) -> Vec<&'static str> {
    [
        (0x0001, "AoE"),
        (0x0002, "EoE"),
        (0x0004, "CoE"),
        (0x0008, "FoE"),
        (0x0010, "SoE"),
        (0x0020, "VoE"),
    ]
    .into_iter()
    .filter(|(bit, _)| word & bit != 0)
    .map(|(_, name)| name)
    .collect()
}

/// A scan that could not complete.
#[derive(Debug, thiserror::Error)]
pub enum ScanError {
    /// A frame did not come back.
    #[error("EtherCAT link: {0}")]
    Link(#[from] LinkError),
    /// Words past the SII's 16-bit word address space.
    #[error("SII words {at:#06x} + {n} run past word address 0xffff")]
    SiiRange {
        /// First word.
        at: u16,
        /// Words.
        n: u16,
    },
    /// No SubDevice at the position asked for.
    #[error("no SubDevice at position {position}")]
    NoSubDevice {
        /// The position asked for.
        position: usize,
    },
    /// A SubDevice's SII EEPROM did not finish a read.
    #[error("SubDevice {position}: SII EEPROM read of word {word:#06x} did not complete")]
    Sii {
        /// Position.
        position: usize,
        /// The word address.
        word: u16,
    },
}

/// Finds the SubDevices on `link` and reads what they are; writes nothing but the SII read
/// requests (no state change, no address, no SyncManager).
pub fn scan(link: &mut dyn Link) -> Result<Vec<ScannedSubDevice>, ScanError> {
    let link = &mut Retrying::new(link, SCAN_RETRIES);
    let mut frame = vec![0u8; FRAME_BUF];
    let count = count_subdevices(link, &mut frame)?;
    (0..count)
        .map(|position| scan_one(link, &mut frame, position))
        .collect()
}

/// `n` words of the SII EEPROM of the SubDevice at `position` from word address `at`
/// (`cellrt bus sii read`): read through the ESC's EEPROM interface by auto-increment
/// addressing, in any AL state, with nothing configured.
pub fn sii_words(
    link: &mut dyn Link,
    position: usize,
    at: u16,
    n: u16,
) -> Result<Vec<u16>, ScanError> {
    if u32::from(at) + u32::from(n) > 0x1_0000 {
        return Err(ScanError::SiiRange { at, n });
    }
    let link = &mut Retrying::new(link, SCAN_RETRIES);
    let mut frame = vec![0u8; FRAME_BUF];
    if position >= count_subdevices(link, &mut frame)? {
        return Err(ScanError::NoSubDevice { position });
    }
    Sii {
        link,
        frame: &mut frame,
        position,
    }
    .words(at, n)
}

/// The SubDevices on the line: the working counter of a broadcast read of register 0000h.
pub fn subdevice_count(link: &mut dyn Link) -> Result<usize, LinkError> {
    count_subdevices(link, &mut [0u8; FRAME_BUF])
}

/// The SubDevices on the line: the working counter of a broadcast read of register 0000h.
fn count_subdevices(link: &mut dyn Link, frame: &mut [u8]) -> Result<usize, LinkError> {
    let mut b = FrameBuilder::new(frame, MASTER_MAC);
    let span = b
        .push(Command::Brd, 1, u32::from(reg::TYPE) << 16, &[0])
        .expect("frame buffer holds one datagram");
    let n = b.finish();
    link.round_trip(frame, n)?;
    Ok(usize::from(frame::wkc(frame, &span)))
}

fn scan_one(
    link: &mut dyn Link,
    frame: &mut [u8],
    position: usize,
) -> Result<ScannedSubDevice, ScanError> {
    let al = read_al_status(link, frame, position)?;
    let features = read_registers::<2>(link, frame, position, reg::SUPPORT_FLAGS)?
        .map_or(0, u16::from_le_bytes);
    let mut sii = Sii {
        link,
        frame,
        position,
    };
    let header = sii.words(0x08, 0x16)?;
    let dword = |i: usize| u32::from(header[i]) | u32::from(header[i + 1]) << 16;
    Ok(ScannedSubDevice {
        position,
        identity: SubDeviceIdentity {
            vendor_id: dword(0),
            product_code: dword(2),
            revision: dword(4),
            serial: dword(6),
        },
        mailbox_protocols: header[0x1C - 0x08],
        name: sii.device_name()?,
        al,
        dc: features & FEATURE_DC != 0,
    })
}

/// SII EEPROM reads of one SubDevice through the ESC's EEPROM interface (0500h–050Fh).
struct Sii<'a> {
    link: &'a mut dyn Link,
    frame: &'a mut [u8],
    position: usize,
}

impl Sii<'_> {
    /// `n` words from word address `at`.
    fn words(&mut self, at: u16, n: u16) -> Result<Vec<u16>, ScanError> {
        let mut out = Vec::with_capacity(usize::from(n));
        while out.len() < usize::from(n) {
            let word = at + out.len() as u16;
            let data = self.read(word)?;
            out.extend(data.iter().take(usize::from(n) - out.len()));
        }
        Ok(out)
    }

    /// One read at `word`: 2 or 4 words, as the ESC's 0502h bit 6 says.
    fn read(&mut self, word: u16) -> Result<Vec<u16>, ScanError> {
        let adp = (self.position as u16).wrapping_neg();
        let [lo, hi] = word.to_le_bytes();
        let request = [0x00, (SII_READ >> 8) as u8, lo, hi, 0, 0];
        let mut b = FrameBuilder::new(self.frame, MASTER_MAC);
        b.push(
            Command::Apwr,
            1,
            (u32::from(reg::SII_CONTROL) << 16) | u32::from(adp),
            &request,
        );
        let n = b.finish();
        self.link.round_trip(self.frame, n)?;
        for _ in 0..SII_POLLS {
            let control =
                read_registers::<2>(self.link, self.frame, self.position, reg::SII_CONTROL)?
                    .map_or(SII_BUSY, u16::from_le_bytes);
            if control & SII_BUSY != 0 {
                continue;
            }
            let data = read_registers::<8>(self.link, self.frame, self.position, reg::SII_DATA)?
                .ok_or(ScanError::Sii {
                    position: self.position,
                    word,
                })?;
            let words = if control & SII_READ_8 != 0 { 4 } else { 2 };
            return Ok((0..words)
                .map(|i| u16::from_le_bytes([data[2 * i], data[2 * i + 1]]))
                .collect());
        }
        Err(ScanError::Sii {
            position: self.position,
            word,
        })
    }

    /// The device name: the Strings category's string the General category names (ETG.2010
    /// §5.2, §5.3); empty where either is missing.
    fn device_name(&mut self) -> Result<String, ScanError> {
        let (mut strings, mut name_index) = (None, None);
        let mut at = FIRST_CATEGORY_WORD;
        while at < MAX_SII_WORDS {
            let head = self.words(at, 2)?;
            let (kind, len) = (head[0], head[1]);
            let Some(end) = category_end(at, len).filter(|_| kind != 0xFFFF && len != 0) else {
                break;
            };
            match kind {
                10 => strings = Some(self.bytes(at + 2, len)?),
                30 => name_index = self.bytes(at + 2, len.min(2))?.get(3).copied(),
                _ => {}
            }
            at = end;
        }
        Ok(match (strings, name_index) {
            (Some(s), Some(i)) => nth_string(&s, i).unwrap_or_default(),
            _ => String::new(),
        })
    }

    fn bytes(&mut self, at: u16, len: u16) -> Result<Vec<u8>, ScanError> {
        Ok(self
            .words(at, len)?
            .iter()
            .flat_map(|w| w.to_le_bytes())
            .collect())
    }
}

/// The word after a category of `len` data words whose header is at word `at`, if it ends
/// within the words a scan reads ([`MAX_SII_WORDS`]); a length word up to FFFFh cannot overflow.
fn category_end(at: u16, len: u16) -> Option<u16> {
    let end = u32::from(at) + 2 + u32::from(len);
    u16::try_from(end).ok().filter(|&end| end <= MAX_SII_WORDS)
}

/// String `index` (1-based) of a Strings category: a count, then length-prefixed strings.
fn nth_string(category: &[u8], index: u8) -> Option<String> {
    let count = *category.first()?;
    if index == 0 || index > count {
        return None;
    }
    let mut at = 1;
    for _ in 1..index {
        at += 1 + usize::from(*category.get(at)?);
    }
    let len = usize::from(*category.get(at)?);
    let s = category.get(at + 1..at + 1 + len)?;
    Some(String::from_utf8_lossy(s).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_are_found_by_their_one_based_index() {
        let cat = [2, 3, b'a', b'b', b'c', 2, b'x', b'y'];
        assert_eq!(nth_string(&cat, 1).as_deref(), Some("abc"));
        assert_eq!(nth_string(&cat, 2).as_deref(), Some("xy"));
        assert_eq!(nth_string(&cat, 0), None);
        assert_eq!(nth_string(&cat, 3), None);
        assert_eq!(nth_string(&[1, 9, b'a'], 1), None, "truncated");
    }

    #[test]
    fn a_category_length_past_the_eeprom_ends_the_walk_without_overflow() {
        // Found by the sii_scan fuzz target: a length word of FFFFh overflowed `at + 2 + len`.
        assert_eq!(category_end(0x40, 0xFFFF), None);
        assert_eq!(category_end(MAX_SII_WORDS - 2, 0xFFFF), None);
        assert_eq!(category_end(0x40, 10), Some(0x4C));
        assert_eq!(category_end(MAX_SII_WORDS - 8, 6), Some(MAX_SII_WORDS));
        assert_eq!(category_end(MAX_SII_WORDS - 8, 7), None);
    }

    #[test]
    fn mailbox_protocols_are_named_by_their_bits() {
        assert_eq!(mailbox_protocol_names(0x000C), ["CoE", "FoE"]);
        assert!(mailbox_protocol_names(0).is_empty());
    }
}
