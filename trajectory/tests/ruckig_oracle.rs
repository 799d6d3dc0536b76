//! Differential test against the official Ruckig (C++ through the `ruckig` crate), behind the
//! `ruckig-oracle` feature: on random feasible state-to-state problems of 1–8 DoF, rsruckig's
//! trajectory duration matches within 1e-9 relative and the sampled states within 1e-9.
//! Never with waypoints (the official crate sends those to a cloud service; ARCHITECTURE.md).
//!
//! Run: `cargo test -p cellrt-trajectory --features ruckig-oracle --test ruckig_oracle`.
//!
//! The domain: any start position and velocity within the limits, start acceleration zero,
//! target at rest. Outside it rsruckig 3.0.1 disagrees with the official library, so the
//! oracle checks only this domain (found by this test; report upstream):
//! - with a non-zero start acceleration (about 1 problem in 1000–4000) rsruckig returns a valid
//!   but far slower profile, e.g. one DoF from p 899.693, v −252.854, a −902.842 to p 350.092
//!   with limits v 925.34, a 2716.31, j 9437.79 takes 3.627 s against the official 1.058 s, or
//!   refuses a problem the official library solves;
//! - with a non-zero target velocity it refuses problems the official library solves, e.g. one
//!   DoF from p −265.654, v −405.827, a 1678.34 to p −295.715, v 359.953 with limits v 820.6,
//!   a 3916.6, j 25411 ("error in step 1").
//!
//! cellrt's moves from rest are in the domain; a re-target mid-move (non-zero acceleration) is
//! not, and may be slower than time-optimal there (still within the limits).

#![cfg(feature = "ruckig-oracle")]

use proptest::prelude::*;
use rsruckig::prelude::{
    InputParameter as RsInput, Ruckig as RsRuckig, RuckigResult, Synchronization as RsSync,
    ThrowErrorHandler, Trajectory as RsTrajectory,
};
use rsruckig::util::DataArrayOrVec;

/// One DoF of a problem: current state, target state and limits.
#[derive(Debug, Clone)]
struct Dof {
    p0: f64,
    v0: f64,
    a0: f64,
    pf: f64,
    vf: f64,
    vmax: f64,
    amax: f64,
    jmax: f64,
}

/// A DoF: any start position and velocity within the limits, a target at rest.
fn dof() -> impl Strategy<Value = Dof> {
    (
        1.0f64..1000.0,     // vmax
        10.0f64..5000.0,    // amax
        100.0f64..50_000.0, // jmax
        -1000.0f64..1000.0,
        -1000.0f64..1000.0,
        -0.5f64..0.5,
    )
        .prop_map(|(vmax, amax, jmax, p0, pf, sv0)| Dof {
            p0,
            // Well inside the limits, so every problem is feasible.
            v0: sv0 * vmax,
            // Zero start acceleration: see the module comment.
            a0: 0.0,
            pf,
            vf: 0.0,
            vmax,
            amax,
            jmax,
        })
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    /// The problems cellrt plans: any start state, a target at rest.
    #[test]
    fn rsruckig_matches_the_official_ruckig(dofs in prop::collection::vec(dof(), 1..=8)) {
        compare(&dofs)?;
    }
}

fn compare(dofs: &[Dof]) -> Result<(), TestCaseError> {
    let n = dofs.len();
    // rsruckig.
    let mut rs_in = RsInput::<0>::new(Some(n));
    rs_in.synchronization = RsSync::Time;
    // Official.
    let mut of_in = ruckig::InputParameter::new(n);
    for (i, d) in dofs.iter().enumerate() {
        rs_in.current_position[i] = d.p0;
        rs_in.current_velocity[i] = d.v0;
        rs_in.current_acceleration[i] = d.a0;
        rs_in.target_position[i] = d.pf;
        rs_in.target_velocity[i] = d.vf;
        rs_in.target_acceleration[i] = 0.0;
        rs_in.max_velocity[i] = d.vmax;
        rs_in.max_acceleration[i] = d.amax;
        rs_in.max_jerk[i] = d.jmax;
        of_in.current_position[i] = d.p0;
        of_in.current_velocity[i] = d.v0;
        of_in.current_acceleration[i] = d.a0;
        of_in.target_position[i] = d.pf;
        of_in.target_velocity[i] = d.vf;
        of_in.target_acceleration[i] = 0.0;
        of_in.max_velocity[i] = d.vmax;
        of_in.max_acceleration[i] = d.amax;
        of_in.max_jerk[i] = d.jmax;
    }
    let mut rs = RsRuckig::<0, ThrowErrorHandler>::new(Some(n), 1e-3);
    let mut rs_traj = RsTrajectory::<0>::new(Some(n));
    let rs_result = rs.calculate(&rs_in, &mut rs_traj);
    let mut of = ruckig::Ruckig::new_direct(n, 1e-3);
    let mut of_traj = ruckig::Trajectory::new_direct(n);
    let of_result = of.calculate(&mut of_in, &mut of_traj);
    let rs_ok = matches!(rs_result, Ok(RuckigResult::Working));
    let of_ok = of_result == ruckig::Result::Working;
    // Both libraries must agree on whether a trajectory exists.
    prop_assert_eq!(
        rs_ok,
        of_ok,
        "rsruckig {:?} vs official {:?}",
        rs_result.map_err(|e| e.to_string()),
        of_result
    );
    if !of_ok {
        return Ok(());
    }

    let (td_rs, td_of) = (rs_traj.get_duration(), of_traj.get_duration());
    prop_assert!(close(td_rs, td_of, 1e-9), "duration {} vs {}", td_rs, td_of);

    let mut p = DataArrayOrVec::<f64, 0>::new(Some(n), 0.0);
    let mut v = DataArrayOrVec::<f64, 0>::new(Some(n), 0.0);
    let mut a = DataArrayOrVec::<f64, 0>::new(Some(n), 0.0);
    let mut section = None;
    for k in 0..=16 {
        let t = td_of * f64::from(k) / 16.0;
        rs_traj.at_time(
            t,
            &mut Some(&mut p),
            &mut Some(&mut v),
            &mut Some(&mut a),
            &mut None,
            &mut section,
        );
        let (op, ov, oa) = of_traj.at_time(t);
        for i in 0..n {
            prop_assert!(
                close(p[i], op[i], 1e-9),
                "t {} dof {}: position {} vs {}",
                t,
                i,
                p[i],
                op[i]
            );
            prop_assert!(
                close(v[i], ov[i], 1e-9),
                "t {} dof {}: velocity {} vs {}",
                t,
                i,
                v[i],
                ov[i]
            );
            prop_assert!(
                close(a[i], oa[i], 1e-9),
                "t {} dof {}: acceleration {} vs {}",
                t,
                i,
                a[i],
                oa[i]
            );
        }
    }
    Ok(())
}
