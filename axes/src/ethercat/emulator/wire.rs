//! The emulated segment on a network interface: frames from the MainDevice are processed and
//! returned on the same interface, as the last SubDevice of a line returns them.

use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use super::{Delivery, Segment};
use crate::ethercat::frame::REPLY_SOURCE_MAC_BIT;
use crate::ethercat::raw_socket::RawSocket;

/// How often the loop looks at the stop flag while no frame arrives.
const STOP_POLL: Duration = Duration::from_millis(50);

/// The local clock of the emulated ESCs: CLOCK_MONOTONIC in ns.
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes the timespec it is given.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

/// What the emulator saw on the wire.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WireStats {
    /// Frames processed and returned.
    pub frames: u64,
    /// Frames that were not EtherCAT datagram frames and were dropped.
    pub malformed: u64,
    /// Frames the segment did not return (an injected wire fault).
    pub lost: u64,
}

/// Serves `segment` on `socket` until `stop` is set.
pub fn serve(
    socket: &RawSocket,
    segment: &mut Segment,
    stop: &AtomicBool,
) -> io::Result<WireStats> {
    let mut buf = vec![0u8; 1536];
    let mut stats = WireStats::default();
    while !stop.load(Ordering::Acquire) {
        let Some(n) = socket.recv(&mut buf, STOP_POLL)? else {
            continue;
        };
        // Our own replies, seen on the way out.
        if n < 7 || buf[6] & REPLY_SOURCE_MAC_BIT != 0 {
            continue;
        }
        match segment.process(&mut buf[..n], monotonic_ns()) {
            Ok(Delivery::Returned) => {
                socket.send(&buf[..n])?;
                stats.frames += 1;
            }
            Ok(Delivery::Lost) => stats.lost += 1,
            Err(_) => stats.malformed += 1,
        }
    }
    Ok(stats)
}
