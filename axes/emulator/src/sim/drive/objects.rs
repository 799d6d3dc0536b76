//! Objects written by SDO and the parameter save they may start (1010h:01); the SDO
//! services themselves are `sim::sdo`.

use super::SimDrive;

impl SimDrive {
    /// SDO download of 6060h Modes of operation. Refused with the model's abort code when 6060h
    /// is mapped in the RxPDO (MR-J3-T04 §3.9: 0x06010000; MR-J4-TM/MR-JET/MR-J5: 0x06010006).
    /// The switch itself waits for zero speed like a PDO request and stays pending until then.
    pub fn sdo_write_mode(&mut self, raw: i8) -> Result<(), u32> {
        self.sdo_download(
            cellrt_cia402::pdo::objects::MODES_OF_OPERATION,
            0,
            &[raw as u8],
        )
        .map_err(|e| e.0)
    }

    /// Whether a parameter save (1010h:01) is still running.
    pub fn saving(&self) -> bool {
        self.saving_left > 0
    }

    pub(in crate::sim) fn start_saving(&mut self) {
        let ms = u64::from(self.params.store_parameters_ms);
        let cycles = self
            .cycle_time
            .cycles_for(std::time::Duration::from_millis(ms))
            .0
            .max(1);
        self.saving_left = cycles;
    }

    pub(in crate::sim) fn set_sdo_mode(&mut self, raw: i8) {
        self.sdo_mode = raw;
    }

    /// The model's object-dictionary entry `index:sub` (looked up every cycle: indexed).
    pub(in crate::sim) fn object(
        &self,
        index: u16,
        sub: u8,
    ) -> Option<&'static cellrt_cia402::profiles::OdEntry> {
        self.od.get(index, sub)
    }

    pub(in crate::sim) fn sdo_value(&self, index: u16, sub: u8) -> Option<i64> {
        self.sdo_values
            .iter()
            .find(|(i, s, _)| *i == index && *s == sub)
            .map(|v| v.2)
    }

    pub(in crate::sim) fn store_sdo_value(&mut self, index: u16, sub: u8, value: i64) {
        match self
            .sdo_values
            .iter_mut()
            .find(|(i, s, _)| *i == index && *s == sub)
        {
            Some(v) => v.2 = value,
            None => self.sdo_values.push((index, sub, value)),
        }
    }
}
