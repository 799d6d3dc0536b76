//! The controller's link devices for an MR-JE-C in a positioning mode (pt, idx, jg, hm) over
//! CC-Link IE Field Basic: RWw as the MR-JE-C manual's Table 2.3 (§2.3.2) assigns it, and RWr
//! as the drive's default response mapping for that table (1A00h, §7.4.6; the RWr column is
//! partly garbled in the manual, so its positions follow the extract's reconstruction). 32-bit
//! objects take two devices, the low word in the lower one; 8-bit ones the low byte of a word.

/// RWw device numbers of Table 2.3.
mod rww {
    pub const MODE: usize = 0x00;
    pub const CONTROLWORD: usize = 0x01;
    pub const CONTROL_DI_1: usize = 0x02;
    pub const TARGET_POINT_TABLE: usize = 0x05;
    pub const PROFILE_VELOCITY: usize = 0x06;
    pub const ACCELERATION: usize = 0x08;
    pub const DECELERATION: usize = 0x0A;
    pub const TOUCH_PROBE_FUNCTION: usize = 0x0C;
    pub const TARGET_SPEED_NO: usize = 0x0D;
}

/// RWr device numbers of the default Table 2.3 response mapping.
mod rwr {
    pub const MODE_DISPLAY: usize = 0x00;
    pub const STATUSWORD: usize = 0x01;
    pub const POSITION: usize = 0x02;
    pub const VELOCITY: usize = 0x04;
    pub const FOLLOWING_ERROR: usize = 0x06;
    pub const TORQUE: usize = 0x08;
    /// Status DO 1, 2, 3, 5 and 7.
    pub const STATUS_DO: [usize; 5] = [0x09, 0x0A, 0x0B, 0x0C, 0x0D];
    pub const POINT_DEMAND: usize = 0x0E;
    pub const POINT_ACTUAL: usize = 0x0F;
    pub const M_CODE: usize = 0x10;
    pub const ALARM: usize = 0x11;
}

/// What the controller writes in a positioning mode (RWw, Table 2.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PositioningCommand {
    /// 6060h (e.g. −101 pt, −103 idx, −100 jg, 6 hm).
    pub mode: i8,
    /// 6040h.
    pub controlword: u16,
    /// Control DI 1–3 (2D01h–2D03h).
    pub control_di: [u16; 3],
    /// 2D60h: the point table (pt: 1–255, −1 high-speed home return) or next station (idx).
    pub target_point_table: i16,
    /// 6081h, 0.01 r/min.
    pub profile_velocity: u32,
    /// 6083h, ms.
    pub acceleration_ms: u32,
    /// 6084h, ms.
    pub deceleration_ms: u32,
    /// 60B8h.
    pub touch_probe_function: u16,
    /// 2DD1h: the point table whose speed and ramps a start takes (0: the started one's).
    pub target_speed_no: i16,
}

impl PositioningCommand {
    /// The station's RWw block (32 words, little-endian).
    pub fn rww(&self) -> [u8; 64] {
        let mut w = [0u8; 64];
        let mut put = |device: usize, bytes: &[u8]| {
            w[2 * device..2 * device + bytes.len()].copy_from_slice(bytes);
        };
        put(rww::MODE, &self.mode.to_le_bytes());
        put(rww::CONTROLWORD, &self.controlword.to_le_bytes());
        for (k, di) in self.control_di.iter().enumerate() {
            put(rww::CONTROL_DI_1 + k, &di.to_le_bytes());
        }
        put(
            rww::TARGET_POINT_TABLE,
            &self.target_point_table.to_le_bytes(),
        );
        put(rww::PROFILE_VELOCITY, &self.profile_velocity.to_le_bytes());
        put(rww::ACCELERATION, &self.acceleration_ms.to_le_bytes());
        put(rww::DECELERATION, &self.deceleration_ms.to_le_bytes());
        put(
            rww::TOUCH_PROBE_FUNCTION,
            &self.touch_probe_function.to_le_bytes(),
        );
        put(rww::TARGET_SPEED_NO, &self.target_speed_no.to_le_bytes());
        w
    }
}

/// What the drive answers in a positioning mode (RWr of the default Table 2.3 mapping).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PositioningFeedback {
    /// 6061h.
    pub mode: i8,
    /// 6041h.
    pub statusword: u16,
    /// 6064h, pos units.
    pub position: i32,
    /// 606Ch, 0.01 r/min.
    pub velocity: i32,
    /// 60F4h, pos units.
    pub following_error: i32,
    /// 6077h, 0.1 %.
    pub torque: i16,
    /// Status DO 1, 2, 3, 5 and 7 (2D11h, 2D12h, 2D13h, 2D15h, 2D17h).
    pub status_do: [u16; 5],
    /// 2D68h: the point table running (or 2D60h while stopped).
    pub point_demand: i16,
    /// 2D69h: the point table completed last.
    pub point_actual: i16,
    /// 2D6Ah: its M code.
    pub m_code: u8,
    /// 2A42h (0: no alarm).
    pub alarm: u16,
}

impl PositioningFeedback {
    /// Reads the station's RWr block.
    pub fn from_rwr(r: &[u8; 64]) -> PositioningFeedback {
        let word = |device: usize| u16::from_le_bytes([r[2 * device], r[2 * device + 1]]);
        let long = |device: usize| {
            i32::from_le_bytes([
                r[2 * device],
                r[2 * device + 1],
                r[2 * device + 2],
                r[2 * device + 3],
            ])
        };
        PositioningFeedback {
            mode: r[2 * rwr::MODE_DISPLAY] as i8,
            statusword: word(rwr::STATUSWORD),
            position: long(rwr::POSITION),
            velocity: long(rwr::VELOCITY),
            following_error: long(rwr::FOLLOWING_ERROR),
            torque: word(rwr::TORQUE) as i16,
            status_do: rwr::STATUS_DO.map(word),
            point_demand: word(rwr::POINT_DEMAND) as i16,
            point_actual: word(rwr::POINT_ACTUAL) as i16,
            m_code: r[2 * rwr::M_CODE],
            alarm: word(rwr::ALARM),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The devices of Table 2.3, byte for byte: 6060h = −101 in RWwn00's low byte, 6040h in
    /// RWwn01, 2D60h = 3 in RWwn05, 6081h = 100000 (1000 r/min) in RWwn06–07 low word first,
    /// 6083h/6084h = 200/300 ms in RWwn08–0B, 2DD1h = 7 in RWwn0D.
    #[test]
    fn the_command_lands_on_the_devices_of_table_2_3() {
        let w = PositioningCommand {
            mode: -101,
            controlword: 0x001F,
            control_di: [0x0001, 0, 0x0800],
            target_point_table: 3,
            profile_velocity: 100_000,
            acceleration_ms: 200,
            deceleration_ms: 300,
            touch_probe_function: 0x0033,
            target_speed_no: 7,
        }
        .rww();
        let expect: [u8; 28] = [
            0x9B, 0x00, 0x1F, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x08, 0x03, 0x00, 0xA0, 0x86,
            0x01, 0x00, 0xC8, 0x00, 0x00, 0x00, 0x2C, 0x01, 0x00, 0x00, 0x33, 0x00, 0x07, 0x00,
        ];
        assert_eq!(&w[..28], &expect);
        assert!(w[28..].iter().all(|&b| b == 0));
    }

    #[test]
    fn the_feedback_reads_the_default_table_2_3_mapping() {
        let mut r = [0u8; 64];
        r[0] = 0x9B; // 6061h = −101
        r[2..4].copy_from_slice(&0x1637u16.to_le_bytes());
        r[4..8].copy_from_slice(&(-131_072i32).to_le_bytes());
        r[0x0F * 2..0x0F * 2 + 2].copy_from_slice(&5u16.to_le_bytes());
        r[0x10 * 2] = 42;
        r[0x11 * 2..0x11 * 2 + 2].copy_from_slice(&0x0E3Au16.to_le_bytes());
        let f = PositioningFeedback::from_rwr(&r);
        assert_eq!(
            (
                f.mode,
                f.statusword,
                f.position,
                f.point_actual,
                f.m_code,
                f.alarm
            ),
            (-101, 0x1637, -131_072, 5, 42, 0x0E3A)
        );
    }
}
