//! Conversion between axis units (mm, deg, rad, ...) and drive position counts.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Errors from building a [`Scaling`] or converting with it.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum UnitsError {
    /// The scale factor is NaN, infinite, zero or negative.
    #[error("counts per unit must be finite and > 0, got {0}")]
    InvalidCountsPerUnit(f64),
    /// The value to convert (or its product with the scale) is NaN or infinite.
    #[error("cannot convert {units} units to counts: result {counts} is not finite")]
    NonFinite {
        /// Value in axis units that was given.
        units: f64,
        /// Resulting (non-finite) count value.
        counts: f64,
    },
    /// The rounded count value does not fit into an `i32` drive position.
    #[error(
        "{units} units is {counts} counts, outside the i32 range [{}, {}]",
        i32::MIN,
        i32::MAX
    )]
    OutOfI32Range {
        /// Value in axis units that was given.
        units: f64,
        /// Rounded count value that overflowed.
        counts: f64,
    },
}

/// Linear scale between axis units and drive counts (e.g. 8 388 608 counts per revolution).
///
/// Always positive: direction inversion belongs to the drive profile, not to the scale.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ScalingRepr", into = "ScalingRepr")]
pub struct Scaling {
    counts_per_unit: f64,
}

impl Scaling {
    /// Builds a scale; `counts_per_unit` must be finite and strictly positive.
    pub fn new(counts_per_unit: f64) -> Result<Scaling, UnitsError> {
        if counts_per_unit.is_finite() && counts_per_unit > 0.0 {
            Ok(Scaling { counts_per_unit })
        } else {
            Err(UnitsError::InvalidCountsPerUnit(counts_per_unit))
        }
    }

    /// Counts per axis unit.
    pub fn counts_per_unit(&self) -> f64 {
        self.counts_per_unit
    }

    /// Axis units to fractional counts (no rounding, no range check).
    pub fn to_counts(&self, units: f64) -> f64 {
        units * self.counts_per_unit
    }

    /// Axis units to counts rounded to the nearest integer (ties away from zero), checked
    /// against the `i32` range of a CiA 402 position object.
    pub fn to_counts_i32(&self, units: f64) -> Result<i32, UnitsError> {
        let counts = self.to_counts(units);
        if !counts.is_finite() {
            return Err(UnitsError::NonFinite { units, counts });
        }
        let rounded = counts.round();
        // Both bounds are exactly representable as f64.
        if rounded < f64::from(i32::MIN) || rounded > f64::from(i32::MAX) {
            return Err(UnitsError::OutOfI32Range {
                units,
                counts: rounded,
            });
        }
        // In range and integral: the cast is exact.
        Ok(rounded as i32)
    }

    /// Counts (fractional allowed) to axis units.
    pub fn to_units(&self, counts: f64) -> f64 {
        counts / self.counts_per_unit
    }
}

/// Serialized form of [`Scaling`]; deserializing validates through [`Scaling::new`].
#[derive(Serialize, Deserialize)]
struct ScalingRepr {
    counts_per_unit: f64,
}

impl TryFrom<ScalingRepr> for Scaling {
    type Error = UnitsError;

    fn try_from(r: ScalingRepr) -> Result<Self, Self::Error> {
        Scaling::new(r.counts_per_unit)
    }
}

impl From<Scaling> for ScalingRepr {
    fn from(s: Scaling) -> ScalingRepr {
        ScalingRepr {
            counts_per_unit: s.counts_per_unit,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn rejects_bad_scale() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(matches!(
                Scaling::new(bad),
                Err(UnitsError::InvalidCountsPerUnit(_))
            ));
        }
    }

    #[test]
    fn converts_and_rounds() {
        let s = Scaling::new(1000.0).unwrap();
        assert_eq!(s.counts_per_unit(), 1000.0);
        assert_eq!(s.to_counts(1.2345), 1234.5);
        assert_eq!(s.to_counts_i32(1.2345).unwrap(), 1235);
        assert_eq!(s.to_counts_i32(-1.2345).unwrap(), -1235);
        assert_eq!(s.to_units(1500.0), 1.5);
    }

    #[test]
    fn i32_overflow_is_an_error() {
        let s = Scaling::new(8_388_608.0).unwrap(); // 23-bit encoder, units = rev
                                                    // 256 rev = 2^31 counts: one past i32::MAX.
        assert!(matches!(
            s.to_counts_i32(256.0),
            Err(UnitsError::OutOfI32Range { .. })
        ));
        assert_eq!(s.to_counts_i32(-256.0).unwrap(), i32::MIN);
        assert!(s.to_counts_i32(255.9999).is_ok());
        let exact_max = f64::from(i32::MAX) / 8_388_608.0;
        assert_eq!(s.to_counts_i32(exact_max).unwrap(), i32::MAX);
        assert!(matches!(
            s.to_counts_i32(f64::NAN),
            Err(UnitsError::NonFinite { .. })
        ));
        assert!(matches!(
            s.to_counts_i32(f64::INFINITY),
            Err(UnitsError::NonFinite { .. })
        ));
        let msg = s.to_counts_i32(300.0).unwrap_err().to_string();
        assert!(msg.contains("300") && msg.contains("2147483647"), "{msg}");
    }

    proptest! {
        #[test]
        fn round_trip(cpu in 1e-3f64..1e7, units in -1e3f64..1e3) {
            let s = Scaling::new(cpu).unwrap();
            let back = s.to_units(s.to_counts(units));
            prop_assert!((back - units).abs() <= 1e-12 * units.abs().max(1.0));
            if let Ok(c) = s.to_counts_i32(units) {
                // Rounding loses at most half a count.
                prop_assert!((s.to_units(f64::from(c)) - units).abs() <= 0.5 / cpu * (1.0 + 1e-12));
            }
        }
    }
}
