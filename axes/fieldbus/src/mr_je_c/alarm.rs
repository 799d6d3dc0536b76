//! MR-JE-C alarm numbers as the objects carry them (MR-JE-C manual §7.3 2A41h, 2A42h, 2A00h):
//! alarm No. and detail No., e.g. "AL. 86.1".

/// An alarm (or warning) number with its detail number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Alarm {
    /// Alarm No. (86h in "AL. 86.1": the manual's numbers read as hexadecimal digits).
    pub number: u8,
    /// Detail No.
    pub detail: u8,
}

impl Alarm {
    /// AL. 86.1 Network communication error 1: no CC-Link IE Field Basic cyclic data for
    /// [Pr. PN02] (MR-JE-C manual §5.2.3).
    pub const NETWORK_1: Alarm = Alarm::new(0x86, 0x1);
    /// AL. 86.4 Network communication error 4: no SLMP / Modbus/TCP message for [Pr. PN10]
    /// (MR-JE-C manual §5.2.3, SW A4+).
    pub const NETWORK_4: Alarm = Alarm::new(0x86, 0x4);
    /// AL. 8A.2 Modbus RTU communication time-out: no message for [Pr. PF46] (§5.2.2).
    pub const MODBUS_RTU_TIMEOUT: Alarm = Alarm::new(0x8A, 0x2);

    /// Alarm No. and detail No.
    pub const fn new(number: u8, detail: u8) -> Alarm {
        Alarm { number, detail }
    }

    /// The 2A41h / 2A00h:1 form: alarm No. in bits 16–31, detail in bits 0–15.
    pub const fn current(self) -> u32 {
        (self.number as u32) << 16 | self.detail as u32
    }

    /// The 2A42h / 2A00h:3 form: alarm No. in bits 8–15, detail in bits 0–7.
    pub const fn current2(self) -> u16 {
        (self.number as u16) << 8 | self.detail as u16
    }

    /// The alarm of a 2A42h value (0: none).
    pub const fn from_current2(v: u16) -> Option<Alarm> {
        if v == 0 {
            None
        } else {
            Some(Alarm::new((v >> 8) as u8, v as u8))
        }
    }
}

impl std::fmt::Display for Alarm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "AL. {:02X}.{:X}", self.number, self.detail)
    }
}
