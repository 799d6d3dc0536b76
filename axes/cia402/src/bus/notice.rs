//! What a bus reports besides the process data, in terms of no particular fieldbus: the
//! messages its nodes send unasked and the state of each axis' communication link.

/// One Emergency message (CiA 301 §7.2.7.3.1 EMCY write: error code, error register,
/// 5 manufacturer-specific bytes); on EtherCAT it comes as a CoE Emergency in the mailbox.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Emergency {
    /// Emergency error code; on a CiA 402 drive the alarm's 603Fh value.
    pub error_code: u16,
    /// The error register 1001h at the time of the alarm.
    pub error_register: u8,
    /// Manufacturer-specific bytes.
    pub data: [u8; 5],
}

/// Error register (1001h) bit 0: generic error, set with every alarm (CiA 301 §7.5.2.2).
pub const ERROR_REGISTER_GENERIC: u8 = 0x01;

/// A mailbox message a node sent unasked, by axis (see
/// [`CyclicBus::take_mailbox_notice`](super::CyclicBus::take_mailbox_notice)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MailboxNotice {
    /// An Emergency of `axis` (on a multi-axis unit the slot it names, else its first axis).
    Emergency {
        /// The axis.
        axis: usize,
        /// What the drive sent.
        emergency: Emergency,
    },
    /// Something else that was not asked for (not CoE, or another CoE service), discarded.
    Discarded {
        /// The first axis of the node.
        axis: usize,
        /// Mailbox type (ETG.1000.4 Table 29; 0 if malformed).
        mailbox_type: u8,
        /// CoE service (0 if not CoE).
        service: u16,
    },
}

/// The communication state of the node that carries an axis, as the last cyclic exchange read
/// it; on EtherCAT the SubDevice's AL status (ETG.1000.6 §6.4), converted by the master.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkState {
    /// The node exchanges process data both ways (EtherCAT: OP without error indication).
    pub operational: bool,
    /// The whole state as the bus encodes it for the recording (EtherCAT: the AL status
    /// register and the AL status code).
    pub encoded: i64,
}

/// Which manufacturer-specific byte carries the axis slot of a multi-axis unit (0 = A, 1 = B,
/// 2 = C): cellrt's choice, the manuals give no layout (MR-J5-G-N1 manual §5 "codes not given").
pub const EMERGENCY_SLOT_BYTE: usize = 0;

/// The alarm convention of cellrt's emulated drives.
impl Emergency {
    /// The Emergency cellrt's emulated drives send for alarm `code` (603Fh) of axis `slot`:
    /// error register [`ERROR_REGISTER_GENERIC`], the slot in byte [`EMERGENCY_SLOT_BYTE`], the
    /// other manufacturer bytes 0.
    pub const fn of_alarm(code: u16, slot: u8) -> Self {
        let mut data = [0u8; 5];
        data[EMERGENCY_SLOT_BYTE] = slot;
        Emergency {
            error_code: code,
            error_register: ERROR_REGISTER_GENERIC,
            data,
        }
    }

    /// The axis slot an emulated multi-axis unit names ([`EMERGENCY_SLOT_BYTE`]).
    pub const fn slot(&self) -> u8 {
        self.data[EMERGENCY_SLOT_BYTE]
    }
}
