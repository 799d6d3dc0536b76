//! The homing methods (6098h) the manuals describe, as searches the simulated drive runs: what
//! is searched (dog edges, the Z phase), the starting direction, what a stroke end does, and
//! per model the warning of a failed homing and the object of the home position shift.
//!
//! Sources: MR-J3-T04 manual §8.11.4.1 (−1, −17 dog type, 35 data set), MR-J4-TM manual
//! §5.4.9(4)/(5)/(6) (the 39 methods of 60E3h). Every method the MR-J4-TM manual lists is
//! emulated; the figures it names without a number or default (the "travel distance after
//! proximity dog", [Pr. PT10] stopper time, [Pr. PT11] stopper torque limit) are named
//! parameters of the simulated drive (`sim::drive::HomingParams`). [`check_emulated`]
//! refuses a method a manual does not list. The MR-JET-G-N1 and MR-J5-G-N1 manuals list no
//! methods (MR-JET-G-N1 manual §8.3,
//! MR-J5-G-N1 manual §8.3: "Set the homing method in 6098h … for details refer to 'Homing mode
//! (hm) and homing' in the Function manual", which is not among the manuals).

use super::{DriveModel, DriveProfile};

/// What the search ends on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchTarget {
    /// Decelerate at the dog's front end; after its rear end, the first Z phase (MR-J3-T04
    /// −1/−17, MR-J4-TM −1/−33 dog type, rear-end detection, Z-phase reference).
    ZAfterDogRearEnd,
    /// The first Z phase after the dog's front end (MR-J4-TM −8/−40 dog cradle type, 4/6/8/12).
    ZAfterDogFrontEnd,
    /// After the dog's front end, back away from the dog; the first Z phase once it is off
    /// (MR-J4-TM −9/−41 last Z-phase reference, 3/5/7/11).
    ZLeavingDog,
    /// The first Z phase, no dog (MR-J4-TM −11/−43 dogless, 33/34 homing on index pulse).
    Z,
    /// Decelerate at the dog's front end, travel the "travel distance after proximity dog"
    /// from it, then the next Z phase (MR-J4-TM −2/−34 count type, front-end detection,
    /// Z-phase reference, §5.4.9(6)(b): any dog length; AL. 90 if the travel is covered
    /// before the creep speed is reached).
    ZAfterTravel,
    /// Decelerate at the dog's front end; home = its rear end + the travel distance after
    /// proximity dog (+ shift) (MR-J4-TM −6/−38 dog type, rear-end reference, §5.4.9(6)(e):
    /// AL. 90 if the rear end comes before the creep speed is reached).
    TravelAfterDogRearEnd,
    /// Decelerate at the dog's front end; home = the front end + the travel distance after
    /// proximity dog (+ shift).
    TravelAfterDogFrontEnd {
        /// The dog's rear end before the creep speed is reached is an AL. 90: the dog type
        /// front-end reference (−10/−42, §5.4.9(6)(i)) and 19/21/23/27 ("same as the dog
        /// type front end reference", §5.4.9(4)). False: the count type −7/−39 (§5.4.9(6)(f),
        /// any dog length) and 20/22/24/28 (the dog cradle motion, §5.4.9(5)(b)6), 8), whose
        /// figures give no such note).
        dog_outlasts_creep: bool,
    },
    /// Press against a mechanical stopper at 6099h:1 with the torque limited; home = where
    /// the motor stands once it has stood at the torque limit for [Pr. PT10] (MR-J4-TM
    /// −4/−36 stopper type, §5.4.9(6)(d)).
    Stopper,
}

impl SearchTarget {
    /// Whether the search looks for the home dog (and first leaves it when started on it).
    pub fn uses_dog(self) -> bool {
        !matches!(self, SearchTarget::Z | SearchTarget::Stopper)
    }
}

/// What a limit switch reached in the search direction does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrokeEndReaction {
    /// Homing error (statusword bit 13) and the model's warning (MR-J4-TM 3–6: "stroke end →
    /// AL. 90").
    Error,
    /// Stop, go back past the dog, search again (MR-J3-T04 −1: "reverse until the reverse-side
    /// dog edge, then retry"; MR-J4-TM 7/8/11/12: "the stroke end reverses the search"). The
    /// limit on the other side is a homing error.
    Reverse,
}

/// One searching method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SearchRecipe {
    /// Starting direction: +1 forward (positive counts), −1 reverse.
    pub direction: i8,
    /// What the search ends on.
    pub target: SearchTarget,
    /// A limit switch reached in the search direction.
    pub stroke_end: StrokeEndReaction,
    /// The creep speed 6099h:2 from the start (MR-J4-TM 33/34); otherwise 6099h:1 until the
    /// dog (or, dogless, the Z phase).
    pub creep_from_start: bool,
}

const fn recipe(
    direction: i8,
    target: SearchTarget,
    stroke_end: StrokeEndReaction,
) -> SearchRecipe {
    SearchRecipe {
        direction,
        target,
        stroke_end,
        creep_from_start: false,
    }
}

/// The search of `method`, where cellrt emulates one (the data-set methods do not search).
pub fn search(method: i8) -> Option<SearchRecipe> {
    use SearchTarget::*;
    use StrokeEndReaction::*;
    Some(match method {
        -1 => recipe(1, ZAfterDogRearEnd, Reverse),
        -17 | -33 => recipe(-1, ZAfterDogRearEnd, Reverse),
        // §5.4.9(6)(g), (h): the dog cradle and last-Z dog types reverse at a stroke end ("when
        // the movement is returned at the stroke end"); their CiA 402 twins 3–6 stop with AL. 90.
        4 => recipe(1, ZAfterDogFrontEnd, Error),
        6 => recipe(-1, ZAfterDogFrontEnd, Error),
        -8 | 8 => recipe(1, ZAfterDogFrontEnd, Reverse),
        -40 | 12 => recipe(-1, ZAfterDogFrontEnd, Reverse),
        3 => recipe(1, ZLeavingDog, Error),
        5 => recipe(-1, ZLeavingDog, Error),
        -9 => recipe(1, ZLeavingDog, Reverse),
        -41 => recipe(-1, ZLeavingDog, Reverse),
        7 => recipe(1, ZLeavingDog, Reverse),
        11 => recipe(-1, ZLeavingDog, Reverse),
        -11 => recipe(1, Z, Error),
        -43 => recipe(-1, Z, Error),
        // §5.4.9(6)(b), (d)–(f), (i) and §5.4.9(5)(b)5)–8): the stroke-end figures "when the
        // movement is returned at the stroke end" (reverse) and "the servo motor stops due to
        // the occurrence of [AL. 90]" (error).
        -2 => recipe(1, ZAfterTravel, Reverse),
        -34 => recipe(-1, ZAfterTravel, Reverse),
        -4 => recipe(1, Stopper, Error),
        -36 => recipe(-1, Stopper, Error),
        -6 => recipe(1, TravelAfterDogRearEnd, Reverse),
        -38 => recipe(-1, TravelAfterDogRearEnd, Reverse),
        -7 | -39 | -10 | -42 | 19..=24 | 27 | 28 => {
            let forward = matches!(method, -7 | -10 | 19 | 20 | 23 | 24);
            let stroke_end = if (19..=22).contains(&method) {
                Error
            } else {
                Reverse
            };
            let dog_outlasts_creep = matches!(method, -10 | -42 | 19 | 21 | 23 | 27);
            recipe(
                if forward { 1 } else { -1 },
                TravelAfterDogFrontEnd { dog_outlasts_creep },
                stroke_end,
            )
        }
        33 | 34 => SearchRecipe {
            creep_from_start: true,
            ..recipe(if method == 34 { 1 } else { -1 }, Z, Error)
        },
        _ => return None,
    })
}

/// Whether the simulated `profile` runs `method`: listed by its manual and either a data-set
/// method or an emulated search; the refusal names the method and the manual.
pub fn check_emulated(
    profile: &DriveProfile,
    method: i8,
) -> Result<(), crate::homing::HomingChoiceError> {
    use crate::homing::HomingChoiceError;
    let model = profile.name;
    if profile.homing.methods.is_empty() {
        return Err(HomingChoiceError::NoMethods {
            model,
            statement: no_methods_statement(profile.model),
        });
    }
    if !profile.homing.methods.contains(&method) {
        return Err(HomingChoiceError::NotListed {
            model,
            method,
            listed: profile.homing.methods.to_vec(),
        });
    }
    if profile.homing.data_set_methods.contains(&method) || search(method).is_some() {
        return Ok(());
    }
    Err(HomingChoiceError::NotEmulated { model, method })
}

/// What a manual without a method list says instead, for the refusal.
pub fn no_methods_statement(model: DriveModel) -> &'static str {
    match model {
        DriveModel::MrJetGN1 => {
            "its §8.3 says only \"Set the homing method in [Homing method (Obj. 6098h)], then \
             perform homing\" and refers to the Function manual, which is not among the manuals"
        }
        DriveModel::MrJ5GN1 | DriveModel::MrJ5W2GN1 | DriveModel::MrJ5W3GN1 => {
            "its §8.3 says only \"set any homing method in [Homing method (Obj. 6098h)]\" and \
             refers to the Function manual's \"Homing mode (hm) and homing\", which is not among \
             the manuals"
        }
        _ => "it gives no method table",
    }
}

/// What a model's manual names around its searches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomingModel {
    /// The warning of a failed search (MR-J3-T04 AL.90 "Home position not completed", §7.2;
    /// MR-J4-TM AL. 90 "Home position return incomplete warning", §9).
    pub warning: Option<u16>,
    /// The object of the home position shift distance (pulses from the Z phase), where the
    /// manual gives one (MR-J3-T04 2080h, §8.11.4.1; the MR-J4-TM manual names the shift but
    /// not its object).
    pub shift_object: Option<u16>,
}

/// The homing facts of `model` beyond its method list.
pub fn homing_model(model: DriveModel) -> HomingModel {
    match model {
        DriveModel::MrJ3T04 => HomingModel {
            warning: Some(super::mr_j3_t04::AL_90),
            shift_object: Some(HOME_POSITION_SHIFT),
        },
        DriveModel::MrJ4TM => HomingModel {
            warning: Some(super::mr_j4_tm::AL_90),
            shift_object: None,
        },
        _ => HomingModel {
            warning: None,
            shift_object: None,
        },
    }
}

/// MR-J3-T04 2080h Home position shift distance (U32, pulses, §8.11.4.1).
pub const HOME_POSITION_SHIFT: u16 = 0x2080;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profiles::profile;

    #[test]
    fn each_model_refuses_what_its_manual_does_not_list_or_cellrt_does_not_emulate() {
        let j3 = profile(DriveModel::MrJ3T04);
        for m in [-1, -17, 35] {
            check_emulated(j3, m).unwrap();
        }
        assert!(check_emulated(j3, -33)
            .unwrap_err()
            .to_string()
            .contains("lists no homing method -33"));
        let j4 = profile(DriveModel::MrJ4TM);
        // Every method of the MR-J4-TM's list (§5.4.9(4)), 39 as 60E3h:0 says.
        assert_eq!(j4.homing.methods.len(), 39);
        for &m in j4.homing.methods {
            check_emulated(j4, m).unwrap_or_else(|e| panic!("{m}: {e}"));
        }
        for m in [-17, 1, 2, 17, 25, 26, 29, 30] {
            assert!(
                check_emulated(j4, m)
                    .unwrap_err()
                    .to_string()
                    .contains("lists no homing method"),
                "{m}"
            );
        }
        let jet = profile(DriveModel::MrJetGN1);
        assert!(check_emulated(jet, 37)
            .unwrap_err()
            .to_string()
            .contains("§8.3"));
    }

    #[test]
    fn the_j4_travel_and_stopper_methods_have_the_manuals_direction_and_stroke_end() {
        use SearchTarget::*;
        use StrokeEndReaction::*;
        let front = |dog_outlasts_creep| TravelAfterDogFrontEnd { dog_outlasts_creep };
        for (m, dir, target, stroke_end) in [
            (-2, 1, ZAfterTravel, Reverse),
            (-34, -1, ZAfterTravel, Reverse),
            (-4, 1, Stopper, Error),
            (-36, -1, Stopper, Error),
            (-6, 1, TravelAfterDogRearEnd, Reverse),
            (-38, -1, TravelAfterDogRearEnd, Reverse),
            (-7, 1, front(false), Reverse),
            (-39, -1, front(false), Reverse),
            (-10, 1, front(true), Reverse),
            (-42, -1, front(true), Reverse),
            (19, 1, front(true), Error),
            (20, 1, front(false), Error),
            (21, -1, front(true), Error),
            (22, -1, front(false), Error),
            (23, 1, front(true), Reverse),
            (24, 1, front(false), Reverse),
            (27, -1, front(true), Reverse),
            (28, -1, front(false), Reverse),
        ] {
            let r = search(m).unwrap();
            assert_eq!(
                (r.direction, r.target, r.stroke_end, r.creep_from_start),
                (dir, target, stroke_end, false),
                "{m}"
            );
        }
        assert!(!Stopper.uses_dog() && !Z.uses_dog() && ZAfterTravel.uses_dog());
    }
}
