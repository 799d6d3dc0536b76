//! Status DO 1–3 (2D11h–2D13h): the Mitsubishi statusword extension of the MR-J4-TM, MR-J5-G-N1
//! (and W2/W3) and MR-JET-G-N1, one bit per output signal. The three manuals give the same
//! bit map (MR-J4-TM manual §5.3.2, MR-J5-G-N1 manual §7.3, MR-JET-G-N1 manual §7.3); bits
//! not listed there are undefined and stay 0.

use crate::pdo::objects::{TxExtras, TxExtrasFull, STATUS_DO};
use crate::pdo::TxPdo;

/// One Status DO signal: which of the three words, and which bit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::IntoStaticStr, strum::EnumIter)]
pub enum StatusDoSignal {
    /// S_SA speed reached (2D11h bit 2): off at servo-off.
    #[strum(serialize = "S_SA")]
    SpeedReached,
    /// S_MBR electromagnetic brake interlock (2D11h bit 3): off at servo-off or on an alarm.
    #[strum(serialize = "S_MBR")]
    BrakeInterlock,
    /// S_INP in-position (2D11h bit 12): droop within the in-position range; position modes.
    #[strum(serialize = "S_INP")]
    InPosition,
    /// S_TLC limiting torque (2D11h bit 13): the torque has reached its limit; not in torque
    /// modes, off at servo-off.
    #[strum(serialize = "S_TLC")]
    TorqueLimiting,
    /// S_ZPAS Z-phase passed since start-up (2D12h bit 0).
    #[strum(serialize = "S_ZPAS")]
    ZPhasePassed,
    /// S_ZSP zero speed (2D12h bit 3): the gate for mode switches to or from a position mode.
    #[strum(serialize = "S_ZSP")]
    ZeroSpeed,
    /// S_VLC limiting speed (2D12h bit 4): in torque mode, at the speed limit.
    #[strum(serialize = "S_VLC")]
    SpeedLimiting,
    /// S_DB external dynamic brake output (2D12h bit 10): off when the dynamic brake must act.
    #[strum(serialize = "S_DB")]
    DynamicBrakeOutput,
    /// S_ZP2 home position return completion 2 (2D12h bit 15).
    #[strum(serialize = "S_ZP2")]
    HomeCompleted2,
    /// S_STO STO active (2D13h bit 5).
    #[strum(serialize = "S_STO")]
    SafeTorqueOff,
}

impl StatusDoSignal {
    /// (word 0–2 for 2D11h–2D13h, bit).
    pub const fn position(self) -> (usize, u8) {
        match self {
            Self::SpeedReached => (0, 2),
            Self::BrakeInterlock => (0, 3),
            Self::InPosition => (0, 12),
            Self::TorqueLimiting => (0, 13),
            Self::ZPhasePassed => (1, 0),
            Self::ZeroSpeed => (1, 3),
            Self::SpeedLimiting => (1, 4),
            Self::DynamicBrakeOutput => (1, 10),
            Self::HomeCompleted2 => (1, 15),
            Self::SafeTorqueOff => (2, 5),
        }
    }

    /// The manual's symbol (S_ZSP, …).
    pub fn symbol(self) -> &'static str {
        self.into()
    }
}

/// The three Status DO words as received (2D11h, 2D12h, 2D13h).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct StatusDo(pub [u16; 3]);

impl StatusDo {
    /// Whether `signal` is on.
    pub fn get(self, signal: StatusDoSignal) -> bool {
        let (w, b) = signal.position();
        self.0[w] & (1 << b) != 0
    }

    /// Sets `signal` to `on`.
    pub fn set(&mut self, signal: StatusDoSignal, on: bool) {
        let (w, b) = signal.position();
        if on {
            self.0[w] |= 1 << b;
        } else {
            self.0[w] &= !(1 << b);
        }
    }

    /// The words a TxPDO image carries (2D11h–2D13h among [`TxPdo::extras`], 0 where the image
    /// does not carry one).
    #[inline]
    pub fn of(tx: &TxPdo) -> Self {
        StatusDo(STATUS_DO.map(|index| tx.extra_word(index)))
    }

    /// Puts the three words into `extras` as 2D11h–2D13h.
    #[inline]
    pub fn write_to(self, extras: &mut TxExtras) -> Result<(), TxExtrasFull> {
        for (index, word) in STATUS_DO.into_iter().zip(self.0) {
            extras.set(index, 0, u64::from(word))?;
        }
        Ok(())
    }

    /// The symbols of the signals that are on, in the manual's order (for `cellrt status`).
    pub fn symbols_on(self) -> impl Iterator<Item = &'static str> {
        use strum::IntoEnumIterator;
        StatusDoSignal::iter()
            .filter(move |s| self.get(*s))
            .map(StatusDoSignal::symbol)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bits_of_the_manuals_bit_map() {
        // MR-J4-TM manual §5.3.2: S_ZSP is 2D12h bit 3 (0x0008), S_INP 2D11h bit 12 (0x1000),
        // S_STO 2D13h bit 5 (0x0020).
        let mut s = StatusDo::default();
        s.set(StatusDoSignal::ZeroSpeed, true);
        s.set(StatusDoSignal::InPosition, true);
        s.set(StatusDoSignal::SafeTorqueOff, true);
        assert_eq!(s.0, [0x1000, 0x0008, 0x0020]);
        assert_eq!(
            s.symbols_on().collect::<Vec<_>>(),
            ["S_INP", "S_ZSP", "S_STO"]
        );
        s.set(StatusDoSignal::InPosition, false);
        assert!(!s.get(StatusDoSignal::InPosition) && s.get(StatusDoSignal::ZeroSpeed));
        let from_wire = StatusDo([0x000C, 0x8400, 0]);
        assert_eq!(
            from_wire.symbols_on().collect::<Vec<_>>(),
            ["S_SA", "S_MBR", "S_DB", "S_ZP2"]
        );
    }
}
