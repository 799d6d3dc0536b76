//! The operator service under load: a hundred clients hammering a running cell with status
//! requests while `stop` and `status` from another client and from the CLI are still answered,
//! none refused. Judged by what is answered and a generous bound, not by machine speed.

mod common;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Barrier};
use std::time::{Duration, Instant};

use cellrt_runtime::host::operator::client::OperatorClient;
use cellrt_runtime::host::operator::wire::{Reply, Request};
use common::cell::Cell;

/// Concurrent clients hammering the service.
const CLIENTS: usize = 100;
/// Most requests one hammering client sends (the test bounds its own load).
const MAX_REQUESTS: usize = 300;
/// The bound within which stop and status must be answered under that load.
const ANSWER_BOUND: Duration = Duration::from_secs(2);

/// What one hammering client saw.
struct Hammered {
    answered: usize,
    failures: Vec<String>,
}

fn hammer(cell: String, start: Arc<Barrier>, done: Arc<AtomicBool>) -> Hammered {
    let client = OperatorClient::connect(Some(&cell));
    start.wait();
    let client = match client {
        Ok(c) => c,
        Err(e) => {
            return Hammered {
                answered: 0,
                failures: vec![format!("connect: {e}")],
            }
        }
    };
    let mut seen = Hammered {
        answered: 0,
        failures: Vec::new(),
    };
    while !done.load(Ordering::Acquire) && seen.answered < MAX_REQUESTS {
        match client.request(&Request::Status, Duration::from_secs(30)) {
            Ok(Reply::Status(_)) => seen.answered += 1,
            Ok(other) => seen.failures.push(format!("{other:?}")),
            Err(e) => seen.failures.push(e.to_string()),
        }
    }
    seen
}

/// Sends `req` through `client`, asserting it is answered within [`ANSWER_BOUND`].
fn answered_in_bound(client: &OperatorClient, req: &Request) -> Reply {
    let t = Instant::now();
    let reply = client
        .request(req, Duration::from_secs(30))
        .unwrap_or_else(|e| panic!("{req:?} under load: {e}"));
    let took = t.elapsed();
    eprintln!("{} answered in {took:?} under load", req.name());
    assert!(took < ANSWER_BOUND, "{req:?} answered after {took:?}");
    reply
}

#[test]
fn a_hundred_clients_do_not_keep_stop_and_status_from_being_answered() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::demo_cell(dir.path(), "");
    let cell = Cell::start(&cfg, &dir.path().join("run.mcap"));
    let start = Arc::new(Barrier::new(CLIENTS + 1));
    let done = Arc::new(AtomicBool::new(false));
    let hammers: Vec<_> = (0..CLIENTS)
        .map(|_| {
            let (name, start, done) = (cell.name.clone(), start.clone(), done.clone());
            std::thread::spawn(move || hammer(name, start, done))
        })
        .collect();
    let t0 = Instant::now();
    start.wait();
    eprintln!("{CLIENTS} clients connected in {:?}", t0.elapsed());
    let operator = OperatorClient::connect(Some(&cell.name)).expect("the operator connects");
    for _ in 0..5 {
        assert!(matches!(
            answered_in_bound(&operator, &Request::Status),
            Reply::Status(_)
        ));
    }
    let (code, out, err) = cell.cli(&["status"]);
    assert_eq!(code, 0, "cellrt status under load: {out}{err}");
    assert!(matches!(
        answered_in_bound(&operator, &Request::Stop),
        Reply::Accepted { .. }
    ));
    let (code, out, err) = cell.cli(&["stop"]);
    assert_eq!(code, 0, "cellrt stop under load: {out}{err}");
    done.store(true, Ordering::Release);
    let mut total = 0;
    for (k, h) in hammers.into_iter().enumerate() {
        let seen = h.join().expect("a hammering client panicked");
        assert!(
            seen.failures.is_empty(),
            "client {k}: {} failures, first: {}",
            seen.failures.len(),
            seen.failures[0]
        );
        total += seen.answered;
    }
    eprintln!("{total} status requests of the hammering clients answered");
    assert!(total >= CLIENTS, "{total} status requests answered");
    cell.end();
}
