//! A searching homing method run by the simulated drive: the velocity generator that moves at
//! 6099h:1 until the dog, at the creep speed 6099h:2 to the Z phase, ramps at the homing
//! acceleration 609Ah, reverses or fails at a stroke end as the method says
//! (`profiles::homing_methods`), and finally positions on the home (Z phase + shift).
//!
//! Edges and the Z phase are found on the generator's position (the drive's command), so the
//! home is exact. A failed search stops at the plant's maximum deceleration (MR-J3-T04 manual
//! §8.11.3: "stroke end during hm gives a sudden stop"). Allocation-free plain copies.

use crate::profiles::homing_methods::{SearchRecipe, SearchTarget, StrokeEndReaction};
use crate::sim::homing_switches::HomingSwitches;

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
    /// Positioning on the home.
    ToHome { target: f64 },
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
        let phase = if recipe.target != SearchTarget::Z && on_dog {
            Phase::Retreat { seen: true }
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
    /// how.
    pub fn step(
        &mut self,
        switches: &HomingSwitches,
        z: ZPulses,
        dt: f64,
    ) -> (f64, f64, Option<SearchEnd>) {
        let dir = f64::from(self.recipe.direction);
        let p = self.profile;
        let (goal, rate) = match self.phase {
            Phase::Retreat { .. } => (-dir * p.fast, p.acceleration),
            Phase::Seek => (dir * p.fast, p.acceleration),
            Phase::ToRearEnd => (dir * p.creep, p.acceleration),
            Phase::LeaveDog => (-dir * p.creep, p.acceleration),
            Phase::ZSearch { dir, speed } => (dir * speed, p.acceleration),
            Phase::ToHome { target } => (self.approach(target, dt), p.acceleration),
            Phase::Failing => (0.0, p.emergency_deceleration),
        };
        let v0 = self.vel;
        let step = rate * dt;
        self.vel = goal.clamp(v0 - step, v0 + step);
        let from = self.pos;
        self.pos += 0.5 * (v0 + self.vel) * dt;
        if let Phase::ToHome { target } = self.phase {
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
            Phase::Seek | Phase::ToRearEnd => dir,
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
        self.phase = match self.phase {
            Phase::Retreat { seen } if falling && (seen || rising) => Phase::Seek,
            Phase::Retreat { seen } => Phase::Retreat {
                seen: seen || rising,
            },
            Phase::Seek if rising => match self.recipe.target {
                SearchTarget::ZAfterDogRearEnd => Phase::ToRearEnd,
                SearchTarget::ZAfterDogFrontEnd => Phase::ZSearch { dir, speed: creep },
                SearchTarget::ZLeavingDog | SearchTarget::Z => Phase::LeaveDog,
            },
            // MR-J3-T04 AL.90: "could not decelerate to creep speed" before the dog's end.
            Phase::ToRearEnd if falling && self.vel.abs() > creep * (1.0 + 1e-9) => Phase::Failing,
            Phase::ToRearEnd if falling => Phase::ZSearch { dir, speed: creep },
            Phase::LeaveDog if !dog && self.vel * dir < 0.0 => Phase::ZSearch {
                dir: -dir,
                speed: creep,
            },
            Phase::ZSearch { dir: zdir, .. } => match z.crossed(from, to) {
                Some(zp) if (to - from) * zdir > 0.0 => Phase::ToHome {
                    target: zp + zdir * self.profile.shift,
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
    use crate::profiles::homing_methods::search;

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
    };

    fn run(method: i8, start: f64, s: &HomingSwitches, p: SearchProfile) -> (SearchEnd, f64) {
        let mut h = HomingSearch::start(search(method).unwrap(), p, start, s);
        let mut peak: f64 = 0.0;
        for _ in 0..200_000 {
            let (_, v, end) = h.step(s, Z, 0.001);
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

    #[test]
    fn a_dog_too_short_to_reach_the_creep_speed_fails() {
        let short = HomingSwitches {
            home_dog: Some([30_000.0, 30_500.0]),
            ..dog()
        };
        assert_eq!(run(-1, 0.0, &short, P).0, SearchEnd::Failed);
    }
}
