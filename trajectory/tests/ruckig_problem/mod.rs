//! A state-to-state problem as both Ruckig implementations take it: the set-up shared by the
//! differential oracle (`ruckig_oracle.rs`) and the rsruckig regression tests.
#![allow(dead_code)]

use rsruckig::prelude::{InputParameter, Synchronization};

/// One DoF of a problem: current state, target state and limits.
#[derive(Debug, Clone, Copy)]
pub struct Dof {
    pub p0: f64,
    pub v0: f64,
    pub a0: f64,
    pub pf: f64,
    pub vf: f64,
    pub af: f64,
    pub vmax: f64,
    pub amax: f64,
    pub jmax: f64,
}

/// Writes `dofs` into the input of either implementation (their fields are named alike).
macro_rules! fill_input {
    ($input:ident, $dofs:ident) => {
        for (i, d) in $dofs.iter().enumerate() {
            $input.current_position[i] = d.p0;
            $input.current_velocity[i] = d.v0;
            $input.current_acceleration[i] = d.a0;
            $input.target_position[i] = d.pf;
            $input.target_velocity[i] = d.vf;
            $input.target_acceleration[i] = d.af;
            $input.max_velocity[i] = d.vmax;
            $input.max_acceleration[i] = d.amax;
            $input.max_jerk[i] = d.jmax;
        }
    };
}

/// rsruckig's input for `dofs`, time-synchronised.
pub fn rsruckig_input(dofs: &[Dof]) -> InputParameter<0> {
    let mut input = InputParameter::<0>::new(Some(dofs.len()));
    input.synchronization = Synchronization::Time;
    fill_input!(input, dofs);
    input
}

/// The official Ruckig's input for `dofs` (its default synchronisation is time).
#[cfg(feature = "ruckig-oracle")]
pub fn official_input(dofs: &[Dof]) -> ruckig::InputParameter {
    let mut input = ruckig::InputParameter::new(dofs.len());
    fill_input!(input, dofs);
    input
}

/// `a` and `b` agree within `tol`, relative to the larger magnitude (absolute below 1).
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs())
}
