//! The drive's parameter memory (MR-J3-T04 manual §8.10.1, §8.10.2): an SDO write goes to RAM
//! (the drive's object values), Store Parameter (1010h:01) copies RAM to the non-volatile
//! memory, a power cycle reloads RAM from it, and a parameter marked `*` acts with the value it
//! had at power-on. The write inhibit (PA19, manual §5.1) limits which groups are read and
//! written, by its value at power-on. Off the RT path: the SDO surface may allocate.

use super::SimDrive;
use crate::sim::sdo_abort::SdoAbort;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::params::{Derived, Effect, Parameter, SaveReadback};

/// Saved values and the `*` parameters' values at power-on, by object.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(super) struct ParameterMemory {
    /// The non-volatile memory; a parameter absent here holds the manual's initial value.
    saved: Vec<(u16, u8, i64)>,
    /// The values of the `*` parameters since the last power-on.
    at_power_on: Vec<(u16, u8, i64)>,
}

fn find(v: &[(u16, u8, i64)], p: &Parameter) -> Option<i64> {
    v.iter()
        .find(|(i, s, _)| (*i, *s) == (p.object.index, p.object.sub))
        .map(|e| e.2)
}

fn put(v: &mut Vec<(u16, u8, i64)>, p: &Parameter, value: i64) {
    let key = (p.object.index, p.object.sub);
    match v.iter_mut().find(|(i, s, _)| (*i, *s) == key) {
        Some(e) => e.2 = value,
        None => v.push((key.0, key.1, value)),
    }
}

impl SimDrive {
    /// The value of parameter `name` the drive acts with: the power-on value of a `*`
    /// parameter, the RAM value of the others; `None` for a name the model's table lacks.
    pub fn parameter_in_force(&self, name: &str) -> Option<i64> {
        let p = self.profile.parameters.parameter(name)?;
        Some(self.in_force(p))
    }

    fn in_force(&self, p: &Parameter) -> i64 {
        match p.effect() {
            Effect::AfterPowerCycle => find(&self.memory.at_power_on, p),
            Effect::Immediately => self.sdo_value(p.object.index, p.object.sub),
        }
        .or(p.object.default)
        .unwrap_or_default()
    }

    /// The communication parameters with PO02 and PO03 as in force since power-on (the
    /// configured ones until a saved change and a power cycle replace them), and the sync
    /// error counter limit the master wrote to 10F1h:02 (ETG.1020), where the model has it.
    pub(super) fn comm_in_force(&self) -> crate::sim::comm::CommParams {
        let mut c = self.params.comm;
        if let Some(v) = self.parameter_in_force("PO02") {
            c.po02 = v as u16;
        }
        if let Some(v) = self.parameter_in_force("PO03") {
            c.po03 = v as u16;
        }
        if let Some(v) = self.sdo_value(SYNC_ERROR_COUNTER_LIMIT.0, SYNC_ERROR_COUNTER_LIMIT.1) {
            c.sync_error_limit = v.clamp(0, i64::from(u16::MAX)) as u32;
        }
        c
    }

    /// The values held in the non-volatile memory at start: the manual's initial values, with
    /// the communication parameters the simulator is configured with (PO02, PO03).
    pub(super) fn seed_saved_parameters(&mut self) {
        let f = self.profile.parameters;
        let comm = self.params.comm;
        for (name, value) in [("PO02", comm.po02), ("PO03", comm.po03)] {
            if let Some(p) = f.parameter(name) {
                put(&mut self.memory.saved, p, i64::from(value));
            }
        }
    }

    /// Power-on: RAM reloads from the non-volatile memory and the `*` parameters take the
    /// saved values.
    pub(super) fn reload_parameters(&mut self) {
        self.memory.at_power_on.clear();
        for p in self.profile.parameters.table {
            let saved = find(&self.memory.saved, p);
            self.sdo_values
                .retain(|(i, s, _)| (*i, *s) != (p.object.index, p.object.sub));
            if let Some(v) = saved {
                self.store_sdo_value(p.object.index, p.object.sub, v);
                if p.effect() == Effect::AfterPowerCycle {
                    put(&mut self.memory.at_power_on, p, v);
                }
            }
        }
    }

    /// Store Parameter: every parameter's RAM value into the non-volatile memory; refused
    /// while the write inhibit limits writing to itself (the manual's 1010h read returns 0
    /// then; the abort code is not stated, the simulator answers 0800 0020h).
    pub(in crate::sim) fn save_parameters(&mut self, group: Option<u16>) -> Result<(), SdoAbort> {
        if !self.storable(group) {
            return Err(SdoAbort::CANNOT_STORE);
        }
        let rows = self.profile.parameters.table.iter();
        for p in rows.filter(|p| group.is_none_or(|g| p.object.index == g)) {
            if let Some(v) = self.sdo_value(p.object.index, p.object.sub) {
                put(&mut self.memory.saved, p, v);
            }
        }
        Ok(())
    }

    /// What a read of store sub-index `group`'s object returns on this model (1010h:01 for
    /// every parameter, `group` for one group).
    pub(in crate::sim) fn save_readback(&self, group: Option<u16>) -> i64 {
        match self.profile.parameters.save.map(|s| s.readback) {
            Ok(SaveReadback::Availability) => {
                if self.storable(group) {
                    3
                } else {
                    0
                }
            }
            _ => i64::from(!self.saving()),
        }
    }

    /// False while the write inhibit limits writing to itself or leaves `group` out.
    fn storable(&self, group: Option<u16>) -> bool {
        self.inhibit_access()
            .is_none_or(|(groups, only)| !only && group.is_none_or(|g| groups.contains(&g)))
    }

    /// What a write of the save signature to `index:sub` stores, if it is a store object:
    /// `Some(None)` every parameter, `Some(Some(group))` one group.
    pub(in crate::sim) fn store_target(&self, index: u16, sub: u8) -> Option<Option<u16>> {
        let s = self.profile.parameters.save.ok()?;
        if index != s.object.0 {
            return None;
        }
        s.stores(sub)
    }

    /// The write inhibit in force: (readable group objects, writing limited to itself).
    fn inhibit_access(&self) -> Option<(&'static [u16], bool)> {
        let w = self.profile.parameters.write_inhibit?;
        let p = self.profile.parameters.by_object(w.object.0, w.object.1)?;
        Some(w.access(self.in_force(p)))
    }

    /// Checks a read (`write` false) or write of parameter object `index:sub` against the write
    /// inhibit in force (MR-J3-T04 manual §8.10.1, §8.7: read outside the reference range →
    /// 0601 0000h, write outside the writing range → 0800 0020h).
    pub(in crate::sim) fn parameter_access(
        &self,
        index: u16,
        sub: u8,
        write: bool,
    ) -> Result<(), SdoAbort> {
        let (Some(w), Some((groups, only))) =
            (self.profile.parameters.write_inhibit, self.inhibit_access())
        else {
            return Ok(());
        };
        let grouped = w.settings.iter().any(|(_, g, _)| g.contains(&index));
        if !grouped {
            return Ok(());
        }
        let refused = !groups.contains(&index) || (write && only && (index, sub) != w.object);
        match (refused, write) {
            (false, _) => Ok(()),
            (true, false) => Err(SdoAbort::UNSUPPORTED_ACCESS),
            (true, true) => Err(SdoAbort::CANNOT_STORE),
        }
    }

    /// The value of a parameter the drive sets itself ([`Derived`]), if `index:sub` is one.
    pub(in crate::sim) fn derived_parameter(&self, index: u16, sub: u8) -> Option<i64> {
        let p = self.profile.parameters.by_object(index, sub)?;
        match p.derived? {
            Derived::ControlMode { position, velocity } => Some(match self.mode_display {
                ModeOfOperation::CyclicSyncVelocity | ModeOfOperation::ProfileVelocity => velocity,
                _ => position,
            }),
        }
    }

    /// Records alarm `code` in the history, where the model keeps one.
    pub(super) fn record_alarm(&mut self, code: u16) {
        if self.profile.parameters.alarm_history.is_ok() {
            let secs = self.cycle_time.as_secs_f64() * self.uptime_cycles as f64;
            self.history.record(code, (secs / 3600.0) as u32);
        }
    }

    /// The value of alarm history object `index:sub`; `None` where it is not one.
    pub(in crate::sim) fn history_value(&self, index: u16, sub: u8) -> Option<i64> {
        let facts = self.profile.parameters.alarm_history.ok()?;
        self.history.object_value(&facts, index, sub)
    }

    /// Clears the history if `index` is the model's clear object and `value` its clear code.
    pub(in crate::sim) fn clear_history(&mut self, index: u16, value: i64) -> bool {
        let Ok(facts) = self.profile.parameters.alarm_history else {
            return false;
        };
        let hit = (index, value) == (facts.clear.0, i64::from(facts.clear.1));
        if hit {
            self.history.clear();
        }
        hit
    }

    /// The alarm history, newest first (entry 0 = 2030h on the MR-J3-T04).
    pub fn alarm_history(&self) -> &super::alarm_history::AlarmHistory {
        &self.history
    }
}

/// 10F1h:02 Sync Error Counter Limit (ETG.1020; MR-JET/MR-J5 manual §2.4 name it beside PN18).
const SYNC_ERROR_COUNTER_LIMIT: (u16, u8) = (0x10F1, 2);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::drive::SimDriveParams;
    use cellrt_cia402::cycles::CycleTime;
    use cellrt_cia402::profiles::{mr_j3_t04, mr_jet_g_n1};

    fn j3() -> SimDrive {
        let ct = CycleTime::from_micros(1000).unwrap();
        SimDrive::new(&mr_j3_t04::PROFILE, SimDriveParams::default(), ct)
    }

    fn write(d: &mut SimDrive, index: u16, sub: u8, v: i32) -> Result<(), SdoAbort> {
        d.sdo_download(index, sub, &v.to_le_bytes())
    }

    fn save(d: &mut SimDrive) -> Result<(), SdoAbort> {
        write(d, 0x1010, 1, crate::sim::sdo::SAVE_SIGNATURE as i32)
    }

    #[test]
    fn a_star_parameter_acts_after_save_and_power_cycle_and_an_unsaved_one_is_lost() {
        let mut d = j3();
        // PA14 *POL: RAM at once, in force only after a power cycle of the saved value.
        assert_eq!(d.sdo_upload(0x2300, 14), Ok(0));
        write(&mut d, 0x2300, 14, 1).unwrap();
        assert_eq!(d.sdo_upload(0x2300, 14), Ok(1));
        assert_eq!(d.parameter_in_force("PA14"), Some(0));
        d.power_cycle();
        assert_eq!(d.sdo_upload(0x2300, 14), Ok(0), "not saved: lost");
        write(&mut d, 0x2300, 14, 1).unwrap();
        save(&mut d).unwrap();
        assert_eq!(d.parameter_in_force("PA14"), Some(0));
        d.power_cycle();
        assert_eq!(d.sdo_upload(0x2300, 14), Ok(1));
        assert_eq!(d.parameter_in_force("PA14"), Some(1));
        // PC02 STB (no *): in force at once.
        write(&mut d, 0x2302, 2, 500).unwrap();
        assert_eq!(d.parameter_in_force("PC02"), Some(500));
    }

    #[test]
    fn po02_and_po03_act_from_the_power_on_after_their_save() {
        // MR-J3-T04 manual §2.4: free-run (PO02 = 0001h) with the counter check on (PO03
        // digit 0 = 1) is AL.37 at power-on.
        let mut d = j3();
        write(&mut d, 0x2309, 2, 0x0001).unwrap();
        write(&mut d, 0x2309, 3, 0x0001).unwrap();
        d.power_cycle();
        assert_eq!(d.alarm(), None, "not saved: lost at the power cycle");
        write(&mut d, 0x2309, 2, 0x0001).unwrap();
        write(&mut d, 0x2309, 3, 0x0001).unwrap();
        save(&mut d).unwrap();
        assert_eq!(d.alarm(), None, "saved, not in force yet");
        d.power_cycle();
        assert_eq!(d.alarm(), Some(mr_j3_t04::AL_37));
        assert_eq!(d.sdo_upload(0x2030, 1), Ok(i64::from(mr_j3_t04::AL_37)));
    }

    #[test]
    fn a_group_store_saves_only_its_group() {
        // MR-J3-T04 manual §8.10.2: 1010h:05 stores PB, 1010h:06 PC.
        let mut d = j3();
        write(&mut d, 0x2301, 3, 100).unwrap();
        write(&mut d, 0x2302, 2, 300).unwrap();
        let sig = crate::sim::sdo::SAVE_SIGNATURE as i32;
        write(&mut d, 0x1010, 5, sig).unwrap();
        assert_eq!(write(&mut d, 0x1010, 6, 1), Err(SdoAbort::CANNOT_STORE));
        d.power_cycle();
        assert_eq!(d.sdo_upload(0x2301, 3), Ok(100), "PB stored");
        assert_eq!(d.sdo_upload(0x2302, 2), Ok(0), "PC not stored");
        // PA19 = 000Bh (PA, PB, PC): the PD and PO groups cannot be stored.
        write(&mut d, 0x2300, 19, 0x000B).unwrap();
        save(&mut d).unwrap();
        d.power_cycle();
        assert_eq!(d.sdo_upload(0x1010, 6), Ok(3));
        assert_eq!(d.sdo_upload(0x1010, 7), Ok(0));
        assert_eq!(write(&mut d, 0x1010, 13, sig), Err(SdoAbort::CANNOT_STORE));
    }

    #[test]
    fn pa01_follows_the_control_mode() {
        // MR-J3-T04 manual §5.1: 0 in csp and hm, 2 in csv (the mode comes from 6060h by SDO).
        let mut d = j3();
        assert_eq!(d.sdo_upload(0x2300, 1), Ok(0x0000));
        d.sdo_download(0x6060, 0, &[9]).unwrap();
        for _ in 0..5 {
            d.cycle_lost(
                &mut [0u8; 64][..d.profile().pdo.tx.byte_len()],
                cellrt_cia402::cycles::Cycles(1),
            )
            .unwrap();
        }
        assert_eq!(d.mode_display(), ModeOfOperation::CyclicSyncVelocity);
        assert_eq!(d.sdo_upload(0x2300, 1), Ok(0x0002));
    }

    #[test]
    fn the_drive_refuses_values_outside_the_manuals_setting() {
        let mut d = j3();
        assert_eq!(write(&mut d, 0x2301, 3, 20_001), Err(SdoAbort::VALUE_RANGE));
        assert_eq!(write(&mut d, 0x2309, 3, 0x0100), Err(SdoAbort::VALUE_RANGE));
        assert_eq!(d.sdo_upload(0x2309, 3), Ok(0), "nothing written");
        write(&mut d, 0x2309, 3, 0x0200).unwrap();
    }

    #[test]
    fn pa19_limits_reads_and_writes_from_the_next_power_on() {
        let mut d = j3();
        write(&mut d, 0x2300, 19, 0x100B).unwrap();
        // Not in force yet: PB is still written.
        write(&mut d, 0x2301, 3, 10).unwrap();
        assert_eq!(d.sdo_upload(0x1010, 1), Ok(3));
        save(&mut d).unwrap();
        d.power_cycle();
        assert_eq!(d.sdo_upload(0x2301, 3), Err(SdoAbort::UNSUPPORTED_ACCESS));
        assert_eq!(write(&mut d, 0x2301, 3, 20), Err(SdoAbort::CANNOT_STORE));
        assert_eq!(write(&mut d, 0x2300, 14, 1), Err(SdoAbort::CANNOT_STORE));
        assert_eq!(d.sdo_upload(0x2300, 14), Ok(0), "PA still readable");
        assert_eq!(d.sdo_upload(0x1010, 1), Ok(0), "not storable");
        assert_eq!(save(&mut d), Err(SdoAbort::CANNOT_STORE));
        // PA19 itself stays writable.
        write(&mut d, 0x2300, 19, 0x000E).unwrap();
    }

    #[test]
    fn alarms_land_in_the_history_newest_first_and_1ea5h_clears_it() {
        let mut d = j3();
        d.inject_alarm(mr_j3_t04::AL_52);
        d.inject_alarm(mr_j3_t04::AL_52);
        d.power_cycle();
        d.inject_alarm(mr_j3_t04::AL_35);
        assert_eq!(d.sdo_upload(0x2030, 1), Ok(0x35));
        assert_eq!(
            d.sdo_upload(0x2031, 1),
            Ok(0x52),
            "one entry per occurrence"
        );
        assert_eq!(d.sdo_upload(0x2032, 1), Ok(0));
        assert_eq!(d.sdo_upload(0x2030, 0), Ok(3));
        assert_eq!(d.sdo_upload(0x2040, 0), Err(SdoAbort::WRITE_ONLY));
        assert_eq!(
            d.sdo_download(0x2040, 0, &[0x34, 0x12]),
            Err(SdoAbort::VALUE_RANGE)
        );
        assert_eq!(d.sdo_upload(0x2030, 1), Ok(0x35));
        d.sdo_download(0x2040, 0, &[0xA5, 0x1E]).unwrap();
        assert_eq!(d.sdo_upload(0x2030, 1), Ok(0));
        assert_eq!(d.sdo_upload(0x2031, 1), Ok(0));
    }

    #[test]
    fn a_model_without_a_history_has_no_history_objects() {
        let ct = CycleTime::from_micros(1000).unwrap();
        let mut d = SimDrive::new(&mr_jet_g_n1::PROFILE, SimDriveParams::default(), ct);
        d.inject_alarm(mr_jet_g_n1::AL_037);
        assert_eq!(d.sdo_upload(0x2030, 1), Err(SdoAbort::NO_OBJECT));
        assert_eq!(d.alarm_history().entry(0).number, 0);
        // PC43 (2D6Dh:02) is held and range-checked.
        assert_eq!(d.sdo_upload(0x2D6D, 2), Ok(10_000));
        assert_eq!(
            d.sdo_download(0x2D6D, 2, &10_001u16.to_le_bytes()),
            Err(SdoAbort::VALUE_RANGE)
        );
        d.sdo_download(0x2D6D, 2, &5_000u16.to_le_bytes()).unwrap();
        assert_eq!(d.parameter_in_force("PC43"), Some(5_000));
    }
}
