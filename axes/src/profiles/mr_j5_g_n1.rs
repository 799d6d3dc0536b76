//! Mitsubishi MR-J5-G-N1 (1-axis), from mr-j5-g-n1.md (manual SH(NA)-030372CHN-A).

use super::{DriveModel, DriveProfile};
use crate::cia402::fsa::FsaQuirks;
use crate::cia402::mode::ModeOfOperation as M;
use crate::cycles::ALLOWED_MICROS;
use crate::pdo::{PdoEntry, PdoMap};

const fn obj(index: u16, bits: u16) -> PdoEntry {
    PdoEntry::object(index, 0, bits)
}

/// Default 1st RxPDO 1600h, 24 bytes (mr-j5-g-n1.md §5.2 / manual §4.3).
pub const RX_PDO_1600: PdoMap = PdoMap {
    index: 0x1600,
    entries: &[
        obj(0x6060, 8),       // 0  Modes of operation
        PdoEntry::padding(8), // 1  padding
        obj(0x6040, 16),      // 2  Controlword
        obj(0x2D01, 16),      // 4  Control DI 1
        obj(0x2D02, 16),      // 6  Control DI 2
        obj(0x2D03, 16),      // 8  Control DI 3
        obj(0x607A, 32),      // 10 Target position
        obj(0x60FF, 32),      // 14 Target velocity
        obj(0x2D20, 32),      // 18 Velocity limit value
        obj(0x6071, 16),      // 22 Target torque
    ],
};

/// Default 1st TxPDO 1A00h, 24 bytes (mr-j5-g-n1.md §5.2 / manual §4.3).
pub const TX_PDO_1A00: PdoMap = PdoMap {
    index: 0x1A00,
    entries: &[
        obj(0x6061, 8),       // 0  Modes of operation display
        PdoEntry::padding(8), // 1  padding
        obj(0x6041, 16),      // 2  Statusword
        obj(0x2D11, 16),      // 4  Status DO 1
        obj(0x2D12, 16),      // 6  Status DO 2
        obj(0x2D13, 16),      // 8  Status DO 3
        obj(0x6064, 32),      // 10 Position actual value
        obj(0x606C, 32),      // 14 Velocity actual value
        obj(0x60F4, 32),      // 18 Following error actual value
        obj(0x6077, 16),      // 22 Torque actual value
    ],
};

/// The MR-J5-G-N1 1-axis profile.
///
/// Identity is `None`: vendor ID and product code are only in the ESI (§1.1). Modes: all seven
/// with PT01.2 = pulse (§1.2). Cycles 0.125–8 ms (§1.3). Quirks: shortcut transitions (§3.2),
/// quick stop present, transition 16 not supported (§3.1). Fault Reset held ≥ 10 ms, ≥ 20 ms at
/// the 8 ms cycle (§2.4 / manual §7.1).
pub const PROFILE: DriveProfile = DriveProfile {
    model: DriveModel::MrJ5GN1,
    name: "Mitsubishi MR-J5-G-N1",
    vendor_id: None,
    product_code: None,
    modes: &[
        M::ProfilePosition,
        M::ProfileVelocity,
        M::ProfileTorque,
        M::Homing,
        M::CyclicSyncPosition,
        M::CyclicSyncVelocity,
        M::CyclicSyncTorque,
    ],
    cycle_times_us: &ALLOWED_MICROS,
    rx_pdo: RX_PDO_1600,
    tx_pdo: TX_PDO_1A00,
    quirks: FsaQuirks {
        shortcut_transitions: true,
        has_quick_stop: true,
        quick_stop_returns_to_enabled: false,
    },
    fault_reset_hold_ms: 10,
    fault_reset_hold_long_cycle_ms: 20,
    long_cycle_from_us: 8000,
    axes_per_unit: 1,
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cia402::controlword::Controlword;
    use crate::cia402::statusword::Statusword;
    use crate::cycles::{CycleTime, Cycles};
    use crate::pdo::{PdoError, RxPdo, TxPdo};
    use crate::profiles::{profile, DriveModel};

    #[test]
    fn rx_offsets_match_spec_table() {
        // mr-j5-g-n1.md §5.2, 1st RxPDO.
        let m = &PROFILE.rx_pdo;
        assert_eq!(m.byte_len(), 24);
        let expect = [
            (0x6060, 0),
            (0x6040, 2),
            (0x2D01, 4),
            (0x2D02, 6),
            (0x2D03, 8),
            (0x607A, 10),
            (0x60FF, 14),
            (0x2D20, 18),
            (0x6071, 22),
        ];
        for (idx, off) in expect {
            assert_eq!(m.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        assert_eq!(
            m.layout().nth(1).map(|(o, e)| (o, e.is_padding())),
            Some((1, true))
        );
    }

    #[test]
    fn tx_offsets_match_spec_table() {
        // mr-j5-g-n1.md §5.2, 1st TxPDO.
        let m = &PROFILE.tx_pdo;
        assert_eq!(m.byte_len(), 24);
        let expect = [
            (0x6061, 0),
            (0x6041, 2),
            (0x2D11, 4),
            (0x2D12, 6),
            (0x2D13, 8),
            (0x6064, 10),
            (0x606C, 14),
            (0x60F4, 18),
            (0x6077, 22),
        ];
        for (idx, off) in expect {
            assert_eq!(m.offset_of(idx, 0), Some(off), "{idx:#06x}");
        }
        assert!(!m.maps(0x603F));
    }

    #[test]
    fn rx_bytes_are_little_endian_at_the_offsets() {
        let pdo = RxPdo {
            mode: 8,
            controlword: Controlword(0x000F),
            target_position: -2,
            target_velocity: 0x0102_0304,
            velocity_limit: 0xA0B0_C0D0,
            target_torque: -300,
        };
        let mut buf = [0xEEu8; 24];
        PROFILE.rx_pdo.encode_rx(&pdo, &mut buf).unwrap();
        assert_eq!(buf[0], 8);
        assert_eq!(buf[1], 0, "padding is zero");
        assert_eq!(&buf[2..4], &[0x0F, 0x00]);
        assert_eq!(&buf[4..10], &[0; 6], "Control DI 1-3 not carried: zero");
        assert_eq!(&buf[10..14], &[0xFE, 0xFF, 0xFF, 0xFF]);
        assert_eq!(&buf[14..18], &[0x04, 0x03, 0x02, 0x01]);
        assert_eq!(&buf[18..22], &[0xD0, 0xC0, 0xB0, 0xA0]);
        assert_eq!(&buf[22..24], &(-300i16).to_le_bytes());
        assert_eq!(PROFILE.rx_pdo.decode_rx(&buf), Ok(pdo));
    }

    #[test]
    fn tx_round_trip_and_error_code_not_mapped() {
        let pdo = TxPdo {
            mode_display: -101,
            statusword: Statusword(0x0237),
            position_actual: i32::MIN,
            velocity_actual: i32::MAX,
            following_error: -12345,
            torque_actual: i16::MIN,
            error_code: 0x8611,
        };
        let mut buf = [0u8; 24];
        PROFILE.tx_pdo.encode_tx(&pdo, &mut buf).unwrap();
        let back = PROFILE.tx_pdo.decode_tx(&buf).unwrap();
        assert_eq!(
            back,
            TxPdo {
                error_code: 0,
                ..pdo
            }
        );
        assert_eq!(&buf[2..4], &[0x37, 0x02]);
    }

    #[test]
    fn short_buffer_names_the_map() {
        let mut buf = [0u8; 23];
        let e = PROFILE
            .rx_pdo
            .encode_rx(&RxPdo::default(), &mut buf)
            .unwrap_err();
        assert_eq!(
            e,
            PdoError::Length {
                map: 0x1600,
                expected: 24,
                actual: 23
            }
        );
        assert!(e.to_string().contains("0x1600"), "{e}");
        let e = PROFILE.tx_pdo.decode_tx(&[]).unwrap_err().to_string();
        assert!(e.contains("0x1A00") && e.contains("24"), "{e}");
        assert!(PROFILE.rx_pdo.decode_rx(&buf).is_err());
        assert!(PROFILE
            .tx_pdo
            .encode_tx(&TxPdo::default(), &mut buf)
            .is_err());
    }

    #[test]
    fn identity_modes_cycles_quirks() {
        let p = profile(DriveModel::MrJ5GN1);
        assert_eq!(p.vendor_id, None);
        assert_eq!(p.product_code, None);
        assert_eq!(p.modes.len(), 7);
        for us in ALLOWED_MICROS {
            assert!(p.supports_cycle_time(CycleTime::from_micros(us).unwrap()));
        }
        assert!(p.quirks.shortcut_transitions && p.quirks.has_quick_stop);
        assert!(!p.quirks.quick_stop_returns_to_enabled);
        assert_eq!(p.axes_per_unit, 1);
    }

    #[test]
    fn fault_reset_hold_per_cycle_time() {
        // mr-j5-g-n1.md TV-5.
        let expect = [
            (125, 80),
            (250, 40),
            (500, 20),
            (1000, 10),
            (2000, 5),
            (4000, 3),
            (8000, 3),
        ];
        for (us, n) in expect {
            let c = CycleTime::from_micros(us).unwrap();
            assert_eq!(PROFILE.fault_reset_hold(c), Cycles(n), "{us} µs");
        }
    }
}
