//! One module per subcommand.

pub mod planner;
pub mod run;
