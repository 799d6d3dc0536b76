//! A line of SubDevices made of the fuzz input, for the master's `bus scan`: registers, SII
//! EEPROM contents and wire faults (lost and truncated frames) all come from the input.

use cellrt_ethercat::frame::{self, Command};
use cellrt_ethercat::master::link::{Link, LinkError};
use cellrt_ethercat::register as reg;

/// Bytes before the per-frame fault tape: count, SII flags (8-byte reads, always busy), AL status (6), feature flags (2),
/// tape length.
const HEAD: usize = 11;

/// SubDevices answering auto-increment reads of their AL status, feature flags, SII control
/// and SII data from the input, and SII read requests.
pub struct FuzzedEsc {
    count: u16,
    read_8: bool,
    busy: bool,
    al_status: [u8; 6],
    features: [u8; 2],
    tape: Vec<u8>,
    sii: Vec<u8>,
    sii_word: usize,
}

impl FuzzedEsc {
    /// The line `data` describes (zeros where it is short).
    pub fn new(data: &[u8]) -> Self {
        let mut head = [0u8; HEAD];
        let n = data.len().min(HEAD);
        head[..n].copy_from_slice(&data[..n]);
        let rest = &data[n..];
        let tape_len = usize::from(head[10] % 32).min(rest.len());
        FuzzedEsc {
            count: u16::from(head[0] % 3),
            read_8: head[1] & 1 != 0,
            busy: head[1] & 2 != 0,
            al_status: head[2..8].try_into().expect("6 bytes"),
            features: head[8..10].try_into().expect("2 bytes"),
            tape: rest[..tape_len].iter().rev().copied().collect(),
            sii: rest[tape_len..].to_vec(),
            sii_word: 0,
        }
    }

    fn read(&self, ado: u16, out: &mut [u8]) {
        for (i, b) in out.iter_mut().enumerate() {
            let at = usize::from(ado) + i;
            *b = match at {
                _ if (0x130..0x136).contains(&at) => self.al_status[at - 0x130],
                0x008 | 0x009 => self.features[at - 0x008],
                0x502 => u8::from(self.read_8) << 6,
                0x503 => 0x01 | u8::from(self.busy) << 7,
                _ if (0x508..0x510).contains(&at) => {
                    let sii_at = 2 * self.sii_word + (at - 0x508);
                    self.sii.get(sii_at).copied().unwrap_or(0xFF)
                }
                _ => 0,
            };
        }
    }
}

impl Link for FuzzedEsc {
    fn round_trip(&mut self, buf: &mut [u8], len: usize) -> Result<usize, LinkError> {
        let fault = self.tape.pop();
        if fault == Some(0xFF) {
            return Err(LinkError::Timeout(0));
        }
        let spans: Vec<_> = frame::datagrams(&buf[..len]).flatten().collect();
        for span in spans {
            let h = span.header;
            let data_len = usize::from(h.len);
            let data = span.data_offset..span.data_offset + data_len;
            let position = h.adp().wrapping_neg();
            let addressed = position < self.count;
            let wkc = match h.command {
                Command::Brd => self.count,
                Command::Aprd if addressed => {
                    self.read(h.ado(), &mut buf[data]);
                    1
                }
                Command::Apwr if addressed => {
                    if h.ado() == reg::SII_CONTROL && data_len >= 4 {
                        let d = &buf[data];
                        self.sii_word = usize::from(u16::from_le_bytes([d[2], d[3]]));
                    }
                    1
                }
                _ => 0,
            };
            buf[span.wkc_offset..span.wkc_offset + 2].copy_from_slice(&wkc.to_le_bytes());
        }
        Ok(match fault {
            Some(cut @ 0xC0..=0xFE) => len.min(usize::from(cut - 0xC0)),
            _ => len,
        })
    }
}
