//! The profile and the steps the motion modules' tests share (pp toward one revolution on a
//! 131072-pulse encoder, 1 ms ticks).

use std::time::Duration;

use super::motion::Motion;
use super::profile::Target;
use super::profile::TorquePlant;
use super::profile::{Profile, Ramp, PROFILE_POSITION};
use cellrt_cia402::controlword::Controlword;

/// pp toward one revolution at 600 r/min with 100 ms ramps, on a 131072-pulse encoder.
pub fn pp() -> Profile {
    Profile {
        mode: PROFILE_POSITION,
        target_position: 131_072,
        target_velocity: 0,
        profile_velocity: 60_000, // 600 r/min = 10 rev/s
        acceleration_ms: 100,
        deceleration_ms: 100,
        rated_speed: 300_000,
        max_speed: 600_000,
        units_per_rev: 131_072,
        position_window: 100,
        velocity_window: 2000,
        homing_method: 37,
        homing_acceleration_ms: 0,
        homing_speed: 10_000,
        home_offset: 0,
        target_torque: 0,
        torque_slope: 0,
        positive_torque_limit: 3000,
        negative_torque_limit: 3000,
        velocity_limit: 50_000,
        plant: TorquePlant::default(),
        point: Target::None,
        indexer_station: 0,
        indexer_ramp: Ramp {
            acceleration_ms: 100,
            deceleration_ms: 100,
        },
        s_pattern_ms: 0,
        position_loop_gain: 1000.0,
    }
}

/// Steps of 1 ms; the peak speed in 0.01 r/min.
pub fn run(m: &mut Motion, p: &Profile, ms: u64) -> i64 {
    let mut peak = 0;
    for _ in 0..ms {
        m.advance(Duration::from_millis(1), p, false);
        peak = peak.max(m.velocity(p).abs());
    }
    peak
}

/// The controlword `word`.
pub fn cw(word: u16) -> Controlword {
    Controlword(word)
}

/// Runs `ms` steps of 1 ms with the halt bit `halted`.
pub fn run_halted(m: &mut Motion, p: &Profile, ms: u64, halted: bool) {
    for _ in 0..ms {
        m.advance(Duration::from_millis(1), p, halted);
    }
}
