//! The mode modules' tests: they drive [`super::motion::Motion`], which the modes do not
//! depend on.

mod homing;
mod indexer;
mod jog;
mod point_table;
mod torque;
