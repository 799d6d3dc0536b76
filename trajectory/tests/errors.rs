//! Bad input gives the specific error, never a panic.

use cellrt_trajectory::{
    plan_move, AxisState, KinematicLimits, LimitsError, MoveAxis, PlanError, PositionRange,
    Quantity, MAX_MOVE_AXES,
};

const AXIS_LIMITS: KinematicLimits = KinematicLimits {
    velocity: 1.0,
    acceleration: 5.0,
    jerk: 50.0,
};

fn axis(target: f64) -> MoveAxis {
    MoveAxis {
        start: AxisState::default(),
        target,
        limits: AXIS_LIMITS,
    }
}

#[test]
fn nan_target() {
    let err = plan_move(&[axis(1.0), axis(f64::NAN)]).unwrap_err();
    assert!(
        matches!(err, PlanError::NonFiniteTarget { axis: 1, value } if value.is_nan()),
        "{err}"
    );
    assert!(err.to_string().contains("axis 1"), "{err}");
    assert!(matches!(
        plan_move(&[axis(f64::INFINITY)]),
        Err(PlanError::NonFiniteTarget { axis: 0, .. })
    ));
}

#[test]
fn non_finite_start() {
    let mut a = axis(1.0);
    a.start.velocity = f64::NAN;
    assert!(matches!(
        plan_move(&[a]),
        Err(PlanError::NonFiniteStart { axis: 0, .. })
    ));
}

#[test]
fn non_positive_limit() {
    for (limits, quantity) in [
        (
            KinematicLimits {
                velocity: 0.0,
                ..AXIS_LIMITS
            },
            Quantity::Velocity,
        ),
        (
            KinematicLimits {
                acceleration: -5.0,
                ..AXIS_LIMITS
            },
            Quantity::Acceleration,
        ),
        (
            KinematicLimits {
                jerk: f64::NAN,
                ..AXIS_LIMITS
            },
            Quantity::Jerk,
        ),
    ] {
        let mut a = axis(1.0);
        a.limits = limits;
        let err = plan_move(&[axis(2.0), a]).unwrap_err();
        assert!(
            matches!(err, PlanError::InvalidLimits { axis: 1, source: LimitsError::NotPositive { quantity: q, .. } } if q == quantity),
            "{err}"
        );
        assert!(err.to_string().contains(&quantity.to_string()), "{err}");
    }
}

#[test]
fn too_many_and_no_axes() {
    let axes = vec![axis(1.0); MAX_MOVE_AXES + 1];
    assert!(matches!(
        plan_move(&axes),
        Err(PlanError::TooManyAxes { count, max: MAX_MOVE_AXES }) if count == MAX_MOVE_AXES + 1
    ));
    let plan = plan_move(&axes[..MAX_MOVE_AXES]).unwrap();
    assert_eq!(plan.axis_count(), MAX_MOVE_AXES);
    assert!(matches!(plan_move(&[]), Err(PlanError::Empty)));
}

#[test]
fn per_move_limit_above_axis_limit() {
    let fast = KinematicLimits {
        velocity: 1.5,
        ..AXIS_LIMITS
    };
    let err = MoveAxis::checked(AxisState::default(), 1.0, &fast, &AXIS_LIMITS, None).unwrap_err();
    assert_eq!(
        err,
        LimitsError::ExceedsAxisLimit {
            quantity: Quantity::Velocity,
            requested: 1.5,
            axis_limit: 1.0
        }
    );
    let slow = KinematicLimits {
        velocity: 0.5,
        ..AXIS_LIMITS
    };
    let ok = MoveAxis::checked(AxisState::default(), 1.0, &slow, &AXIS_LIMITS, None).unwrap();
    assert_eq!(ok.limits, slow);
}

#[test]
fn target_outside_position_range() {
    let range = PositionRange {
        min: -1.0,
        max: 1.0,
    };
    let err = MoveAxis::checked(
        AxisState::default(),
        1.5,
        &AXIS_LIMITS,
        &AXIS_LIMITS,
        Some(&range),
    )
    .unwrap_err();
    assert_eq!(
        err,
        LimitsError::OutOfRange {
            value: 1.5,
            min: -1.0,
            max: 1.0
        }
    );
    let err = MoveAxis::checked(
        AxisState::default(),
        f64::NAN,
        &AXIS_LIMITS,
        &AXIS_LIMITS,
        Some(&range),
    )
    .unwrap_err();
    assert!(matches!(err, LimitsError::OutOfRange { .. }));
    assert!(MoveAxis::checked(
        AxisState::default(),
        1.0,
        &AXIS_LIMITS,
        &AXIS_LIMITS,
        Some(&range)
    )
    .is_ok());
}
