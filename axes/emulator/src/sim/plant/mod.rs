//! A deterministic servo plant: P position loop over a P velocity loop with velocity and
//! acceleration (torque) saturation, integrated at a fixed substep.
//!
//! Not from the manual (the communication manual has no servo-loop data); a simple model with
//! the qualitative behaviour of a position-controlled servo, fixed so runs are reproducible.

mod cycle_map;

use std::f64::consts::TAU;
use std::sync::Arc;

pub use cycle_map::{CycleMap, CycleMapPool, MAX_MAPPED_SUBSTEPS};

/// Longest internal integration step; every cycle is split into equal substeps no longer than this.
pub const MAX_SUBSTEP_S: f64 = 62.5e-6;
/// Fewest substeps per call (the brief's dt/4 at the shortest cycles).
pub const MIN_SUBSTEPS: u32 = 4;
/// Most substeps per call; bounds the work when a long time span is integrated at once.
pub const MAX_SUBSTEPS: u32 = 4096;

/// Servo-loop tuning and limits, in position counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantParams {
    /// Position loop bandwidth; the position gain is 2π·this (1/s).
    pub position_bandwidth_hz: f64,
    /// Velocity loop bandwidth; the velocity gain is 2π·this (1/s).
    pub velocity_bandwidth_hz: f64,
    /// Velocity saturation in counts/s.
    pub max_velocity: f64,
    /// Acceleration saturation in counts/s², the proxy for the torque limit.
    pub max_acceleration: f64,
}

impl Default for PlantParams {
    /// 15 Hz position / 150 Hz velocity loop, 4 M counts/s, 40 M counts/s²: a ramp at
    /// 1 M counts/s lags by about 10 600 counts without feed-forward.
    fn default() -> Self {
        PlantParams {
            position_bandwidth_hz: 15.0,
            velocity_bandwidth_hz: 150.0,
            max_velocity: 4.0e6,
            max_acceleration: 4.0e7,
        }
    }
}

/// Mechanical stoppers on the axis, raw counts: hard stops the motor cannot pass (the plant
/// is not a catalogue model: the stop is rigid, the motor comes to rest on it at once and keeps
/// pushing with whatever torque its loops command). The MR-J4-TM stopper type homing (−4/−36,
/// MR-J4-TM manual §5.4.9(6)(d)) presses against one. Default none.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stoppers {
    /// The motor cannot move above this position.
    pub positive: Option<f64>,
    /// The motor cannot move below this position.
    pub negative: Option<f64>,
}

impl Stoppers {
    /// `position` held within the stoppers: the clamped position, and whether a stopper took it.
    fn clamp(&self, position: f64) -> (f64, bool) {
        match (self.positive, self.negative) {
            (Some(p), _) if position > p => (p, true),
            (_, Some(n)) if position < n => (n, true),
            _ => (position, false),
        }
    }
}

/// The motor and its servo loops, in counts, counts/s and counts/s².
#[derive(Debug, Clone, PartialEq)]
pub struct ServoPlant {
    params: PlantParams,
    position: f64,
    velocity: f64,
    acceleration: f64,
    /// The position command at the end of the previous step (interpolation start).
    last_command: f64,
    /// Fractions of `max_acceleration` allowed in the positive / negative direction (torque
    /// limits 60E0h/60E1h), 0.0…1.0.
    accel_scale: (f64, f64),
    /// The servo-on recurrence composed over one cycle (see [`ServoPlant::prepare_cycle`]).
    cycle_map: Option<Arc<CycleMap>>,
    /// Hard stops the motor cannot pass.
    stoppers: Stoppers,
}

impl ServoPlant {
    /// A plant at rest at `initial_position_counts`.
    pub fn new(params: PlantParams, initial_position_counts: f64) -> Self {
        ServoPlant {
            params,
            position: initial_position_counts,
            velocity: 0.0,
            acceleration: 0.0,
            last_command: initial_position_counts,
            accel_scale: (1.0, 1.0),
            cycle_map: None,
            stoppers: Stoppers::default(),
        }
    }

    /// The plant with mechanical `stoppers` (a start beyond one is moved onto it).
    pub fn with_stoppers(mut self, stoppers: Stoppers) -> Self {
        self.stoppers = stoppers;
        (self.position, _) = stoppers.clamp(self.position);
        self.last_command = self.position;
        self
    }

    /// Precomputes the servo-on step for time steps of exactly `dt_s` (the drive's cycle), so
    /// [`ServoPlant::step`] costs a few dot products while no limit engages. Same model: a
    /// step that would saturate anywhere still runs the substep loop. Each plant builds its own
    /// map (a few hundred multiplications); a bus then shares equal ones
    /// ([`ServoPlant::share_cycle_map`]). Allocates; call at start-up, not in the cycle.
    pub fn prepare_cycle(&mut self, dt_s: f64) {
        let (n, h) = Self::substeps(dt_s);
        let kp = TAU * self.params.position_bandwidth_hz;
        let kv = TAU * self.params.velocity_bandwidth_hz;
        let g = if h > 0.0 { (kv * h).min(1.0) / h } else { 0.0 };
        self.cycle_map = CycleMap::build(dt_s, n, h, kp, g).map(Arc::new);
    }

    /// Uses an equal map of `pool` instead of this plant's own (or adds it there). Start-up only.
    pub fn share_cycle_map(&mut self, pool: &mut CycleMapPool) {
        if let Some(map) = self.cycle_map.as_mut() {
            pool.share(map);
        }
    }

    /// Whether this plant and `other` read the very same cycle map (not merely an equal one).
    pub fn shares_cycle_map_with(&self, other: &ServoPlant) -> bool {
        matches!((&self.cycle_map, &other.cycle_map), (Some(a), Some(b)) if Arc::ptr_eq(a, b))
    }

    /// Whether a prepared cycle map serves steps of `dt_s`.
    pub fn has_cycle_map(&self, dt_s: f64) -> bool {
        self.cycle_map.as_ref().is_some_and(|m| m.dt_s == dt_s)
    }

    fn substeps(dt_s: f64) -> (u32, f64) {
        if dt_s.is_nan() || dt_s <= 0.0 {
            return (0, 0.0);
        }
        let n = (dt_s / MAX_SUBSTEP_S).ceil();
        let n = if n.is_finite() {
            n as u32
        } else {
            MAX_SUBSTEPS
        };
        let n = n.clamp(MIN_SUBSTEPS, MAX_SUBSTEPS);
        (n, dt_s / f64::from(n))
    }

    /// Servo on for `dt_s`: follow `position_command`, linearly interpolated from the previous
    /// command over the step, with `velocity_feedforward` (counts/s) added to the velocity command.
    pub fn step(&mut self, position_command: f64, velocity_feedforward: f64, dt_s: f64) {
        let ff = if velocity_feedforward.is_finite() {
            velocity_feedforward
        } else {
            0.0
        };
        if self.step_mapped(position_command, ff, dt_s) {
            return;
        }
        self.step_substeps(position_command, ff, dt_s);
    }

    /// [`ServoPlant::step`] through the cycle map; false (nothing changed) when there is no map
    /// for `dt_s` or a limit would engage.
    fn step_mapped(&mut self, position_command: f64, ff: f64, dt_s: f64) -> bool {
        let Some(map) = self.cycle_map.as_deref() else {
            return false;
        };
        if map.dt_s != dt_s {
            return false;
        }
        let amax = self.params.max_acceleration.abs();
        let lim = cycle_map::Limits {
            vmax: self.params.max_velocity.abs(),
            accel_hi: amax * self.accel_scale.0,
            accel_lo: -amax * self.accel_scale.1,
        };
        let p0 = self.position;
        let z = [
            self.velocity,
            self.last_command - p0,
            position_command - p0,
            ff,
        ];
        let Some(end) = map.step(z, lim) else {
            return false;
        };
        if self.stoppers.clamp(p0 + end.delta_position).1 {
            // Reaching a stopper: the substep loop stops the motor on it.
            return false;
        }
        self.position = p0 + end.delta_position;
        self.velocity = end.velocity;
        self.acceleration = end.acceleration;
        self.last_command = position_command;
        true
    }

    /// [`ServoPlant::step`] integrated substep by substep, with every saturation.
    fn step_substeps(&mut self, position_command: f64, ff: f64, dt_s: f64) {
        let (n, h) = Self::substeps(dt_s);
        let kp = TAU * self.params.position_bandwidth_hz;
        let kv = TAU * self.params.velocity_bandwidth_hz;
        // An explicit step never overshoots the velocity command: gain·h is capped at 1.
        let kv_h = (kv * h).min(1.0);
        let vmax = self.params.max_velocity.abs();
        let amax = self.params.max_acceleration.abs();
        let start = self.last_command;
        for i in 1..=n {
            let frac = f64::from(i) / f64::from(n);
            let cmd = start + (position_command - start) * frac;
            let v_cmd = (ff + kp * (cmd - self.position)).clamp(-vmax, vmax);
            let a = if h > 0.0 {
                (kv_h * (v_cmd - self.velocity) / h)
                    .clamp(-amax * self.accel_scale.1, amax * self.accel_scale.0)
            } else {
                0.0
            };
            self.integrate(a, h, vmax);
        }
        if n > 0 {
            self.last_command = position_command;
        }
    }

    /// Torque control for `dt_s`: accelerate at `acceleration` (counts/s², clamped by the torque
    /// limits) while keeping |velocity| ≤ `velocity_limit` (the cst speed limit 2D20h).
    pub fn step_torque(&mut self, acceleration: f64, velocity_limit: f64, dt_s: f64) {
        let (n, h) = Self::substeps(dt_s);
        let amax = self.params.max_acceleration.abs();
        let vlim = velocity_limit.abs().min(self.params.max_velocity.abs());
        let a_cmd = if acceleration.is_finite() {
            acceleration.clamp(-amax * self.accel_scale.1, amax * self.accel_scale.0)
        } else {
            0.0
        };
        for _ in 0..n {
            // Speed limit: never accelerate beyond ±vlim; brake back inside it at max torque.
            let a = if h <= 0.0 {
                0.0
            } else if self.velocity + a_cmd * h > vlim {
                ((vlim - self.velocity) / h).clamp(-amax, amax)
            } else if self.velocity + a_cmd * h < -vlim {
                ((-vlim - self.velocity) / h).clamp(-amax, amax)
            } else {
                a_cmd
            };
            self.integrate(a, h, vlim);
        }
        if n > 0 {
            self.last_command = self.position;
        }
    }

    /// Sets the torque limits as fractions of `max_acceleration` (clamped to 0.0…1.0); 0.0 in a
    /// direction means no torque there.
    pub fn set_torque_limits(&mut self, positive: f64, negative: f64) {
        let c = |v: f64| {
            if v.is_finite() {
                v.clamp(0.0, 1.0)
            } else {
                1.0
            }
        };
        self.accel_scale = (c(positive), c(negative));
    }

    /// Servo off (or a stop ramp) for `dt_s`: decelerate to standstill at `max_acceleration`.
    ///
    /// Takes the time step like [`ServoPlant::step`]; the interpolation start follows the
    /// position so a later servo-on starts from where the motor is.
    pub fn hold(&mut self, dt_s: f64) {
        let (n, h) = Self::substeps(dt_s);
        if self.velocity == 0.0 && n > 0 {
            // At standstill every substep is a no-op.
            self.acceleration = 0.0;
            self.last_command = self.position;
            return;
        }
        let amax = self.params.max_acceleration.abs();
        let vmax = self.params.max_velocity.abs();
        for _ in 0..n {
            // Decelerate, but never past zero within one substep.
            let a = if h > 0.0 {
                (-self.velocity / h).clamp(-amax, amax)
            } else {
                0.0
            };
            self.integrate(a, h, vmax);
        }
        if n > 0 {
            self.last_command = self.position;
        }
    }

    /// No torque for `dt_s` (safe torque off, energy cut): the motor keeps its speed, as
    /// friction and load are not modelled; the interpolation start follows the position.
    pub fn coast(&mut self, dt_s: f64) {
        self.acceleration = 0.0;
        if dt_s > 0.0 {
            self.position += self.velocity * dt_s;
        }
        let (position, stopped) = self.stoppers.clamp(self.position);
        if stopped {
            self.position = position;
            self.velocity = 0.0;
        }
        self.last_command = self.position;
    }

    fn integrate(&mut self, a: f64, h: f64, vmax: f64) {
        self.acceleration = a;
        self.velocity = (self.velocity + a * h).clamp(-vmax, vmax);
        let (position, stopped) = self.stoppers.clamp(self.position + self.velocity * h);
        self.position = position;
        if stopped {
            // On the stopper: at rest, the torque `a` pushing against it.
            self.velocity = 0.0;
        }
    }

    /// Sets the interpolation start, e.g. to the first target after servo-on.
    pub fn set_last_command(&mut self, position_command: f64) {
        self.last_command = position_command;
    }

    /// Ends a residual creep below the encoder's speed resolution: velocity and acceleration
    /// 0 (the loops' exponential settling never reaches exact zero by itself).
    pub fn come_to_rest(&mut self) {
        self.velocity = 0.0;
        self.acceleration = 0.0;
    }

    /// Motor position in counts.
    pub fn position(&self) -> f64 {
        self.position
    }

    /// Motor velocity in counts/s.
    pub fn velocity(&self) -> f64 {
        self.velocity
    }

    /// Acceleration of the last substep in counts/s² (the torque proxy).
    pub fn acceleration(&self) -> f64 {
        self.acceleration
    }

    /// The last substep's acceleration is at a torque limit (S_TLC): pushing with all the
    /// torque the limits allow in its direction.
    pub fn at_torque_limit(&self) -> bool {
        let amax = self.params.max_acceleration.abs();
        let a = self.acceleration;
        (a > 0.0 && a >= amax * self.accel_scale.0 * (1.0 - 1e-9))
            || (a < 0.0 && -a >= amax * self.accel_scale.1 * (1.0 - 1e-9))
    }

    /// The parameters the plant was built with.
    pub fn params(&self) -> &PlantParams {
        &self.params
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 1e-3;

    #[test]
    fn ramp_gives_bounded_nonzero_following_error() {
        let p = PlantParams::default();
        let mut plant = ServoPlant::new(p, 0.0);
        let v = 1.0e6;
        let mut max_err: f64 = 0.0;
        let mut last_err = 0.0;
        for k in 1..=2000 {
            let cmd = v * DT * f64::from(k);
            plant.step(cmd, 0.0, DT);
            last_err = cmd - plant.position();
            max_err = max_err.max(last_err.abs());
        }
        let kp = TAU * p.position_bandwidth_hz;
        // Steady state of a P position loop without feed-forward: e = v / Kp.
        assert!(
            (last_err - v / kp).abs() < 0.02 * v / kp,
            "{last_err} vs {}",
            v / kp
        );
        assert!(max_err < 2.0 * v / kp, "{max_err}");
        assert!((plant.velocity() - v).abs() < 1.0);
    }

    #[test]
    fn feedforward_shrinks_the_error() {
        let mut a = ServoPlant::new(PlantParams::default(), 0.0);
        let mut b = ServoPlant::new(PlantParams::default(), 0.0);
        let v = 1.0e6;
        for k in 1..=1000 {
            let cmd = v * DT * f64::from(k);
            a.step(cmd, 0.0, DT);
            b.step(cmd, v, DT);
        }
        let cmd = v * DT * 1000.0;
        assert!((cmd - b.position()).abs() < 0.1 * (cmd - a.position()).abs());
    }

    #[test]
    fn velocity_and_acceleration_saturate() {
        let p = PlantParams::default();
        let mut plant = ServoPlant::new(p, 0.0);
        for _ in 0..1000 {
            plant.step(1.0e9, 0.0, DT);
            assert!(plant.velocity().abs() <= p.max_velocity);
            assert!(plant.acceleration().abs() <= p.max_acceleration);
        }
        assert!((plant.velocity() - p.max_velocity).abs() < 1e-3);
    }

    #[test]
    fn hold_stops_at_max_deceleration() {
        let p = PlantParams::default();
        let mut plant = ServoPlant::new(p, 0.0);
        for _ in 0..500 {
            plant.step(1.0e9, 0.0, DT);
        }
        // 4e6 / 4e7 = 0.1 s to stop: not yet stopped after 90 ms, stopped after 110 ms.
        for _ in 0..90 {
            plant.hold(DT);
        }
        assert!(plant.velocity() > 0.0);
        for _ in 0..20 {
            plant.hold(DT);
        }
        assert_eq!(plant.velocity(), 0.0);
    }

    #[test]
    fn garbage_time_steps_do_nothing() {
        let mut plant = ServoPlant::new(PlantParams::default(), 5.0);
        plant.step(100.0, f64::NAN, f64::NAN);
        plant.step(100.0, 0.0, -1.0);
        plant.hold(0.0);
        assert_eq!(plant.position(), 5.0);
        plant.step(100.0, f64::INFINITY, 1e300);
        assert!(plant.position().is_finite());
    }
}

#[cfg(test)]
mod stopper_tests {
    use super::*;

    #[test]
    fn a_stopper_holds_the_motor_which_pushes_at_its_torque_limit() {
        let stoppers = Stoppers {
            positive: Some(10_000.0),
            negative: Some(-5_000.0),
        };
        for mapped in [false, true] {
            let mut p = ServoPlant::new(PlantParams::default(), 0.0).with_stoppers(stoppers);
            if mapped {
                p.prepare_cycle(1e-3);
            }
            p.set_torque_limits(0.05, 1.0);
            // A command running on past the stopper at 100 000 counts/s.
            for k in 1..=300 {
                p.step(100.0 * f64::from(k), 100_000.0, 1e-3);
                assert!(
                    p.position() <= 10_000.0,
                    "passed the stopper: {}",
                    p.position()
                );
            }
            assert_eq!((p.position(), p.velocity()), (10_000.0, 0.0));
            // Pushing with the 5 % limit, the proxy of S_TLC.
            assert!(p.at_torque_limit());
            assert_eq!(
                p.acceleration(),
                0.05 * PlantParams::default().max_acceleration
            );
            // Free to leave it backwards, and the other stopper holds the other way.
            for _ in 0..2_000 {
                p.step(-20_000.0, 0.0, 1e-3);
            }
            assert_eq!(p.position(), -5_000.0);
        }
        // A start beyond a stopper is moved onto it.
        let p = ServoPlant::new(PlantParams::default(), 12_000.0).with_stoppers(stoppers);
        assert_eq!(p.position(), 10_000.0);
    }
}

#[cfg(test)]
mod cycle_map_tests {
    use super::*;

    /// Runs the same command sequence through a mapped and an unmapped plant.
    fn compare(commands: &[(f64, f64)], dt: f64, torque: (f64, f64)) -> (usize, f64) {
        let mut mapped = ServoPlant::new(PlantParams::default(), 1.0e6);
        mapped.prepare_cycle(dt);
        mapped.set_torque_limits(torque.0, torque.1);
        let mut looped = mapped.clone();
        looped.cycle_map = None;
        let mut used = 0;
        let mut worst: f64 = 0.0;
        for &(cmd, ff) in commands {
            let before = mapped.clone();
            if before.clone().step_mapped(cmd, ff, dt) {
                used += 1;
            }
            mapped.step(cmd, ff, dt);
            looped.step(cmd, ff, dt);
            worst = worst
                .max((mapped.position() - looped.position()).abs())
                .max((mapped.velocity() - looped.velocity()).abs() * dt)
                .max((mapped.acceleration() - looped.acceleration()).abs() * dt * dt);
        }
        (used, worst)
    }

    /// A smooth 200 000-count move (sine-ramp), then hold.
    fn smooth_move(cycles: usize) -> Vec<(f64, f64)> {
        (0..cycles)
            .map(|i| {
                let t = (i as f64 / (cycles as f64 * 0.6)).min(1.0);
                let s = 0.5 - 0.5 * (std::f64::consts::PI * t).cos();
                (1.0e6 + 2.0e5 * s, 0.0)
            })
            .collect()
    }

    #[test]
    fn mapped_cycle_equals_the_substep_loop_on_a_smooth_move() {
        for dt in [125e-6, 250e-6, 1e-3, 4e-3, 8e-3] {
            let (used, worst) = compare(&smooth_move(3000), dt, (1.0, 1.0));
            assert!(
                used > 2000,
                "dt {dt}: the map served only {used} of 3000 cycles"
            );
            assert!(worst < 1e-6, "dt {dt}: mapped and looped differ by {worst}");
        }
    }

    #[test]
    fn saturating_steps_fall_back_to_the_loop_and_still_agree() {
        // A 5e6-count step saturates velocity and acceleration: the map must refuse those
        // cycles and the result must still be the substep loop's.
        let mut cmds = vec![(6.0e6, 0.0); 400];
        cmds.extend(vec![(1.0e6, 0.0); 400]);
        let (used, worst) = compare(&cmds, 1e-3, (1.0, 1.0));
        assert!(used < 800, "saturated cycles must not be mapped");
        assert!(worst < 1e-6, "differ by {worst}");
        // With the positive torque limit at 0 no accelerating cycle may be mapped.
        let (_, worst) = compare(&smooth_move(500), 1e-3, (0.0, 1.0));
        assert!(worst < 1e-6, "torque-limited: differ by {worst}");
    }

    #[test]
    fn the_map_serves_only_its_own_time_step_and_finite_inputs() {
        let mut p = ServoPlant::new(PlantParams::default(), 0.0);
        p.prepare_cycle(1e-3);
        assert!(p.has_cycle_map(1e-3));
        assert!(
            !p.clone().step_mapped(10.0, 0.0, 2e-3),
            "2 ms step with a 1 ms map"
        );
        assert!(!p.clone().step_mapped(f64::NAN, 0.0, 1e-3), "NaN command");
        assert!(p.clone().step_mapped(10.0, 0.0, 1e-3));
        let mut twin = ServoPlant::new(PlantParams::default(), 5.0);
        twin.prepare_cycle(1e-3);
        assert_eq!(
            p.cycle_map, twin.cycle_map,
            "identical axes build the same map"
        );
        let mut other = ServoPlant::new(
            PlantParams {
                velocity_bandwidth_hz: 100.0,
                ..PlantParams::default()
            },
            0.0,
        );
        other.prepare_cycle(1e-3);
        assert_ne!(p.cycle_map, other.cycle_map);
        assert!(
            !p.shares_cycle_map_with(&twin),
            "built apart, not shared yet"
        );
        let mut pool = CycleMapPool::default();
        for plant in [&mut p, &mut twin, &mut other] {
            plant.share_cycle_map(&mut pool);
        }
        assert!(p.shares_cycle_map_with(&twin), "equal maps are one table");
        assert!(
            !p.shares_cycle_map_with(&other),
            "other gains keep their own"
        );
        assert_eq!(pool.len(), 2);
        let mut long = ServoPlant::new(PlantParams::default(), 0.0);
        long.prepare_cycle(1.0);
        assert!(
            !long.has_cycle_map(1.0),
            "16 000 substeps are above MAX_MAPPED_SUBSTEPS"
        );
    }
}
