//! Physical plausibility at the door: the motor and mechanics figures of a configuration
//! (encoder resolution, gear ratio and lead, rated and maximum speeds) bounded to what a real
//! drive and motor can be, each with a margin over the largest figure the drives' manuals
//! (`shared/seeds/`) give. A value outside is refused at load time naming its key; nothing is
//! clamped. (Torques: [`crate::MAX_TORQUE_PERCENT`]; torque slopes, accelerations and jerks:
//! what one cycle can reach, `validate/cycle_reach.rs`.)

/// A closed range a physical figure must lie in, with its unit and where the bounds come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plausible {
    /// Smallest value a real drive or motor can have.
    pub min: f64,
    /// Largest value a real drive or motor can have.
    pub max: f64,
    /// The unit the value is in.
    pub unit: &'static str,
    /// What the figure is, for the error.
    pub what: &'static str,
}

/// Position units per motor revolution (`motor.counts_per_rev`, `je_c.counts_per_rev`, the
/// 6092h feed constant): at most 2^28 = 268435456, four times the finest encoder of the
/// manuals — the MR-J5 / MR-JET 26-bit encoder, 2^26 = 67108864 pulses/rev (MR-JET-G-N1
/// manual, electronic gear example; MR-J4: 22 bit, 4194304). At least 1: an indexer counts 2
/// stations per revolution at the fewest ([Pr. PT28], [`crate::je_c_axis::STATIONS`]).
pub const COUNTS_PER_REV: Plausible = Plausible {
    min: 1.0,
    max: 268_435_456.0,
    unit: "pos units/rev",
    what: "position units per motor revolution (encoder resolution × electronic gear)",
};

/// Position units per mm of a linear motor (`motor.counts_per_mm`): at most 10^6 (1 nm), five
/// times the finest linear scale used with these amplifiers (0.005 µm = 200000 /mm; the
/// manuals in the seeds give no linear-scale figure: a field figure); at least 1 (1 mm).
pub const COUNTS_PER_MM: Plausible = Plausible {
    min: 1.0,
    max: 1_000_000.0,
    unit: "pos units/mm",
    what: "position units per mm of a linear motor (linear scale resolution)",
};

/// A motor speed (`motor.rated_speed`, `motor.max_speed`, `je_c.rated_speed`, and the motor
/// speed `limits.velocity` implies), r/min (rotary) or mm/s (linear): at most 20000, the top
/// of 607Fh Max profile velocity's setting range 0–2000000 × 0.01 r/min (MR-JE-C manual,
/// object 607Fh; 0.01 mm/s for linear motors, MR-J4-TM manual "Vel unit") and about three
/// times the fastest servo motors of these families (6000–6700 r/min: a catalogue figure, not
/// in the seeds); at least 1 r/min, below any motor's rated speed.
pub const MOTOR_SPEED: Plausible = Plausible {
    min: 1.0,
    max: 20_000.0,
    unit: "r/min (mm/s for a linear motor)",
    what: "a motor speed",
};

/// Motor revolutions (mm of a linear motor) per unit of travel — the gear ratio over the lead,
/// `counts_per_unit` ÷ the position units per revolution (per mm) — within 10^-6…10^6: a
/// 1:10000 reducer on a 0.01 mm lead counted in µm is 10^3 rev/unit (10^6 would take a
/// 1:10^7 reducer on it), a 1 m belt pulley counted in µm 10^-6 rev/unit; beyond either, the
/// unit or one of the two counts is wrong.
pub const REVS_PER_UNIT: Plausible = Plausible {
    min: 1e-6,
    max: 1e6,
    unit: "motor revolutions (mm of a linear motor) per unit",
    what: "a gear ratio over a lead (counts_per_unit ÷ the motor's position units per revolution or mm)",
};

impl Plausible {
    /// `v` if it lies within the bounds; otherwise why not, in one line.
    pub fn check(&self, v: f64) -> Result<f64, String> {
        if v.is_finite() && v >= self.min && v <= self.max {
            Ok(v)
        } else {
            Err(format!(
                "{v} is not {}: a real drive and motor have {} to {} {}",
                self.what, self.min, self.max, self.unit
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_hold_the_manuals_figures_and_refuse_the_absurd() {
        // The 26-bit MR-J5 encoder, the 22-bit MR-J4 one, an indexer of 2 stations.
        for v in [67_108_864.0, 4_194_304.0, 2.0] {
            assert_eq!(COUNTS_PER_REV.check(v), Ok(v));
        }
        for v in [1e18, 0.5, -1.0, f64::NAN, f64::INFINITY] {
            let e = COUNTS_PER_REV.check(v).unwrap_err();
            assert!(e.contains("268435456"), "{e}");
        }
        assert!(MOTOR_SPEED.check(6700.0).is_ok());
        assert!(MOTOR_SPEED.check(1e18).is_err());
        assert!(MOTOR_SPEED.check(1e-300).is_err());
        assert!(COUNTS_PER_MM.check(200_000.0).is_ok());
        assert!(COUNTS_PER_MM.check(1e18).is_err());
        assert!(REVS_PER_UNIT.check(0.1).is_ok());
        assert!(REVS_PER_UNIT.check(1e-18).is_err());
    }
}
