//! CoE Emergency (ETG.1000.6 §5.6.2.1; the CiA 301 §7.2.7 EMCY message in a mailbox): a
//! SubDevice reports an alarm by writing it into its SubDevice→master mailbox (SM1) unasked.
//!
//! Wire layout, in the SM1 buffer: the mailbox header (6 bytes: length, address,
//! channel/priority, type 3 = CoE | counter << 4), the CoE header (2 bytes: number 0, service 1 =
//! Emergency << 12), then the 8 EMCY bytes: error code (u16 LE), error register (1001h, u8),
//! 5 bytes manufacturer-specific ([`Emergency::data`], see [`EMERGENCY_SLOT_BYTE`]).
//!
//! The message itself is the bus-neutral [`Emergency`]; this module adds its CoE mailbox
//! encoding and the slot convention of cellrt's emulated multi-axis units.

pub use cellrt_cia402::bus::{Emergency, EMERGENCY_SLOT_BYTE, ERROR_REGISTER_GENERIC};

/// Mailbox header bytes (ETG.1000.4 §5.7).
const MAILBOX_HEADER_LEN: usize = 6;
/// Mailbox type CoE (ETG.1000.4 Table 29).
const MAILBOX_TYPE_COE: u8 = 3;
/// CoE service 1: Emergency (ETG.1000.6 Table 29).
pub const COE_SERVICE_EMERGENCY: u16 = 1;
/// CoE header + EMCY bytes: the mailbox header's length field of an Emergency.
const EMERGENCY_BODY_LEN: usize = 2 + 8;
/// Bytes of an Emergency in the mailbox, headers included.
pub const EMERGENCY_MAILBOX_LEN: usize = MAILBOX_HEADER_LEN + EMERGENCY_BODY_LEN;
/// The CoE mailbox encoding of an [`Emergency`] (what an emulated SubDevice writes into SM1).
pub trait CoeEmergency {
    /// Writes the whole mailbox message (headers included) with mailbox `counter` (1..=7) into
    /// `out`; returns the bytes written (`out` shorter than [`EMERGENCY_MAILBOX_LEN`]: 0).
    fn encode(&self, counter: u8, out: &mut [u8]) -> usize;
}

impl CoeEmergency for Emergency {
    fn encode(&self, counter: u8, out: &mut [u8]) -> usize {
        let Some(m) = out.get_mut(..EMERGENCY_MAILBOX_LEN) else {
            return 0;
        };
        m[0..2].copy_from_slice(&(EMERGENCY_BODY_LEN as u16).to_le_bytes());
        m[2..5].fill(0);
        m[5] = MAILBOX_TYPE_COE | ((counter & 7) << 4);
        m[6..8].copy_from_slice(&(COE_SERVICE_EMERGENCY << 12).to_le_bytes());
        m[8..10].copy_from_slice(&self.error_code.to_le_bytes());
        m[10] = self.error_register;
        m[11..16].copy_from_slice(&self.data);
        EMERGENCY_MAILBOX_LEN
    }
}

/// What a SubDevice→master mailbox buffer holds, for a master that reads it unasked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MailboxMessage {
    /// A CoE Emergency.
    Emergency(Emergency),
    /// Anything else: mailbox type (ETG.1000.4 Table 29) and, for CoE, the service (else 0).
    Other {
        /// Mailbox type (low nibble of header byte 5).
        mailbox_type: u8,
        /// CoE service (CoE header bits 12–15), 0 for other types.
        service: u16,
    },
    /// Shorter than its headers.
    Malformed,
}

impl MailboxMessage {
    /// Decodes the SM1 buffer `mailbox`.
    pub fn decode(mailbox: &[u8]) -> Self {
        if mailbox.len() < MAILBOX_HEADER_LEN + 2 {
            return MailboxMessage::Malformed;
        }
        let mailbox_type = mailbox[5] & 0x0F;
        if mailbox_type != MAILBOX_TYPE_COE {
            return MailboxMessage::Other {
                mailbox_type,
                service: 0,
            };
        }
        let service = u16::from_le_bytes([mailbox[6], mailbox[7]]) >> 12;
        let len = usize::from(u16::from_le_bytes([mailbox[0], mailbox[1]]));
        if service != COE_SERVICE_EMERGENCY {
            return MailboxMessage::Other {
                mailbox_type,
                service,
            };
        }
        let Some(b) = mailbox.get(8..EMERGENCY_MAILBOX_LEN) else {
            return MailboxMessage::Malformed;
        };
        if len < EMERGENCY_BODY_LEN {
            return MailboxMessage::Malformed;
        }
        let mut data = [0u8; 5];
        data.copy_from_slice(&b[3..8]);
        MailboxMessage::Emergency(Emergency {
            error_code: u16::from_le_bytes([b[0], b[1]]),
            error_register: b[2],
            data,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ETG.1000.6 §5.6.2.1: the bytes of an Emergency, and back.
    #[test]
    fn an_emergency_round_trips_through_its_mailbox_bytes() {
        let e = Emergency::of_alarm(0x2250, 1);
        let mut buf = [0xAAu8; 32];
        assert_eq!(e.encode(3, &mut buf), 16);
        assert_eq!(
            &buf[..16],
            &[10, 0, 0, 0, 0, 0x33, 0x00, 0x10, 0x50, 0x22, 0x01, 1, 0, 0, 0, 0]
        );
        assert_eq!(MailboxMessage::decode(&buf), MailboxMessage::Emergency(e));
        assert_eq!(e.slot(), 1);
        // An SDO response is not an Emergency.
        buf[7] = 0x30;
        assert_eq!(
            MailboxMessage::decode(&buf),
            MailboxMessage::Other {
                mailbox_type: 3,
                service: 3
            }
        );
        assert_eq!(MailboxMessage::decode(&buf[..4]), MailboxMessage::Malformed);
        assert_eq!(e.encode(1, &mut [0u8; 8]), 0);
    }
}
