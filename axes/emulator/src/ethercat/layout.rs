//! Where an emulated SubDevice keeps its mailboxes and process data in process RAM, and the
//! SyncManager settings it advertises in its SII. Mitsubishi's ESI values are not in the
//! manuals; these are the emulator's choices (standard CiA 402 layout: SM0/SM1 mailbox,
//! SM2 outputs, SM3 inputs).

use cellrt_cia402::profiles::DriveProfile;

/// The SyncManager usage types of the SII (ETG.2010 Table 12).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum SmUsage {
    /// Mailbox master → SubDevice.
    MailboxOut = 1,
    /// Mailbox SubDevice → master.
    MailboxIn = 2,
    /// Process data outputs (RxPDO).
    Outputs = 3,
    /// Process data inputs (TxPDO).
    Inputs = 4,
}

/// One SyncManager's area.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SmArea {
    /// Physical start address.
    pub start: u16,
    /// Length in bytes.
    pub len: u16,
    /// Control byte (mode, direction, interrupts, watchdog).
    pub control: u8,
    /// Usage.
    pub usage: SmUsage,
}

/// Bytes of each mailbox.
pub const MAILBOX_LEN: u16 = 128;

/// The four SyncManagers of an emulated drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct StationLayout {
    /// SM0: mailbox written by the master.
    pub mailbox_out: SmArea,
    /// SM1: mailbox read by the master.
    pub mailbox_in: SmArea,
    /// SM2: RxPDO.
    pub outputs: SmArea,
    /// SM3: TxPDO.
    pub inputs: SmArea,
}

impl StationLayout {
    /// The layout for `profile`'s default PDO maps.
    pub fn of_profile(profile: &DriveProfile) -> Self {
        Self::of_lengths(
            profile.pdo.rx.byte_len() as u16,
            profile.pdo.tx.byte_len() as u16,
        )
    }

    /// The layout for process data of `rx_len` output and `tx_len` input bytes (on a
    /// multi-axis unit: every axis' PDOs together).
    pub fn of_lengths(rx_len: u16, tx_len: u16) -> Self {
        StationLayout {
            mailbox_out: SmArea {
                start: 0x1000,
                len: MAILBOX_LEN,
                control: 0x26,
                usage: SmUsage::MailboxOut,
            },
            mailbox_in: SmArea {
                start: 0x1080,
                len: MAILBOX_LEN,
                control: 0x22,
                usage: SmUsage::MailboxIn,
            },
            outputs: SmArea {
                start: 0x1100,
                len: rx_len,
                control: 0x64,
                usage: SmUsage::Outputs,
            },
            inputs: SmArea {
                start: 0x1400,
                len: tx_len,
                control: 0x20,
                usage: SmUsage::Inputs,
            },
        }
    }

    /// SM0..SM3 in order.
    pub fn sync_managers(&self) -> [SmArea; 4] {
        [self.mailbox_out, self.mailbox_in, self.outputs, self.inputs]
    }
}
