//! Differential test against the official Ruckig (C++ through the `ruckig` crate), behind the
//! `ruckig-oracle` feature: on random feasible state-to-state problems of 1–8 DoF, rsruckig's
//! trajectory duration matches within 1e-9 relative and the sampled states within 1e-9.
//! Never with waypoints (the official crate sends those to a cloud service; docs/architecture.md).
//!
//! Run: `cargo test -p cellrt-trajectory --features ruckig-oracle --test ruckig_oracle`.
//!
//! The domain, per DoF: limits v 1–1000, a 10–5000, j 100–50 000; start and target positions
//! in ±1000; start and target velocity within half the velocity limit; start and target
//! acceleration within half of the smaller of the acceleration limit and the largest |a| from
//! which the velocity still reaches zero acceleration inside its limit (|v| + a²/(2 j) ≤ v_max,
//! Ruckig's validity condition on the start and target states). Both libraries must agree on whether a
//! trajectory exists.
//!
//! rsruckig 3.0.1 as published disagreed here (found by this test, when the domain was
//! restricted to start acceleration zero and target at rest because of it): with a non-zero
//! start acceleration or target velocity it refused problems the official library solves or
//! returned a valid but slower profile, and in time synchronization it refused problems in
//! step 2. cellrt uses a patched copy (`vendor/rsruckig`, fixes and causes in its
//! `CELLRT-PATCHES.md`); the failing problems are regression tests in `rsruckig_regressions.rs`.

#![cfg(feature = "ruckig-oracle")]

mod ruckig_problem;

use proptest::prelude::*;
use rsruckig::prelude::{
    Ruckig as RsRuckig, RuckigResult, ThrowErrorHandler, Trajectory as RsTrajectory,
};
use rsruckig::util::DataArrayOrVec;
use ruckig_problem::{close, official_input, rsruckig_input, Dof};

/// The largest |a| a state with velocity `v` may have so that it can still reach zero acceleration
/// within the velocity limit (jerk `jmax`, either sign): |v| + a²/(2 jmax) ≤ vmax.
fn a_reachable(v: f64, vmax: f64, jmax: f64) -> f64 {
    (2.0 * jmax * (vmax - v.abs())).sqrt()
}

/// A DoF: start and target velocity within half the velocity limit, start and target acceleration
/// within half the acceleration limit and within half of what still lets the velocity stay inside
/// its limit (Ruckig's validity condition on the states), any positions.
fn dof() -> impl Strategy<Value = Dof> {
    (
        (
            1.0f64..1000.0,     // vmax
            10.0f64..5000.0,    // amax
            100.0f64..50_000.0, // jmax
        ),
        (-1000.0f64..1000.0, -0.5f64..0.5, -0.5f64..0.5),
        (-1000.0f64..1000.0, -0.5f64..0.5, -0.5f64..0.5),
    )
        .prop_map(|((vmax, amax, jmax), (p0, sv0, sa0), (pf, svf, saf))| {
            let (v0, vf) = (sv0 * vmax, svf * vmax);
            Dof {
                p0,
                v0,
                a0: sa0 * amax.min(a_reachable(v0, vmax, jmax)),
                pf,
                vf,
                af: saf * amax.min(a_reachable(vf, vmax, jmax)),
                vmax,
                amax,
                jmax,
            }
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    /// Any start state and any target state within the domain above.
    #[test]
    fn rsruckig_matches_the_official_ruckig(dofs in prop::collection::vec(dof(), 1..=8)) {
        compare(&dofs)?;
    }
}

fn compare(dofs: &[Dof]) -> Result<(), TestCaseError> {
    let n = dofs.len();
    let rs_in = rsruckig_input(dofs);
    let mut of_in = official_input(dofs);
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
