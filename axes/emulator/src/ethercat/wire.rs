//! The emulated segment on a network interface: frames from the MainDevice are processed and
//! returned on the same interface, as the last SubDevice of a line returns them, with the
//! cell's wire faults injected on their schedule ([`FaultSchedule`]).

use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use super::delay_line::{DelayLine, MAX_FRAME};
use super::schedule::{carries_process_data, FaultSchedule, FrameFate, InjectedCounts};
use super::{Delivery, Segment};
use cellrt_ethercat::master::SYNC0_FRAME_PHASE_DIVISOR;
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
    /// As real drives: the ESCs run on this machine's clock, and every SYNC0 without new
    /// outputs is a lost RxPDO for their communication checks.
    #[default]
    Counted,
    /// The drives live on the MainDevice's clock, as on the in-process segment: in OP each
    /// process-data frame that arrives is one SYNC0 cycle later than the one before (placed
    /// where the master aims its frames in the cycle, [`SYNC0_FRAME_PHASE_DIVISOR`]), whatever
    /// the time between them, so a stall of the master's host or of this process is no lost
    /// frame and frame jitter no missed edge. A frame an injected fault loses still takes its
    /// cycle (a lost RxPDO), and the fault schedule counts these cycles. For emulation on a
    /// loaded machine (`cellrt drive-sim ethercat --excuse-host-stalls`).
    Excused {
        /// The cycle when the master has not started SYNC0 (free run).
        cycle: Duration,
    },
}

/// The segment's clock under [`HostStalls::Excused`]: wall time outside OP, one cycle per
/// process-data frame in OP.
#[derive(Debug)]
struct FramePacedClock {
    free_run_cycle_ns: u64,
    /// This clock minus wall time, ns.
    offset: i128,
    /// The time given to the last process-data frame in OP, and the cycle it was taken at.
    last_pd: Option<(u64, u64)>,
    /// The last time given (the clock never goes back).
    last: u64,
}

impl FramePacedClock {
    fn new(policy: HostStalls) -> Option<Self> {
        match policy {
            HostStalls::Counted => None,
            HostStalls::Excused { cycle } => Some(FramePacedClock {
                free_run_cycle_ns: u64::try_from(cycle.as_nanos()).unwrap_or(u64::MAX).max(1),
                offset: 0,
                last_pd: None,
                last: 0,
            }),
        }
    }

    /// The segment's time for `frame`, arriving at wall time `wall` (a delayed frame reaching
    /// the segment: `frame` is `None`).
    fn at(&mut self, wall: u64, frame: Option<&[u8]>, segment: &Segment) -> u64 {
        let in_op = segment
            .stations()
            .iter()
            .all(|st| st.al_state() == AlState::Op);
        if !in_op {
            self.last_pd = None;
        }
        let shifted = u64::try_from((i128::from(wall) + self.offset).max(0)).unwrap_or(u64::MAX);
        let pd = in_op && frame.is_some_and(carries_process_data);
        let t = match (pd, self.last_pd) {
            (true, Some((p, cycle))) => self.took_pd(p + cycle, cycle, wall),
            // The first one in OP: onto the place in the SYNC0 cycle the master aims at.
            (true, None) => match segment
                .stations()
                .iter()
                .find_map(|st| st.sync0_phase(shifted))
            {
                Some((phase, cycle)) => {
                    let aim = cycle / SYNC0_FRAME_PHASE_DIVISOR;
                    let late = if phase > aim { cycle } else { 0 };
                    self.took_pd(shifted.saturating_sub(phase) + aim + late, cycle, wall)
                }
                None => self.took_pd(shifted, self.free_run_cycle_ns, wall),
            },
            // Other frames in OP (mailbox, delayed ones) stay before the next cycle's edge.
            (false, Some((p, cycle))) => shifted.min(p + cycle - 1),
            (false, None) => shifted,
        };
        let t = t.max(self.last);
        self.last = t;
        t
    }

    /// A process-data frame in OP takes time `t` on a grid of `cycle`.
    fn took_pd(&mut self, t: u64, cycle: u64, wall: u64) -> u64 {
        self.last_pd = Some((t, cycle));
        self.offset = i128::from(t) - i128::from(wall);
        t
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
    let mut clock = FramePacedClock::new(stalls);
    while !stop.load(Ordering::Acquire) {
        // Delayed frames that are due go first, processed when they reach the segment.
        while let Some(n) = late.pop_due(monotonic_ns(), &mut buf) {
            let wall = monotonic_ns();
            let now = clock.as_mut().map_or(wall, |c| c.at(wall, None, segment));
            if deliver(socket, segment, &mut buf[..n], now, &mut stats)? {
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
        let wall = monotonic_ns();
        let now = clock
            .as_mut()
            .map_or(wall, |c| c.at(wall, Some(&buf[..n]), segment));
        match faults.before_frame(&buf[..n], now, segment) {
            FrameFate::Process => {
                deliver(socket, segment, &mut buf[..n], now, &mut stats)?;
            }
            FrameFate::Lose => stats.lost += 1,
            FrameFate::Delay(ns) => {
                if !late.push(&buf[..n], wall.saturating_add(ns)) {
                    stats.lost += 1;
                }
            }
        }
    }
    stats.injected = faults.injected();
    Ok(stats)
}

/// Processes `frame` on `segment` at its time `now` and returns it on `socket` unless the
/// segment lost it; true if it was returned.
fn deliver(
    socket: &RawSocket,
    segment: &mut Segment,
    frame: &mut [u8],
    now: u64,
    stats: &mut WireStats,
) -> io::Result<bool> {
    let wall = monotonic_ns();
    let in_op = segment
        .stations()
        .iter()
        .all(|st| st.al_state() == AlState::Op);
    if in_op && stats.last_op_frame_ns != 0 {
        stats.max_gap_ns = stats
            .max_gap_ns
            .max(wall.saturating_sub(stats.last_op_frame_ns));
    }
    stats.last_frame_ns = wall;
    stats.last_op_frame_ns = if in_op { wall } else { 0 };
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
