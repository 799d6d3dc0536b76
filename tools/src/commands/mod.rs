//! One module per subcommand.

pub mod bench;
pub mod bus;
pub mod bus_commission;
pub mod bus_diag;
pub mod docs;
pub mod drive_sim;
pub mod drive_sim_lineup;
pub mod drive_sim_mr_je_c;
pub mod esi;
pub mod inspect;
pub mod je_c;
pub mod je_c_search;
pub mod operate;
pub mod param;
pub mod planner;
pub mod recover;
pub mod replay;
pub mod report;
pub mod run;
pub mod sdo;
