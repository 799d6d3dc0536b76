//! Waiting for what the mailbox worker reads: notices come in a later cycle than the cyclic
//! frame that saw SM1 full, so a test keeps the cyclic exchange going until they are there.

use std::time::{Duration, Instant};

use cellrt_cia402::bus::{CyclicBus, MailboxNotice};
use cellrt_cia402::Cycles;

/// How long a test waits for the worker (wall-clock; it only bounds a failure).
const PATIENCE: Duration = Duration::from_secs(5);

/// The next `n` notices, exchanging cycles (the images as they are) until they have come.
pub fn await_notices(bus: &mut impl CyclicBus, n: usize) -> Vec<MailboxNotice> {
    let end = Instant::now() + PATIENCE;
    let mut got = Vec::new();
    while got.len() < n && Instant::now() < end {
        match bus.take_mailbox_notice() {
            Some(notice) => got.push(notice),
            None => {
                let _ = bus.exchange(Cycles(1));
                std::thread::sleep(Duration::from_micros(200));
            }
        }
    }
    got
}

/// True if no notice comes within `cycles` further exchanges (the worker given time for each).
pub fn no_notice_within(bus: &mut impl CyclicBus, cycles: u32) -> bool {
    for _ in 0..cycles {
        if bus.take_mailbox_notice().is_some() {
            return false;
        }
        let _ = bus.exchange(Cycles(1));
        std::thread::sleep(Duration::from_micros(500));
    }
    bus.take_mailbox_notice().is_none()
}
