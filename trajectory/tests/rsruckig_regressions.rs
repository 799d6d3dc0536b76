//! Regression tests for cellrt's fixes to rsruckig 3.0.1 (`vendor/rsruckig/CELLRT-PATCHES.md`):
//! problems on which the unpatched port disagreed with the official Ruckig (C++ 0.19.4, the
//! differential oracle of `ruckig_oracle.rs`), found by that oracle. Each case asserts that
//! rsruckig plans it, with the official library's duration (within 1e-9 relative), and that the
//! trajectory ends in the target state.
//!
//! The reference durations were taken from the official library; with the `ruckig-oracle`
//! feature, `reference_durations_are_the_official_ones` recomputes them.

mod ruckig_problem;

use rsruckig::prelude::{Ruckig, RuckigResult, ThrowErrorHandler, Trajectory};
use rsruckig::util::DataArrayOrVec;
use ruckig_problem::{close, rsruckig_input, Dof};

/// A problem and the official library's trajectory duration for it.
struct Case {
    name: &'static str,
    dofs: &'static [Dof],
    official_duration: f64,
}

/// Non-zero start acceleration, target at rest: the unpatched port refused it ("error in step
/// 1"): the ACC0 plateau acceleration came out 1.8e-12 above the limit and `Profile::check`
/// rejected the profile (C++ sets the plateau to the limit exactly: `check<…, true>`).
const A0_REFUSED: Case = Case {
    name: "a0, refused",
    dofs: &[Dof {
        p0: -200.71299463388527,
        v0: -389.3119758850135,
        a0: -976.1059585067974,
        pf: -40.364917539443354,
        vf: 0.0,
        af: 0.0,
        vmax: 880.8417407755353,
        amax: 4961.903035672502,
        jmax: 46832.34190170728,
    }],
    official_duration: 0.6282165390274768,
};

/// Non-zero start acceleration, target at rest: the unpatched port took 0.602 s (a valid but
/// slower profile, the time-optimal one having been rejected as above).
const A0_SLOWER: Case = Case {
    name: "a0, slower",
    dofs: &[Dof {
        p0: 232.7638690397996,
        v0: 380.41298623878924,
        a0: 816.9544816726633,
        pf: 352.89799551389,
        vf: 0.0,
        af: 0.0,
        vmax: 920.4858711116274,
        amax: 3994.6018915470827,
        jmax: 45575.209598211615,
    }],
    official_duration: 0.34277496806193264,
};

/// Non-zero target velocity: refused by the unpatched port ("error in step 1").
const VF_REFUSED: Case = Case {
    name: "vf, refused",
    dofs: &[Dof {
        p0: -30.259778845970686,
        v0: -236.9859416701819,
        a0: 0.0,
        pf: -146.62346178485802,
        vf: 342.8007391336247,
        af: 0.0,
        vmax: 764.1559503057191,
        amax: 3054.4481003540977,
        jmax: 21776.005263960044,
    }],
    official_duration: 0.6399497587029563,
};

/// Non-zero target velocity: the unpatched port took 0.586 s.
const VF_SLOWER: Case = Case {
    name: "vf, slower",
    dofs: &[Dof {
        p0: 684.4318564956561,
        v0: -462.1295475131904,
        a0: 0.0,
        pf: 500.93727600803095,
        vf: -163.95927337522295,
        af: 0.0,
        vmax: 943.6987030542066,
        amax: 3964.0083922826448,
        jmax: 47460.539449065116,
    }],
    official_duration: 0.3682558438748267,
};

/// The example of the oracle's former module comment (exact inputs from its persisted failure):
/// start acceleration and target velocity non-zero, refused by the unpatched port ("error in
/// step 1").
const VF_ORACLE_EXAMPLE: Case = Case {
    name: "vf, oracle example",
    dofs: &[Dof {
        p0: -265.6544886605587,
        v0: -405.8274118771232,
        a0: 1678.3425028703266,
        pf: -295.7145859124058,
        vf: 359.95301096694686,
        af: 0.0,
        vmax: 820.5979096424403,
        amax: 3916.6119776154433,
        jmax: 25411.0566069279,
    }],
    official_duration: 0.421770308428262,
};

/// Non-zero start acceleration, target velocity and target acceleration: refused by the
/// unpatched port ("error in step 1").
const A0_VF_AF_REFUSED: Case = Case {
    name: "a0 vf af, refused",
    dofs: &[Dof {
        p0: 127.24693265325794,
        v0: 204.88780846994726,
        a0: 189.56120811658175,
        pf: 250.07944658548632,
        vf: -309.26387979657557,
        af: -1261.622410745803,
        vmax: 826.4656404000478,
        amax: 4502.87350864196,
        jmax: 29686.812948661194,
    }],
    official_duration: 0.5045806965284028,
};

/// Time synchronization: the second DoF needs the three-step UZU profile with a reduced jerk,
/// which the unpatched `PositionThirdOrderStep2::time_none` checked with the maximum jerk
/// instead ("error in step 2").
const SYNC_REDUCED_JERK: Case = Case {
    name: "sync, reduced jerk",
    dofs: &[
        Dof {
            p0: 0.0,
            v0: -0.30571222593150893,
            a0: 0.0,
            pf: 917.3600044055455,
            vf: 0.0,
            af: 0.0,
            vmax: 1.0,
            amax: 10.0,
            jmax: 100.0,
        },
        Dof {
            p0: 0.0,
            v0: 0.0,
            a0: 0.0,
            pf: -718.3149587957413,
            vf: -171.56741504251642,
            af: -71.64395441054778,
            vmax: 577.0171146785949,
            amax: 1011.5086949657036,
            jmax: 40282.78110916458,
        },
    ],
    official_duration: 917.6105342376894,
};

/// Time synchronization: the UZU profile's cubic has a zero constant term here, and the
/// unpatched `roots::solve_cub` solved the wrong quadratic ("error in step 2").
const SYNC_CUBIC: Case = Case {
    name: "sync, cubic with zero constant term",
    dofs: &[
        Dof {
            p0: 334.3976483305971,
            v0: -365.53974559914695,
            a0: 272.0997632678973,
            pf: -625.7186244419877,
            vf: -324.7270832527724,
            af: -452.72343272051893,
            vmax: 813.0044280034192,
            amax: 1715.1454752024258,
            jmax: 30355.74375384824,
        },
        Dof {
            p0: -471.25285166527965,
            v0: -0.0006456581825491894,
            a0: -68.76794686163798,
            pf: 868.3090109143641,
            vf: -1.0615394691349758,
            af: -138.4975839220089,
            vmax: 3.356807133637883,
            amax: 3667.2701336136856,
            jmax: 39288.10349765234,
        },
        Dof {
            p0: 175.1182118281929,
            v0: -156.95196405858962,
            a0: -95.23747136872008,
            pf: 837.0351307302678,
            vf: -140.02168451543784,
            af: -161.85276792896232,
            vmax: 469.63012088492866,
            amax: 616.955838342482,
            jmax: 38851.00723016227,
        },
    ],
    official_duration: 399.079921567787,
};

#[cfg(feature = "ruckig-oracle")]
const CASES: [&Case; 8] = [
    &A0_REFUSED,
    &A0_SLOWER,
    &VF_REFUSED,
    &VF_SLOWER,
    &VF_ORACLE_EXAMPLE,
    &A0_VF_AF_REFUSED,
    &SYNC_REDUCED_JERK,
    &SYNC_CUBIC,
];

/// Plans `case` with rsruckig (time synchronization) and checks duration and end state.
fn check(case: &Case) {
    let n = case.dofs.len();
    let inp = rsruckig_input(case.dofs);
    let mut ruckig = Ruckig::<0, ThrowErrorHandler>::new(Some(n), 1e-3);
    let mut traj = Trajectory::<0>::new(Some(n));
    let result = ruckig.calculate(&inp, &mut traj);
    assert!(
        matches!(result, Ok(RuckigResult::Working)),
        "{}: {:?}",
        case.name,
        result.map_err(|e| e.to_string())
    );
    let td = traj.get_duration();
    assert!(
        close(td, case.official_duration, 1e-9),
        "{}: duration {} vs official {}",
        case.name,
        td,
        case.official_duration
    );

    let mut p = DataArrayOrVec::<f64, 0>::new(Some(n), 0.0);
    let mut v = DataArrayOrVec::<f64, 0>::new(Some(n), 0.0);
    let mut a = DataArrayOrVec::<f64, 0>::new(Some(n), 0.0);
    let mut section = None;
    traj.at_time(
        td,
        &mut Some(&mut p),
        &mut Some(&mut v),
        &mut Some(&mut a),
        &mut None,
        &mut section,
    );
    for (i, d) in case.dofs.iter().enumerate() {
        assert!(
            close(p[i], d.pf, 1e-9),
            "{}: dof {i} position {} vs {}",
            case.name,
            p[i],
            d.pf
        );
        assert!(
            close(v[i], d.vf, 1e-9),
            "{}: dof {i} velocity {} vs {}",
            case.name,
            v[i],
            d.vf
        );
        assert!(
            close(a[i], d.af, 1e-9),
            "{}: dof {i} acceleration {} vs {}",
            case.name,
            a[i],
            d.af
        );
    }
}

#[test]
fn start_acceleration_at_the_limit_plateau_is_not_refused() {
    check(&A0_REFUSED);
}

#[test]
fn start_acceleration_gets_the_time_optimal_profile() {
    check(&A0_SLOWER);
}

#[test]
fn target_velocity_is_not_refused() {
    check(&VF_REFUSED);
}

#[test]
fn target_velocity_gets_the_time_optimal_profile() {
    check(&VF_SLOWER);
}

#[test]
fn the_oracle_example_is_not_refused() {
    check(&VF_ORACLE_EXAMPLE);
}

#[test]
fn start_acceleration_with_moving_target_is_not_refused() {
    check(&A0_VF_AF_REFUSED);
}

#[test]
fn time_synchronization_with_reduced_jerk() {
    check(&SYNC_REDUCED_JERK);
}

#[test]
fn time_synchronization_through_a_cubic_with_zero_constant_term() {
    check(&SYNC_CUBIC);
}

/// The reference durations above are the official library's.
#[cfg(feature = "ruckig-oracle")]
#[test]
fn reference_durations_are_the_official_ones() {
    for case in CASES {
        let n = case.dofs.len();
        let mut inp = ruckig_problem::official_input(case.dofs);
        let mut of = ruckig::Ruckig::new_direct(n, 1e-3);
        let mut traj = ruckig::Trajectory::new_direct(n);
        assert_eq!(
            of.calculate(&mut inp, &mut traj),
            ruckig::Result::Working,
            "{}",
            case.name
        );
        assert!(
            close(traj.get_duration(), case.official_duration, 1e-12),
            "{}: official {} vs recorded {}",
            case.name,
            traj.get_duration(),
            case.official_duration
        );
    }
}
