//! The simulated drive's FSoE slave (MR-JET-G-N1, MR-JET-G-N1 manual §4.3, §9.3, §7; manual §9.3), at
//! the level the manual describes: SafeData in the 11-byte safety PDOs, the connection
//! parameter set, the address check, the watchdog, and STO acting on the drive.
//!
//! Like the master side (`cellrt_cia402::fsoe`), the ETG.5100 protocol is **not** modelled (the manual
//! leaves the CRC and the command/state sequence to ETG.5100, §7.1 item 5): the slave answers
//! every frame with the master's Command and ConnectionID echoed and zero CRCs, and checks
//! none of them. Before [`FsoeSlave::connect`] and after a watchdog expiry the slave is in the
//! safe state (**[background]** ETG.5100: outputs, here STO, off until the connection runs).
//!
//! STO acts on the drive (`SimDrive`): while [`FsoeSlave::sto`] is true the power drive
//! system cannot be in Ready to switch on or beyond (it is forced to Switch on disabled; a
//! fault reaction ends in Fault at once) and the plant gets no torque: it coasts
//! ([`StoStop::Coast`]) or is braked ([`StoStop::DynamicBrake`]). The manual states only
//! "STO active, energy cut" (§7.2); the PDS state during STO is **[inferred]**.
//!
//! SS1, SDIP, SDIN, SLS and SLT are reported active while commanded; their monitoring limits
//! and ramps are in the Function manual, not available here (§7.2), and are not simulated.
//! Allocation-free per cycle.

use cellrt_cia402::fsoe::{
    decode_commands, encode_status, ConnectionParams, FsoeError, FsoeFrame, SafetyRequest,
    SafetyStatus,
};
use cellrt_cia402::profiles::FsoeFacts;

/// How the motor stops while STO is active (the manual says only "energy supply shut off").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum StoStop {
    /// No torque at all: the motor coasts (friction is not modelled).
    #[default]
    Coast,
    /// A dynamic-brake stop (the plant's maximum deceleration, then standstill).
    DynamicBrake,
}

/// The slave's functional safety parameters and the simulator's choices where the manual is
/// silent (each named, with its default).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FsoeSlaveParams {
    /// [Pr. PSA01.0] Safety sub-function activation (1 = enabled); default enabled (§7.1).
    pub psa01_0_enabled: bool,
    /// [Pr. PSA01.1] Input mode selection (1 = network); default network (§7.1).
    pub psa01_1_network: bool,
    /// [Pr. PSC07] FSoE Address setting; default 1 (the manual gives no default).
    pub psc07_address: u16,
    /// Bus cycles between the frame that changes the STO command and the cycle in which STO
    /// takes effect (torque cut; STOS = 1 in the next safety frame): the delay "is not stated"
    /// (TV-12); default 0 (effective in the same bus cycle's drive step).
    pub sto_delay_cycles: u32,
    /// SBCS follows STOS (a brake configured for SBC). Whether it does "in every configuration"
    /// is not stated (TV-12, [inferred]); default false (SBCS stays 0).
    pub sbc_follows_sto: bool,
    /// SSM speed in counts/s; `None`: SSM disabled, SSMS = 0 (§7.2). The SSM speed itself is in
    /// the Function manual.
    pub ssm_speed: Option<f64>,
    /// Shortest PDO cycle at which the slave accepts a connection, µs; `None`: the profile's
    /// (0.25 ms, [inferred], §1.3).
    pub min_cycle_us: Option<u32>,
    /// Alarm raised in the drive when the FSoE watchdog expires: the manual names none (§7.3);
    /// default `None` (the slave enters the safe state and sets Error, **[background]**
    /// ETG.5100).
    pub watchdog_alarm: Option<u16>,
    /// While Error = 1 the slave keeps STO active until an Error Ack edge clears it
    /// (**[inferred]**; the manual defines only the bits); default true.
    pub error_holds_sto: bool,
    /// How the motor stops during STO.
    pub sto_stop: StoStop,
}

impl Default for FsoeSlaveParams {
    fn default() -> Self {
        FsoeSlaveParams {
            psa01_0_enabled: true,
            psa01_1_network: true,
            psc07_address: 1,
            sto_delay_cycles: 0,
            sbc_follows_sto: false,
            ssm_speed: None,
            min_cycle_us: None,
            watchdog_alarm: None,
            error_holds_sto: true,
            sto_stop: StoStop::Coast,
        }
    }
}

/// What the connection parameter set and the last frames left in the slave's objects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Received {
    /// E901h:04 / :07 / :08 as last received.
    params: Option<ConnectionParams>,
    /// The last master frame (E700h).
    master: FsoeFrame,
    /// The last slave frame (E600h).
    slave: FsoeFrame,
}

/// One drive's FSoE slave state. Holds no heap data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FsoeSlave {
    facts: FsoeFacts,
    params: FsoeSlaveParams,
    cycle_us: u32,
    /// True while the connection runs (parameter set accepted, watchdog not expired).
    connected: bool,
    /// The functions last commanded (all active before the first frame).
    commands: SafetyRequest,
    /// Error Ack as last received.
    ack: bool,
    /// Error present (F601h:04).
    error: bool,
    /// STO in effect.
    sto: bool,
    /// Cycles left before `sto` follows a changed command.
    pending: u32,
    /// µs since the last frame of the running connection (counted from the end of the cycle
    /// that brought it).
    since_frame_us: u64,
    /// A frame arrived in the current cycle.
    fresh: bool,
    received: Received,
}

impl FsoeSlave {
    /// A slave in the safe state (STO active, not connected).
    pub fn new(facts: FsoeFacts, params: FsoeSlaveParams, cycle_us: u32) -> FsoeSlave {
        FsoeSlave {
            facts,
            params,
            cycle_us,
            connected: false,
            commands: SafetyRequest::ALL_ACTIVE,
            ack: false,
            error: false,
            sto: true,
            pending: params.sto_delay_cycles,
            since_frame_us: 0,
            fresh: false,
            received: Received::default(),
        }
    }

    /// Control-power cycle: back to the safe state, the received parameters forgotten.
    pub fn reset(&mut self) {
        *self = FsoeSlave::new(self.facts, self.params, self.cycle_us);
    }

    /// The connection parameter set (MR-JET-G-N1 manual §9.3 item 4). Refused when PSA01.0 = 0 or
    /// PSA01.1 = 0 (§7.1: set both before connecting), when the cycle is below the FSoE minimum
    /// (§1.3, [inferred]), or when the master's slave address differs from PSC07
    /// ([`FsoeError::AddressMismatch`]; the caller raises AL.584.1). A watchdog below the 16 ms
    /// minimum is accepted and shown in E901h:04: the slave's reaction to it is not stated
    /// (TV-12), the check is the master's.
    pub fn connect(&mut self, p: &ConnectionParams) -> Result<(), FsoeError> {
        if !self.params.psa01_0_enabled {
            return Err(FsoeError::SafetyDisabled);
        }
        if !self.params.psa01_1_network {
            return Err(FsoeError::NotNetworkMode);
        }
        let minimum_us = self.params.min_cycle_us.unwrap_or(self.facts.min_cycle_us);
        if self.cycle_us < minimum_us {
            return Err(FsoeError::CycleTooShort {
                cycle_us: self.cycle_us,
                minimum_us,
            });
        }
        if p.slave_address != self.params.psc07_address {
            self.connected = false;
            self.error = true;
            return Err(FsoeError::AddressMismatch {
                master: p.slave_address,
                psc07: self.params.psc07_address,
                alarm: self.facts.address_mismatch_alarm,
            });
        }
        self.received.params = Some(*p);
        self.connected = true;
        self.commands = SafetyRequest::ALL_ACTIVE;
        self.since_frame_us = 0;
        self.fresh = false;
        Ok(())
    }

    /// One frame from the master; returns the slave's answer (its status as of now). Before
    /// the connection (or after a watchdog expiry) the commands are not taken.
    pub fn frame(&mut self, rx: &FsoeFrame, speed: f64) -> FsoeFrame {
        self.received.master = *rx;
        if self.connected {
            self.fresh = true;
            let (request, ack) = decode_commands(&self.facts.commands, &rx.safe_data);
            if ack && !self.ack {
                // Error Ack 0→1 (§7.2): the connection runs again, so the cause is gone.
                self.error = false;
            }
            self.ack = ack;
            self.commands = request;
        }
        let status = self.status(speed);
        let tx = FsoeFrame {
            command: rx.command,
            safe_data: encode_status(&self.facts.status, &status),
            crc: [0, 0],
            connection_id: rx.connection_id,
        };
        self.received.slave = tx;
        tx
    }

    /// Advances the slave by `cycles` bus cycles: the watchdog (the connection drops to the
    /// safe state with Error = 1 when no frame came for longer than E901h:04) and the STO
    /// delay. Returns the alarm to raise on a watchdog expiry, if one is configured.
    pub fn tick(&mut self, cycles: u32) -> Option<u16> {
        let mut alarm = None;
        if self.fresh {
            self.fresh = false;
            self.since_frame_us = 0;
        } else if self.connected {
            self.since_frame_us = self
                .since_frame_us
                .saturating_add(u64::from(cycles) * u64::from(self.cycle_us));
            let wd_us = self
                .received
                .params
                .map_or(0, |p| u64::from(p.watchdog_ms) * 1000);
            if self.since_frame_us > wd_us {
                self.connected = false;
                self.error = true;
                self.commands = SafetyRequest::ALL_ACTIVE;
                alarm = self.params.watchdog_alarm;
            }
        }
        let want =
            !self.connected || self.commands.sto || (self.error && self.params.error_holds_sto);
        if want == self.sto {
            self.pending = self.params.sto_delay_cycles;
        } else if self.pending == 0 {
            self.sto = want;
            self.pending = self.params.sto_delay_cycles;
        } else {
            self.pending = self.pending.saturating_sub(cycles);
        }
        alarm
    }

    /// STO in effect: the drive has no torque.
    pub fn sto(&self) -> bool {
        self.sto
    }

    /// True while the connection runs.
    pub fn connected(&self) -> bool {
        self.connected
    }

    /// How the motor stops during STO.
    pub fn sto_stop(&self) -> StoStop {
        self.params.sto_stop
    }

    /// The status the slave reports at motor speed `speed` (counts/s).
    pub fn status(&self, speed: f64) -> SafetyStatus {
        let c = if self.connected {
            self.commands
        } else {
            SafetyRequest::RUN
        };
        SafetyStatus {
            sto: self.sto,
            ssm: self.params.ssm_speed.is_some_and(|v| speed.abs() <= v),
            error: self.error,
            ss1: c.ss1,
            sdip: c.sdip,
            sdin: c.sdin,
            sls: c.sls,
            sbc: self.params.sbc_follows_sto && self.sto,
            slt: c.slt,
        }
    }

    /// SDO upload of an FSoE object, `None` if `index:sub` is not one: 1608h:00 / 1A08h:00,
    /// E600h/E700h :01–:04 (the last frames), E901h:04/:07/:08 (the parameter set received, 0
    /// before it), F601h / F701h sub-indexes (the status and command bits).
    pub fn upload(&self, index: u16, sub: u8, speed: f64) -> Option<i64> {
        let f = &self.facts;
        let frame_field = |fr: &FsoeFrame| match sub {
            1 => Some(i64::from(fr.command)),
            2 => Some(i64::from(fr.connection_id)),
            3 => Some(i64::from(fr.crc[0])),
            4 => Some(i64::from(fr.crc[1])),
            _ => None,
        };
        if (index == f.rx_pdo || index == f.tx_pdo) && sub == 0 {
            return Some(i64::from(f.mapping_entries));
        }
        if index == f.master_frame_object {
            return frame_field(&self.received.master);
        }
        if index == f.slave_frame_object {
            return frame_field(&self.received.slave);
        }
        if index == f.info_object {
            let p = self.received.params;
            let v = |g: fn(&ConnectionParams) -> u16| i64::from(p.as_ref().map_or(0, g));
            return match sub {
                s if s == f.watchdog_sub => Some(v(|p| p.watchdog_ms)),
                s if s == f.comm_param_len_sub => Some(v(|p| p.comm_param_len)),
                s if s == f.app_param_len_sub => Some(v(|p| p.app_param_len)),
                _ => None,
            };
        }
        let bit_of = |sd: &[u8; 4], bits: &[cellrt_cia402::profiles::SafeBit]| {
            bits.iter()
                .find(|b| b.sub == sub)
                .map(|b| i64::from(b.get(sd)))
        };
        if index == f.status_object {
            let sd = encode_status(&f.status, &self.status(speed));
            return bit_of(&sd, &status_bits(f));
        }
        if index == f.command_object {
            return bit_of(&self.received.master.safe_data, &command_bits(f));
        }
        None
    }

    /// True if `index` is one of the FSoE objects [`FsoeSlave::upload`] serves.
    pub fn serves(&self, index: u16) -> bool {
        let f = &self.facts;
        [
            f.rx_pdo,
            f.tx_pdo,
            f.master_frame_object,
            f.slave_frame_object,
            f.info_object,
            f.status_object,
            f.command_object,
        ]
        .contains(&index)
    }
}

fn status_bits(f: &FsoeFacts) -> [cellrt_cia402::profiles::SafeBit; 15] {
    let s = &f.status;
    [
        s.sto, s.ssm, s.error, s.ss1, s.sdip, s.sdin, s.sls[0], s.sls[1], s.sls[2], s.sls[3],
        s.sbc, s.slt[0], s.slt[1], s.slt[2], s.slt[3],
    ]
}

fn command_bits(f: &FsoeFacts) -> [cellrt_cia402::profiles::SafeBit; 13] {
    let c = &f.commands;
    [
        c.sto,
        c.ss1,
        c.sdip,
        c.sdin,
        c.error_ack,
        c.sls[0],
        c.sls[1],
        c.sls[2],
        c.sls[3],
        c.slt[0],
        c.slt[1],
        c.slt[2],
        c.slt[3],
    ]
}
