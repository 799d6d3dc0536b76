//! Kinematic limits (velocity, acceleration, jerk) and position ranges, with validation.

use core::fmt;

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Which kinematic quantity an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Velocity, unit/s.
    Velocity,
    /// Acceleration, unit/s².
    Acceleration,
    /// Jerk, unit/s³.
    Jerk,
}

impl Quantity {
    /// SI-style unit suffix of this quantity in axis units.
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Velocity => "unit/s",
            Quantity::Acceleration => "unit/s^2",
            Quantity::Jerk => "unit/s^3",
        }
    }
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Quantity::Velocity => "velocity",
            Quantity::Acceleration => "acceleration",
            Quantity::Jerk => "jerk",
        })
    }
}

/// The longest a planned motion may take, s: one day. A move whose limits would make it take
/// longer (`cellrt move … --vel 1e-300`) is a mistake, not a motion: it is refused before
/// anything moves ([`KinematicLimits::check_travel`]), and the planner never sees values so
/// far apart that it cannot represent them.
pub const MAX_MOTION_S: f64 = 86_400.0;

/// The smallest per-move limit taken, as a fraction of the axis limit: below it the planner's
/// arithmetic degenerates (a velocity of 1e-300 unit/s is not a move). The operator service
/// and the program check refuse smaller ones.
pub const MIN_LIMIT_FRACTION: f64 = 1e-6;

/// Errors from validating or combining limits and ranges.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum LimitsError {
    /// A limit is NaN, infinite, zero or negative.
    #[error("{quantity} limit must be finite and > 0, got {value} {}", quantity.unit())]
    NotPositive {
        /// The offending field.
        quantity: Quantity,
        /// Its value.
        value: f64,
    },
    /// A per-move limit asks for more than the axis allows (never clamped silently).
    #[error("requested {quantity} limit {requested} {} exceeds the axis limit {axis_limit} {}", quantity.unit(), quantity.unit())]
    ExceedsAxisLimit {
        /// The offending field.
        quantity: Quantity,
        /// The per-move value.
        requested: f64,
        /// The axis' configured value.
        axis_limit: f64,
    },
    /// A position range with non-finite bounds or `min >= max`.
    #[error("invalid position range [{min}, {max}]: bounds must be finite and min < max")]
    InvalidRange {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// A travel the limits would take longer than [`MAX_MOTION_S`] over.
    #[error("{distance:?} unit at {quantity} {limit:?} {} takes at least {seconds:.3e} s, longer than a motion may take ({MAX_MOTION_S} s, one day)", quantity.unit())]
    TooLong {
        /// The distance, unit.
        distance: f64,
        /// The limit that makes it long.
        quantity: Quantity,
        /// Its value.
        limit: f64,
        /// The least time the travel takes within that limit, s.
        seconds: f64,
    },
    /// A position outside (or a non-finite position checked against) a range.
    #[error("position {value} is outside the allowed range [{min}, {max}]")]
    OutOfRange {
        /// The offending position.
        value: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
}

/// Symmetric kinematic limits of one axis, in axis units: unit/s, unit/s², unit/s³.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KinematicLimits {
    /// Maximum |velocity|, unit/s.
    pub velocity: f64,
    /// Maximum |acceleration|, unit/s².
    pub acceleration: f64,
    /// Maximum |jerk|, unit/s³.
    pub jerk: f64,
}

impl KinematicLimits {
    /// The three limits paired with their names, in a fixed order.
    fn fields(&self) -> [(Quantity, f64); 3] {
        [
            (Quantity::Velocity, self.velocity),
            (Quantity::Acceleration, self.acceleration),
            (Quantity::Jerk, self.jerk),
        ]
    }

    /// Checks that every limit is finite and strictly positive.
    pub fn validate(&self) -> Result<(), LimitsError> {
        for (quantity, value) in self.fields() {
            if !(value.is_finite() && value > 0.0) {
                return Err(LimitsError::NotPositive { quantity, value });
            }
        }
        Ok(())
    }

    /// Checks that travelling `distance` (unit, ≥ 0) from rest to rest within these limits can
    /// take at most [`MAX_MOTION_S`]; refuses, naming the limit, when even the least time it
    /// can take is longer. The least times are bounds any profile meets: `d / v` (speed at most
    /// v), `2 √(d / a)` (speed at most a·min(t, T − t)), `∛(24 d / j)` (speed at most
    /// j·min(t, T − t)²/2, from rest at zero acceleration).
    pub fn check_travel(&self, distance: f64) -> Result<(), LimitsError> {
        self.validate()?;
        let d = distance.abs();
        let least = [
            (Quantity::Velocity, self.velocity, d / self.velocity),
            (
                Quantity::Acceleration,
                self.acceleration,
                2.0 * (d / self.acceleration).sqrt(),
            ),
            (Quantity::Jerk, self.jerk, (24.0 * d / self.jerk).cbrt()),
        ];
        // A NaN distance is refused as well.
        match least
            .into_iter()
            .find(|&(_, _, t)| t.is_nan() || t > MAX_MOTION_S)
        {
            Some((quantity, limit, seconds)) => Err(LimitsError::TooLong {
                distance: d,
                quantity,
                limit,
                seconds,
            }),
            None => Ok(()),
        }
    }

    /// Returns `self` (per-move limits) after checking that both sets are valid and that
    /// none of `self` exceeds `axis`; an excess is an error, never clamped.
    pub fn capped_by(&self, axis: &KinematicLimits) -> Result<KinematicLimits, LimitsError> {
        axis.validate()?;
        self.validate()?;
        for ((quantity, requested), (_, axis_limit)) in self.fields().into_iter().zip(axis.fields())
        {
            if requested > axis_limit {
                return Err(LimitsError::ExceedsAxisLimit {
                    quantity,
                    requested,
                    axis_limit,
                });
            }
        }
        Ok(*self)
    }
}

/// Allowed position interval of an axis (software limits), in axis units, bounds inclusive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PositionRange {
    /// Lowest allowed position.
    pub min: f64,
    /// Highest allowed position.
    pub max: f64,
}

impl PositionRange {
    /// Checks that both bounds are finite and `min < max`.
    pub fn validate(&self) -> Result<(), LimitsError> {
        if self.min.is_finite() && self.max.is_finite() && self.min < self.max {
            Ok(())
        } else {
            Err(LimitsError::InvalidRange {
                min: self.min,
                max: self.max,
            })
        }
    }

    /// Checks that `target` is finite and inside `[min, max]`; also validates the range.
    pub fn check(&self, target: f64) -> Result<(), LimitsError> {
        self.validate()?;
        // Written so that NaN fails.
        if target >= self.min && target <= self.max {
            Ok(())
        } else {
            Err(LimitsError::OutOfRange {
                value: target,
                min: self.min,
                max: self.max,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_travel_longer_than_a_day_is_refused_naming_the_limit() {
        let l = |v, a, j| KinematicLimits {
            velocity: v,
            acceleration: a,
            jerk: j,
        };
        // 800 mm at the demo's limits, and nothing to travel at the tiniest.
        assert_eq!(l(400.0, 2000.0, 20000.0).check_travel(800.0), Ok(()));
        assert_eq!(l(1e-300, 1e-300, 1e-300).check_travel(0.0), Ok(()));
        for (limits, quantity) in [
            (l(1e-300, 2000.0, 20000.0), Quantity::Velocity),
            (l(400.0, 1e-300, 20000.0), Quantity::Acceleration),
            (l(400.0, 2000.0, 1e-300), Quantity::Jerk),
        ] {
            let e = limits.check_travel(-100.0).unwrap_err();
            assert!(
                matches!(e, LimitsError::TooLong { quantity: q, distance, .. } if q == quantity && distance == 100.0),
                "{e}"
            );
            assert!(e.to_string().contains("one day"), "{e}");
        }
        // Just within and just beyond a day at 1 unit/s.
        assert!(l(1.0, 1e9, 1e9).check_travel(MAX_MOTION_S).is_ok());
        assert!(l(1.0, 1e9, 1e9).check_travel(MAX_MOTION_S * 1.001).is_err());
        assert!(l(1.0, 1.0, 1.0).check_travel(f64::INFINITY).is_err());
    }

    const AXIS: KinematicLimits = KinematicLimits {
        velocity: 1.0,
        acceleration: 10.0,
        jerk: 100.0,
    };

    #[test]
    fn validate_names_field_and_value() {
        assert_eq!(AXIS.validate(), Ok(()));
        let bad = KinematicLimits {
            acceleration: 0.0,
            ..AXIS
        };
        let err = bad.validate().unwrap_err();
        assert_eq!(
            err,
            LimitsError::NotPositive {
                quantity: Quantity::Acceleration,
                value: 0.0
            }
        );
        assert!(err.to_string().contains("acceleration"), "{err}");
        for (v, a, j, q) in [
            (-1.0, 1.0, 1.0, Quantity::Velocity),
            (1.0, 1.0, f64::NAN, Quantity::Jerk),
            (f64::INFINITY, 1.0, 1.0, Quantity::Velocity),
        ] {
            let l = KinematicLimits {
                velocity: v,
                acceleration: a,
                jerk: j,
            };
            assert!(
                matches!(l.validate(), Err(LimitsError::NotPositive { quantity, .. }) if quantity == q)
            );
        }
    }

    #[test]
    fn capped_by_rejects_excess() {
        let slower = KinematicLimits {
            velocity: 0.5,
            ..AXIS
        };
        assert_eq!(slower.capped_by(&AXIS), Ok(slower));
        assert_eq!(AXIS.capped_by(&AXIS), Ok(AXIS));
        let too_jerky = KinematicLimits {
            jerk: 100.5,
            ..AXIS
        };
        let err = too_jerky.capped_by(&AXIS).unwrap_err();
        assert_eq!(
            err,
            LimitsError::ExceedsAxisLimit {
                quantity: Quantity::Jerk,
                requested: 100.5,
                axis_limit: 100.0
            }
        );
        assert!(err.to_string().contains("jerk"), "{err}");
        let bad_axis = KinematicLimits {
            velocity: f64::NAN,
            ..AXIS
        };
        assert!(matches!(
            slower.capped_by(&bad_axis),
            Err(LimitsError::NotPositive {
                quantity: Quantity::Velocity,
                ..
            })
        ));
    }

    #[test]
    fn position_range() {
        let r = PositionRange {
            min: -1.0,
            max: 2.0,
        };
        assert_eq!(r.validate(), Ok(()));
        assert_eq!(r.check(-1.0), Ok(()));
        assert_eq!(r.check(2.0), Ok(()));
        let err = r.check(2.5).unwrap_err();
        assert_eq!(
            err,
            LimitsError::OutOfRange {
                value: 2.5,
                min: -1.0,
                max: 2.0
            }
        );
        assert!(
            err.to_string().contains("2.5") && err.to_string().contains("[-1, 2]"),
            "{err}"
        );
        assert!(matches!(
            r.check(f64::NAN),
            Err(LimitsError::OutOfRange { .. })
        ));
        for (min, max) in [
            (1.0, 1.0),
            (2.0, 1.0),
            (f64::NAN, 1.0),
            (0.0, f64::INFINITY),
        ] {
            let bad = PositionRange { min, max };
            assert!(matches!(
                bad.validate(),
                Err(LimitsError::InvalidRange { .. })
            ));
            assert!(matches!(
                bad.check(0.5),
                Err(LimitsError::InvalidRange { .. })
            ));
        }
    }
}
