//! The switches a homing searches for, placed on the simulated axis: the home dog (proximity
//! dog), the positive and negative limit switches (stroke ends LSP/LSN), read as 60FDh Digital
//! inputs. The bit layout of 60FDh is not in the Mitsubishi extracts (MR-J4-TM manual §5.4.9
//! names the object for the stroke-end state only); it is CiA 402's [background]: bit 0
//! negative limit switch, bit 1 positive limit switch, bit 2 home switch.

/// 60FDh bit 0: negative limit switch.
pub const NEGATIVE_LIMIT_SWITCH: u32 = 1 << 0;
/// 60FDh bit 1: positive limit switch.
pub const POSITIVE_LIMIT_SWITCH: u32 = 1 << 1;
/// 60FDh bit 2: home switch (the proximity dog).
pub const HOME_SWITCH: u32 = 1 << 2;

/// Where the switches sit on the axis, in raw motor counts (6064h before any homing).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HomingSwitches {
    /// The home dog is on while the position is within `[from, to]`.
    pub home_dog: Option<[f64; 2]>,
    /// The positive limit switch (LSP off) is on at and above this position.
    pub positive_limit: Option<f64>,
    /// The negative limit switch (LSN off) is on at and below this position.
    pub negative_limit: Option<f64>,
}

impl HomingSwitches {
    /// Whether the home dog is on at `position`.
    pub fn dog(&self, position: f64) -> bool {
        self.home_dog
            .is_some_and(|[a, b]| position >= a.min(b) && position <= a.max(b))
    }

    /// The dog's end met first (`front`) or last moving in the direction `dir` (+1 positive,
    /// −1 negative): its exact edge, where a search measures the travel distance after
    /// proximity dog from (MR-J4-TM manual §5.4.9(6)).
    pub fn dog_end(&self, dir: f64, front: bool) -> Option<f64> {
        self.home_dog.map(|[a, b]| {
            let (low, high) = (a.min(b), a.max(b));
            if (dir > 0.0) == front {
                low
            } else {
                high
            }
        })
    }

    /// Whether the limit switch in the direction `dir` (+1 positive, −1 negative) is on at
    /// `position`.
    pub fn limit(&self, position: f64, dir: f64) -> bool {
        if dir > 0.0 {
            self.positive_limit.is_some_and(|l| position >= l)
        } else {
            self.negative_limit.is_some_and(|l| position <= l)
        }
    }

    /// 60FDh Digital inputs at `position`.
    pub fn digital_inputs(&self, position: f64) -> u32 {
        (if self.limit(position, -1.0) {
            NEGATIVE_LIMIT_SWITCH
        } else {
            0
        }) | (if self.limit(position, 1.0) {
            POSITIVE_LIMIT_SWITCH
        } else {
            0
        }) | (if self.dog(position) { HOME_SWITCH } else { 0 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_digital_inputs_follow_the_position() {
        let s = HomingSwitches {
            home_dog: Some([100.0, 200.0]),
            positive_limit: Some(1000.0),
            negative_limit: Some(-1000.0),
        };
        assert_eq!(s.digital_inputs(0.0), 0);
        assert_eq!(s.digital_inputs(150.0), HOME_SWITCH);
        assert_eq!(s.digital_inputs(200.0), HOME_SWITCH);
        assert_eq!(s.digital_inputs(200.5), 0);
        assert_eq!(s.digital_inputs(1000.0), POSITIVE_LIMIT_SWITCH);
        assert_eq!(s.digital_inputs(-1001.0), NEGATIVE_LIMIT_SWITCH);
        assert_eq!(HomingSwitches::default().digital_inputs(1e9), 0);
        assert_eq!(s.dog_end(1.0, true), Some(100.0));
        assert_eq!(s.dog_end(1.0, false), Some(200.0));
        assert_eq!(s.dog_end(-1.0, true), Some(200.0));
        assert_eq!(s.dog_end(-1.0, false), Some(100.0));
        assert_eq!(HomingSwitches::default().dog_end(1.0, true), None);
    }
}
