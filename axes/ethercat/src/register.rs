//! ESC register addresses and the values cellrt reads or the emulator serves (ETG.1000.4
//! §6, Beckhoff ESC datasheet section II). One definition, used by the emulator and the master.

/// 0000h Type.
pub const TYPE: u16 = 0x0000;
/// 0004h FMMUs supported.
pub const FMMU_COUNT: u16 = 0x0004;
/// 0005h SyncManagers supported.
pub const SM_COUNT: u16 = 0x0005;
/// 0006h Process RAM size in KiB.
pub const RAM_SIZE: u16 = 0x0006;
/// 0007h Port descriptor.
pub const PORT_DESCRIPTOR: u16 = 0x0007;
/// 0008h ESC features supported.
pub const SUPPORT_FLAGS: u16 = 0x0008;
/// 0010h Configured station address.
pub const STATION_ADDRESS: u16 = 0x0010;
/// 0012h Configured station alias.
pub const STATION_ALIAS: u16 = 0x0012;
/// 0110h DL status.
pub const DL_STATUS: u16 = 0x0110;
/// DL status bits (0110h): physical link on port 0 / port 1.
pub const DL_LINK_PORT0: u16 = 0x0010;
/// DL status: physical link on port 1.
pub const DL_LINK_PORT1: u16 = 0x0020;
/// DL status: loop port 1 closed.
pub const DL_LOOP_PORT1: u16 = 0x0400;
/// DL status: communication established on port 0.
pub const DL_COMM_PORT0: u16 = 0x0200;
/// DL status: communication established on port 1.
pub const DL_COMM_PORT1: u16 = 0x0800;
/// RX error counters (0300h–0307h): per port p, 0300h + 2p the invalid frame counter (frames
/// with a CRC error, counted by the first ESC that detects it), 0301h + 2p the RX error
/// counter (physical layer errors). Saturate at FFh; a write to 0300h–0313h clears them all.
pub const RX_ERROR_COUNTER: u16 = 0x0300;
/// Forwarded RX error counters (0308h–030Bh): per port, frames already marked as erroneous by
/// a previous ESC.
pub const FORWARDED_RX_ERROR_COUNTER: u16 = 0x0308;
/// Lost link counters (0310h–0313h): per port, link losses.
pub const LOST_LINK_COUNTER: u16 = 0x0310;
/// 0120h AL control.
pub const AL_CONTROL: u16 = 0x0120;
/// 0130h AL status.
pub const AL_STATUS: u16 = 0x0130;
/// 0134h AL status code.
pub const AL_STATUS_CODE: u16 = 0x0134;
/// 0400h Watchdog divider.
pub const WATCHDOG_DIVIDER: u16 = 0x0400;
/// 0420h SyncManager watchdog time (process data), in watchdog divider units.
pub const SM_WATCHDOG: u16 = 0x0420;
/// 0440h SyncManager watchdog status: bit 0 clear once the process-data watchdog expired.
pub const SM_WATCHDOG_STATUS: u16 = 0x0440;
/// 0442h SyncManager watchdog counter: expirations of the process-data watchdog.
pub const SM_WATCHDOG_COUNTER: u16 = 0x0442;
/// The ESC's reset value of 0400h: (2498 + 2) × 40 ns = 100 µs units.
pub const WATCHDOG_DIVIDER_DEFAULT: u16 = 0x09C2;
/// The ESC's reset value of 0420h: 1000 units of 100 µs = 100 ms.
pub const SM_WATCHDOG_DEFAULT: u16 = 0x03E8;
/// SyncManager control bit 6: a write to the SyncManager triggers the process-data watchdog.
pub const SM_CONTROL_WATCHDOG: u8 = 0x40;
/// 0500h SII EEPROM configuration.
pub const SII_CONFIG: u16 = 0x0500;
/// 0502h SII EEPROM control/status.
pub const SII_CONTROL: u16 = 0x0502;
/// 0504h SII EEPROM address (words).
pub const SII_ADDRESS: u16 = 0x0504;
/// 0508h SII EEPROM data.
pub const SII_DATA: u16 = 0x0508;
/// 0600h FMMU 0; 16 bytes each.
pub const FMMU_BASE: u16 = 0x0600;
/// Bytes of one FMMU.
pub const FMMU_LEN: u16 = 16;
/// 0800h SyncManager 0; 8 bytes each.
pub const SM_BASE: u16 = 0x0800;
/// Bytes of one SyncManager.
pub const SM_LEN: u16 = 8;
/// 0900h Receive time port 0 (a write latches the port receive times).
pub const DC_TIME_PORT0: u16 = 0x0900;
/// 0910h System time.
pub const DC_SYSTEM_TIME: u16 = 0x0910;
/// 0918h Receive time processing unit.
pub const DC_RECEIVE_TIME: u16 = 0x0918;
/// 0920h System time offset.
pub const DC_SYSTEM_TIME_OFFSET: u16 = 0x0920;
/// 0928h System time delay.
pub const DC_SYSTEM_TIME_DELAY: u16 = 0x0928;
/// 0981h Sync activation.
pub const DC_SYNC_ACTIVE: u16 = 0x0981;
/// The ESI `AssignActivate` (and SII DC category) word of a SYNC0-synchronised device: 0981h
/// = 03h (cyclic operation and SYNC0 on), 0980h = 00h (ETG.2000 `Dc/OpMode`).
pub const DC_ASSIGN_ACTIVATE_SYNC0: u16 = 0x0300;
/// 0990h Start time of SYNC0.
pub const DC_SYNC_START_TIME: u16 = 0x0990;
/// 09A0h SYNC0 cycle time (ns).
pub const DC_SYNC0_CYCLE: u16 = 0x09A0;
/// The first byte of process RAM.
pub const PROCESS_RAM: u16 = 0x1000;

/// The register of FMMU `n`.
pub const fn fmmu(n: u8) -> u16 {
    FMMU_BASE + FMMU_LEN * n as u16
}

/// The register of SyncManager `n`.
pub const fn sync_manager(n: u8) -> u16 {
    SM_BASE + SM_LEN * n as u16
}

/// The AL states (AL control/status bits 0–3, ETG.1000.6 §6.4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum AlState {
    /// INIT.
    Init = 1,
    /// PRE-OP: mailbox.
    PreOp = 2,
    /// BOOT: firmware update.
    Bootstrap = 3,
    /// SAFE-OP: inputs valid, outputs safe.
    SafeOp = 4,
    /// OP.
    Op = 8,
}

impl AlState {
    /// The state of the low nibble of AL control/status, `None` for a code that is no state.
    pub const fn from_bits(bits: u8) -> Option<AlState> {
        Some(match bits & 0x0F {
            1 => AlState::Init,
            2 => AlState::PreOp,
            3 => AlState::Bootstrap,
            4 => AlState::SafeOp,
            8 => AlState::Op,
            _ => return None,
        })
    }

    /// The ESM name as printed in the manuals.
    pub const fn as_str(self) -> &'static str {
        match self {
            AlState::Init => "INIT",
            AlState::PreOp => "PRE-OP",
            AlState::Bootstrap => "BOOT",
            AlState::SafeOp => "SAFE-OP",
            AlState::Op => "OP",
        }
    }
}

/// AL status bit 4: an error is indicated, the state is the one before the refused request.
pub const AL_ERROR_INDICATION: u8 = 0x10;

/// AL status codes the emulator raises (ETG.1000.6 Table 11, ETG.1020 §14).
pub mod al_code {
    /// 0011h Invalid requested state change.
    pub const INVALID_STATE_CHANGE: u16 = 0x0011;
    /// 0012h Unknown requested state.
    pub const UNKNOWN_STATE: u16 = 0x0012;
    /// 0016h Invalid mailbox configuration.
    pub const INVALID_MAILBOX_CONFIG: u16 = 0x0016;
    /// 001Bh Sync manager watchdog.
    pub const SM_WATCHDOG: u16 = 0x001B;
    /// 001Dh Invalid output configuration.
    pub const INVALID_OUTPUT_CONFIG: u16 = 0x001D;
    /// 001Eh Invalid input configuration.
    pub const INVALID_INPUT_CONFIG: u16 = 0x001E;
    /// 0030h Invalid DC SYNC configuration.
    pub const INVALID_DC_SYNC: u16 = 0x0030;
    /// 0035h Invalid sync cycle time.
    pub const INVALID_SYNC_CYCLE: u16 = 0x0035;

    /// The ETG.1000.6 name of an AL status code (Table 11), for events and logs; "vendor
    /// specific" from 8000h, "unknown" for codes the table does not list.
    pub fn name(code: u16) -> &'static str {
        match code {
            0x0000 => "no error",
            0x0001 => "unspecified error",
            0x0002 => "no memory",
            0x0011 => "invalid requested state change",
            0x0012 => "unknown requested state",
            0x0013 => "bootstrap not supported",
            0x0014 => "no valid firmware",
            0x0015 => "invalid mailbox configuration (bootstrap)",
            0x0016 => "invalid mailbox configuration",
            0x0017 => "invalid sync manager configuration",
            0x0018 => "no valid inputs available",
            0x0019 => "no valid outputs",
            0x001A => "synchronization error",
            0x001B => "sync manager watchdog",
            0x001C => "invalid sync manager types",
            0x001D => "invalid output configuration",
            0x001E => "invalid input configuration",
            0x001F => "invalid watchdog configuration",
            0x0020 => "SubDevice needs cold start",
            0x0021 => "SubDevice needs INIT",
            0x0022 => "SubDevice needs PRE-OP",
            0x0023 => "SubDevice needs SAFE-OP",
            0x0024 => "invalid input mapping",
            0x0025 => "invalid output mapping",
            0x0026 => "inconsistent settings",
            0x0027 => "free-run not supported",
            0x0028 => "synchronization not supported",
            0x0029 => "free-run needs 3-buffer mode",
            0x002A => "background watchdog",
            0x002B => "no valid inputs and outputs",
            0x002C => "fatal sync error",
            0x002D => "no sync error",
            0x0030 => "invalid DC SYNC configuration",
            0x0031 => "invalid DC latch configuration",
            0x0032 => "PLL error",
            0x0033 => "DC sync I/O error",
            0x0034 => "DC sync timeout error",
            0x0035 => "invalid sync cycle time",
            0x0036 => "invalid DC SYNC0 cycle time",
            0x0037 => "invalid DC SYNC1 cycle time",
            0x8000..=0xFFFF => "vendor specific",
            _ => "unknown",
        }
    }
}

/// A SubDevice's AL status as the cyclic frame reads it: 0130h (state, error indication) and
/// 0134h (AL status code).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AlStatus {
    /// The state; `None` for bits that name no state.
    pub state: Option<AlState>,
    /// Error indication (0130h bit 4): the SubDevice refused a request or left a state on its own.
    pub error: bool,
    /// AL status code (0134h), meaningful with `error`.
    pub code: u16,
}

/// The AL status as the bus-neutral link state the RT loop watches: operational in OP without
/// error, the record value [`AlStatus::encode`].
impl From<AlStatus> for cellrt_cia402::bus::LinkState {
    fn from(s: AlStatus) -> Self {
        cellrt_cia402::bus::LinkState {
            operational: s.is_op(),
            encoded: s.encode(),
        }
    }
}

/// Bytes the cyclic frame reads from [`AL_STATUS`]: the status, a reserved word, the code.
pub const AL_STATUS_READ_LEN: usize = 6;

impl AlStatus {
    /// From the AL status and AL status code registers.
    pub fn from_registers(status: u16, code: u16) -> AlStatus {
        AlStatus {
            state: AlState::from_bits(status as u8),
            error: status as u8 & AL_ERROR_INDICATION != 0,
            code,
        }
    }

    /// From the [`AL_STATUS_READ_LEN`] bytes read at [`AL_STATUS`].
    pub fn from_bytes(b: &[u8; AL_STATUS_READ_LEN]) -> AlStatus {
        AlStatus::from_registers(
            u16::from_le_bytes([b[0], b[1]]),
            u16::from_le_bytes([b[4], b[5]]),
        )
    }

    /// In OP without an error: the SubDevice takes its outputs.
    pub fn is_op(&self) -> bool {
        self.state == Some(AlState::Op) && !self.error
    }

    /// Packed into an event value: bits 0–7 the 0130h status byte, bits 16–31 the code.
    pub fn encode(&self) -> i64 {
        let status =
            self.state.map_or(0, |s| s as u8) | if self.error { AL_ERROR_INDICATION } else { 0 };
        i64::from(status) | (i64::from(self.code) << 16)
    }

    /// Inverse of [`AlStatus::encode`].
    pub fn decode(v: i64) -> AlStatus {
        AlStatus::from_registers((v & 0xFF) as u16, ((v >> 16) & 0xFFFF) as u16)
    }

    /// E.g. "SAFE-OP, error 001Bh (sync manager watchdog)" or "OP".
    pub fn describe(&self) -> String {
        let state = self.state.map_or("no state", AlState::as_str);
        if self.error {
            format!(
                "{state}, error {:04X}h ({})",
                self.code,
                al_code::name(self.code)
            )
        } else {
            state.to_string()
        }
    }
}
