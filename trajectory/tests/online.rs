//! Online motion: re-targeting, jogging, halting and the feed override continue from the
//! current state without a step, stay within the limits and end where they should.

use cellrt_trajectory::{
    AxisGoal, AxisState, KinematicLimits, OnlineAxis, OnlineError, OnlineMotion, PositionRange,
};

const PERIOD: f64 = 1e-3;
const LIMITS: KinematicLimits = KinematicLimits {
    velocity: 400.0,
    acceleration: 2000.0,
    jerk: 20000.0,
};

fn cell(n: usize) -> OnlineMotion {
    let axes = (0..n)
        .map(|_| OnlineAxis {
            limits: LIMITS,
            range: PositionRange {
                min: 0.0,
                max: 800.0,
            },
        })
        .collect();
    OnlineMotion::new(axes, PERIOD, &vec![50.0; n])
}

/// Steps until done (or `max` cycles), checking limits and continuity every cycle; returns the
/// samples.
fn run(m: &mut OnlineMotion, max: usize, stop_when_done: bool) -> Vec<Vec<AxisState>> {
    let n = m.axis_count();
    let mut prev: Vec<AxisState> = (0..n).map(|i| m.state(i)).collect();
    let mut out = vec![AxisState::default(); n];
    let mut samples = Vec::new();
    for _ in 0..max {
        m.step(&mut out).unwrap();
        for (p, o) in prev.iter().zip(&out) {
            check_cycle(p, o);
        }
        prev.clone_from(&out);
        samples.push(out.clone());
        if stop_when_done && m.is_done() {
            break;
        }
    }
    samples
}

/// No step: one cycle changes position by about velocity × period, velocity by at most
/// acceleration × period, acceleration by at most jerk × period (with a small tolerance).
fn check_cycle(a: &AxisState, b: &AxisState) {
    let tol = 1.0 + 1e-6;
    assert!(b.velocity.abs() <= LIMITS.velocity * tol, "{b:?}");
    assert!(b.acceleration.abs() <= LIMITS.acceleration * tol, "{b:?}");
    assert!(
        (b.acceleration - a.acceleration).abs() <= LIMITS.jerk * PERIOD * tol,
        "acceleration step {a:?} -> {b:?}"
    );
    assert!(
        (b.velocity - a.velocity).abs() <= LIMITS.acceleration * PERIOD * tol,
        "velocity step {a:?} -> {b:?}"
    );
    assert!(
        (b.position - a.position).abs() <= LIMITS.velocity * PERIOD * tol,
        "position step {a:?} -> {b:?}"
    );
}

#[test]
fn synchronised_move_ends_at_rest_on_target_together() {
    let mut m = cell(2);
    m.move_to(&[(0, 300.0, LIMITS), (1, 100.0, LIMITS)])
        .unwrap();
    let s = run(&mut m, 10_000, true);
    assert!(m.is_done());
    let last = s.last().unwrap();
    assert_eq!(last[0].position, 300.0);
    assert_eq!(last[1].position, 100.0);
    // Time-synchronised: the short axis is still moving until shortly before the end.
    let moving_1 = s.iter().rposition(|r| r[1].velocity.abs() > 1e-6).unwrap();
    let moving_0 = s.iter().rposition(|r| r[0].velocity.abs() > 1e-6).unwrap();
    assert!(moving_0.abs_diff(moving_1) <= 2, "{moving_0} vs {moving_1}");
}

#[test]
fn retarget_mid_move_is_smooth_and_reaches_the_new_target() {
    let mut m = cell(1);
    m.move_to(&[(0, 700.0, LIMITS)]).unwrap();
    let first = run(&mut m, 300, false);
    let mid = first.last().unwrap()[0];
    assert!(mid.velocity > 100.0, "moving at the re-target: {mid:?}");
    // Re-target behind the current position: the axis must brake and reverse.
    m.move_to(&[(0, 100.0, LIMITS)]).unwrap();
    let mut out = [AxisState::default()];
    m.step(&mut out).unwrap();
    check_cycle(&mid, &out[0]);
    let rest = run(&mut m, 10_000, true);
    assert!(m.is_done());
    assert_eq!(rest.last().unwrap()[0].position, 100.0);
    let max = first
        .iter()
        .chain(&rest)
        .map(|r| r[0].position)
        .fold(f64::MIN, f64::max);
    assert!(max > mid.position && max < 800.0, "overshoot to {max}");
}

#[test]
fn halt_brakes_to_rest_and_holds_there() {
    let mut m = cell(1);
    m.move_to(&[(0, 700.0, LIMITS)]).unwrap();
    run(&mut m, 200, false);
    m.halt(None).unwrap();
    let s = run(&mut m, 5000, true);
    assert!(m.is_done());
    let end = s.last().unwrap()[0];
    assert_eq!(end.velocity, 0.0);
    assert!(end.position < 700.0);
    assert_eq!(m.goal(0), AxisGoal::Position(end.position));
}

#[test]
fn jog_holds_its_velocity_and_stops_inside_the_range() {
    let mut m = cell(1);
    m.jog(0, 200.0, LIMITS).unwrap();
    let s = run(&mut m, 1000, false);
    let v = s.last().unwrap()[0].velocity;
    assert!((v - 200.0).abs() < 1e-9, "jog velocity {v}");
    // Keeps jogging towards the end of the range and stops before it.
    let s = run(&mut m, 10_000, true);
    assert!(m.is_done());
    let end = s.last().unwrap()[0];
    assert!(end.position <= 800.0 && end.position > 790.0, "{end:?}");
    assert!(s.iter().all(|r| r[0].position <= 800.0));
}

#[test]
fn override_scales_the_velocity_and_zero_is_a_feed_hold() {
    let mut m = cell(1);
    m.set_override(0.5).unwrap();
    m.move_to(&[(0, 700.0, LIMITS)]).unwrap();
    let s = run(&mut m, 500, false);
    let vmax = s.iter().map(|r| r[0].velocity).fold(0.0, f64::max);
    assert!((vmax - 200.0).abs() < 1e-6, "{vmax}");
    m.set_override(0.0).unwrap();
    let s = run(&mut m, 1000, false);
    assert_eq!(s.last().unwrap()[0].velocity, 0.0);
    assert!(!m.is_done(), "a feed hold is not the end of the move");
    m.set_override(1.0).unwrap();
    let s = run(&mut m, 10_000, true);
    assert!(m.is_done());
    assert_eq!(s.last().unwrap()[0].position, 700.0);
}

#[test]
fn bad_commands_are_refused_and_change_nothing() {
    let mut m = cell(2);
    assert_eq!(
        m.move_to(&[(2, 1.0, LIMITS)]),
        Err(OnlineError::UnknownAxis(2))
    );
    assert!(matches!(
        m.move_to(&[(0, f64::NAN, LIMITS)]),
        Err(OnlineError::NotFinite { axis: 0, .. })
    ));
    assert!(matches!(
        m.move_to(&[(0, 100.0, LIMITS), (1, 900.0, LIMITS)]),
        Err(OnlineError::Limits { axis: 1, .. })
    ));
    let fast = KinematicLimits {
        velocity: 500.0,
        ..LIMITS
    };
    assert!(matches!(
        m.move_to(&[(0, 100.0, fast)]),
        Err(OnlineError::Limits { axis: 0, .. })
    ));
    assert!(matches!(
        m.jog(1, -401.0, LIMITS),
        Err(OnlineError::VelocityAboveLimit { axis: 1, .. })
    ));
    assert_eq!(m.set_override(1.5), Err(OnlineError::Override(1.5)));
    assert!(m.set_override(f64::NAN).is_err());
    assert_eq!(m.goal(0), AxisGoal::Position(50.0));
    assert_eq!(m.goal(1), AxisGoal::Position(50.0));
    assert_eq!(m.feed_override(), 1.0);
}

#[test]
fn a_target_at_the_end_of_the_range_never_leaves_it_by_numerical_noise() {
    // Four axes of different limits; z ends at its range end 0 (rsruckig's last working sample
    // passes it by ~3e-15 without polishing).
    let l = |v, a, j| KinematicLimits {
        velocity: v,
        acceleration: a,
        jerk: j,
    };
    let range = |min, max| PositionRange { min, max };
    let axes = vec![
        OnlineAxis {
            limits: l(400.0, 2000.0, 20000.0),
            range: range(0.0, 800.0),
        },
        OnlineAxis {
            limits: l(400.0, 2000.0, 20000.0),
            range: range(0.0, 600.0),
        },
        OnlineAxis {
            limits: l(250.0, 1500.0, 15000.0),
            range: range(-200.0, 0.0),
        },
        OnlineAxis {
            limits: l(180.0, 720.0, 3600.0),
            range: range(-360.0, 360.0),
        },
    ];
    let mut m = OnlineMotion::new(axes.clone(), 0.5e-3, &[300.0, 200.0, -100.0, 27.767]);
    let targets: Vec<_> = [50.0, 50.0, 0.0, 0.0]
        .iter()
        .enumerate()
        .map(|(i, &t)| (i, t, axes[i].limits))
        .collect();
    m.move_to(&targets).unwrap();
    let mut out = vec![AxisState::default(); 4];
    let mut cycles = 0;
    while !m.is_done() {
        m.step(&mut out).unwrap();
        assert!(
            out[2].position <= 0.0,
            "z left its range: {:e}",
            out[2].position
        );
        cycles += 1;
        assert!(cycles < 10_000);
    }
}
