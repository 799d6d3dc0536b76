//! Helpers shared by the integration tests.
#![allow(dead_code)]

use cellrt_trajectory::{AxisState, KinematicLimits, MoveAxis, MoveSampler, PlannedMove};

/// Samples `plan` at `period`: index 0 is the start state, index k (1..=n) cycle k.
pub fn sample(plan: &PlannedMove, period: f64) -> Vec<Vec<AxisState>> {
    let sampler = MoveSampler::new(plan.clone(), period).unwrap();
    let n = plan.axis_count();
    (0..=sampler.cycles())
        .map(|k| {
            let mut out = vec![AxisState::default(); n];
            assert_eq!(sampler.fill(k, &mut out), n);
            out
        })
        .collect()
}

/// Checks sampled states and the finite differences of sampled positions against `limits`.
///
/// Because positions are piecewise cubic with continuous acceleration, the k-th finite
/// difference divided by dt^k is a weighted mean of the k-th derivative over the stencil, so
/// it can never exceed the limit: no discretisation allowance is needed, also across the
/// clamped end (the final state is held). Tolerance per quantity:
/// `limit * 1e-6` (solver round-off) `+ c * EPSILON * max|p| / dt^k` (floating-point
/// cancellation in the difference: c = 8, 16, 32 for k = 1, 2, 3, i.e. ~4 ulp per sample times
/// the sum of the stencil weights).
pub fn check_limits(samples: &[Vec<AxisState>], limits: &[KinematicLimits], dt: f64) {
    let axes = limits.len();
    for (axis, l) in limits.iter().enumerate() {
        let p: Vec<f64> = samples.iter().map(|s| s[axis].position).collect();
        let scale = p.iter().fold(1.0_f64, |m, x| m.max(x.abs())) * f64::EPSILON;
        let tol = |limit: f64, c: f64, k: i32| limit * (1.0 + 1e-6) + c * scale / dt.powi(k);
        for s in samples {
            assert!(
                s[axis].velocity.abs() <= l.velocity * (1.0 + 1e-6),
                "axis {axis}: {s:?} vs {l:?}"
            );
            assert!(
                s[axis].acceleration.abs() <= l.acceleration * (1.0 + 1e-6),
                "axis {axis}: {s:?} vs {l:?}"
            );
        }
        for (i, w) in p.windows(2).enumerate() {
            let v = (w[1] - w[0]) / dt;
            assert!(
                v.abs() <= tol(l.velocity, 8.0, 1),
                "axis {axis}/{axes} cycle {i}: fd velocity {v} > {l:?}"
            );
        }
        for (i, w) in p.windows(3).enumerate() {
            let a = (w[2] - 2.0 * w[1] + w[0]) / (dt * dt);
            assert!(
                a.abs() <= tol(l.acceleration, 16.0, 2),
                "axis {axis}/{axes} cycle {i}: fd acceleration {a} > {l:?}"
            );
        }
        for (i, w) in p.windows(4).enumerate() {
            let j = (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]) / (dt * dt * dt);
            assert!(
                j.abs() <= tol(l.jerk, 32.0, 3),
                "axis {axis}/{axes} cycle {i}: fd jerk {j} > {l:?}"
            );
        }
    }
}

/// Limits of every axis of a move, in order.
pub fn limits_of(axes: &[MoveAxis]) -> Vec<KinematicLimits> {
    axes.iter().map(|a| a.limits).collect()
}
