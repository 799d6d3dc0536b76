//! FSoE (Safety over EtherCAT) safety process data, master side, at the level the MR-JET-G-N1
//! manual describes it (MR-JET-G-N1 manual §4.3, §9.3, §7; manual §9.3).
//!
//! What is modelled: the 11-byte frames of the safety PDOs 1608h (master → slave) and 1A08h
//! (slave → master) with their byte layout ([`FsoeFrame`]), the SafeData bit assignment in both
//! directions ([`SafetyRequest`] ↔ commands, where **0 activates** a function; [`SafetyStatus`]
//! ↔ status, where 1 = active), Error Ack as a 0→1 edge, the FSoE Connection Parameter Set the
//! master sends at start-up ([`ConnectionParams`]: slave address, watchdog, parameter lengths),
//! and the master-side configuration checks ([`FsoeMaster::new`]): watchdog at least
//! T_Ref + 4 × T_Com = 16 ms (§7.3), FSoE only at cycles of 0.25 ms or more (§1.3, [inferred]),
//! the slave address within PSC07's range (§7.1).
//!
//! What is **not** modelled: the ETG.5100 protocol itself. The manual says the CRC and the
//! command/state sequence "are those of ETG.5100 and are not described in this manual" (§7.1
//! item 5), and ETG.5100 is not among the sources. The frame's Command, CRC_0/CRC_1 and
//! ConnectionID fields are therefore carried as opaque values at their §5.4 offsets
//! (little-endian, the EtherCAT byte order [background]): the master writes
//! [`FsoeMasterConfig::frame_command`], zero CRCs and its connection ID; the simulated slave
//! (`sim::fsoe`) does not check them. The connection parameter set is passed as a structured
//! call instead of the ETG.5100 Connection/Parameter frames. Everything called per cycle
//! ([`FsoeMaster::write_frame`], [`FsoeMaster::read_frame`]) is allocation-free.

use crate::cycles::CycleTime;
use crate::profiles::{
    DriveModel, DriveProfile, FsoeCommandBits, FsoeFacts, FsoeFrameLayout, FsoeStatusBits,
};

/// An FSoE configuration or frame that cannot be used, with what was wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum FsoeError {
    /// The drive model has no FSoE (or the simulated drive was built without it).
    #[error("{model} has no FSoE safety process data (or FSoE is not configured on this drive)")]
    NotSupported {
        /// The model.
        model: DriveModel,
    },
    /// The watchdog is below the minimum configurable value (MR-JET-G-N1 manual §9.3).
    #[error(
        "FSoE watchdog {watchdog_ms} ms refused: the minimum is {minimum_ms} ms \
         (T_Ref + 4 × T_Com, MR-JET-G-N1 manual §9.3)"
    )]
    WatchdogTooShort {
        /// The configured watchdog, ms.
        watchdog_ms: u16,
        /// The minimum, ms.
        minimum_ms: u32,
    },
    /// The PDO cycle is too short for FSoE (MR-JET-G-N1 manual §2.1, §4.1, §6.2, §6.3, [inferred]).
    #[error(
        "FSoE needs a PDO cycle of at least {minimum_us} µs; the cycle is {cycle_us} µs \
         (MR-JET-G-N1 manual §2.1, §4.1, §6.2, §6.3)"
    )]
    CycleTooShort {
        /// The cycle, µs.
        cycle_us: u32,
        /// The shortest cycle with FSoE, µs.
        minimum_us: u32,
    },
    /// The FSoE slave address is outside PSC07's range.
    #[error(
        "FSoE slave address {address} is outside {min}..={max} ([Pr. PSC07], MR-JET-G-N1 manual §9.3)"
    )]
    AddressOutOfRange {
        /// The address.
        address: u16,
        /// Lowest allowed.
        min: u16,
        /// Highest allowed.
        max: u16,
    },
    /// A safety PDO image of the wrong size.
    #[error(
        "FSoE frame of {actual} bytes; the safety PDO holds {expected} bytes (MR-JET-G-N1 manual §4.3, §9.3)"
    )]
    FrameLength {
        /// Bytes the safety PDO holds.
        expected: usize,
        /// Bytes given.
        actual: usize,
    },
    /// The master's slave address differs from the slave's [Pr. PSC07] (AL.584.1).
    #[error(
        "FSoE address mismatch: the master addresses slave {master}, [Pr. PSC07] is {psc07} \
         (alarm {alarm:#06X}, AL.584.1)"
    )]
    AddressMismatch {
        /// The address the master sent.
        master: u16,
        /// The slave's PSC07.
        psc07: u16,
        /// The alarm the drive raised.
        alarm: u16,
    },
    /// [Pr. PSA01.0] = 0: safety sub-functions are disabled on the slave.
    #[error(
        "FSoE refused: safety sub-functions are disabled ([Pr. PSA01.0] = 0, MR-JET-G-N1 manual §9.3)"
    )]
    SafetyDisabled,
    /// [Pr. PSA01.1] = 0: safety sub-functions are controlled by input devices, not the network.
    #[error(
        "FSoE refused: [Pr. PSA01.1] = 0 (safety sub-functions by input devices); set 1 for \
         network control (MR-JET-G-N1 manual §9.3)"
    )]
    NotNetworkMode,
}

/// The safety sub-functions the master asks for; `true` = **activate** the function (the wire
/// bit is then 0, MR-JET-G-N1 manual §9.3). [`SafetyRequest::RUN`] cancels them all.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SafetyRequest {
    /// STO (safe torque off).
    pub sto: bool,
    /// SS1 (safe stop 1).
    pub ss1: bool,
    /// SDIP (safe direction positive).
    pub sdip: bool,
    /// SDIN (safe direction negative).
    pub sdin: bool,
    /// SLS1–SLS4 (safely-limited speed).
    pub sls: [bool; 4],
    /// SLT1–SLT4 (safely-limited torque).
    pub slt: [bool; 4],
}

impl SafetyRequest {
    /// Every function cancelled: the run command of TV-12.
    pub const RUN: SafetyRequest = SafetyRequest {
        sto: false,
        ss1: false,
        sdip: false,
        sdin: false,
        sls: [false; 4],
        slt: [false; 4],
    };

    /// STO requested, everything else cancelled (TV-12 "STO request").
    pub const STO: SafetyRequest = SafetyRequest {
        sto: true,
        ..SafetyRequest::RUN
    };

    /// Every function active: the safe state (what a slave assumes before any command).
    pub const ALL_ACTIVE: SafetyRequest = SafetyRequest {
        sto: true,
        ss1: true,
        sdip: true,
        sdin: true,
        sls: [true; 4],
        slt: [true; 4],
    };
}

/// The slave's SafeData status (MR-JET-G-N1 manual §9.3); `true` = active / present.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SafetyStatus {
    /// STOS: STO active, energy cut.
    pub sto: bool,
    /// SSMS: speed at or below the SSM speed (false with SSM disabled).
    pub ssm: bool,
    /// Error: an error is present.
    pub error: bool,
    /// SS1S.
    pub ss1: bool,
    /// SDIPS.
    pub sdip: bool,
    /// SDINS.
    pub sdin: bool,
    /// SLS1S–SLS4S.
    pub sls: [bool; 4],
    /// SBCS: STO active and the brake supply cut.
    pub sbc: bool,
    /// SLT1S–SLT4S.
    pub slt: [bool; 4],
}

/// SafeData of the master's commands: every bit "not available" is 0, every function bit is
/// the inverse of `request`, Error Ack is `error_ack`.
pub fn encode_commands(
    bits: &FsoeCommandBits,
    request: &SafetyRequest,
    error_ack: bool,
) -> [u8; 4] {
    let mut sd = [0u8; 4];
    bits.sto.set(&mut sd, !request.sto);
    bits.ss1.set(&mut sd, !request.ss1);
    bits.sdip.set(&mut sd, !request.sdip);
    bits.sdin.set(&mut sd, !request.sdin);
    for (b, on) in bits.sls.iter().zip(request.sls) {
        b.set(&mut sd, !on);
    }
    for (b, on) in bits.slt.iter().zip(request.slt) {
        b.set(&mut sd, !on);
    }
    bits.error_ack.set(&mut sd, error_ack);
    sd
}

/// The request and the Error Ack bit carried by command SafeData `sd`.
pub fn decode_commands(bits: &FsoeCommandBits, sd: &[u8; 4]) -> (SafetyRequest, bool) {
    let mut r = SafetyRequest {
        sto: !bits.sto.get(sd),
        ss1: !bits.ss1.get(sd),
        sdip: !bits.sdip.get(sd),
        sdin: !bits.sdin.get(sd),
        ..SafetyRequest::RUN
    };
    for (k, b) in bits.sls.iter().enumerate() {
        r.sls[k] = !b.get(sd);
    }
    for (k, b) in bits.slt.iter().enumerate() {
        r.slt[k] = !b.get(sd);
    }
    (r, bits.error_ack.get(sd))
}

/// SafeData of the slave's status (bits "not available" are 0).
pub fn encode_status(bits: &FsoeStatusBits, status: &SafetyStatus) -> [u8; 4] {
    let mut sd = [0u8; 4];
    bits.sto.set(&mut sd, status.sto);
    bits.ssm.set(&mut sd, status.ssm);
    bits.error.set(&mut sd, status.error);
    bits.ss1.set(&mut sd, status.ss1);
    bits.sdip.set(&mut sd, status.sdip);
    bits.sdin.set(&mut sd, status.sdin);
    for (b, on) in bits.sls.iter().zip(status.sls) {
        b.set(&mut sd, on);
    }
    bits.sbc.set(&mut sd, status.sbc);
    for (b, on) in bits.slt.iter().zip(status.slt) {
        b.set(&mut sd, on);
    }
    sd
}

/// The status carried by status SafeData `sd`.
pub fn decode_status(bits: &FsoeStatusBits, sd: &[u8; 4]) -> SafetyStatus {
    let mut s = SafetyStatus {
        sto: bits.sto.get(sd),
        ssm: bits.ssm.get(sd),
        error: bits.error.get(sd),
        ss1: bits.ss1.get(sd),
        sdip: bits.sdip.get(sd),
        sdin: bits.sdin.get(sd),
        sbc: bits.sbc.get(sd),
        ..SafetyStatus::default()
    };
    for (k, b) in bits.sls.iter().enumerate() {
        s.sls[k] = b.get(sd);
    }
    for (k, b) in bits.slt.iter().enumerate() {
        s.slt[k] = b.get(sd);
    }
    s
}

/// One FSoE frame (either direction), its fields at the offsets of [`FsoeFrameLayout`].
/// Command, CRCs and ConnectionID are opaque here (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct FsoeFrame {
    /// FSoE Command (E700h:01 / E600h:01).
    pub command: u8,
    /// SafeData[0]–[3].
    pub safe_data: [u8; 4],
    /// CRC_0 and CRC_1 (E700h/E600h :03, :04).
    pub crc: [u16; 2],
    /// ConnectionID (E700h/E600h :02).
    pub connection_id: u16,
}

impl FsoeFrame {
    /// Writes the frame into `out`, which must be exactly `layout.len` bytes.
    pub fn encode(&self, layout: &FsoeFrameLayout, out: &mut [u8]) -> Result<(), FsoeError> {
        check_len(layout, out.len())?;
        let mut put = |at: u8, bytes: &[u8]| {
            let at = usize::from(at);
            if let Some(dst) = out.get_mut(at..at + bytes.len()) {
                dst.copy_from_slice(bytes);
            }
        };
        put(layout.command, &[self.command]);
        for (at, b) in layout.safe_data.iter().zip(self.safe_data) {
            put(*at, &[b]);
        }
        for (at, c) in layout.crc.iter().zip(self.crc) {
            put(*at, &c.to_le_bytes());
        }
        put(layout.connection_id, &self.connection_id.to_le_bytes());
        Ok(())
    }

    /// Reads a frame from `bytes`, which must be exactly `layout.len` bytes.
    pub fn decode(layout: &FsoeFrameLayout, bytes: &[u8]) -> Result<FsoeFrame, FsoeError> {
        check_len(layout, bytes.len())?;
        let byte = |at: u8| bytes.get(usize::from(at)).copied().unwrap_or(0);
        let word = |at: u8| u16::from_le_bytes([byte(at), byte(at.saturating_add(1))]);
        let mut safe_data = [0u8; 4];
        for (d, at) in safe_data.iter_mut().zip(layout.safe_data) {
            *d = byte(at);
        }
        Ok(FsoeFrame {
            command: byte(layout.command),
            safe_data,
            crc: [word(layout.crc[0]), word(layout.crc[1])],
            connection_id: word(layout.connection_id),
        })
    }
}

fn check_len(layout: &FsoeFrameLayout, actual: usize) -> Result<(), FsoeError> {
    let expected = usize::from(layout.len);
    if actual == expected {
        Ok(())
    } else {
        Err(FsoeError::FrameLength { expected, actual })
    }
}

/// The FSoE Connection Parameter Set the master sends during start-up (MR-JET-G-N1 manual §9.3
/// item 4), plus the slave address the connection is opened with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ConnectionParams {
    /// The FSoE slave address configured in the master (must equal the slave's PSC07).
    pub slave_address: u16,
    /// The master's connection ID (carried in every frame's ConnectionID field).
    pub connection_id: u16,
    /// Watchdog Time (E901h:04), ms.
    pub watchdog_ms: u16,
    /// Communication Parameter Length (E901h:07).
    pub comm_param_len: u16,
    /// Application Parameter Length (E901h:08).
    pub app_param_len: u16,
}

/// How the master derives the minimum watchdog (MR-JET-G-N1 manual §9.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum WatchdogRule {
    /// The manual's minimum configurable value, T_Ref + 4 × T_Com = 16 ms, at every cycle.
    #[default]
    ManualMinimum,
    /// **[inferred]** T_Ref + 4 × the actual PDO cycle, rounded up to whole ms (1 ms cycle:
    /// 19 ms, 4 ms: 31 ms, 8 ms: 47 ms); never below the manual's minimum. The manual does not
    /// say whether the minimum grows with the cycle; this is the spec's "safe choice".
    ScaledWithCycle,
}

/// The master's FSoE configuration for one slave.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FsoeMasterConfig {
    /// The FSoE slave address (the slave's [Pr. PSC07] must be the same, §7.1).
    pub slave_address: u16,
    /// FSoE Watchdog Time, ms (§7.3: at least 16 ms; also allow for the controller's own
    /// response time).
    pub watchdog_ms: u16,
    /// The connection ID the master uses (opaque, ETG.5100).
    pub connection_id: u16,
    /// The Command byte the master puts in each frame (opaque: the ETG.5100 command values are
    /// not in the manual; the simulated slave does not check it). Default 0.
    pub frame_command: u8,
    /// Communication Parameter Length sent in the parameter set. **[background]** ETG.5100's
    /// communication parameter is the 2-byte watchdog; the manual names the object only.
    pub comm_param_len: u16,
    /// Application Parameter Length sent in the parameter set; the manual gives no value
    /// (default 0).
    pub app_param_len: u16,
    /// How the minimum watchdog is derived.
    pub watchdog_rule: WatchdogRule,
    /// Shortest PDO cycle with FSoE, µs; `None`: the profile's (0.25 ms, [inferred], §1.3).
    pub min_cycle_us: Option<u32>,
}

impl FsoeMasterConfig {
    /// A configuration for `slave_address` with watchdog `watchdog_ms` and the defaults above
    /// (connection ID 1).
    pub const fn new(slave_address: u16, watchdog_ms: u16) -> FsoeMasterConfig {
        FsoeMasterConfig {
            slave_address,
            watchdog_ms,
            connection_id: 1,
            frame_command: 0,
            comm_param_len: 2,
            app_param_len: 0,
            watchdog_rule: WatchdogRule::ManualMinimum,
            min_cycle_us: None,
        }
    }
}

/// The smallest watchdog (ms) `rule` allows at `cycle` for the FSoE facts `f`.
pub fn minimum_watchdog_ms(f: &FsoeFacts, rule: WatchdogRule, cycle: CycleTime) -> u32 {
    match rule {
        WatchdogRule::ManualMinimum => f.watchdog_min_ms,
        WatchdogRule::ScaledWithCycle => {
            let us = u64::from(f.t_ref_us) + 4 * u64::from(cycle.as_micros());
            let ms = u32::try_from(us.div_ceil(1000)).unwrap_or(u32::MAX);
            ms.max(f.watchdog_min_ms)
        }
    }
}

/// The master's side of one FSoE connection: a validated configuration, the request it sends,
/// and the Error Ack edge. Holds no heap data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FsoeMaster {
    facts: FsoeFacts,
    config: FsoeMasterConfig,
    request: SafetyRequest,
    /// An Error Ack edge is wanted and not yet sent.
    ack_pending: bool,
    /// Error Ack as sent in the last frame.
    ack_sent: bool,
}

impl FsoeMaster {
    /// A master for a drive of `profile` at `cycle`, after the configuration checks: the
    /// model has FSoE, the cycle is long enough, the watchdog is at least the minimum (a 15 ms
    /// watchdog is refused, TV-12), the slave address is within PSC07's range. It starts
    /// requesting [`SafetyRequest::ALL_ACTIVE`] (the safe state) until told otherwise.
    pub fn new(
        profile: &DriveProfile,
        cycle: CycleTime,
        config: FsoeMasterConfig,
    ) -> Result<FsoeMaster, FsoeError> {
        let facts = profile.fsoe.ok_or(FsoeError::NotSupported {
            model: profile.model,
        })?;
        let minimum_us = config.min_cycle_us.unwrap_or(facts.min_cycle_us);
        if cycle.as_micros() < minimum_us {
            return Err(FsoeError::CycleTooShort {
                cycle_us: cycle.as_micros(),
                minimum_us,
            });
        }
        let minimum_ms = minimum_watchdog_ms(&facts, config.watchdog_rule, cycle);
        if u32::from(config.watchdog_ms) < minimum_ms {
            return Err(FsoeError::WatchdogTooShort {
                watchdog_ms: config.watchdog_ms,
                minimum_ms,
            });
        }
        let (min, max) = facts.address_range;
        if !(min..=max).contains(&config.slave_address) {
            return Err(FsoeError::AddressOutOfRange {
                address: config.slave_address,
                min,
                max,
            });
        }
        Ok(FsoeMaster {
            facts,
            config,
            request: SafetyRequest::ALL_ACTIVE,
            ack_pending: false,
            ack_sent: false,
        })
    }

    /// The connection parameter set to send to the slave at start-up.
    pub fn connection_params(&self) -> ConnectionParams {
        ConnectionParams {
            slave_address: self.config.slave_address,
            connection_id: self.config.connection_id,
            watchdog_ms: self.config.watchdog_ms,
            comm_param_len: self.config.comm_param_len,
            app_param_len: self.config.app_param_len,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &FsoeMasterConfig {
        &self.config
    }

    /// The FSoE facts of the slave's model.
    pub fn facts(&self) -> &FsoeFacts {
        &self.facts
    }

    /// Sets the functions to request from the next frame on.
    pub fn request(&mut self, request: SafetyRequest) {
        self.request = request;
    }

    /// The current request.
    pub fn current_request(&self) -> SafetyRequest {
        self.request
    }

    /// Asks for errors to be cleared: the next frames carry an Error Ack 0→1 edge (a 0 first if
    /// the last frame had the bit set), then the bit returns to 0 (MR-JET-G-N1 manual §9.3, TV-12:
    /// 0x63 followed by 0xE3).
    pub fn acknowledge_errors(&mut self) {
        self.ack_pending = true;
    }

    /// The frame for this cycle into `out` (the safety RxPDO image, 11 bytes); returns the
    /// SafeData sent. Allocation-free.
    pub fn write_frame(&mut self, out: &mut [u8]) -> Result<[u8; 4], FsoeError> {
        check_len(&self.facts.frame, out.len())?;
        let ack = if self.ack_pending && !self.ack_sent {
            self.ack_pending = false;
            true
        } else {
            false
        };
        let safe_data = encode_commands(&self.facts.commands, &self.request, ack);
        let frame = FsoeFrame {
            command: self.config.frame_command,
            safe_data,
            crc: [0, 0],
            connection_id: self.config.connection_id,
        };
        frame.encode(&self.facts.frame, out)?;
        self.ack_sent = ack;
        Ok(safe_data)
    }

    /// The slave's status from its frame (the safety TxPDO image, 11 bytes). Allocation-free.
    pub fn read_frame(&self, input: &[u8]) -> Result<SafetyStatus, FsoeError> {
        let frame = FsoeFrame::decode(&self.facts.frame, input)?;
        Ok(decode_status(&self.facts.status, &frame.safe_data))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profiles::mr_jet_g_n1::FSOE;

    #[test]
    fn frame_fields_land_at_their_offsets() {
        let f = FsoeFrame {
            command: 0xA5,
            safe_data: [0x11, 0x22, 0x33, 0x44],
            crc: [0x0201, 0x0403],
            connection_id: 0x0605,
        };
        let mut b = [0u8; 11];
        f.encode(&FSOE.frame, &mut b).unwrap();
        assert_eq!(
            b,
            [0xA5, 0x11, 0x22, 0x01, 0x02, 0x33, 0x44, 0x03, 0x04, 0x05, 0x06]
        );
        assert_eq!(FsoeFrame::decode(&FSOE.frame, &b), Ok(f));
        assert_eq!(
            FsoeFrame::decode(&FSOE.frame, &b[..10]),
            Err(FsoeError::FrameLength {
                expected: 11,
                actual: 10
            })
        );
    }

    #[test]
    fn status_round_trips_bit_by_bit() {
        for k in 0..32u32 {
            let sd = (1u32 << k).to_le_bytes();
            let s = decode_status(&FSOE.status, &sd);
            // Bits "not available" decode to nothing and encode back to 0.
            let back = encode_status(&FSOE.status, &s);
            assert!(back == sd || back == [0; 4], "bit {k}: {back:?}");
        }
    }
}
