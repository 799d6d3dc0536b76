//! The drive's communication time-outs (MR-JE-C manual §5.1.3 POINT, §5.2.2, §5.2.3): each is
//! armed by the first message of its protocol, raises its alarm when no message has come for
//! the parameter's time, and is disarmed by an alarm reset until the next message (the manual
//! says so for [Pr. PN10]; the emulator does the same for the other two). 0 switches a
//! time-out off, the default for PN10 and PF46: then a master that vanishes leaves the motor
//! running (§3.7, §4.9 POINT). All is judged on the virtual clock passed in.

use std::time::Duration;

use cellrt_fieldbus::mr_je_c::alarm::Alarm;

/// A protocol the drive serves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, strum::Display)]
pub enum Transport {
    /// CC-Link IE Field Network Basic cyclic data ([Pr. PN02] → AL. 86.1).
    #[strum(serialize = "CC-Link IE Field Basic")]
    CcLink,
    /// SLMP ([Pr. PN10] → AL. 86.4, shared with Modbus/TCP).
    #[strum(serialize = "SLMP")]
    Slmp,
    /// Modbus/TCP ([Pr. PN10] → AL. 86.4).
    #[strum(serialize = "Modbus/TCP")]
    ModbusTcp,
    /// Modbus RTU ([Pr. PF46] → AL. 8A.2).
    #[strum(serialize = "Modbus RTU")]
    ModbusRtu,
}

/// The three time-outs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Watch {
    CcLink,
    Ethernet,
    Rtu,
}

impl Watch {
    const ALL: [Watch; 3] = [Watch::CcLink, Watch::Ethernet, Watch::Rtu];

    fn of(t: Transport) -> Watch {
        match t {
            Transport::CcLink => Watch::CcLink,
            Transport::Slmp | Transport::ModbusTcp => Watch::Ethernet,
            Transport::ModbusRtu => Watch::Rtu,
        }
    }

    fn alarm(self) -> Alarm {
        match self {
            Watch::CcLink => Alarm::NETWORK_1,
            Watch::Ethernet => Alarm::NETWORK_4,
            Watch::Rtu => Alarm::MODBUS_RTU_TIMEOUT,
        }
    }
}

/// The time-out settings in effect (0: off).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Timeouts {
    /// [Pr. PN02].
    pub cclink: Duration,
    /// [Pr. PN10] (always off before SW A4).
    pub ethernet: Duration,
    /// [Pr. PF46].
    pub rtu: Duration,
}

impl Timeouts {
    fn of(&self, w: Watch) -> Duration {
        match w {
            Watch::CcLink => self.cclink,
            Watch::Ethernet => self.ethernet,
            Watch::Rtu => self.rtu,
        }
    }
}

/// When each armed time-out last saw a message.
#[derive(Debug, Clone, Default)]
pub struct CommWatchdog {
    last: [Option<Duration>; 3],
}

impl CommWatchdog {
    /// A message of `t` arrived at `now`: arms or feeds its time-out.
    pub fn received(&mut self, t: Transport, now: Duration) {
        self.last[Watch::of(t) as usize] = Some(now);
    }

    /// The alarm of the first time-out expired at `now` under `settings`, which is disarmed.
    pub fn expired(&mut self, now: Duration, settings: &Timeouts) -> Option<Alarm> {
        for w in Watch::ALL {
            let limit = settings.of(w);
            let slot = &mut self.last[w as usize];
            if let Some(last) = *slot {
                if !limit.is_zero() && now.saturating_sub(last) >= limit {
                    *slot = None;
                    return Some(w.alarm());
                }
            }
        }
        None
    }

    /// An alarm reset: every time-out waits for its protocol's next message.
    pub fn disarm(&mut self) {
        self.last = [None; 3];
    }
}
