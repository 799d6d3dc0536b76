//! MR-JE-C alarm numbers as the objects carry them (MR-JE-C manual §7.3 2A41h, 2A42h, 2A00h):
//! alarm No. and detail No., e.g. "AL. 86.1", and the alarms the manual names, in words.

use cellrt_cia402::profiles::{
    AlarmInfo, AlarmKind, AlarmRegister, AlarmText, Clearing, StopBehaviour,
};

/// The drive, as [`AlarmText`] names it for a code it does not list.
const DRIVE: &str = "Mitsubishi MR-JE-C";

/// One row of [`ALARMS`]: the 2A42h code, display, name, kind and source; stop and clearing
/// are in the Troubleshooting manual, not this one (MR-JE-C manual §9 [GAP]).
const fn row(
    alarm: Alarm,
    display: &'static str,
    name: &'static str,
    kind: AlarmKind,
    source: &'static str,
) -> AlarmInfo {
    AlarmInfo {
        code: alarm.current2(),
        display,
        name,
        kind,
        stop: StopBehaviour::Unstated,
        clearing: Clearing::Unstated,
        source,
        cause: None,
        remedy: None,
    }
}

/// The alarms and warnings with a detail No. the MR-JE-C manual names (it names them in
/// passing: §1.1, §2.5, §4.9.2, §5.2.1–§5.2.3, §7.3), keyed by their 2A42h value, with the
/// cause where the manual states one; it gives no remedies.
#[rustfmt::skip]
pub const ALARMS: &[AlarmInfo] = &[
    row(Alarm::new(0x11, 0x1), "AL. 11.1", "Rotary switch setting error", AlarmKind::Alarm, "§4.9.2")
        .explained(Some("Modbus RTU: SW1/SW2 set to F8h–FFh (station No. outside 0–247)"), None),
    row(Alarm::new(0x37, 0x1), "AL. 37.1", "Parameter error", AlarmKind::Alarm, "§5.2.1, §7.3 (2A44h/2A45h name the parameters)")
        .explained(Some("A parameter out of its range, e.g. [Pr. PC71] with baud rate digit 5; 2A44h/2A45h name the parameters"), None),
    row(Alarm::NETWORK_1, "AL. 86.1", "Network communication error 1", AlarmKind::Alarm, "§2.5, §5.2.3")
        .explained(Some("CC-Link IE Field Basic: no cyclic data for [Pr. PN02] (default 1000 ms); a small PN02 may also raise it after a power cycle or an instantaneous power failure"), None),
    row(Alarm::NETWORK_4, "AL. 86.4", "Network communication error 4", AlarmKind::Alarm, "§2.5, §3.7, §5.2.3 (software A4 or later)")
        .explained(Some("SLMP or Modbus/TCP: no message for [Pr. PN10] s after the first one"), None),
    row(Alarm::MODBUS_RTU_TIMEOUT, "AL. 8A.2", "Modbus RTU communication time-out", AlarmKind::Alarm, "§4.9, §5.2.2")
        .explained(Some("Modbus RTU: no message for [Pr. PF46] s"), None),
    row(Alarm::new(0xE3, 0x1), "AL. E3.1", "Multi-revolution counter travel distance excess warning", AlarmKind::Warning, "§1.1 (not detected with the degree unit)"),
];

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

    /// A 2A42h value in words: the manual's number, name and cause where [`ALARMS`] lists it.
    pub fn text_of(current2: u16) -> AlarmText {
        AlarmText::decode(ALARMS, DRIVE, AlarmRegister::CurrentAlarm2A42, current2)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_2a42h_value_reads_as_the_manuals_alarm() {
        let t = Alarm::text_of(Alarm::NETWORK_4.current2());
        assert_eq!(
            t.name().as_deref(),
            Some("AL. 86.4 Network communication error 4")
        );
        assert_eq!(
            t.to_string(),
            "AL. 86.4 Network communication error 4 (2A42h = 8604h)"
        );
        assert!(t.cause().is_some_and(|c| c.contains("[Pr. PN10]")));
        assert_eq!(t.remedy(), None);
        // Each row's display is the alarm's own number.
        for a in ALARMS {
            let alarm = Alarm::from_current2(a.code).expect("non-zero");
            assert_eq!(alarm.to_string(), a.display);
        }
        assert_eq!(
            Alarm::text_of(0x9901).to_string(),
            "2A42h = 9901h (not listed for Mitsubishi MR-JE-C)"
        );
    }
}
