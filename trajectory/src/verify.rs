//! The checks between rsruckig and a [`crate::PlannedMove`]: every planned profile is verified
//! against the move's limits, and each axis' end state is polished onto its target.
//!
//! * [`verify_axis`]: a move is sampled into setpoints the drives follow, so a plan must never
//!   exceed a limit, whatever the solver returns; a plan that does is refused
//!   ([`crate::PlanError::LimitViolation`]), loudly, instead of being sampled.
//! * [`polish_end_state`]: rsruckig accepts profiles that end off the target by up to its
//!   position precision (1e-8; end velocity and acceleration up to 1e-8 and 1e-10), while a
//!   planned move ends exactly at the target ([`crate::PlannedMove::state_at`]). The gap would
//!   be a position step in the last cycle, an extra jerk of `gap / dt³` (a gap of 3.5e-9 is
//!   3.5 unit/s³ at 1 ms, 1 800 unit/s³ at 125 µs; `regression_stretched_axis_end_gap_jerk` in
//!   `tests/motion.rs`). Polishing changes phase durations only (jerks and phase structure
//!   unchanged), so that the profile itself ends at the target to rounding; the polished
//!   profile is kept only if it passes [`verify_axis`] too.

// `!(x > y)` is deliberate throughout: NaN must fail the check. Phase arrays are indexed in
// lock-step (t, j, a, v, p), which reads better with indices.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use rsruckig::brake::BrakeProfile;
use rsruckig::prelude::Profile;

use crate::axis::MoveAxis;
use crate::limits::Quantity;

/// Relative slack on every limit check (solver and polish round-off).
pub(crate) const LIMIT_TOLERANCE: f64 = 1e-9;

/// Newton steps of [`polish_end_state`] at most (it converges in one or two).
const POLISH_ITERATIONS: usize = 6;

/// A planned trajectory exceeding a limit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Violation {
    /// Index of the axis in the move.
    pub axis: usize,
    /// What is exceeded.
    pub quantity: Quantity,
    /// The planned |value|.
    pub value: f64,
    /// The limit it exceeds (including any allowance for the start state).
    pub limit: f64,
}

/// Kinematic state at the start of each of the seven phases and at the end.
struct States {
    a: [f64; 8],
    v: [f64; 8],
    p: [f64; 8],
}

/// Re-integrates `profile` with phase durations `t` (its jerks unchanged), the way rsruckig's
/// `Profile::check*` and `util::integrate` do. Accelerations are propagated as *changes* of
/// the stored ones, so the values rsruckig pins exactly (a = 0 in a cruise phase, a = ±a_max
/// on a plateau) stay pinned wherever the changed phases do not affect them; with `t` equal
/// to `profile.t` this reproduces the stored arrays.
fn integrate_phases(profile: &Profile, t: &[f64; 7]) -> States {
    let mut s = States {
        a: profile.a,
        v: profile.v,
        p: profile.p,
    };
    for i in 0..7 {
        let j = profile.j[i];
        s.a[i + 1] = profile.a[i + 1] + (s.a[i] - profile.a[i]) + (t[i] - profile.t[i]) * j;
        s.v[i + 1] = s.v[i] + t[i] * (s.a[i] + t[i] * j / 2.0);
        s.p[i + 1] = s.p[i] + t[i] * (s.v[i] + t[i] * (s.a[i] / 2.0 + t[i] * j / 6.0));
    }
    s
}

/// Sequential sum, as rsruckig builds `t_sum`.
fn total(t: &[f64; 7]) -> f64 {
    t.iter().fold(0.0, |acc, x| acc + x)
}

/// Closes the end-position gap `target - p[7]` of `profile` (see the module docs) by
/// changing phase durations, keeping the jerks. Returns whether the profile was changed.
///
/// * If the profile has a cruise phase (t > 0, j = 0, a = 0 exactly, v ≠ 0), only that
///   phase's duration changes, by `gap / v`: no acceleration or velocity anywhere changes,
///   only the positions after it — so no limit can be affected. The axis' total duration
///   changes by the same (tiny) amount; the caller extends the move's duration if needed.
/// * Otherwise a few Newton steps solve the linearised end conditions (position, total
///   duration, velocity, acceleration — in that priority, a condition linearly dependent on
///   the ones before it dropped) for the minimum-norm *relative* change of the durations of
///   the phases with t > 0; this may move accelerations/velocities by rounding-sized
///   amounts, so the caller re-verifies the limits.
///
/// The change is kept only if it reduces the gap.
pub(crate) fn polish_end_state(profile: &mut Profile, target: f64) -> bool {
    let gap0 = (target - profile.p[7]).abs();
    if !(gap0 > 0.0) {
        return false;
    }
    let cruise = (0..7)
        .filter(|&k| {
            profile.t[k] > 0.0 && profile.j[k] == 0.0 && profile.a[k] == 0.0 && profile.v[k] != 0.0
        })
        .max_by(|&x, &y| profile.v[x].abs().total_cmp(&profile.v[y].abs()));
    let goal_total = total(&profile.t);
    let mut t = profile.t;
    let mut s = integrate_phases(profile, &t);
    let mut best = (target - s.p[7]).abs();
    let mut changed = false;

    for _ in 0..POLISH_ITERATIONS {
        if best == 0.0 {
            break;
        }
        let mut next = t;
        if let Some(k) = cruise {
            next[k] += (target - s.p[7]) / s.v[k];
        } else {
            // Rows: d(p7, total, v7, a7) / d(relative change of t_i), for phases with t_i > 0.
            let mut rows = [[0.0; 7]; 4];
            let mut rest = 0.0;
            for i in (0..7).rev() {
                let j = profile.j[i];
                if t[i] > 0.0 {
                    rows[0][i] = t[i] * (s.v[i + 1] + rest * (s.a[i + 1] + rest * j / 2.0));
                    rows[1][i] = t[i];
                    rows[2][i] = t[i] * (s.a[i + 1] + rest * j);
                    rows[3][i] = t[i] * j;
                }
                rest += t[i];
            }
            let rhs = [target - s.p[7], goal_total - total(&t), -s.v[7], -s.a[7]];
            let Some(x) = min_norm_solution(&rows, &rhs) else {
                break;
            };
            for i in 0..7 {
                next[i] += t[i] * x[i];
            }
        }
        if next.iter().any(|x| !(*x >= 0.0 && x.is_finite())) {
            break;
        }
        let ns = integrate_phases(profile, &next);
        let g = (target - ns.p[7]).abs();
        if !(g < best) {
            break;
        }
        best = g;
        t = next;
        s = ns;
        changed = true;
    }

    if changed {
        profile.t = t;
        let mut acc = 0.0;
        for (sum, ti) in profile.t_sum.iter_mut().zip(&t) {
            acc += ti;
            *sum = acc;
        }
        profile.a = s.a;
        profile.v = s.v;
        profile.p = s.p;
    }
    changed
}

/// Minimum-norm `x` with `rows[k] · x = rhs[k]` for the rows that are linearly independent
/// of the rows before them (Gram–Schmidt in row order). `None` if no row is usable.
fn min_norm_solution(rows: &[[f64; 7]; 4], rhs: &[f64; 4]) -> Option<[f64; 7]> {
    let dot = |a: &[f64; 7], b: &[f64; 7]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut q = [[0.0; 7]; 4]; // orthonormal basis of the accepted rows
    let mut c = [0.0; 4]; // coefficients of x in that basis
    let mut used = 0;
    for (row, &r) in rows.iter().zip(rhs) {
        let norm = dot(row, row).sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            continue;
        }
        // row = Σ_l L_l q_l + L_k q_k; row · x = Σ_l L_l c_l + L_k c_k = r.
        let mut perp = *row;
        let mut known = 0.0;
        for l in 0..used {
            let coef = dot(row, &q[l]);
            known += coef * c[l];
            for (p, ql) in perp.iter_mut().zip(&q[l]) {
                *p -= coef * ql;
            }
        }
        let perp_norm = dot(&perp, &perp).sqrt();
        if perp_norm <= 1e-9 * norm {
            continue; // dependent on higher-priority conditions: dropped
        }
        for p in &mut perp {
            *p /= perp_norm;
        }
        q[used] = perp;
        c[used] = (r - known) / perp_norm;
        used += 1;
    }
    if used == 0 {
        return None;
    }
    let mut x = [0.0; 7];
    for l in 0..used {
        for (xi, qi) in x.iter_mut().zip(&q[l]) {
            *xi += c[l] * qi;
        }
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Bounds one axis may reach, with the allowance for a start state that itself exceeds them.
#[derive(Clone, Copy)]
struct Bounds {
    velocity: f64,
    acceleration: f64,
    jerk: f64,
}

impl Bounds {
    fn check(&self, axis: usize, quantity: Quantity, value: f64) -> Result<(), Violation> {
        let limit = match quantity {
            Quantity::Velocity => self.velocity,
            Quantity::Acceleration => self.acceleration,
            Quantity::Jerk => self.jerk,
        };
        // Written so that NaN fails.
        if value.abs() <= limit * (1.0 + LIMIT_TOLERANCE) {
            Ok(())
        } else {
            Err(Violation {
                axis,
                quantity,
                value: value.abs(),
                limit,
            })
        }
    }

    /// One constant-jerk phase from `(v, a)` over `t` s with jerk `j`: the jerk, the
    /// acceleration at both ends (it is linear in between) and the velocity at both ends and
    /// at its extremum inside the phase, where the acceleration changes sign.
    fn check_phase(
        &self,
        axis: usize,
        t: f64,
        j: f64,
        v: f64,
        a: f64,
        check_start: bool,
    ) -> Result<(), Violation> {
        if !(t > 0.0) {
            return Ok(());
        }
        self.check(axis, Quantity::Jerk, j)?;
        let a_end = a + j * t;
        let v_end = v + t * (a + j * t / 2.0);
        if check_start {
            self.check(axis, Quantity::Acceleration, a)?;
            self.check(axis, Quantity::Velocity, v)?;
        }
        self.check(axis, Quantity::Acceleration, a_end)?;
        self.check(axis, Quantity::Velocity, v_end)?;
        if j != 0.0 {
            let t_zero = -a / j;
            if t_zero > 0.0 && t_zero < t {
                self.check(axis, Quantity::Velocity, v - a * a / (2.0 * j))?;
            }
        }
        Ok(())
    }
}

fn check_sub_profile(
    axis: usize,
    sub: &BrakeProfile,
    bounds: &Bounds,
    check_start: bool,
) -> Result<(), Violation> {
    if !(sub.duration > 0.0) {
        return Ok(());
    }
    for k in 0..2 {
        bounds.check_phase(
            axis,
            sub.t[k],
            sub.j[k],
            sub.v[k],
            sub.a[k],
            check_start || k > 0,
        )?;
    }
    Ok(())
}

/// Checks every phase with `t > 0` of one axis' profile (brake and accel
/// sub-profiles included) against the axis' limits with relative slack [`LIMIT_TOLERANCE`]:
/// |jerk|; |acceleration| at phase boundaries; |velocity| at phase boundaries and at its
/// extremum inside a phase where the acceleration changes sign.
///
/// Allowance for the start state: where the start state itself exceeds a limit (|a0| above
/// the acceleration limit, or |v0|, or the velocity reached while ramping a0 to zero at the
/// jerk limit, above the velocity limit), the braking pre-trajectory — or, without one, the
/// first phase of the profile — may reach that start-determined value; every later phase
/// must respect the limits.
pub(crate) fn verify_axis(axis: usize, profile: &Profile, m: &MoveAxis) -> Result<(), Violation> {
    let l = m.limits;
    let strict = Bounds {
        velocity: l.velocity,
        acceleration: l.acceleration,
        jerk: l.jerk,
    };
    let (v0, a0) = (m.start.velocity, m.start.acceleration);
    let v_ramp = v0 + a0 * a0.abs() / (2.0 * l.jerk);
    let start = Bounds {
        velocity: l.velocity.max(v0.abs()).max(v_ramp.abs()),
        acceleration: l.acceleration.max(a0.abs()),
        jerk: l.jerk,
    };
    let braking = profile.brake.duration > 0.0;
    // The start state itself is the caller's and not checked; the brake's end is.
    check_sub_profile(axis, &profile.brake, &start, false)?;
    for k in 0..7 {
        // The first phase with t > 0 of an unbraked profile starts at the start state.
        let first = !braking && profile.t[..k].iter().all(|t| !(*t > 0.0));
        let bounds = if first { &start } else { &strict };
        bounds.check_phase(
            axis,
            profile.t[k],
            profile.j[k],
            profile.v[k],
            profile.a[k],
            !first,
        )?;
    }
    check_sub_profile(axis, &profile.accel, &strict, true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::AxisState;
    use crate::limits::KinematicLimits;
    use rsruckig::prelude::{
        InputParameter, Ruckig, Synchronization, ThrowErrorHandler, Trajectory,
    };

    /// The shrunk proptest case: axis 0 is stretched by time synchronisation.
    fn regression_axes() -> [MoveAxis; 2] {
        [
            MoveAxis {
                start: AxisState {
                    position: -0.8304404172300521,
                    velocity: -1.2629348247216845,
                    acceleration: 4.4318178823658245,
                },
                target: -0.9648417308949346,
                limits: KinematicLimits {
                    velocity: 3.5246569108835275,
                    acceleration: 21.462700554763405,
                    jerk: 27.79606347643826,
                },
            },
            MoveAxis {
                start: AxisState {
                    position: 4.949841443847839,
                    velocity: -2.846021645180635,
                    acceleration: 0.0,
                },
                target: -2.419766765089452,
                limits: KinematicLimits {
                    velocity: 2.964605880396495,
                    acceleration: 6.722803599879222,
                    jerk: 508.16633601743416,
                },
            },
        ]
    }

    /// rsruckig's raw (unpolished) time-synchronised plan.
    fn raw_plan(axes: &[MoveAxis]) -> Trajectory<0> {
        let n = axes.len();
        let mut input = InputParameter::<0>::new(Some(n));
        input.synchronization = Synchronization::Time;
        for (i, a) in axes.iter().enumerate() {
            input.current_position[i] = a.start.position;
            input.current_velocity[i] = a.start.velocity;
            input.current_acceleration[i] = a.start.acceleration;
            input.target_position[i] = a.target;
            input.max_velocity[i] = a.limits.velocity;
            input.max_acceleration[i] = a.limits.acceleration;
            input.max_jerk[i] = a.limits.jerk;
        }
        let mut otg = Ruckig::<0, ThrowErrorHandler>::new(Some(n), 1e-3);
        let mut t = Trajectory::<0>::new(Some(n));
        otg.calculate(&input, &mut t).unwrap();
        t
    }

    #[test]
    fn finding_raw_profile_is_within_limits_but_ends_off_target() {
        let axes = regression_axes();
        let t = raw_plan(&axes);
        let p = t.profiles[0][0];
        // Every phase jerk is at (not above) the limit: the profile itself is fine ...
        assert!(p.j.iter().all(|j| j.abs() <= axes[0].limits.jerk));
        assert_eq!(verify_axis(0, &p, &axes[0]), Ok(()));
        // ... but it ends 3.5e-9 short of the target.
        let gap = axes[0].target - p.p[7];
        assert!(gap > 3e-9 && gap < 4e-9, "{gap}");
    }

    #[test]
    fn polish_closes_the_gap_without_touching_accelerations() {
        let axes = regression_axes();
        let t = raw_plan(&axes);
        let raw = t.profiles[0][0];
        let mut p = raw;
        assert!(polish_end_state(&mut p, axes[0].target));
        assert!(
            (axes[0].target - p.p[7]).abs() <= 2.0 * f64::EPSILON,
            "{}",
            p.p[7]
        );
        assert_eq!(p.a, raw.a);
        assert_eq!(p.j, raw.j);
        assert_eq!(p.v, raw.v);
        // Only the cruise phase changed, by gap / v.
        assert!((p.t_sum[6] - raw.t_sum[6]).abs() < 1e-6);
        assert_eq!(verify_axis(0, &p, &axes[0]), Ok(()));
        // Already exact: nothing to do.
        let mut again = p;
        let changed = polish_end_state(&mut again, axes[0].target);
        assert!(!changed || (axes[0].target - again.p[7]).abs() < (axes[0].target - p.p[7]).abs());
    }

    #[test]
    fn polish_without_cruise_phase_uses_newton() {
        // A short rest-to-rest move that never reaches the velocity limit: no cruise phase.
        let limits = KinematicLimits {
            velocity: 10.0,
            acceleration: 5.0,
            jerk: 50.0,
        };
        let a = MoveAxis {
            start: AxisState::default(),
            target: 0.3,
            limits,
        };
        let t = raw_plan(&[a]);
        let raw = t.profiles[0][0];
        // Pretend rsruckig missed the target by 1e-9.
        let target = a.target + 1e-9;
        let mut p = raw;
        assert!(polish_end_state(&mut p, target));
        assert!(
            (target - p.p[7]).abs() <= 4.0 * f64::EPSILON,
            "{}",
            target - p.p[7]
        );
        assert!((p.t_sum[6] - raw.t_sum[6]).abs() < 1e-12);
        assert!(p.v[7].abs() < 1e-12 && p.a[7].abs() < 1e-9, "{:?}", p);
    }

    #[test]
    fn verify_catches_each_quantity() {
        let axes = regression_axes();
        let t = raw_plan(&axes);
        let p = t.profiles[0][1];
        let m = axes[1];
        let mut jerky = p;
        jerky.j[6] *= 1.01;
        assert!(matches!(
            verify_axis(1, &jerky, &m),
            Err(Violation {
                axis: 1,
                quantity: Quantity::Jerk,
                ..
            })
        ));
        let mut fast = p;
        fast.v[3] *= 1.01; // cruise at the velocity limit
        assert!(matches!(
            verify_axis(1, &fast, &m),
            Err(Violation {
                quantity: Quantity::Velocity,
                ..
            })
        ));
        let mut hard = p;
        hard.a[5] *= 1.01; // plateau at the acceleration limit
        assert!(matches!(
            verify_axis(1, &hard, &m),
            Err(Violation {
                quantity: Quantity::Acceleration,
                ..
            })
        ));
        let nan = Profile {
            v: [f64::NAN; 8],
            ..p
        };
        assert!(verify_axis(1, &nan, &m).is_err());
    }

    #[test]
    fn velocity_extremum_inside_a_phase_is_checked() {
        let m = MoveAxis {
            start: AxisState::default(),
            target: 0.0,
            limits: KinematicLimits {
                velocity: 1.0,
                acceleration: 10.0,
                jerk: 100.0,
            },
        };
        // Second phase: starts at v = 0.9, a = 2, jerk -100 over 0.04 s: a crosses zero at
        // 0.02 s where v = 0.92; the ends are at 0.9. Fine; with a = 5 the peak is 1.025.
        let mut p = Profile::default();
        p.t[0] = 0.01;
        p.t[2] = 0.04;
        p.j[2] = -100.0;
        p.v[1] = 0.9;
        p.v[2] = 0.9;
        p.a[2] = 2.0;
        p.v[3] = 0.9;
        p.a[3] = -2.0;
        assert_eq!(verify_axis(0, &p, &m), Ok(()));
        p.a[2] = 5.0;
        p.t[2] = 0.1;
        p.a[3] = -5.0;
        assert!(matches!(
            verify_axis(0, &p, &m),
            Err(Violation {
                quantity: Quantity::Velocity,
                ..
            })
        ));
    }
}
