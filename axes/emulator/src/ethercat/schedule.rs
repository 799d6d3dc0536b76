//! Wire faults on a schedule, for the emulated segment on a network interface (`cellrt
//! drive-sim ethercat`): the cell's `[[inject]]` wire faults, applied by the segment itself
//! because the master on a real network cannot reach into the wire.
//!
//! The schedule runs on the cell's cycle clock as the segment sees it: cycle 0 is the first
//! frame carrying a logical (process-data) datagram, LRD/LWR/LRW, and cycle `n` begins `n`
//! cycle times later on the emulator's monotonic clock (so a master that skipped cycles in an
//! overrun still meets its faults at the same cycle numbers). Durations are counted in
//! frames, as on the in-process segment.

use super::Segment;
use cellrt_cia402::cycles::CycleTime;
use cellrt_ethercat::frame::{self, Command};

/// A fault the segment injects on the wire; durations are frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WireFault {
    /// The next `frames` frames are lost on the wire: no SubDevice sees them, none returns
    /// (`rx_loss` on an EtherCAT cell).
    FrameLoss {
        /// Frames.
        frames: u32,
    },
    /// The next `frames` frames reach the segment and return `delay_ns` late.
    FrameDelay {
        /// The delay, ns.
        delay_ns: u64,
        /// Frames.
        frames: u32,
    },
    /// Bit errors on the link in front of `station` (see [`Segment::corrupt`]).
    FrameCorruption {
        /// Station position (0: the master's link).
        station: usize,
        /// Frames.
        frames: u32,
    },
    /// The logical datagrams are removed (see [`Segment::drop_datagrams`]).
    DatagramDrop {
        /// Frames.
        frames: u32,
    },
    /// The link in front of `station` is down (see [`Segment::lose_link`]).
    LinkLoss {
        /// Station position (0: the master's link).
        station: usize,
        /// Frames.
        frames: u32,
    },
    /// `station` does not answer (see [`Segment::stall`]).
    SubdeviceStall {
        /// Station position.
        station: usize,
        /// Frames.
        frames: u32,
    },
}

impl WireFault {
    /// The fault's name in a cell configuration (`[[inject]] fault`).
    pub fn name(&self) -> &'static str {
        match self {
            WireFault::FrameLoss { .. } => "rx_loss",
            WireFault::FrameDelay { .. } => "frame_delay",
            WireFault::FrameCorruption { .. } => "frame_corruption",
            WireFault::DatagramDrop { .. } => "datagram_drop",
            WireFault::LinkLoss { .. } => "link_loss",
            WireFault::SubdeviceStall { .. } => "subdevice_stall",
        }
    }

    /// The station the fault is at, where it is at one.
    pub fn station(&self) -> Option<usize> {
        match *self {
            WireFault::FrameCorruption { station, .. }
            | WireFault::LinkLoss { station, .. }
            | WireFault::SubdeviceStall { station, .. } => Some(station),
            WireFault::FrameLoss { .. }
            | WireFault::FrameDelay { .. }
            | WireFault::DatagramDrop { .. } => None,
        }
    }

    /// The same fault at station `to` where it is at a station (a cell's axis index turned
    /// into the position of the SubDevice that carries the axis: a multi-axis unit is one).
    pub fn at_station(self, to: usize) -> WireFault {
        match self {
            WireFault::FrameCorruption { frames, .. } => WireFault::FrameCorruption {
                station: to,
                frames,
            },
            WireFault::LinkLoss { frames, .. } => WireFault::LinkLoss {
                station: to,
                frames,
            },
            WireFault::SubdeviceStall { frames, .. } => WireFault::SubdeviceStall {
                station: to,
                frames,
            },
            other => other,
        }
    }

    /// How many frames it lasts.
    pub fn frames(&self) -> u32 {
        match *self {
            WireFault::FrameLoss { frames }
            | WireFault::FrameDelay { frames, .. }
            | WireFault::FrameCorruption { frames, .. }
            | WireFault::DatagramDrop { frames }
            | WireFault::LinkLoss { frames, .. }
            | WireFault::SubdeviceStall { frames, .. } => frames,
        }
    }
}

/// A wire fault due at a cycle of the cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScheduledFault {
    /// The cycle, counted from the first process-data frame (cycle 0).
    pub cycle: u64,
    /// What happens.
    pub fault: WireFault,
}

/// A schedule that names a station the segment does not have.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("fault '{fault}' at cycle {cycle} names SubDevice {station}, the segment has {stations}")]
pub struct NoSuchStation {
    /// The fault's name.
    pub fault: &'static str,
    /// Its cycle.
    pub cycle: u64,
    /// The station it names.
    pub station: usize,
    /// The segment's stations.
    pub stations: usize,
}

/// What becomes of a frame before the segment processes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameFate {
    /// Processed and returned now.
    Process,
    /// Lost on the wire (not processed, not returned).
    Lose,
    /// Processed and returned this many ns from now.
    Delay(u64),
}

/// How many of each fault were injected.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct InjectedCounts {
    /// Frame losses (`rx_loss`).
    pub frame_loss: u32,
    /// Frame delays.
    pub frame_delay: u32,
    /// Link corruptions.
    pub frame_corruption: u32,
    /// Datagram drops.
    pub datagram_drop: u32,
    /// Lost links.
    pub link_loss: u32,
    /// Stalled SubDevices.
    pub subdevice_stall: u32,
}

impl InjectedCounts {
    /// All of them.
    pub fn total(&self) -> u32 {
        self.frame_loss
            + self.frame_delay
            + self.frame_corruption
            + self.datagram_drop
            + self.link_loss
            + self.subdevice_stall
    }

    /// The non-zero counts by fault name, e.g. "1 link_loss, 2 frame_delay"; "none" if none.
    pub fn describe(&self) -> String {
        let parts: Vec<String> = [
            ("rx_loss", self.frame_loss),
            ("frame_delay", self.frame_delay),
            ("frame_corruption", self.frame_corruption),
            ("datagram_drop", self.datagram_drop),
            ("link_loss", self.link_loss),
            ("subdevice_stall", self.subdevice_stall),
        ]
        .into_iter()
        .filter(|&(_, n)| n > 0)
        .map(|(name, n)| format!("{n} {name}"))
        .collect();
        if parts.is_empty() {
            "none".to_string()
        } else {
            parts.join(", ")
        }
    }

    fn count(&mut self, fault: &WireFault) {
        let c = match fault {
            WireFault::FrameLoss { .. } => &mut self.frame_loss,
            WireFault::FrameDelay { .. } => &mut self.frame_delay,
            WireFault::FrameCorruption { .. } => &mut self.frame_corruption,
            WireFault::DatagramDrop { .. } => &mut self.datagram_drop,
            WireFault::LinkLoss { .. } => &mut self.link_loss,
            WireFault::SubdeviceStall { .. } => &mut self.subdevice_stall,
        };
        *c += 1;
    }
}

/// The cell's wire faults, applied to a segment as their cycles come.
#[derive(Debug, Clone)]
pub struct FaultSchedule {
    faults: Vec<ScheduledFault>,
    next: usize,
    cycle: CycleTime,
    /// When the first process-data frame arrived (cycle 0), ns.
    origin_ns: Option<u64>,
    /// Frames left that are lost before the segment.
    loss_frames: u32,
    /// Frames left that are delayed, and by how much.
    delay_frames: u32,
    delay_ns: u64,
    injected: InjectedCounts,
}

impl FaultSchedule {
    /// `faults` (in any order) at a cell cycle time of `cycle`, for a segment of `stations`
    /// SubDevices; an error names a fault at a station the segment lacks.
    pub fn new(
        mut faults: Vec<ScheduledFault>,
        cycle: CycleTime,
        stations: usize,
    ) -> Result<Self, NoSuchStation> {
        if let Some(f) = faults
            .iter()
            .find(|f| f.fault.station().is_some_and(|s| s >= stations))
        {
            return Err(NoSuchStation {
                fault: f.fault.name(),
                cycle: f.cycle,
                station: f.fault.station().unwrap_or(0),
                stations,
            });
        }
        faults.sort_by_key(|f| f.cycle);
        Ok(FaultSchedule {
            faults,
            ..FaultSchedule::empty(cycle)
        })
    }

    /// No faults.
    pub fn empty(cycle: CycleTime) -> Self {
        FaultSchedule {
            faults: Vec::new(),
            next: 0,
            cycle,
            origin_ns: None,
            loss_frames: 0,
            delay_frames: 0,
            delay_ns: 0,
            injected: InjectedCounts::default(),
        }
    }

    /// The faults, by cycle.
    pub fn faults(&self) -> &[ScheduledFault] {
        &self.faults
    }

    /// The cycle time the schedule counts in.
    pub fn cycle_time(&self) -> CycleTime {
        self.cycle
    }

    /// The cell's cycle at `now_ns`; `None` before the first process-data frame.
    pub fn cycle_at(&self, now_ns: u64) -> Option<u64> {
        self.origin_ns
            .map(|t0| now_ns.saturating_sub(t0) / self.cycle.as_nanos())
    }

    /// What was injected so far.
    pub fn injected(&self) -> InjectedCounts {
        self.injected
    }

    /// Called for each frame that arrives, at `now_ns`, before the segment processes it:
    /// starts the clock at the first process-data frame, applies the faults due by now to
    /// `segment`, and says what becomes of this frame. A malformed frame starts no clock.
    pub fn before_frame(&mut self, frame: &[u8], now_ns: u64, segment: &mut Segment) -> FrameFate {
        if self.origin_ns.is_none() && carries_process_data(frame) {
            self.origin_ns = Some(now_ns);
        }
        if let Some(now) = self.cycle_at(now_ns) {
            while let Some(f) = self.faults.get(self.next).copied() {
                if f.cycle > now {
                    break;
                }
                self.next += 1;
                self.apply(f.fault, segment);
            }
        }
        if self.loss_frames > 0 {
            self.loss_frames -= 1;
            return FrameFate::Lose;
        }
        if self.delay_frames > 0 {
            self.delay_frames -= 1;
            return FrameFate::Delay(self.delay_ns);
        }
        FrameFate::Process
    }

    fn apply(&mut self, fault: WireFault, segment: &mut Segment) {
        let applied = match fault {
            WireFault::FrameLoss { frames } => {
                self.loss_frames = frames;
                true
            }
            WireFault::FrameDelay { delay_ns, frames } => {
                self.delay_ns = delay_ns;
                self.delay_frames = frames;
                true
            }
            WireFault::FrameCorruption { station, frames } => segment.corrupt(station, frames),
            WireFault::DatagramDrop { frames } => {
                segment.drop_datagrams(frames);
                true
            }
            WireFault::LinkLoss { station, frames } => segment.lose_link(station, frames),
            WireFault::SubdeviceStall { station, frames } => segment.stall(station, frames),
        };
        // Stations were checked in `new`; a fault the segment refused is not counted.
        if applied {
            self.injected.count(&fault);
        }
    }
}

/// True if `frame` carries a logical datagram (LRD, LWR, LRW): process data.
pub(super) fn carries_process_data(frame: &[u8]) -> bool {
    frame::datagrams(frame).any(|d| {
        d.is_ok_and(|d| matches!(d.header.command, Command::Lrd | Command::Lwr | Command::Lrw))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ethercat::Delivery;
    use crate::{SimDrive, SimDriveParams};
    use cellrt_cia402::{profile, DriveModel};
    use cellrt_ethercat::frame::FrameBuilder;
    use cellrt_ethercat::register as reg;

    const MS: u64 = 1_000_000;
    /// When the first process-data frame arrives in these tests.
    const T0: u64 = 5_000 * MS;

    fn cycle() -> CycleTime {
        CycleTime::from_micros(1000).unwrap()
    }

    fn segment(stations: usize) -> Segment {
        Segment::new(
            (0..stations)
                .map(|_| {
                    SimDrive::new(
                        profile(DriveModel::MrJ4TM),
                        SimDriveParams::default(),
                        cycle(),
                    )
                })
                .collect(),
        )
    }

    /// A frame with a BRD of the DL status (every answering station adds 1 to its working
    /// counter), with an LRW in front if `process_data`.
    fn frame(process_data: bool) -> Vec<u8> {
        let mut buf = vec![0u8; 128];
        let mut b = FrameBuilder::new(&mut buf, [0x10, 0, 0, 0, 0, 1]);
        if process_data {
            b.push(Command::Lrw, 1, 0, &[0; 8]).unwrap();
        }
        b.push(Command::Brd, 2, u32::from(reg::DL_STATUS) << 16, &[0; 2])
            .unwrap();
        let n = b.finish();
        buf.truncate(n);
        buf
    }

    /// The working counter of the frame's BRD (its last datagram).
    fn brd_wkc(frame: &[u8]) -> u16 {
        let span = frame::datagrams(frame).last().unwrap().unwrap();
        frame::wkc(frame, &span)
    }

    fn schedule(faults: &[(u64, WireFault)], stations: usize) -> FaultSchedule {
        FaultSchedule::new(
            faults
                .iter()
                .map(|&(cycle, fault)| ScheduledFault { cycle, fault })
                .collect(),
            cycle(),
            stations,
        )
        .unwrap()
    }

    /// What a frame met: its fate before the segment, and the segment's delivery and BRD
    /// working counter where it was processed.
    type Seen = (FrameFate, Option<(Delivery, u16)>);

    /// Passes one frame through `s` and `seg` at `now`.
    fn pass(s: &mut FaultSchedule, seg: &mut Segment, process_data: bool, now: u64) -> Seen {
        let mut f = frame(process_data);
        let fate = s.before_frame(&f, now, seg);
        if fate != FrameFate::Process {
            return (fate, None);
        }
        let d = seg.process(&mut f, now).unwrap();
        (fate, Some((d, brd_wkc(&f))))
    }

    #[test]
    fn the_clock_starts_at_the_first_process_data_frame() {
        let mut seg = segment(2);
        let mut s = schedule(&[(0, WireFault::FrameLoss { frames: 1 })], 2);
        // Bring-up frames (no logical datagram) before it start no clock and meet no fault,
        // however long bring-up takes.
        for t in [0, 10 * MS, T0 - 1] {
            assert_eq!(s.cycle_at(t), None);
            assert_eq!(
                pass(&mut s, &mut seg, false, t),
                (FrameFate::Process, Some((Delivery::Returned, 2)))
            );
        }
        assert_eq!(s.injected().total(), 0);
        // The first LRW is cycle 0: the fault due at 0 takes it.
        assert_eq!(pass(&mut s, &mut seg, true, T0).0, FrameFate::Lose);
        assert_eq!(s.cycle_at(T0 + 999_999), Some(0));
        assert_eq!(s.cycle_at(T0 + 7 * MS), Some(7));
        assert_eq!(s.injected().frame_loss, 1);
        assert_eq!(pass(&mut s, &mut seg, true, T0 + MS).0, FrameFate::Process);
    }

    #[test]
    fn a_fault_waits_for_its_cycle_then_lasts_its_frames() {
        let mut seg = segment(2);
        let mut s = schedule(&[(3, WireFault::FrameLoss { frames: 2 })], 2);
        let fates: Vec<FrameFate> = (0..7)
            .map(|c| pass(&mut s, &mut seg, true, T0 + c * MS + 200_000).0)
            .collect();
        use FrameFate::{Lose, Process};
        assert_eq!(
            fates,
            [Process, Process, Process, Lose, Lose, Process, Process]
        );
    }

    #[test]
    fn faults_due_in_cycles_the_master_skipped_are_applied_at_its_next_frame() {
        let mut seg = segment(2);
        let mut s = schedule(
            &[
                (2, WireFault::DatagramDrop { frames: 4 }),
                (
                    3,
                    WireFault::SubdeviceStall {
                        station: 1,
                        frames: 4,
                    },
                ),
            ],
            2,
        );
        pass(&mut s, &mut seg, true, T0);
        // The master overran: its next frame comes at cycle 5.
        assert_eq!(
            pass(&mut s, &mut seg, true, T0 + 5 * MS),
            (FrameFate::Process, Some((Delivery::Returned, 1)))
        );
        assert_eq!(seg.dropping_datagrams(), 3);
        assert_eq!(s.injected().datagram_drop, 1);
        assert_eq!(s.injected().subdevice_stall, 1);
    }

    #[test]
    fn each_wire_fault_reaches_the_segment_at_its_cycle() {
        // (fault, what the frame at its cycle shows) — the frame before is untouched.
        let stall = WireFault::SubdeviceStall {
            station: 0,
            frames: 2,
        };
        let cases = [
            (WireFault::FrameLoss { frames: 2 }, FrameFate::Lose, None),
            (
                WireFault::FrameDelay {
                    delay_ns: 300_000,
                    frames: 2,
                },
                FrameFate::Delay(300_000),
                None,
            ),
            (
                WireFault::FrameCorruption {
                    station: 1,
                    frames: 2,
                },
                FrameFate::Process,
                Some((Delivery::Lost, 1)),
            ),
            (
                WireFault::LinkLoss {
                    station: 1,
                    frames: 2,
                },
                FrameFate::Process,
                Some((Delivery::Returned, 1)),
            ),
            (
                WireFault::LinkLoss {
                    station: 0,
                    frames: 2,
                },
                FrameFate::Process,
                Some((Delivery::Lost, 0)),
            ),
            (stall, FrameFate::Process, Some((Delivery::Returned, 1))),
        ];
        for (fault, fate, seen) in cases {
            let mut seg = segment(2);
            let mut s = schedule(&[(10, fault)], 2);
            for c in 0..10 {
                assert_eq!(
                    pass(&mut s, &mut seg, true, T0 + c * MS),
                    (FrameFate::Process, Some((Delivery::Returned, 2))),
                    "{fault:?} at cycle {c}"
                );
            }
            assert_eq!(
                pass(&mut s, &mut seg, true, T0 + 10 * MS),
                (fate, seen),
                "{fault:?}"
            );
            assert_eq!(s.injected().total(), 1, "{fault:?}");
            // Two frames long: the third after it is untouched again.
            pass(&mut s, &mut seg, true, T0 + 11 * MS);
            assert_eq!(
                pass(&mut s, &mut seg, true, T0 + 12 * MS),
                (FrameFate::Process, Some((Delivery::Returned, 2))),
                "{fault:?} after its frames"
            );
        }
        // The datagram drop: the cyclic LRW removed for its frames, the frame itself returns.
        let mut seg = segment(2);
        let mut s = schedule(&[(10, WireFault::DatagramDrop { frames: 2 })], 2);
        for c in 0..10 {
            pass(&mut s, &mut seg, true, T0 + c * MS);
            assert_eq!(seg.dropping_datagrams(), 0);
        }
        assert_eq!(
            pass(&mut s, &mut seg, true, T0 + 10 * MS),
            (FrameFate::Process, Some((Delivery::Returned, 2)))
        );
        assert_eq!(seg.dropping_datagrams(), 1);
        assert_eq!(s.injected().datagram_drop, 1);
    }

    #[test]
    fn a_fault_at_a_station_the_segment_lacks_is_refused_by_name() {
        let e = FaultSchedule::new(
            vec![ScheduledFault {
                cycle: 4,
                fault: WireFault::LinkLoss {
                    station: 2,
                    frames: 1,
                },
            }],
            cycle(),
            2,
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "fault 'link_loss' at cycle 4 names SubDevice 2, the segment has 2"
        );
    }

    #[test]
    fn the_injected_counts_read_by_fault_name() {
        let mut c = InjectedCounts::default();
        assert_eq!(c.describe(), "none");
        c.count(&WireFault::LinkLoss {
            station: 0,
            frames: 1,
        });
        c.count(&WireFault::FrameDelay {
            delay_ns: 1,
            frames: 1,
        });
        c.count(&WireFault::FrameDelay {
            delay_ns: 1,
            frames: 1,
        });
        assert_eq!(c.describe(), "2 frame_delay, 1 link_loss");
    }
}
