//! Waypoint moves (rsruckig offline waypoints): through every waypoint, within the limits, to
//! the target at rest; malformed waypoints are refused.

use cellrt_trajectory::{plan_waypoints, AxisState, KinematicLimits, MoveAxis, PlanError};

const L: KinematicLimits = KinematicLimits {
    velocity: 400.0,
    acceleration: 2000.0,
    jerk: 20000.0,
};

fn axis(target: f64) -> MoveAxis {
    MoveAxis {
        start: AxisState::default(),
        target,
        limits: L,
    }
}

#[test]
fn a_waypoint_move_passes_every_waypoint_within_the_limits() {
    let via = vec![vec![100.0, 200.0], vec![300.0, 50.0]];
    let m = plan_waypoints(&[axis(400.0), axis(300.0)], &via).unwrap();
    let dt = 1e-5;
    let steps = (m.duration() / dt).ceil() as usize;
    let mut s = [AxisState::default(); 2];
    let mut closest = vec![f64::INFINITY; via.len()];
    for k in 0..=steps {
        m.state_at(k as f64 * dt, &mut s);
        for st in &s {
            assert!(st.velocity.abs() <= L.velocity * (1.0 + 1e-6), "{st:?}");
            assert!(
                st.acceleration.abs() <= L.acceleration * (1.0 + 1e-6),
                "{st:?}"
            );
        }
        for (c, w) in closest.iter_mut().zip(&via) {
            let d = ((s[0].position - w[0]).powi(2) + (s[1].position - w[1]).powi(2)).sqrt();
            *c = c.min(d);
        }
    }
    // Sampled every 10 µs at ≤ 400 mm/s per axis: within 0.006 of each waypoint.
    assert!(closest.iter().all(|&d| d < 0.006), "{closest:?}");
    m.state_at(m.duration(), &mut s);
    assert_eq!((s[0].position, s[1].position), (400.0, 300.0));
    assert_eq!((s[0].velocity, s[1].velocity), (0.0, 0.0));
}

#[test]
fn malformed_waypoints_are_refused() {
    assert!(matches!(
        plan_waypoints(&[axis(1.0), axis(2.0)], &[vec![1.0]]),
        Err(PlanError::WaypointShape {
            waypoint: 0,
            got: 1,
            axes: 2
        })
    ));
    assert!(matches!(
        plan_waypoints(&[axis(1.0)], &[vec![f64::NAN]]),
        Err(PlanError::NonFiniteTarget { .. })
    ));
    assert!(matches!(
        plan_waypoints(&[axis(1.0)], &vec![vec![0.5]; 65]),
        Err(PlanError::TooManyWaypoints { count: 65, max: 64 })
    ));
    assert!(matches!(plan_waypoints(&[], &[]), Err(PlanError::Empty)));
}
