//! Asking a cell of this process through its operator service, patiently: the planner thread
//! that serves it may be starved on a loaded test machine.

use std::time::Duration;

use cellrt_runtime::host::operator::client::OperatorClient;
use cellrt_runtime::host::operator::wire::{Reply, Request, StatusReport};

/// A request, asked again while the cell's planner thread (which serves the operator) is too
/// starved on the loaded test machine to answer within 5 s.
pub fn request(c: &OperatorClient, r: &Request) -> Reply {
    let mut tries = 0;
    loop {
        match c.request(r, Duration::from_secs(5)) {
            Ok(reply) => return reply,
            Err(e) if tries < 6 => {
                tries += 1;
                eprintln!("{e}; asking again");
            }
            Err(e) => panic!("{e}"),
        }
    }
}

/// The cell's status report.
pub fn status(c: &OperatorClient) -> StatusReport {
    match request(c, &Request::Status) {
        Reply::Status(s) => *s,
        r => panic!("{r:?}"),
    }
}
