//! Controlword (6040h, U16): the master's command word.
//!
//! Bits from MR-J5-G-N1 manual §7.2; commands from §7.1.

use std::fmt;

/// The controlword 6040h as sent by the master every cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Controlword(pub u16);

/// A device-control command encoded in controlword bits 0–3 and 7 (§3.2).
///
/// Switch On and Disable Operation share one bit pattern (0x0007); it decodes as
/// [`Command::SwitchOn`] and the state machine gives it its meaning from the current state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Command {
    /// Shutdown, `0xxx x110`: transitions (2), (6), (8).
    Shutdown,
    /// Switch On, `0xxx 0111`: transition (3); in Operation enabled it is Disable Operation (5).
    SwitchOn,
    /// Disable Voltage, `0xxx xx0x`: transitions (7), (9), (10), (12).
    DisableVoltage,
    /// Quick Stop, `0xxx x01x`: transitions (7), (10), (11).
    QuickStop,
    /// Disable Operation, `0xxx 0111`: transition (5). Never produced by decoding (see type doc).
    DisableOperation,
    /// Enable Operation, `0xxx 1111`: transitions (4), (16).
    EnableOperation,
    /// Fault Reset, bit 7 set: transition (15) acts on the 0→1 edge only.
    FaultReset,
}

const SWITCH_ON_BIT: u16 = 1 << 0;
const ENABLE_VOLTAGE_BIT: u16 = 1 << 1;
const QUICK_STOP_BIT: u16 = 1 << 2;
const ENABLE_OPERATION_BIT: u16 = 1 << 3;
const FAULT_RESET_BIT: u16 = 1 << 7;
const HALT_BIT: u16 = 1 << 8;

/// Bit 4 in pp: New set-point (its rising edge takes 607Ah); in hm: Homing operation start.
pub const NEW_SET_POINT: u16 = 1 << 4;
/// Bit 5 in pp: Change set immediately.
pub const CHANGE_SET_IMMEDIATELY: u16 = 1 << 5;
/// Bit 8: Halt.
pub const HALT: u16 = HALT_BIT;

impl Controlword {
    /// Shutdown (typical word, §3.2).
    pub const SHUTDOWN: Controlword = Controlword(0x0006);
    /// Switch On (typical word, §3.2).
    pub const SWITCH_ON: Controlword = Controlword(0x0007);
    /// Disable Voltage (typical word, §3.2).
    pub const DISABLE_VOLTAGE: Controlword = Controlword(0x0000);
    /// Quick Stop (typical word, §3.2).
    pub const QUICK_STOP: Controlword = Controlword(0x0002);
    /// Disable Operation (same bits as Switch On, §3.2).
    pub const DISABLE_OPERATION: Controlword = Controlword(0x0007);
    /// Enable Operation (typical word, §3.2).
    pub const ENABLE_OPERATION: Controlword = Controlword(0x000F);
    /// Fault Reset (effective on the 0→1 edge of bit 7, §3.2).
    pub const FAULT_RESET: Controlword = Controlword(0x0080);

    /// The raw word.
    pub const fn bits(self) -> u16 {
        self.0
    }

    /// Bit 0 SO, switch on.
    pub const fn switch_on(self) -> bool {
        self.0 & SWITCH_ON_BIT != 0
    }

    /// Bit 1 EV, enable voltage.
    pub const fn enable_voltage(self) -> bool {
        self.0 & ENABLE_VOLTAGE_BIT != 0
    }

    /// Bit 2 QS as on the wire. Active low: `false` (bit 2 = 0) requests a quick stop.
    pub const fn quick_stop(self) -> bool {
        self.0 & QUICK_STOP_BIT != 0
    }

    /// True when bit 2 = 0 with bit 1 = 1, i.e. the word is a Quick Stop command.
    pub const fn quick_stop_requested(self) -> bool {
        self.enable_voltage() && !self.quick_stop()
    }

    /// Bit 3 EO, enable operation.
    pub const fn enable_operation(self) -> bool {
        self.0 & ENABLE_OPERATION_BIT != 0
    }

    /// Bit 7 FR, fault reset (the drive acts on its rising edge).
    pub const fn fault_reset(self) -> bool {
        self.0 & FAULT_RESET_BIT != 0
    }

    /// Bit 8 HALT: 1 pauses the motion (§3.3, §3.5).
    pub const fn halt(self) -> bool {
        self.0 & HALT_BIT != 0
    }

    /// The same word with bit 8 HALT set or cleared.
    pub const fn with_halt(self, on: bool) -> Self {
        if on {
            Controlword(self.0 | HALT_BIT)
        } else {
            Controlword(self.0 & !HALT_BIT)
        }
    }

    /// True when bit 7 goes 0→1 from `prev` to `self`: the only way to trigger transition (15).
    pub const fn fault_reset_edge(self, prev: Controlword) -> bool {
        self.fault_reset() && !prev.fault_reset()
    }

    /// Decodes the device-control command (§3.2 table).
    ///
    /// Bit 7 set decodes as [`Command::FaultReset`]; otherwise bits 0–3 select the command.
    /// The CiA 402 table covers every pattern, so this returns `Some` for every word today;
    /// the `Option` leaves room for profiles that reject reserved patterns.
    pub const fn command(self) -> Option<Command> {
        if self.fault_reset() {
            Some(Command::FaultReset)
        } else {
            Some(self.state_command())
        }
    }

    /// The command in bits 0–3, ignoring bit 7 (how a drive reads the word outside Fault).
    pub const fn state_command(self) -> Command {
        if !self.enable_voltage() {
            Command::DisableVoltage
        } else if !self.quick_stop() {
            Command::QuickStop
        } else if !self.switch_on() {
            Command::Shutdown
        } else if !self.enable_operation() {
            Command::SwitchOn
        } else {
            Command::EnableOperation
        }
    }
}

impl fmt::Display for Controlword {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "0x{:04X}", self.0)
    }
}

impl From<u16> for Controlword {
    fn from(v: u16) -> Self {
        Controlword(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typical_words_decode_to_their_command() {
        // MR-J5-G-N1 manual §7.1 "Typical word" column.
        let cases = [
            (Controlword::SHUTDOWN, Command::Shutdown),
            (Controlword::SWITCH_ON, Command::SwitchOn),
            (Controlword::DISABLE_VOLTAGE, Command::DisableVoltage),
            (Controlword::QUICK_STOP, Command::QuickStop),
            (Controlword(0x000B), Command::QuickStop),
            (Controlword::DISABLE_OPERATION, Command::SwitchOn),
            (Controlword::ENABLE_OPERATION, Command::EnableOperation),
            (Controlword::FAULT_RESET, Command::FaultReset),
        ];
        for (cw, cmd) in cases {
            assert_eq!(cw.command(), Some(cmd), "{cw}");
        }
        assert_eq!(Controlword::SHUTDOWN.0, 0x0006);
        assert_eq!(Controlword::SWITCH_ON.0, 0x0007);
        assert_eq!(Controlword::DISABLE_VOLTAGE.0, 0x0000);
        assert_eq!(Controlword::QUICK_STOP.0, 0x0002);
        assert_eq!(Controlword::DISABLE_OPERATION.0, 0x0007);
        assert_eq!(Controlword::ENABLE_OPERATION.0, 0x000F);
        assert_eq!(Controlword::FAULT_RESET.0, 0x0080);
    }

    #[test]
    fn dont_care_bits_follow_the_table() {
        // Every 4-bit pattern of bits 3..0 against the §3.2 bit table (— = either).
        for low in 0u16..16 {
            let cw = Controlword(low);
            let (b0, b1, b2, b3) = (low & 1 != 0, low & 2 != 0, low & 4 != 0, low & 8 != 0);
            let expect = match (b3, b2, b1, b0) {
                (_, _, false, _) => Command::DisableVoltage,
                (_, false, true, _) => Command::QuickStop,
                (_, true, true, false) => Command::Shutdown,
                (false, true, true, true) => Command::SwitchOn,
                (true, true, true, true) => Command::EnableOperation,
            };
            assert_eq!(cw.command(), Some(expect), "{cw}");
            // Upper bits (halt, OMS, torque-limit switches) do not change the command.
            assert_eq!(Controlword(low | 0x1B70).command(), Some(expect));
            assert_eq!(Controlword(low | 0x80).command(), Some(Command::FaultReset));
            assert_eq!(Controlword(low | 0x80).state_command(), expect);
        }
    }

    #[test]
    fn bit_accessors() {
        let cw = Controlword(0x010F);
        assert!(cw.switch_on() && cw.enable_voltage() && cw.quick_stop() && cw.enable_operation());
        assert!(cw.halt() && !cw.fault_reset());
        assert_eq!(cw.with_halt(false), Controlword::ENABLE_OPERATION);
        assert_eq!(Controlword::ENABLE_OPERATION.with_halt(true), cw);
        assert!(Controlword::QUICK_STOP.quick_stop_requested());
        assert!(!Controlword::DISABLE_VOLTAGE.quick_stop_requested());
        assert!(Controlword::FAULT_RESET.fault_reset_edge(Controlword(0)));
        assert!(!Controlword::FAULT_RESET.fault_reset_edge(Controlword::FAULT_RESET));
    }
}
