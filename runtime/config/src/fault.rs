//! Scheduled fault injection (`[[inject]]`): which faults there are, with their names in the
//! configuration and their codes in the recording, and when each one happens.

use cellrt_emulator::ethercat::WireFault;

/// The kinds of injectable faults, the one list of them: the name is the `[[inject]] fault`
/// key and the recording's fault name, the code (`as i64`) the value of a `fault_injected` or
/// `fault_left_to_segment` event.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    strum::IntoStaticStr,
    strum::EnumString,
    strum::FromRepr,
    strum::VariantNames,
)]
#[strum(serialize_all = "snake_case")]
#[repr(u8)]
pub enum FaultKind {
    /// The RT loop body busy-waits (overruns).
    Stall = 1,
    /// A drive raises an alarm.
    DriveAlarm = 2,
    /// The planner publishes nothing for a while.
    PlannerStall = 3,
    /// An axis' RxPDO is lost.
    RxLoss = 4,
    /// The incremental counter a drive receives is corrupted.
    CounterCorruption = 5,
    /// An EtherCAT SubDevice does not answer.
    SubdeviceStall = 6,
    /// The cyclic frames return late.
    FrameDelay = 7,
    /// Bit errors on an EtherCAT link.
    FrameCorruption = 8,
    /// The cyclic LRW datagram is removed.
    DatagramDrop = 9,
    /// An EtherCAT link is down.
    LinkLoss = 10,
}

impl FaultKind {
    /// The value of the `fault_injected` / `fault_left_to_segment` event.
    pub const fn code(self) -> i64 {
        self as i64
    }

    /// The kind an event value names; `None` for a value that names none.
    pub fn from_code(code: i64) -> Option<FaultKind> {
        u8::try_from(code).ok().and_then(FaultKind::from_repr)
    }

    /// The name in the configuration and the recording.
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// A fault to inject at a cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Injection {
    /// Cycle (from the RT loop's start) at which it happens.
    pub cycle: u64,
    /// What happens.
    pub fault: InjectedFault,
}

/// Kinds of injected faults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InjectedFault {
    /// The RT loop body busy-waits this long (overruns).
    Stall {
        /// Nanoseconds.
        ns: u64,
    },
    /// The drive of an axis raises an alarm (603Fh code).
    DriveAlarm {
        /// Axis index.
        axis: usize,
        /// Alarm code.
        code: u16,
    },
    /// The planner publishes nothing for this long (underrun once the lookahead is used up).
    PlannerStall {
        /// Nanoseconds.
        ns: u64,
    },
    /// An axis' RxPDO is not delivered for this many cycles (lost frames).
    RxLoss {
        /// Axis index.
        axis: usize,
        /// Cycles.
        cycles: u32,
    },
    /// The incremental counter an axis' drive receives is corrupted for this many cycles.
    CounterCorruption {
        /// Axis index.
        axis: usize,
        /// Cycles.
        cycles: u32,
    },
    /// EtherCAT: an axis' SubDevice does not answer for this many cycles (working-counter
    /// errors at the master, missed SYNC0 data at the drive).
    SubdeviceStall {
        /// Axis index.
        axis: usize,
        /// Cycles.
        cycles: u32,
    },
    /// EtherCAT, emulated segment: every cyclic frame returns `delay_ns` late for this many
    /// cycles (at or beyond `frame_timeout` lost at the master).
    FrameDelay {
        /// The delay, ns.
        delay_ns: u64,
        /// Cycles.
        cycles: u32,
    },
    /// EtherCAT, emulated segment: bit errors on the link in front of an axis' SubDevice
    /// (CRC errors) for this many cycles.
    FrameCorruption {
        /// Axis index (the link in front of its SubDevice; 0: the master's link).
        axis: usize,
        /// Cycles.
        cycles: u32,
    },
    /// EtherCAT, emulated segment: the cyclic LRW datagram is removed for this many cycles.
    DatagramDrop {
        /// Cycles.
        cycles: u32,
    },
    /// EtherCAT, emulated segment: the link in front of an axis' SubDevice is down for this
    /// many cycles.
    LinkLoss {
        /// Axis index (the link in front of its SubDevice; 0: the master's link).
        axis: usize,
        /// Cycles.
        cycles: u32,
    },
}

impl InjectedFault {
    /// True for the faults only an emulated EtherCAT segment injects: in process by the
    /// master's link, on a network interface by `cellrt drive-sim ethercat` on the far end.
    pub fn needs_emulated_segment(&self) -> bool {
        matches!(
            self,
            InjectedFault::SubdeviceStall { .. }
                | InjectedFault::FrameDelay { .. }
                | InjectedFault::FrameCorruption { .. }
                | InjectedFault::DatagramDrop { .. }
                | InjectedFault::LinkLoss { .. }
        )
    }

    /// The fault as the segment injects it on the wire of an EtherCAT cell (`rx_loss` is the
    /// loss of the segment's frames there); `None` for the faults the controller injects.
    pub fn wire_fault(&self) -> Option<WireFault> {
        Some(match *self {
            InjectedFault::RxLoss { cycles, .. } => WireFault::FrameLoss { frames: cycles },
            InjectedFault::SubdeviceStall { axis, cycles } => WireFault::SubdeviceStall {
                station: axis,
                frames: cycles,
            },
            InjectedFault::FrameDelay { delay_ns, cycles } => WireFault::FrameDelay {
                delay_ns,
                frames: cycles,
            },
            InjectedFault::FrameCorruption { axis, cycles } => WireFault::FrameCorruption {
                station: axis,
                frames: cycles,
            },
            InjectedFault::DatagramDrop { cycles } => WireFault::DatagramDrop { frames: cycles },
            InjectedFault::LinkLoss { axis, cycles } => WireFault::LinkLoss {
                station: axis,
                frames: cycles,
            },
            InjectedFault::Stall { .. }
            | InjectedFault::DriveAlarm { .. }
            | InjectedFault::PlannerStall { .. }
            | InjectedFault::CounterCorruption { .. } => return None,
        })
    }

    /// The fault's kind: its name in the configuration and its code in the recording.
    pub fn kind(&self) -> FaultKind {
        match self {
            InjectedFault::Stall { .. } => FaultKind::Stall,
            InjectedFault::DriveAlarm { .. } => FaultKind::DriveAlarm,
            InjectedFault::PlannerStall { .. } => FaultKind::PlannerStall,
            InjectedFault::RxLoss { .. } => FaultKind::RxLoss,
            InjectedFault::CounterCorruption { .. } => FaultKind::CounterCorruption,
            InjectedFault::SubdeviceStall { .. } => FaultKind::SubdeviceStall,
            InjectedFault::FrameDelay { .. } => FaultKind::FrameDelay,
            InjectedFault::FrameCorruption { .. } => FaultKind::FrameCorruption,
            InjectedFault::DatagramDrop { .. } => FaultKind::DatagramDrop,
            InjectedFault::LinkLoss { .. } => FaultKind::LinkLoss,
        }
    }

    /// The fault's name in the configuration (`[[inject]] fault`).
    pub fn name(&self) -> &'static str {
        self.kind().into()
    }

    /// The axis the fault is injected at; `None` for the faults of the loop, the planner or
    /// the whole segment.
    pub fn axis(&self) -> Option<usize> {
        match *self {
            InjectedFault::DriveAlarm { axis, .. }
            | InjectedFault::RxLoss { axis, .. }
            | InjectedFault::CounterCorruption { axis, .. }
            | InjectedFault::SubdeviceStall { axis, .. }
            | InjectedFault::FrameCorruption { axis, .. }
            | InjectedFault::LinkLoss { axis, .. } => Some(axis),
            InjectedFault::Stall { .. }
            | InjectedFault::PlannerStall { .. }
            | InjectedFault::FrameDelay { .. }
            | InjectedFault::DatagramDrop { .. } => None,
        }
    }
}
