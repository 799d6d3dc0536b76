//! A searching homing method run by the simulated drive: the velocity generator that moves at
//! 6099h:1 until the dog, at the creep speed 6099h:2 to the Z phase, ramps at the homing
//! acceleration 609Ah, reverses or fails at a stroke end as the method says
//! (`profiles::homing_methods`), and finally positions on the home (Z phase + shift, or a dog
//! end + the travel distance after proximity dog + shift, or where the motor stands against a
//! stopper).
//!
//! Edges and the Z phase are found on the generator's position (the drive's command), so the
//! home is exact; the travel distance after proximity dog is measured from the dog's exact
//! edge (the manual's "error of ± (encoder resolution) × 100/65536 pulses at 100 r/min" from
//! reading the dog, MR-J4-TM manual §5.4.9(6)(e)/(f), is not emulated). The stopper type
//! (§5.4.9(6)(d)) is the one search that watches the motor: the drive tells each step whether
//! it stands at its torque limit. A failed search stops at the plant's maximum deceleration (MR-J3-T04 manual
//! §8.11.3: "stroke end during hm gives a sudden stop"). Allocation-free plain copies.

use super::ramp::VelocityRamp;
use crate::sim::homing_switches::HomingSwitches;
use cellrt_cia402::profiles::homing_methods::{SearchRecipe, SearchTarget, StrokeEndReaction};

/// The encoder's Z phase as the search sees it: every `counts_per_rev` from `position`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ZPulses {
    /// Counts per motor revolution.
    pub counts_per_rev: f64,
    /// Raw position of one Z pulse.
    pub position: f64,
}

impl ZPulses {
    /// The first Z pulse strictly after `from` up to and including `to`, in the direction of
    /// travel.
    fn crossed(&self, from: f64, to: f64) -> Option<f64> {
        let rev = self.counts_per_rev;
        if rev <= 0.0 || from == to {
            return None;
        }
        let k = if to > from {
            ((from - self.position) / rev).floor() + 1.0
        } else {
            ((from - self.position) / rev).ceil() - 1.0
        };
        let z = self.position + k * rev;
        let inside = if to > from { z <= to } else { z >= to };
        inside.then_some(z)
    }
}

/// The speeds and rates of one search, counts/s and counts/s².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchProfile {
    /// 6099h:1.
    pub fast: f64,
    /// 6099h:2.
    pub creep: f64,
    /// From 609Ah.
    pub acceleration: f64,
    /// The sudden stop of a failed search.
    pub emergency_deceleration: f64,
    /// The home position shift from the Z phase, counts, in the direction of the Z search.
    pub shift: f64,
    /// The "travel distance after proximity dog" (MR-J4-TM manual §5.4.9(4)), counts, in the
    /// search direction from the dog edge the method names.
    pub travel: f64,
    /// [Pr. PT10] stopper time, s: how long the motor stands at its torque limit before the
    /// stopper type takes its position as home (MR-J4-TM manual §5.4.9(6)(d)).
    pub stopper_time: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Against the search direction until the dog has been passed (on, then off).
    Retreat { seen: bool },
    /// In the search direction until the dog's front end (or, dogless, the Z phase).
    Seek,
    /// Through the dog at the creep speed until its rear end.
    ToRearEnd,
    /// Back away from the dog at the creep speed until it is off.
    LeaveDog,
    /// At `speed` in `dir` until the next Z phase.
    ZSearch { dir: f64, speed: f64 },
    /// At the creep speed until the travel distance after proximity dog ends at `end`, then
    /// the Z phase (count type −2/−34).
    Count { end: f64 },
    /// Positioning on the home; `rear_end_fails`: the dog's rear end passed above the creep
    /// speed is an AL. 90 (−10/−42 and the methods "same as" it).
    ToHome { target: f64, rear_end_fails: bool },
    /// Toward the stopper at 6099h:1; `held`: how long the motor has stood at its torque limit.
    Press { held: f64 },
    /// A failed search stopping.
    Failing,
}

/// How the search ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SearchEnd {
    /// At rest on the home, this raw position.
    Home(f64),
    /// Failed (stroke end, no creep before the dog's end); at rest.
    Failed,
}

/// The state of one running search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HomingSearch {
    recipe: SearchRecipe,
    profile: SearchProfile,
    phase: Phase,
    /// Generator velocity, counts/s.
    vel: f64,
    /// Generator position (the command), counts.
    pos: f64,
    dog_before: bool,
}

impl HomingSearch {
    /// Starts `recipe` at `position` at rest; a dog method started on the dog first leaves it
    /// backwards (MR-J3-T04 manual §8.11.4.1: "if started with the dog ON: first moves
    /// reverse").
    pub fn start(
        recipe: SearchRecipe,
        profile: SearchProfile,
        position: f64,
        switches: &HomingSwitches,
    ) -> Self {
        let on_dog = switches.dog(position);
        let phase = if recipe.target.uses_dog() && on_dog {
            Phase::Retreat { seen: true }
        } else if recipe.target == SearchTarget::Stopper {
            Phase::Press { held: 0.0 }
        } else if recipe.target == SearchTarget::Z {
            let speed = if recipe.creep_from_start {
                profile.creep
            } else {
                profile.fast
            };
            Phase::ZSearch {
                dir: f64::from(recipe.direction),
                speed,
            }
        } else {
            Phase::Seek
        };
        HomingSearch {
            recipe,
            profile,
            phase,
            vel: 0.0,
            pos: position,
            dog_before: on_dog,
        }
    }

    /// The method being run.
    pub fn recipe(&self) -> SearchRecipe {
        self.recipe
    }

    /// The generator velocity, counts/s.
    pub fn velocity(&self) -> f64 {
        self.vel
    }

    /// Stops the search (HOS dropped): the sudden stop of a failed one.
    pub fn interrupt(&mut self) {
        self.phase = Phase::Failing;
    }

    /// Whether the search has failed (or was interrupted) and is stopping.
    pub fn failing(&self) -> bool {
        self.phase == Phase::Failing
    }

    /// One cycle of `dt` s: returns the generator's (position, velocity) and, when it ended,
    /// how. `pressing`: the motor's position while it stands at its torque limit (the stopper
    /// type's end), else `None`.
    pub fn step(
        &mut self,
        switches: &HomingSwitches,
        z: ZPulses,
        pressing: Option<f64>,
        dt: f64,
    ) -> (f64, f64, Option<SearchEnd>) {
        let dir = f64::from(self.recipe.direction);
        let p = self.profile;
        let (goal, rate) = match self.phase {
            Phase::Retreat { .. } => (-dir * p.fast, p.acceleration),
            Phase::Seek => (dir * p.fast, p.acceleration),
            Phase::ToRearEnd | Phase::Count { .. } => (dir * p.creep, p.acceleration),
            Phase::Press { .. } => (dir * p.fast, p.acceleration),
            Phase::LeaveDog => (-dir * p.creep, p.acceleration),
            Phase::ZSearch { dir, speed } => (dir * speed, p.acceleration),
            Phase::ToHome { target, .. } => (self.approach(target, dt), p.acceleration),
            Phase::Failing => (0.0, p.emergency_deceleration),
        };
        let v0 = self.vel;
        let step = rate * dt;
        self.vel = VelocityRamp::symmetric(rate).step(v0, goal, dt);
        let from = self.pos;
        self.pos += 0.5 * (v0 + self.vel) * dt;
        if let Phase::ToHome { target, .. } = self.phase {
            // On the home, or past it this cycle with a speed one cycle's ramp can take away.
            let crossed = (target - self.pos) * (target - from) <= 0.0 && v0.abs() <= step;
            if crossed || ((target - self.pos).abs() < 0.5 && self.vel.abs() <= step) {
                self.pos = target;
                self.vel = 0.0;
                return (self.pos, 0.0, Some(SearchEnd::Home(target)));
            }
        }
        if self.phase == Phase::Failing {
            let end = (self.vel == 0.0).then_some(SearchEnd::Failed);
            return (self.pos, self.vel, end);
        }
        if let Phase::Press { held } = self.phase {
            // "Stop is judged after [Pr. PT10]": at the torque limit at standstill that long.
            let held = pressing.map_or(0.0, |_| held + dt);
            self.phase = Phase::Press { held };
            if let Some(at) = pressing.filter(|_| held >= p.stopper_time - 1e-9) {
                let home = at.round();
                self.pos = home;
                self.vel = 0.0;
                return (home, 0.0, Some(SearchEnd::Home(home)));
            }
        }
        self.advance(from, switches, z);
        (self.pos, self.vel, None)
    }

    /// The velocity that brakes onto `target` at the homing acceleration, at most the creep
    /// speed.
    fn approach(&self, target: f64, dt: f64) -> f64 {
        let d = target - self.pos;
        let a = self.profile.acceleration;
        let room = (d.abs() - 0.5 * self.vel.abs() * dt).max(0.0);
        d.signum() * self.profile.creep.min((2.0 * a * room).sqrt())
    }

    /// The phase changes of this cycle's travel `from` → the generator's position.
    fn advance(&mut self, from: f64, switches: &HomingSwitches, z: ZPulses) {
        let dir = f64::from(self.recipe.direction);
        let to = self.pos;
        let dog = switches.dog(to);
        let (rising, falling) = (dog && !self.dog_before, !dog && self.dog_before);
        self.dog_before = dog;
        let moving = self.vel.signum();
        // A limit counts while moving the way the phase heads (not while braking after a
        // reversal).
        let heading = match self.phase {
            Phase::Retreat { .. } | Phase::LeaveDog => -dir,
            Phase::ZSearch { dir, .. } => dir,
            Phase::ToHome { .. } | Phase::Failing => moving,
            Phase::Seek | Phase::ToRearEnd | Phase::Count { .. } | Phase::Press { .. } => dir,
        };
        if self.vel != 0.0 && moving == heading && switches.limit(to, moving) {
            let reverse = moving == dir
                && self.recipe.stroke_end == StrokeEndReaction::Reverse
                && matches!(self.phase, Phase::Seek | Phase::ZSearch { .. });
            self.phase = if reverse {
                Phase::Retreat { seen: false }
            } else {
                Phase::Failing
            };
            return;
        }
        let creep = self.profile.creep;
        let above_creep = self.vel.abs() > creep * (1.0 + 1e-9);
        let (travel, shift) = (self.profile.travel, self.profile.shift);
        // A dog end, exact where the switches give it.
        let edge = |front: bool| switches.dog_end(dir, front).unwrap_or(to);
        self.phase = match self.phase {
            Phase::Retreat { seen } if falling && (seen || rising) => Phase::Seek,
            Phase::Retreat { seen } => Phase::Retreat {
                seen: seen || rising,
            },
            Phase::Seek if rising => match self.recipe.target {
                SearchTarget::ZAfterDogRearEnd | SearchTarget::TravelAfterDogRearEnd => {
                    Phase::ToRearEnd
                }
                SearchTarget::ZAfterDogFrontEnd => Phase::ZSearch { dir, speed: creep },
                SearchTarget::ZLeavingDog | SearchTarget::Z => Phase::LeaveDog,
                SearchTarget::ZAfterTravel => Phase::Count {
                    end: edge(true) + dir * travel,
                },
                SearchTarget::TravelAfterDogFrontEnd { dog_outlasts_creep } => Phase::ToHome {
                    target: edge(true) + dir * (travel + shift),
                    rear_end_fails: dog_outlasts_creep,
                },
                SearchTarget::Stopper => self.phase,
            },
            // MR-J3-T04 AL.90: "could not decelerate to creep speed" before the dog's end;
            // MR-J4-TM −6/−38: "the rear end … detected without reaching the creep speed".
            Phase::ToRearEnd if falling && above_creep => Phase::Failing,
            Phase::ToRearEnd if falling => match self.recipe.target {
                SearchTarget::TravelAfterDogRearEnd => Phase::ToHome {
                    target: edge(false) + dir * (travel + shift),
                    rear_end_fails: false,
                },
                _ => Phase::ZSearch { dir, speed: creep },
            },
            // −10/−42: the rear end passed (moving on) before the creep speed.
            Phase::ToHome {
                rear_end_fails: true,
                ..
            } if falling && above_creep && self.vel * dir > 0.0 => Phase::Failing,
            // −2/−34: "the distance after proximity dog is traveled without reaching the creep
            // speed" is an AL. 90; else the first Z phase after the travel.
            Phase::Count { end } if (to - end) * dir >= 0.0 => {
                if above_creep {
                    Phase::Failing
                } else {
                    match z.crossed(end, to) {
                        Some(zp) => Phase::ToHome {
                            target: zp + dir * shift,
                            rear_end_fails: false,
                        },
                        None => Phase::ZSearch { dir, speed: creep },
                    }
                }
            }
            Phase::LeaveDog if !dog && self.vel * dir < 0.0 => Phase::ZSearch {
                dir: -dir,
                speed: creep,
            },
            Phase::ZSearch { dir: zdir, .. } => match z.crossed(from, to) {
                Some(zp) if (to - from) * zdir > 0.0 => Phase::ToHome {
                    target: zp + zdir * shift,
                    rear_end_fails: false,
                },
                _ => self.phase,
            },
            p => p,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_cia402::profiles::homing_methods::search;

    const Z: ZPulses = ZPulses {
        counts_per_rev: 10_000.0,
        position: 2_500.0,
    };
    const P: SearchProfile = SearchProfile {
        fast: 50_000.0,
        creep: 5_000.0,
        acceleration: 500_000.0,
        emergency_deceleration: 5_000_000.0,
        shift: 0.0,
        travel: 0.0,
        stopper_time: 0.1,
    };

    fn run(method: i8, start: f64, s: &HomingSwitches, p: SearchProfile) -> (SearchEnd, f64) {
        let mut h = HomingSearch::start(search(method).unwrap(), p, start, s);
        let mut peak: f64 = 0.0;
        for _ in 0..200_000 {
            let (_, v, end) = h.step(s, Z, None, 0.001);
            peak = peak.max(v.abs());
            if let Some(e) = end {
                return (e, peak);
            }
        }
        panic!("no end");
    }

    fn dog() -> HomingSwitches {
        HomingSwitches {
            home_dog: Some([30_000.0, 50_000.0]),
            positive_limit: Some(100_000.0),
            negative_limit: Some(-100_000.0),
        }
    }

    #[test]
    fn the_dog_type_homes_on_the_first_z_after_the_rear_end_plus_the_shift() {
        let (end, peak) = run(-1, 0.0, &dog(), P);
        assert_eq!(end, SearchEnd::Home(52_500.0));
        assert!(peak <= P.fast);
        let (end, _) = run(-1, 0.0, &dog(), SearchProfile { shift: 700.0, ..P });
        assert_eq!(end, SearchEnd::Home(53_200.0));
        // Started on the dog: out backwards first, then the same home.
        assert_eq!(run(-1, 40_000.0, &dog(), P).0, SearchEnd::Home(52_500.0));
        // Reverse: the first Z below the dog's lower end.
        assert_eq!(run(-33, 90_000.0, &dog(), P).0, SearchEnd::Home(22_500.0));
    }

    #[test]
    fn cradle_last_z_and_dogless_methods_home_on_their_z_phase() {
        assert_eq!(run(-8, 0.0, &dog(), P).0, SearchEnd::Home(32_500.0));
        assert_eq!(run(3, 0.0, &dog(), P).0, SearchEnd::Home(22_500.0));
        assert_eq!(run(-11, 0.0, &dog(), P).0, SearchEnd::Home(2_500.0));
        let (end, peak) = run(34, 3_000.0, &dog(), P);
        assert_eq!(end, SearchEnd::Home(12_500.0));
        assert!(peak <= P.creep);
    }

    #[test]
    fn a_stroke_end_reverses_or_fails_as_the_method_says() {
        // Started above the dog going forward: the limit reverses −1, back over the dog,
        // forward again.
        assert_eq!(run(-1, 70_000.0, &dog(), P).0, SearchEnd::Home(52_500.0));
        assert_eq!(run(7, 70_000.0, &dog(), P).0, SearchEnd::Home(22_500.0));
        assert_eq!(run(3, 70_000.0, &dog(), P).0, SearchEnd::Failed);
        // The MR-J4-TM's own dog cradle and last-Z types reverse (§5.4.9(6)(g), (h)), where
        // their CiA 402 twins 4 and 3 fail: the same homes as from below the dog.
        assert_eq!(run(-8, 70_000.0, &dog(), P).0, SearchEnd::Home(32_500.0));
        assert_eq!(run(4, 70_000.0, &dog(), P).0, SearchEnd::Failed);
        assert_eq!(run(-9, 70_000.0, &dog(), P).0, SearchEnd::Home(22_500.0));
        assert_eq!(run(-41, -70_000.0, &dog(), P).0, SearchEnd::Home(52_500.0));
        // No dog at all: both limits.
        let none = HomingSwitches {
            home_dog: None,
            ..dog()
        };
        assert_eq!(run(-1, 0.0, &none, P).0, SearchEnd::Failed);
    }

    #[test]
    fn a_ramp_steeper_than_one_cycle_still_lands_on_the_home() {
        // 1e9 counts/s²: a cycle's ramp step (1e6 counts/s) dwarfs the creep speed, whose
        // 5.0037 counts per cycle never fall within half a count of the home.
        let steep = SearchProfile {
            acceleration: 1.0e9,
            creep: 5_003.7,
            ..P
        };
        assert_eq!(run(-11, 0.0, &dog(), steep).0, SearchEnd::Home(2_500.0));
        assert_eq!(run(-1, 0.0, &dog(), steep).0, SearchEnd::Home(52_500.0));
    }

    /// `P` with the travel distance after proximity dog and the shift. From 6099h:1 to the
    /// creep speed takes (50 000² − 5 000²) / (2 × 500 000) = 2 475 counts.
    fn travel(travel: f64, shift: f64) -> SearchProfile {
        SearchProfile { travel, shift, ..P }
    }

    #[test]
    fn the_travel_methods_home_from_the_dog_edge_by_the_travel_distance_and_the_shift() {
        let (d, t) = (dog(), travel(3_000.0, 700.0));
        let short = HomingSwitches {
            home_dog: Some([30_000.0, 30_500.0]),
            ..dog()
        };
        for (method, start, switches, home) in [
            // −2: front end 30 000 + travel 3 000 = 33 000, next Z 42 500, + shift 700.
            (-2, 0.0, d, 43_200.0),
            // Any dog length: the same on a 500-count dog.
            (-2, 0.0, short, 43_200.0),
            // −34 (reverse): front end 50 000 − 3 000 = 47 000, Z below 42 500, − 700.
            (-34, 90_000.0, d, 41_800.0),
            // −6: rear end 50 000 + 3 000 + 700.
            (-6, 0.0, d, 53_700.0),
            // −38: rear end 30 000 − 3 000 − 700.
            (-38, 90_000.0, d, 26_300.0),
            // −7, −10, 19, 20, 23, 24: front end 30 000 + 3 000 + 700.
            (-7, 0.0, d, 33_700.0),
            (-7, 0.0, short, 33_700.0),
            (-10, 0.0, d, 33_700.0),
            (19, 0.0, d, 33_700.0),
            (20, 0.0, short, 33_700.0),
            (24, 0.0, d, 33_700.0),
            // −39, −42, 21, 22, 27, 28 (reverse): front end 50 000 − 3 000 − 700.
            (-39, 90_000.0, d, 46_300.0),
            (-42, 90_000.0, d, 46_300.0),
            (21, 90_000.0, d, 46_300.0),
            (28, 90_000.0, d, 46_300.0),
            // Started on the dog: out backwards first, then the same home.
            (-6, 40_000.0, d, 53_700.0),
            // Above the dog: the stroke end at 100 000 reverses −2 and 23.
            (-2, 70_000.0, d, 43_200.0),
            (23, 70_000.0, d, 33_700.0),
        ] {
            assert_eq!(
                run(method, start, &switches, t).0,
                SearchEnd::Home(home),
                "{method} from {start}"
            );
        }
        // Travel 0 on −7: the home is the front end itself, reached back after the 2 475
        // counts of braking.
        assert_eq!(
            run(-7, 0.0, &d, travel(0.0, 0.0)).0,
            SearchEnd::Home(30_000.0)
        );
    }

    #[test]
    fn the_travel_methods_fail_where_the_manual_gives_al_90() {
        let short = HomingSwitches {
            home_dog: Some([30_000.0, 30_500.0]),
            ..dog()
        };
        let t = travel(3_000.0, 0.0);
        // The 500-count dog ends before the 2 475 counts to the creep speed: −6, −10 and 19
        // fail, the cradle-motion 20 does not (checked above).
        for m in [-6, -10, 19, 23] {
            assert_eq!(run(m, 0.0, &short, t).0, SearchEnd::Failed, "{m}");
        }
        // −2: the 2 000-count travel is covered before the creep speed.
        assert_eq!(
            run(-2, 0.0, &dog(), travel(2_000.0, 0.0)).0,
            SearchEnd::Failed
        );
        // Stroke end in the search direction: 19–22 stop with AL. 90.
        for (m, start) in [
            (19, 70_000.0),
            (20, 70_000.0),
            (21, 10_000.0),
            (22, 10_000.0),
        ] {
            assert_eq!(run(m, start, &dog(), t).0, SearchEnd::Failed, "{m}");
        }
    }

    #[test]
    fn the_stopper_type_homes_where_the_motor_has_stood_at_its_torque_limit_for_pt10() {
        for (method, stopper) in [(-4, 60_000.0_f64), (-36, -60_000.0)] {
            let mut h = HomingSearch::start(search(method).unwrap(), P, 0.0, &dog());
            let mut pressed = 0;
            let end = (0..10_000).find_map(|_| {
                // The motor stands on the stopper once the command has reached it.
                let at = (h.pos.abs() >= stopper.abs()).then_some(stopper);
                pressed += u32::from(at.is_some());
                h.step(&dog(), Z, at, 0.001).2
            });
            assert_eq!(end, Some(SearchEnd::Home(stopper)), "{method}");
            // PT10 0.1 s at 1 ms: the 100th cycle at the torque limit ends the search.
            assert_eq!(pressed, 100, "{method}");
        }
        // No stopper before the stroke end: AL. 90.
        assert_eq!(run(-4, 0.0, &dog(), P).0, SearchEnd::Failed);
    }

    #[test]
    fn a_dog_too_short_to_reach_the_creep_speed_fails() {
        let short = HomingSwitches {
            home_dog: Some([30_000.0, 30_500.0]),
            ..dog()
        };
        assert_eq!(run(-1, 0.0, &short, P).0, SearchEnd::Failed);
    }
}
