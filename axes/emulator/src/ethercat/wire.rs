//! The emulated segment on a network interface: frames from the MainDevice are processed and
//! returned on the same interface, as the last SubDevice of a line returns them, with the
//! cell's wire faults injected on their schedule ([`FaultSchedule`]).

use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use super::delay_line::{DelayLine, MAX_FRAME};
use super::schedule::{FaultSchedule, FrameFate, InjectedCounts};
use super::{Delivery, Segment};
use cellrt_ethercat::raw_socket::RawSocket;
use cellrt_ethercat::register::AlState;

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
    /// Frames not returned because of an injected wire fault (lost, corrupted, behind a lost
    /// link, or delayed while the delay line was full).
    pub lost: u64,
    /// Frames returned late by an injected frame delay.
    pub delayed: u64,
    /// The scheduled faults injected.
    pub injected: InjectedCounts,
    /// The longest time between two frames the segment processed while every station was in
    /// OP, ns: a stall of the master or of the emulator's own thread (a loaded host), which the
    /// drives count as lost frames (they count none outside OP, where bring-up pauses are normal).
    pub max_gap_ns: u64,
    /// When the segment last processed a frame (monotonic ns; 0 before the first).
    pub last_frame_ns: u64,
    /// When the segment last processed a frame with every station in OP (monotonic ns; 0 when
    /// the last frame found a station outside OP).
    pub last_op_frame_ns: u64,
}

/// How the emulated drives take a gap in the MainDevice's frames in OP.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HostStalls {
    /// As real drives: every SYNC0 without new outputs is a lost RxPDO for their
    /// communication checks.
    #[default]
    Counted,
    /// A gap of whole `cycle`s between two frames arriving (lost ones included) is a stall of
    /// the MainDevice's host or of this process, not lost frames: the drives run on through it,
    /// as on the in-process segment (`Segment::excuse_host_stall`). Frames lost by an injected
    /// fault still count, one SYNC0 each. For emulation on a loaded machine.
    Excused {
        /// The cell's cycle time (the SYNC0 cycle).
        cycle: Duration,
    },
}

/// Gaps between frames arriving from the MainDevice, excused as host stalls by [`HostStalls`].
#[derive(Debug)]
struct StallExcuser {
    cycle_ns: u64,
    last_arrival_ns: Option<u64>,
}

impl StallExcuser {
    fn new(policy: HostStalls) -> Option<Self> {
        match policy {
            HostStalls::Counted => None,
            HostStalls::Excused { cycle } => Some(StallExcuser {
                cycle_ns: u64::try_from(cycle.as_nanos()).unwrap_or(u64::MAX).max(1),
                last_arrival_ns: None,
            }),
        }
    }

    /// A frame arrived at `now_ns`: the whole cycles beyond one since the previous arrival are
    /// excused on every station (only while all are in OP, where the drives count SYNC0s).
    fn arrival(&mut self, now_ns: u64, segment: &mut Segment) {
        let in_op = segment
            .stations()
            .iter()
            .all(|st| st.al_state() == AlState::Op);
        if let (true, Some(last)) = (in_op, self.last_arrival_ns) {
            let gap = now_ns.saturating_sub(last);
            let edges = (gap + self.cycle_ns / 2) / self.cycle_ns;
            if edges > 1 {
                segment.excuse_host_stall(edges - 1);
            }
        }
        self.last_arrival_ns = Some(now_ns);
    }
}

/// Serves `segment` on `socket` with `faults` injected until `stop` is set, the drives taking
/// gaps in the MainDevice's frames as `stalls` says. Allocates nothing per frame.
pub fn serve(
    socket: &RawSocket,
    segment: &mut Segment,
    faults: &mut FaultSchedule,
    stalls: HostStalls,
    stop: &AtomicBool,
) -> io::Result<WireStats> {
    let mut buf = vec![0u8; MAX_FRAME];
    let mut late = DelayLine::new();
    let mut stats = WireStats::default();
    let mut excuser = StallExcuser::new(stalls);
    while !stop.load(Ordering::Acquire) {
        // Delayed frames that are due go first, processed when they reach the segment.
        while let Some(n) = late.pop_due(monotonic_ns(), &mut buf) {
            if deliver(socket, segment, &mut buf[..n], &mut stats)? {
                stats.delayed += 1;
            }
        }
        let wait = late.next_due().map_or(STOP_POLL, |due| {
            STOP_POLL.min(Duration::from_nanos(due.saturating_sub(monotonic_ns())))
        });
        let Some(n) = socket.recv(&mut buf, wait)? else {
            continue;
        };
        // Frames from the MainDevice whatever their source MAC (the socket skips our own
        // replies on the way out by their packet type, not by the MAC bit we set in them).
        if n < 7 {
            continue;
        }
        let now = monotonic_ns();
        if let Some(excuser) = &mut excuser {
            excuser.arrival(now, segment);
        }
        match faults.before_frame(&buf[..n], now, segment) {
            FrameFate::Process => {
                deliver(socket, segment, &mut buf[..n], &mut stats)?;
            }
            FrameFate::Lose => stats.lost += 1,
            FrameFate::Delay(ns) => {
                if !late.push(&buf[..n], now.saturating_add(ns)) {
                    stats.lost += 1;
                }
            }
        }
    }
    stats.injected = faults.injected();
    Ok(stats)
}

/// Processes `frame` on `segment` now and returns it on `socket` unless the segment lost it;
/// true if it was returned.
fn deliver(
    socket: &RawSocket,
    segment: &mut Segment,
    frame: &mut [u8],
    stats: &mut WireStats,
) -> io::Result<bool> {
    let now = monotonic_ns();
    let in_op = segment
        .stations()
        .iter()
        .all(|st| st.al_state() == AlState::Op);
    if in_op && stats.last_op_frame_ns != 0 {
        stats.max_gap_ns = stats
            .max_gap_ns
            .max(now.saturating_sub(stats.last_op_frame_ns));
    }
    stats.last_frame_ns = now;
    stats.last_op_frame_ns = if in_op { now } else { 0 };
    match segment.process(frame, now) {
        Ok(Delivery::Returned) => {
            socket.send(frame)?;
            stats.frames += 1;
            Ok(true)
        }
        Ok(Delivery::Lost) => {
            stats.lost += 1;
            Ok(false)
        }
        Err(_) => {
            stats.malformed += 1;
            Ok(false)
        }
    }
}
