//! A simulated MR-JE-C (MR-JE-C manual §2–§7): the object dictionary with its access rights and
//! ranges and parameter links (`links`), the CiA 402 FSA with quick-stop option code 2 (the
//! 6085h ramp, then Switch on disabled), alarms with their history and reset, the EEPROM with
//! Store parameters 1010h (`eeprom`), and the communication time-outs, all judged on a virtual
//! clock the caller passes in (`now`: time since power-on). The motor moves
//! in pp, pv, tq, hm (method 37), jg, pt and idx (`motion` and its mode modules); in the
//! −20/−21/−22 modes it holds its position and targets are stored.

mod address_rules;
pub mod cyclic;
pub mod eeprom;
#[cfg(test)]
mod fixture;
pub mod homing;
pub mod indexer;
pub mod jog;
pub mod modbus;
#[cfg(test)]
mod mode_tests;
pub mod motion;
pub mod point_table;
pub mod profile;
mod refusal;
pub mod rs485;
pub mod rtu;
pub mod search;
pub mod server;
pub mod slmp;
mod store;
pub mod torque;
pub mod tuning;
mod watchdog;

use std::time::Duration;

use crate::device::pds::{controlword_step, end_of_stop, ControlwordStep, FaultReaction};
use crate::motion::profile_velocity::PvModel;
use crate::motion::window_time::{Held, HeldFrom};
use cellrt_cia402::controlword::Controlword;
use cellrt_cia402::fsa::{FsaQuirks, FsaState};
use cellrt_cia402::statusword::Statusword;
use cellrt_fieldbus::modbus::serial::{Framing, LineSettings};
use cellrt_fieldbus::mr_je_c::alarm::Alarm;
use cellrt_fieldbus::mr_je_c::objects::ObjectId;
use cellrt_fieldbus::mr_je_c::parameters::{
    PC03, PC30, PC31, PC70, PC71, PF45, PF46, PN02, PN08, PN10, PN23, PT28,
};
use cellrt_fieldbus::mr_je_c::types::SoftwareVersion;
use cellrt_fieldbus::mr_je_c::value::Value;

pub use crate::device::alarm_history::Occurrence;
pub use address_rules::AddressRules;
pub use eeprom::{EepromWrites, Region, SaveTime, WriteDuringSave};

/// The alarm history 2A00h (newest) to 2A0Fh (oldest) (MR-JE-C manual §7.3), cleared by
/// writing 1EA5h to 2A40h: the shared history (`device::alarm_history`) of MR-JE-C alarms.
pub type AlarmHistory = crate::device::alarm_history::AlarmHistory<Alarm>;
pub use refusal::Refusal;
pub use watchdog::{Timeouts, Transport};

/// The unit's own facts, which the manual leaves to the model and the motor (named
/// parameters of the emulator; defaults: an MR-JE-20C with an HG-KN23 class motor).
#[derive(Debug, Clone, PartialEq)]
pub struct MrJeCParams {
    /// Software version (objects, [Pr. PN10], 6502h, 60E3h).
    pub software: SoftwareVersion,
    /// Model name (1008h, 2D30h, SLMP 0101h), e.g. "MR-JE-20C".
    pub model: String,
    /// Model code of the SLMP model read; the manual gives none (0).
    pub model_code: u16,
    /// Hardware version (1009h), two characters.
    pub hardware_version: String,
    /// Software version text (100Ah), 16 characters.
    pub software_text: String,
    /// Serial number (2D33h).
    pub serial_number: String,
    /// Main circuit power on (statusword bit 4); servo-on needs it.
    pub main_power: bool,
    /// Rotary switch SW1/SW2 (00h: the station number is [Pr. PC70]; MR-JE-C manual §4.9.2).
    pub rotary_switch: u8,
    /// Encoder resolution, pulses per revolution (608Fh:1).
    pub encoder_resolution: u32,
    /// Rated speed, r/min (2D28h).
    pub rated_speed_rpm: u32,
    /// Maximum speed, r/min (6080h, 2D29h).
    pub max_speed_rpm: u32,
    /// Instantaneous permissible speed, 0.01 r/min (the range of 6081h, 6099h, 2D20h).
    pub permissible_speed: u32,
    /// Maximum torque, 0.1 % (6072h).
    pub max_torque: u16,
    /// The unit's MAC address (NodeSearch, IPAddressSet picks the drive by it).
    pub mac: cellrt_fieldbus::slmp::node_search::Mac,
    /// Vendor code in the NodeSearch response; the manual gives none (0).
    pub vendor_code: u16,
    /// Time the drive takes to process an SLMP request before it answers; the manual gives
    /// none (0: at once). A request whose monitoring timer is shorter gets no answer
    /// ([`cellrt_fieldbus::slmp::monitoring_timer_expires`]).
    pub slmp_processing_time: std::time::Duration,
    /// The motor and load under torque control (tq); the manual gives none.
    pub torque_plant: profile::TorquePlant,
    /// The cyclic link's RWw/RWr table (manual Table 2.2 or 2.3); Table 2.2 by default.
    pub link_layout: cyclic::LinkLayout,
    /// The position loop gain Kp of the motor model, rad/s (0: no droop): the motor follows
    /// the command as a first-order lag with time constant 1 / Kp, a constant speed leaving a
    /// droop of speed / Kp (`motion`). The network manual names the gain parameters ([Pr.
    /// PB06], [Pr. PB08]–[Pr. PB10], §7.5.8 C_RTCDP) without values, so this is an emulator
    /// parameter. Default 1000 rad/s (1 ms): stiffer than a tuned real axis, so a positioning
    /// settles within a few ms and the runtime's timing tests keep their margins.
    pub position_loop_gain: u32,
    /// How long Store parameters 1010h takes to write the EEPROM; the manual gives only "10
    /// seconds maximum" for saving all (§7.4.4). Default: 2 s for the parameters and 8 s for
    /// the point tables (sub 1: 10 s), our choice ([`SaveTime`]).
    pub eeprom_save_time: SaveTime,
    /// What a parameter or point-table write does while a save runs (the manual is silent):
    /// accepted into the RAM by default ([`WriteDuringSave`]).
    pub write_during_save: WriteDuringSave,
    /// Motor motion a one-touch tuning takes to complete (`tuning`; the manual gives no
    /// duration). Default 5 s, our choice.
    pub one_touch_tuning_time: Duration,
}

impl Default for MrJeCParams {
    fn default() -> Self {
        MrJeCParams {
            software: SoftwareVersion::A4,
            model: "MR-JE-20C".into(),
            model_code: 0,
            hardware_version: "A".into(),
            software_text: " BCD-B46W750 A4 ".into(),
            serial_number: "123456789012".into(),
            main_power: true,
            rotary_switch: 0,
            encoder_resolution: 131_072,
            rated_speed_rpm: 3000,
            max_speed_rpm: 6000,
            permissible_speed: 690_000,
            max_torque: 3000,
            mac: cellrt_fieldbus::slmp::node_search::Mac([0x02, 0x00, 0xC0, 0xA8, 0x03, 0x00]),
            vendor_code: 0,
            slmp_processing_time: Duration::ZERO,
            torque_plant: profile::TorquePlant::default(),
            link_layout: cyclic::LinkLayout::default(),
            position_loop_gain: 1000,
            eeprom_save_time: SaveTime::default(),
            write_during_save: WriteDuringSave::default(),
            one_touch_tuning_time: Duration::from_secs(5),
        }
    }
}

/// The MR-JE-C's PDS: no shortcuts; option code 2 ends every quick stop in Switch on disabled.
const QUIRKS: FsaQuirks = FsaQuirks {
    shortcut_transitions: false,
    has_quick_stop: true,
    quick_stop_returns_to_enabled: false,
    quick_stop_options_5_to_8: false,
};

/// The value that resets (2A46h), clears the history (2A40h) and clears counters.
const KEY: i64 = 0x1EA5;
/// 2A68h: RS-485 frames with a CRC or frame length error (SW A4+, §7.5.4).
const COMMUNICATION_ERROR_COUNT: u16 = 0x2A68;
/// 2B01h: the encoder's pulses since power-on or the last clear (§7.3; OV-19).
const CUMULATIVE_FEEDBACK_PULSES: u16 = 0x2B01;

/// A simulated MR-JE-C.
#[derive(Debug, Clone)]
pub struct MrJeC {
    params: MrJeCParams,
    store: store::Store,
    /// The parameters and point tables as last saved (§7.2, §7.4.4).
    eeprom: eeprom::Eeprom,
    /// When the power came on (S_BWNG's power-on time, 2D11h bit 15).
    powered_on: Duration,
    state: FsaState,
    last_cw: Controlword,
    alarm: Option<Alarm>,
    history: AlarmHistory,
    watchdog: watchdog::CommWatchdog,
    cyclic_ready: bool,
    rules: AddressRules,
    keep_alive: KeepAlive,
    restore: Restore,
    motion: motion::Motion,
    /// How long the mode's Target reached window has held (bit 10, §7.3 6068h, 606Eh).
    target_window: Held,
    /// How long the speed has been over Velocity threshold 606Fh (pv bit 12, §7.3 6070h).
    over_threshold: Held,
    /// How long the droop has been over Following error window 6065h (bit 13, §7.3 6066h).
    following: Held,
    /// [`MrJeC::feedback_pulses`] at the last clear of 2B01h (0 from power-on).
    feedback_cleared: i64,
    /// One-touch tuning (2D50h–2D54h).
    tuning: tuning::OneTouchTuning,
    now: Duration,
}

/// The TCP alive check of a Modbus/TCP connection ([Pr. PN23], MR-JE-C manual §5.2.3): a
/// Keep Alive message every `interval` while the peer is silent, and the connection forcibly
/// closed when [`KEEP_ALIVE_UNANSWERED`] of them in a row go unanswered (3600 s × 8 = 28800 s
/// by default). Only Modbus/TCP uses it ("can be used only when Modbus/TCP is set").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KeepAlive {
    /// [Pr. PN23]: the idle time before the first alive check and between the checks.
    pub interval: Duration,
}

/// Unanswered alive checks after which the drive closes the connection. The manual gives the
/// total ("setting value × 8 times"), not how the checks are spaced: the first check follows
/// [Pr. PN23] of silence and the connection closes at the 7th unanswered repeat, 8 × [Pr. PN23]
/// after the peer's last segment.
pub const KEEP_ALIVE_UNANSWERED: u32 = 7;

impl KeepAlive {
    fn latch(store: &store::Store) -> KeepAlive {
        let secs = store.int(ObjectId::new(PN23.index(), 0)).clamp(1, 7200);
        KeepAlive {
            interval: Duration::from_secs(secs as u64),
        }
    }

    /// Time from the peer's last segment until the drive closes the connection.
    pub fn close_after(self) -> Duration {
        self.interval * (KEEP_ALIVE_UNANSWERED + 1)
    }
}

/// What a 1011h "load" asked to restore at the next power-on.
#[derive(Debug, Clone, Copy, Default)]
struct Restore {
    parameters: bool,
    point_tables: bool,
}

use cellrt_cia402::statusword::TARGET_REACHED;

/// The modes whose Statusword bit 10 and 13 judge the droop (§7.3 6065h, 6067h): pp, jg, pt,
/// idx.
fn following_error_judged(mode: i64) -> bool {
    matches!(
        mode,
        profile::PROFILE_POSITION | profile::JOG | profile::POINT_TABLE | profile::INDEXER
    )
}

/// "load" (64616F6Ch) written to 1011h.
const LOAD: i64 = 0x6461_6F6C;
/// "save" (65766173h) written to 1010h (§7.4.4).
pub const SAVE: i64 = 0x6576_6173;

/// Status DO 1 (2D11h) bit 1 S_ERF, EEPROM write completed (§7.5.9).
pub const S_ERF: u16 = 1 << 1;
/// Status DO 1 (2D11h) bit 3 S_MBR, electromagnetic brake interlock (§7.5.9).
pub const S_MBR: u16 = 1 << 3;
/// Status DO 1 (2D11h) bit 8 S_TL1, internal torque limit selection (§7.5.9).
pub const S_TL1: u16 = 1 << 8;
/// Status DO 1 (2D11h) bit 15 S_BWNG, battery warning (§7.5.9).
pub const S_BWNG: u16 = 1 << 15;
/// How long S_BWNG stays on after power-on without a battery warning: the manual gives 2.5 s
/// to 3.5 s (§7.5.9); the middle is our choice.
pub const S_BWNG_AT_POWER_ON: Duration = Duration::from_secs(3);

impl MrJeC {
    /// The drive after power-on, in Switch on disabled; the response mapping 1A00h is its link
    /// layout's default ([`cyclic::LinkLayout::default_mapping`]), as after every power-on
    /// (§7.4.6).
    pub fn new(params: MrJeCParams) -> MrJeC {
        let mut store = store::Store::new(&params);
        let mapping = params.link_layout.default_mapping();
        store.set(ObjectId::new(0x1A00, 0), Value::U8(mapping.len() as u8));
        for (k, entry) in mapping.iter().enumerate() {
            store.set(ObjectId::new(0x1A00, k as u8 + 1), Value::U32(*entry));
        }
        MrJeC {
            rules: AddressRules::latch(&store),
            keep_alive: KeepAlive::latch(&store),
            eeprom: eeprom::Eeprom::factory(&store),
            powered_on: Duration::ZERO,
            store,
            cyclic_ready: false,
            restore: Restore::default(),
            motion: motion::Motion::default(),
            target_window: Held::always(),
            over_threshold: Held::default(),
            following: Held::default(),
            feedback_cleared: 0,
            tuning: tuning::OneTouchTuning::default(),
            params,
            state: FsaState::SwitchOnDisabled,
            last_cw: Controlword(0),
            alarm: None,
            history: AlarmHistory::default(),
            watchdog: Default::default(),
            now: Duration::ZERO,
        }
    }

    /// A drive on an RS-485 line: [Pr. PN08] set to RS-485, station `station` by [Pr. PC70]
    /// (rotary switch 00h), MR-JE-C manual §4.9.2, §5.2.3.
    pub fn on_rs485_line(params: MrJeCParams, station: u8) -> MrJeC {
        let mut d = MrJeC::new(MrJeCParams {
            rotary_switch: 0,
            ..params
        });
        // Both values are in range, so the writes cannot be refused.
        let _ = d.commission(
            ObjectId::new(PN08.index(), 0),
            &Value::U32(0x1000),
            Duration::ZERO,
        );
        let _ = d.commission(
            ObjectId::new(PC70.index(), 0),
            &Value::U32(u32::from(station)),
            Duration::ZERO,
        );
        d
    }

    /// Cycles the power: the parameters and point tables are loaded from the EEPROM ("the
    /// value saved in the EEP-ROM is set to the object at the next power-on", §7.4.4), so a
    /// change not saved by 1010h is lost, and so is a save still running (our choice; the
    /// manual only says not to cut the power then). Everything else starts over (state,
    /// alarm, 1A00h mapping, time-outs), and the `*` parameters of the IP rules take effect.
    /// The history is kept (EEPROM, §7.3). The clock goes on.
    ///
    /// A restore written to 1011h before ("load", §7.4.5) writes the factory values of the
    /// parameters (sub 1, 4) and the point tables (sub 1, 5) into the EEPROM first.
    pub fn power_cycle(&mut self) {
        let mut fresh = MrJeC::new(self.params.clone());
        let mut eeprom = self.eeprom.clone();
        eeprom.advance(self.now);
        eeprom.power_off();
        let restored: Vec<Region> = [
            (self.restore.parameters, Region::Parameters),
            (self.restore.point_tables, Region::PointTables),
        ]
        .into_iter()
        .filter_map(|(asked, r)| asked.then_some(r))
        .filter(|r| self.has(*r))
        .collect();
        eeprom.restore(&fresh.store, &restored);
        eeprom.load(&mut fresh.store);
        fresh.eeprom = eeprom;
        fresh.powered_on = self.now;
        fresh.rules = AddressRules::latch(&fresh.store);
        fresh.keep_alive = KeepAlive::latch(&fresh.store);
        fresh.history = std::mem::take(&mut self.history);
        fresh.now = self.now;
        *self = fresh;
    }

    /// Whether the software has `region` (point tables: SW A4+, §7.3).
    fn has(&self, region: Region) -> bool {
        region == Region::Parameters || self.params.software >= SoftwareVersion::A4
    }

    /// Writes `value` to `id` at `now` as commissioning does (MR Configurator2 or the drive's
    /// own display): checked like an object write, then stored in the EEPROM at once as well
    /// (for a linked object: its parameters), so it survives a power cycle without 1010h.
    /// Each such write counts in [`MrJeC::eeprom_writes`] ("write to the EEPROM due to
    /// parameter setting changes", manual front matter "EEPROM life").
    pub fn commission(
        &mut self,
        id: ObjectId,
        value: &Value,
        now: Duration,
    ) -> Result<(), Refusal> {
        self.write(id, value, now)?;
        let mut ids = vec![id];
        if let Some(link) = cellrt_fieldbus::mr_je_c::links::of_object(id) {
            ids.extend(
                link.held()
                    .into_iter()
                    .flatten()
                    .map(|p| ObjectId::new(p.index(), 0)),
            );
        }
        for id in ids {
            if let (Some(_), Some(v)) = (eeprom::Region::of(id.index), self.store.get(id)) {
                self.eeprom.write(id, v.clone());
            }
        }
        Ok(())
    }

    /// The EEPROM writes so far (saves, commissioning, restores). The manual gives no object
    /// for it and no consequence of its 100 000-write life: for tests, not on any transport.
    pub fn eeprom_writes(&self) -> EepromWrites {
        self.eeprom.writes()
    }

    /// Whether Store parameters 1010h is writing the EEPROM (1010h bit 0 = 0, S_ERF off).
    pub fn saving(&self) -> bool {
        self.eeprom.saving(self.now)
    }

    /// Counts an RS-485 frame with a CRC or frame length error, or with parity or framing
    /// errors, in 2A68h (SW A4+; saturates; §7.5.4).
    pub fn count_rtu_error(&mut self) {
        if self.params.software < SoftwareVersion::A4 {
            return;
        }
        let id = ObjectId::new(COMMUNICATION_ERROR_COUNT, 0);
        let n = self.store.int(id) as u16;
        self.store.set(id, Value::U16(n.saturating_add(1)));
    }

    /// Leaves a Modbus access' trace in the diagnostic objects (§7.5.1–§7.5.2; SW A3+):
    /// 2A60h the abort code (0: none), 2A64h the last object accessed with success (index,
    /// last sub-index), 2A65h how many objects were.
    pub fn note_modbus_access(&mut self, abort: u32, last: Option<(u16, u8)>, served: u16) {
        if self.params.software < SoftwareVersion::A3 {
            return;
        }
        self.store.set(ObjectId::new(0x2A60, 0), Value::U32(abort));
        if let Some((index, sub)) = last {
            let log = (u32::from(index) << 16) | u32::from(sub);
            self.store.set(ObjectId::new(0x2A64, 0), Value::U32(log));
        }
        self.store.set(ObjectId::new(0x2A65, 0), Value::U16(served));
    }

    /// The subnet mask of [Pr. PN15]–[Pr. PN18].
    pub fn subnet_mask(&self) -> std::net::Ipv4Addr {
        self.pn_octets(15)
    }

    /// The default gateway of [Pr. PN19]–[Pr. PN22].
    pub fn default_gateway(&self) -> std::net::Ipv4Addr {
        self.pn_octets(19)
    }

    /// An address kept one octet per parameter, [Pr. PN`first`] on.
    fn pn_octets(&self, first: u8) -> std::net::Ipv4Addr {
        let o = |k: u8| {
            let p = cellrt_fieldbus::mr_je_c::parameters::Parameter {
                group: cellrt_fieldbus::mr_je_c::parameters::Group::PN,
                number: first + k,
            };
            self.param(p.index()) as u8
        };
        std::net::Ipv4Addr::new(o(0), o(1), o(2), o(3))
    }

    /// The IP rules in effect (latched at power-on).
    pub fn address_rules(&self) -> AddressRules {
        self.rules
    }

    /// The Modbus/TCP alive check in effect ([Pr. PN23], latched at power-on).
    pub fn keep_alive(&self) -> KeepAlive {
        self.keep_alive
    }

    /// Its parameters.
    pub fn params(&self) -> &MrJeCParams {
        &self.params
    }

    /// The PDS state.
    pub fn state(&self) -> FsaState {
        self.state
    }

    /// The current alarm.
    pub fn alarm(&self) -> Option<Alarm> {
        self.alarm
    }

    /// The alarm history, newest first.
    pub fn history(&self) -> &AlarmHistory {
        &self.history
    }

    /// The statusword (MR-JE-C manual §7.6.1): bit 4 the main power, bit 9 left 0 (reserved in
    /// §7.6.1), bits 10, 12 and 13 from the motion in Operation enabled.
    pub fn statusword(&self) -> Statusword {
        let sw = Statusword::for_state_with_power(self.state, self.params.main_power).0 & !(1 << 9);
        let bits = if self.state == FsaState::OperationEnabled {
            self.timed(self.motion.status_bits(&self.profile(), self.halted()))
        } else {
            0
        };
        Statusword(sw | bits)
    }

    /// The motor's raw bits 10 and 12 with the mode's window times (§7.3 6068h, 606Eh, 6070h;
    /// "has elapsed": at least that long, 6070h "for longer than", [`PvModel::MR_JE_C`]), and bit
    /// 13 after the following error time-out 6066h in pp, jg, pt and idx. The times are the
    /// shared timer (`motion::window_time`), counted from when a condition was seen.
    fn timed(&self, raw: u16) -> u16 {
        let secs = |index: u16| self.store.int(ObjectId::new(index, 0)).max(0) as f64 / 1000.0;
        let mode = self.store.int(ObjectId::new(0x6061, 0));
        let window = match mode {
            _ if following_error_judged(mode) => secs(0x6068),
            profile::PROFILE_VELOCITY => {
                let zero = !self
                    .over_threshold
                    .exceeds(secs(0x6070), PvModel::MR_JE_C.threshold_time);
                let reached = self.target_window.at_least(secs(0x606E));
                let bit10 = if raw & TARGET_REACHED != 0 && reached {
                    TARGET_REACHED
                } else {
                    0
                };
                return bit10 | (u16::from(zero) << 12);
            }
            _ => return raw,
        };
        let error = self.following.at_least(secs(0x6066));
        let raw = raw | (u16::from(error) << 13);
        if self.target_window.at_least(window) {
            raw
        } else {
            raw & !TARGET_REACHED
        }
    }

    /// Droop pulses 2B03h: the droop in encoder pulses (608Fh:1 pulses per 6092h:1 pos units
    /// of a revolution, §7.3, §7.6.7).
    fn droop_pulses(&self) -> i64 {
        (self.motion.droop() * self.pulses_per_unit()).round() as i64
    }

    /// Encoder pulses per pos unit of the current mode.
    fn pulses_per_unit(&self) -> f64 {
        let per_rev = self.profile().units_per_rev.max(1) as f64;
        f64::from(self.params.encoder_resolution) / per_rev
    }

    /// The encoder's count since power-on, pulses (homing does not move it).
    fn feedback_pulses(&self) -> i64 {
        (self.motion.travel() * self.pulses_per_unit()).round() as i64
    }

    /// Whether the droop is over Following error window 6065h in a mode that judges it (pp,
    /// jg, pt, idx; 4294967295 turns it off, §7.3 6065h).
    fn following_error(&self) -> bool {
        let window = self.store.int(ObjectId::new(0x6065, 0));
        following_error_judged(self.store.int(ObjectId::new(0x6061, 0)))
            && window != i64::from(u32::MAX)
            && self.motion.droop().abs() > window as f64
    }

    /// Controlword bit 8 (Halt).
    fn halted(&self) -> bool {
        self.last_cw.0 & (1 << 8) != 0
    }

    /// The objects the motion reads.
    fn profile(&self) -> profile::Profile {
        let int = |index: u16, sub: u8| self.store.int(ObjectId::new(index, sub));
        let feed = int(0x6092, 1);
        let mode = int(0x6061, 0);
        let c_rt = int(0x2D08, 0) & (indexer::C_RT | indexer::C_RTCDP) != 0;
        let max_torque = i64::from(self.params.max_torque);
        let max_speed = i64::from(self.params.max_speed_rpm) * 100;
        profile::Profile {
            mode,
            target_position: int(0x607A, 0),
            target_velocity: int(0x60FF, 0),
            profile_velocity: int(0x6081, 0).min(int(0x607F, 0)),
            acceleration_ms: int(0x6083, 0),
            deceleration_ms: int(0x6084, 0),
            rated_speed: i64::from(self.params.rated_speed_rpm) * 100,
            max_speed,
            units_per_rev: match (mode, feed) {
                (profile::INDEXER, _) => indexer::stations(int(PT28.index(), 0)),
                (_, f) if f > 0 => f,
                _ => i64::from(self.params.encoder_resolution),
            },
            position_window: int(0x6067, 0),
            velocity_window: int(0x606D, 0),
            homing_method: int(0x6098, 0),
            homing_acceleration_ms: int(0x609A, 0),
            homing_speed: int(0x6099, 1),
            home_offset: int(0x607C, 0),
            target_torque: int(0x6071, 0),
            torque_slope: int(0x6087, 0),
            positive_torque_limit: int(0x60E0, 0).min(max_torque),
            negative_torque_limit: int(0x60E1, 0).min(max_torque),
            velocity_limit: int(0x2D20, 0),
            plant: self.params.torque_plant,
            point: self.target_point(),
            indexer_station: int(0x2D60, 0),
            indexer_ramp: if c_rt {
                profile::Ramp {
                    acceleration_ms: int(PC30.index(), 0),
                    deceleration_ms: int(PC31.index(), 0),
                }
            } else {
                profile::Ramp {
                    acceleration_ms: int(0x6083, 0),
                    deceleration_ms: int(0x6084, 0),
                }
            },
            s_pattern_ms: int(PC03.index(), 0),
            position_loop_gain: f64::from(self.params.position_loop_gain),
        }
    }

    /// What Target point table 2D60h selects, with 2DD1h's speed and ramps (§7.3).
    fn target_point(&self) -> profile::Target {
        let int = |index: u16, sub: u8| self.store.int(ObjectId::new(index, sub));
        let number = int(0x2D60, 0);
        let table = |n: i64| 0x2800 + n as u16;
        match number {
            point_table::HIGH_SPEED_HOME_RETURN => profile::Target::HomeReturn,
            1..=255 => {
                let speed_no = match int(0x2DD1, 0) {
                    n @ 1..=255 => n,
                    _ => number,
                };
                let (t, s) = (table(number), table(speed_no));
                profile::Target::Table(profile::PointTable {
                    number,
                    position: int(t, 1),
                    speed: int(s, 2),
                    ramp: profile::Ramp {
                        acceleration_ms: int(s, 3),
                        deceleration_ms: int(s, 4),
                    },
                    m_code: int(t, 7),
                })
            }
            _ => profile::Target::None,
        }
    }

    /// Status DO 1 (2D11h), 2 (2D12h) and 5 (2D15h), MR-JE-C manual §7.5.9: 2D11h as
    /// [`MrJeC::status_do1`] gives it, and the home position return completion bits S_ZP2
    /// (2D12h bit 15) and S_ZP (2D15h bit 7, SW A4+; off at servo-off and alarm in the
    /// incremental system).
    fn status_do(&self, index: u16) -> Option<i64> {
        let stored = self.store.int(ObjectId::new(index, 0));
        let homed = self.motion.homed();
        match index {
            0x2D11 => Some(i64::from(self.status_do1())),
            0x2D12 => Some((stored & !(1 << 15)) | (i64::from(homed) << 15)),
            0x2D15 if self.params.software >= SoftwareVersion::A4 => {
                let on = homed && self.state == FsaState::OperationEnabled && self.alarm.is_none();
                Some((stored & !(1 << 7)) | (i64::from(on) << 7))
            }
            _ => None,
        }
    }

    /// Status DO 1 (2D11h, MR-JE-C manual §7.5.9 (1)), the bits the emulator knows:
    /// - bit 1 S_ERF: on when the EEPROM is not being written, off while 1010h saves;
    /// - bit 3 S_MBR: off at servo-off or alarm, so on in Operation enabled and Quick stop
    ///   active without an alarm ([Pr. PC16]'s brake sequence delay, initial 0 ms, not
    ///   emulated);
    /// - bit 8 S_TL1: on while C_TL1 (Control DI 1, 2D01h bit 8) is on (the TL1 input is not
    ///   emulated);
    /// - bit 15 S_BWNG: no battery warning is emulated, so on only until
    ///   [`S_BWNG_AT_POWER_ON`] after power-on ("turns off in 2.5 s to 3.5 s").
    ///
    /// Left 0: S_SA (its set speed belongs to the I/O modes' ST1/ST2 start), S_CDPS (gain
    /// switching by [Pr. PB26], a companion manual's), S_TL (the TL input), S_INP (the
    /// in-position range [Pr. PA10] is a companion manual's), S_TLC (no torque model outside
    /// tq), S_ABSV (the emulated encoder is incremental, 2D35h:1 = 0); bits 0, 5, 6, 9–11 are
    /// undefined and read 0.
    pub fn status_do1(&self) -> u16 {
        let servo_on = matches!(
            self.state,
            FsaState::OperationEnabled | FsaState::QuickStopActive
        );
        let c_tl1 = self.store.int(ObjectId::new(0x2D01, 0)) & (1 << 8) != 0;
        let since_power_on = self.now.saturating_sub(self.powered_on);
        [
            (S_ERF, !self.saving()),
            (S_MBR, servo_on && self.alarm.is_none()),
            (S_TL1, c_tl1),
            (S_BWNG, since_power_on < S_BWNG_AT_POWER_ON),
        ]
        .into_iter()
        .filter(|(_, on)| *on)
        .fold(0, |word, (bit, _)| word | bit)
    }

    /// Whether `t` is served: [Pr. PN08] digit x___ picks Ethernet (0) or RS-485 (1); the
    /// other side is silent (§5.2.3).
    pub fn serves(&self, t: Transport) -> bool {
        let rs485 = (self.param(PN08.index()) >> 12) & 0xF == 1;
        rs485 == (t == Transport::ModbusRtu)
    }

    /// The character format of the drive's RS-485 port: the bit rate of [Pr. PC71] digit
    /// `__x_` and the parity and stop bits of [Pr. PF45] digit `___x` (MR-JE-C manual §4.4,
    /// §5.2); `None` for a setting the manual does not define.
    pub fn rtu_line(&self) -> Option<LineSettings> {
        let baud =
            cellrt_fieldbus::modbus::serial::baud_from_pc71((self.param(PC71.index()) >> 4) & 0xF)?;
        let framing = Framing::from_pf45(self.param(PF45.index()) & 0xF)?;
        LineSettings::new(baud, framing).ok()
    }

    /// Sets [Pr. PC71] digit `__x_` and [Pr. PF45] digit `___x` to `line`'s character format
    /// (the other digits kept), as commissioning does for the line the drive is wired to.
    pub fn set_rtu_line(&mut self, line: &LineSettings) {
        let digit = cellrt_fieldbus::modbus::serial::pc71_digit(line.baud).unwrap_or(4);
        let pc71 = (self.param(PC71.index()) & !0xF0) | digit << 4;
        let pf45 = (self.param(PF45.index()) & !0xF) | line.framing.pf45_digit();
        for (p, v) in [(PC71, pc71), (PF45, pf45)] {
            let value = Value::U32(u32::try_from(v).unwrap_or(0));
            // In range (no range in the table): cannot be refused.
            let _ = self.commission(ObjectId::new(p.index(), 0), &value, self.now);
        }
    }

    /// The Modbus RTU station number: the rotary switch, or [Pr. PC70] when it is 00h; 0 never
    /// answers (§4.9.2).
    pub fn station(&self) -> u8 {
        match self.params.rotary_switch {
            0 => self.param(PC70.index()) as u8,
            s => s,
        }
    }

    fn param(&self, index: u16) -> i64 {
        self.store.int(ObjectId::new(index, 0))
    }

    /// The time-outs in effect: [Pr. PN02] ms, [Pr. PN10] s (SW A4+ only), [Pr. PF46] s.
    pub fn timeouts(&self) -> Timeouts {
        let secs = |index| Duration::from_secs(self.param(index).max(0) as u64);
        Timeouts {
            cclink: Duration::from_millis(self.param(PN02.index()).max(0) as u64),
            ethernet: if self.params.software >= SoftwareVersion::A4 {
                secs(PN10.index())
            } else {
                Duration::ZERO
            },
            rtu: secs(PF46.index()),
        }
    }

    /// A message of `t` arrived at `now` (feeds its time-out).
    pub fn received(&mut self, t: Transport, now: Duration) {
        self.tick(now);
        self.watchdog.received(t, now);
    }

    /// Advances the virtual clock to `now`: time-outs expire, a quick stop ends.
    pub fn tick(&mut self, now: Duration) {
        let dt = now.saturating_sub(self.now);
        self.now = self.now.max(now);
        self.eeprom.advance(self.now);
        match self.state {
            FsaState::OperationEnabled => {
                let p = self.profile();
                self.motion.advance(dt, &p, self.halted());
                let raw = self.motion.status_bits(&p, self.halted());
                let over =
                    self.motion.velocity(&p).abs() > self.store.int(ObjectId::new(0x606F, 0));
                let secs = dt.as_secs_f64();
                self.target_window
                    .update(raw & TARGET_REACHED != 0, secs, HeldFrom::Seen);
                self.over_threshold.update(over, secs, HeldFrom::Seen);
                let following = self.following_error();
                self.following.update(following, secs, HeldFrom::Seen);
                let moving = self.motion.velocity(&p) != 0;
                self.tuning
                    .advance(dt, moving, self.params.one_touch_tuning_time);
            }
            // Option code 2: decelerate with 6085h, then Switch on disabled (§7.6.2).
            FsaState::QuickStopActive => {
                let stopped =
                    self.motion
                        .quick_stop(dt, &self.profile(), self.quick_stop_deceleration_ms());
                // Option code 2 only: the stop ends in Switch on disabled.
                self.state = end_of_stop(self.state, stopped, false);
                if self.state != FsaState::QuickStopActive {
                    self.motion.stand();
                }
            }
            _ => self.motion.stand(),
        }
        if self.state != FsaState::OperationEnabled {
            self.tuning.servo_off();
            // The motor stands where it is: within every window all along (Target reached at
            // once when enabled), under the threshold, no following error.
            self.target_window = Held::always();
            self.over_threshold.clear();
            self.following.clear();
        }
        if let Some(alarm) = self.watchdog.expired(self.now, &self.timeouts()) {
            self.raise(alarm);
        }
    }

    /// 6085h as the drive takes it: "0" runs at 100 ms, the setting is limited to 0–20000 ms
    /// (§7.3 6085h).
    fn quick_stop_deceleration_ms(&self) -> i64 {
        match self.store.int(ObjectId::new(0x6085, 0)) {
            0 => 100,
            ms => ms.min(20_000),
        }
    }

    /// Raises `alarm`: Fault (through Fault reaction active), 1001h bit 0, 603Fh 1000h, the
    /// current alarm objects and a history entry (§7.3, §7.6.1).
    pub fn raise(&mut self, alarm: Alarm) {
        if self.alarm.is_some() {
            return;
        }
        self.alarm = Some(alarm);
        self.state = FaultReaction::Immediate.on_alarm(self.state);
        self.history
            .record(alarm, (self.now.as_secs() / 3600) as u32);
    }

    /// Resets the alarm (Controlword bit 7 edge, 2A46h = 1EA5h): Switch on disabled, and the
    /// time-outs wait for the next message.
    fn reset(&mut self) {
        if self.alarm.take().is_some() {
            self.state = FsaState::SwitchOnDisabled;
            self.watchdog.disarm();
        }
    }

    /// SSR (RX(n+3)F): the cyclic link imports RWw; the response mapping is locked.
    pub fn set_cyclic_ready(&mut self, on: bool) {
        self.cyclic_ready = on;
    }

    /// Whether SSR is on.
    pub fn cyclic_ready(&self) -> bool {
        self.cyclic_ready
    }

    /// The response mapping: 1A00h:1 to 1A00h:(1A00h:0).
    pub fn mapping(&self) -> Vec<u32> {
        let n = self.store.int(ObjectId::new(0x1A00, 0)).clamp(0, 32) as u8;
        (1..=n)
            .map(|k| self.store.int(ObjectId::new(0x1A00, k)) as u32)
            .collect()
    }

    /// The rules of a 1A00h write `v` to sub-index `sub` (§7.4.6 (2), §2.4.5): locked while SSR
    /// is on; a non-zero entry count needs mappable entries of at most 64 bytes in all.
    fn check_mapping(&self, sub: u8, v: i64) -> Result<(), Refusal> {
        if self.cyclic_ready {
            return Err(Refusal::MappingLocked);
        }
        if sub != 0 || v == 0 {
            return Ok(());
        }
        let sw = self.params.software;
        let mut bytes = 0;
        for k in 1..=v.clamp(0, 32) as u8 {
            let e = self.store.int(ObjectId::new(0x1A00, k)) as u32;
            let id = ObjectId::new((e >> 16) as u16, (e >> 8) as u8);
            let bits = (e & 0xFF) as usize;
            let fits = id.index == 0
                || cellrt_fieldbus::mr_je_c::objects::entry(id, sw)
                    .is_some_and(|(_, r)| r.mappable && r.ty.bytes() * 8 == bits);
            if !fits {
                return Err(Refusal::NotMappable);
            }
            bytes += bits / 8;
        }
        if bytes > 64 {
            return Err(Refusal::MappingTooLarge);
        }
        Ok(())
    }

    /// Reads `id`.
    pub fn read(&self, id: ObjectId) -> Result<Value, Refusal> {
        let row = store::readable(id, self.params.software)?;
        let live = |v: i64| Value::from_i64(row.ty, v);
        let alarm = self.alarm;
        let value = match (id.index, id.sub) {
            (0x6041, 0) => live(i64::from(self.statusword().0)),
            (0x6064, 0) => live(self.motion.position_in(&self.profile())),
            (0x606C, 0) => live(self.motion.velocity(&self.profile())),
            (0x6092, 1) if self.store.int(ObjectId::new(0x6061, 0)) == profile::INDEXER => {
                live(self.profile().units_per_rev)
            }
            (0x60F4, 0) => live(self.motion.droop().round() as i64),
            (0x2B03, 0) => live(self.droop_pulses()),
            (0x2D50, 0) => live(i64::from(self.tuning.mode())),
            (0x2D51, 0) => live(i64::from(self.tuning.progress())),
            (0x2D54, 0) => live(i64::from(self.tuning.error() as i16)),
            // Wraps like the drive's 32-bit counter.
            (CUMULATIVE_FEEDBACK_PULSES, 0) => live(i64::from(
                self.feedback_pulses().wrapping_sub(self.feedback_cleared) as i32,
            )),
            (0x6074, 0) => live(self.motion.torque().demand()),
            (0x6077, 0) => live(self.motion.torque().actual()),
            (0x2D11 | 0x2D12 | 0x2D15, 0) => self.status_do(id.index).and_then(live),
            // Bit 0: 1 "can save now", 0 "a parameter is being saved"; bit 1: 0 "not saved
            // automatically" (§7.4.4).
            (0x1010, 1 | 4 | 5) => live(i64::from(!self.saving())),
            (0x2D68, 0) => {
                let selected = self.store.int(ObjectId::new(0x2D60, 0));
                live(self.motion.point_table().demand(selected))
            }
            (0x2D69, 0) => live(self.motion.point_table().actual()),
            (0x2D6A, 0) => live(self.motion.point_table().m_code()),
            (0x1001, 0) => live(i64::from(alarm.is_some())),
            (0x603F, 0) => live(if alarm.is_some() { 0x1000 } else { 0 }),
            (0x2A41, 0) => live(alarm.map_or(0, |a| i64::from(a.current()))),
            (0x2A42, 0) => live(alarm.map_or(0, |a| i64::from(a.current2()))),
            (0x2A00..=0x2A0F, 1..=3) => {
                let o = self.history.get(usize::from(id.index - 0x2A00));
                live(o.map_or(0, |o| match id.sub {
                    1 => i64::from(o.alarm.current()),
                    2 => i64::from(o.hours),
                    _ => i64::from(o.alarm.current2()),
                }))
            }
            (0x2C18, 0) => live((self.now.as_secs() / 3600) as i64),
            _ => None,
        };
        Ok(value
            .or_else(|| self.store.get(id).cloned())
            .unwrap_or(Value::U8(0)))
    }

    /// Writes `value` to `id` at `now`.
    pub fn write(&mut self, id: ObjectId, value: &Value, now: Duration) -> Result<(), Refusal> {
        let sw = self.params.software;
        let row = store::writable(id, sw)?;
        if !value.is(row.ty) {
            return Err(if value.to_le().len() > row.ty.bytes() {
                Refusal::TooLarge
            } else {
                Refusal::TooSmall
            });
        }
        let v = value.as_i64().unwrap_or(0);
        let fixed = row.initial.value(sw).unwrap_or(0);
        store::in_range(id, row, v, fixed, i64::from(self.params.permissible_speed))?;
        if id.index == 0x1A00 {
            self.check_mapping(id.sub, v)?;
        }
        // The RTU communication error count (§7.5.4) and the cumulative feedback pulses (§7.3
        // 2B01h) are only cleared (1EA5h); the manual gives no meaning to other values, so the
        // emulator refuses them.
        if matches!(
            id.index,
            COMMUNICATION_ERROR_COUNT | CUMULATIVE_FEEDBACK_PULSES
        ) && v != KEY
        {
            return Err(Refusal::OutOfRange);
        }
        self.check_linked_parameter(id, v)?;
        self.check_saving(id, v, now)?;
        self.tick(now);
        self.store.set(id, value.clone());
        self.effects(id, v);
        Ok(())
    }

    /// A parameter linked to an object (§7.3 "Parameter" column) takes only what its object
    /// can hold: the object's type and range, and a word of a split value 0000h–FFFFh.
    fn check_linked_parameter(&self, id: ObjectId, v: i64) -> Result<(), Refusal> {
        if id.sub != 0 {
            return Ok(());
        }
        let sw = self.params.software;
        let permissible = i64::from(self.params.permissible_speed);
        for link in cellrt_fieldbus::mr_je_c::links::of_parameter(id.index) {
            let Ok(row) = store::row(link.object, sw) else {
                continue;
            };
            if !link.parameter_fits(v as u32) {
                return Err(Refusal::AboveRange);
            }
            let param = |p: cellrt_fieldbus::mr_je_c::parameters::Parameter| {
                if p.index() == id.index {
                    v as u32
                } else {
                    self.param(p.index()) as u32
                }
            };
            let Some(x) = link.object_value(sw, param) else {
                continue;
            };
            let fixed = row.initial.value(sw).unwrap_or(0);
            store::in_range(link.object, row, x, fixed, permissible)?;
            if let Some((lo, hi)) = row.ty.value_range() {
                if x < lo {
                    return Err(Refusal::BelowRange);
                }
                if x > hi {
                    return Err(Refusal::AboveRange);
                }
            }
        }
        Ok(())
    }

    /// The writes a running save refuses (1010h bit 0 = 0, §7.4.4): another "save" ("the
    /// parameter cannot be saved with the command"), and with [`WriteDuringSave::Refuse`]
    /// the parameters, point tables and the objects linked to parameters.
    fn check_saving(&self, id: ObjectId, v: i64, now: Duration) -> Result<(), Refusal> {
        if !self.eeprom.saving(now) {
            return Ok(());
        }
        let save = id.index == 0x1010 && v == SAVE && !Region::saved_by(id.sub).is_empty();
        let backed = Region::of(id.index).is_some()
            || cellrt_fieldbus::mr_je_c::links::of_object(id)
                .is_some_and(|l| l.held()[0].is_some());
        let refuse_writes = self.params.write_during_save == WriteDuringSave::Refuse;
        if save || (refuse_writes && backed) {
            Err(Refusal::Saving)
        } else {
            Ok(())
        }
    }

    /// Writes the SLMP bytes `data` to `id` (size checked after access, §2.4.5).
    pub fn write_le(&mut self, id: ObjectId, data: &[u8], now: Duration) -> Result<(), Refusal> {
        let row = store::writable(id, self.params.software)?;
        let value = match data.len().cmp(&row.ty.bytes()) {
            std::cmp::Ordering::Greater => return Err(Refusal::TooLarge),
            std::cmp::Ordering::Less => return Err(Refusal::TooSmall),
            std::cmp::Ordering::Equal => {
                Value::from_le(row.ty, data).ok_or(Refusal::SizeDiffers)?
            }
        };
        self.write(id, &value, now)
    }

    /// What a write does beyond storing the value.
    fn effects(&mut self, id: ObjectId, v: i64) {
        if matches!(id.index, 0x1010 | 0x1011) {
            // Both objects keep reading their status, bit 0 "can save now" (§7.4.4, §7.4.5);
            // 1010h's is live while a save runs (`read`).
            let sw = self.params.software;
            let status = store::row(id, sw).ok().and_then(|r| r.initial.value(sw));
            let status = status
                .and_then(|v| Value::from_i64(cellrt_fieldbus::mr_je_c::types::DataType::U32, v));
            if let Some(s) = status {
                self.store.set(id, s);
            }
            if id.index == 0x1010 && v == SAVE {
                self.save(id.sub);
            }
            if id.index == 0x1011 && v == LOAD {
                self.restore.parameters |= matches!(id.sub, 1 | 4);
                self.restore.point_tables |= matches!(id.sub, 1 | 5);
            }
            return;
        }
        match id.index {
            0x6040 => self.controlword(Controlword(v as u16)),
            0x6060 => self.mode(v),
            0x2A46 if v == KEY => self.reset(),
            0x2A40 if v == KEY => self.history.clear(),
            CUMULATIVE_FEEDBACK_PULSES if v == KEY => {
                self.feedback_cleared = self.feedback_pulses()
            }
            0x2D50 if (1..=3).contains(&v) => {
                let torque = self.store.int(ObjectId::new(0x6061, 0)) == profile::PROFILE_TORQUE;
                let on = self.state == FsaState::OperationEnabled;
                self.tuning.start(v as u8, on, torque);
            }
            0x2D52 if v == KEY => self.tuning.stop(),
            COMMUNICATION_ERROR_COUNT => self.store.set(id, Value::U16(0)),
            _ => {}
        }
    }

    /// Starts the save "save" written to 1010h sub-index `sub` asks for (§7.4.4 table): sub 1
    /// the parameters and point tables, 4 the parameters, 5 the point tables, 2 and 3
    /// nothing. It takes [`MrJeCParams::eeprom_save_time`] and stores the values of the moment
    /// it starts.
    fn save(&mut self, sub: u8) {
        let regions: Vec<Region> = Region::saved_by(sub)
            .iter()
            .copied()
            .filter(|r| self.has(*r))
            .collect();
        if regions.is_empty() {
            return;
        }
        let time = self.params.eeprom_save_time.of(&regions);
        self.eeprom.start(&self.store, &regions, self.now, time);
    }

    /// 6061h follows 6060h for the modes the software has (§2.2 of the extract, §7.3).
    fn mode(&mut self, v: i64) {
        let a4 = self.params.software >= SoftwareVersion::A4;
        let supported = matches!(v, 0 | 1 | 3 | 4 | 6 | -20 | -21 | -22)
            || (a4 && matches!(v, -100 | -101 | -103));
        let id = ObjectId::new(0x6061, 0);
        if supported && self.store.int(id) != v {
            let before = self.profile().units_per_rev;
            self.store.set(id, Value::I8(v as i8));
            self.motion.rescale(before, self.profile().units_per_rev);
            self.motion.mode_changed();
        }
    }

    fn controlword(&mut self, cw: Controlword) {
        let prev = std::mem::replace(&mut self.last_cw, cw);
        let next = match controlword_step(self.state, cw, prev, &QUIRKS) {
            ControlwordStep::FaultReset => {
                self.reset();
                return;
            }
            ControlwordStep::To(next) => next,
        };
        self.state = match next {
            // Servo-on needs the main circuit.
            FsaState::OperationEnabled if !self.params.main_power => self.state,
            // Option code 2 in tq: straight to Switch on disabled (dynamic brake, §7.6.2).
            FsaState::QuickStopActive
                if self.store.int(ObjectId::new(0x6061, 0)) == profile::PROFILE_TORQUE =>
            {
                FsaState::SwitchOnDisabled
            }
            s => s,
        };
        if self.state == FsaState::OperationEnabled {
            let p = self.profile();
            self.motion.controlword(cw, prev, &p);
            if self.motion.status_bits(&p, self.halted()) & TARGET_REACHED == 0 {
                // A new set-point or start took the motor out of the window between steps.
                self.target_window.clear();
            }
        } else if self.state != FsaState::QuickStopActive {
            self.motion.stand();
        }
    }
}
