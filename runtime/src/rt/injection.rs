//! The cell's `[[inject]]` schedule as the RT loop applies it: at the start of each cycle the
//! executive asks for the faults that are due, and the schedule injects the bus faults into
//! the bus itself. The executive's bus is only a [`CyclicBus`] and [`AcyclicBus`]: nothing on
//! the RT path can inject a fault the schedule does not hold.
//!
//! [`CyclicBus`]: cellrt_cia402::CyclicBus
//! [`AcyclicBus`]: cellrt_cia402::AcyclicBus

use cellrt_cia402::FaultInjection;

use cellrt_config::{CellConfig, InjectedFault, Injection};

/// What became of a scheduled fault that came due.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// Injected into the bus.
    Injected,
    /// The bus cannot inject it (real drives, or a fault of another kind of bus).
    Refused,
    /// A wire fault of a cell on a network interface: the segment on the far end injects it.
    LeftToSegment,
    /// Not a bus fault: the RT loop carries it out itself (a stall).
    ForTheLoop,
}

/// A scheduled fault that came due, with its outcome.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DueFault {
    /// The fault.
    pub fault: InjectedFault,
    /// What became of it.
    pub outcome: Outcome,
}

/// The faults scheduled for the RT loop (all but the planner's), by cycle, with the one way
/// to inject them into a bus of type `B`. Allocation-free after construction.
pub struct InjectionSchedule<B> {
    due: Vec<Injection>,
    next: usize,
    wire_faults_remote: bool,
    inject: fn(&mut B, InjectedFault) -> bool,
}

impl<B: FaultInjection> InjectionSchedule<B> {
    /// The schedule of `cell`; the wire faults of a cell on a network interface are left to
    /// the segment on the far end ([`CellConfig::faults_left_to_segment`]).
    pub fn for_cell(cell: &CellConfig) -> Self {
        let mut schedule = Self::in_process(cell);
        schedule.wire_faults_remote = !cell.faults_left_to_segment().is_empty();
        schedule
    }

    /// The schedule of `cell` with every bus fault injected into this process's bus (what
    /// `cellrt replay` feeds its simulated drives).
    pub fn in_process(cell: &CellConfig) -> Self {
        InjectionSchedule {
            due: cell
                .inject
                .iter()
                .copied()
                .filter(|i| !matches!(i.fault, InjectedFault::PlannerStall { .. }))
                .collect(),
            next: 0,
            wire_faults_remote: false,
            inject: inject_into_bus::<B>,
        }
    }
}

impl<B> InjectionSchedule<B> {
    /// The next fault due at or before `cycle`, injected into `bus` where it is a bus fault;
    /// `None` once none is due. Call until `None` at each cycle start.
    pub fn next_due(&mut self, cycle: u64, bus: &mut B) -> Option<DueFault> {
        let fault = self.due.get(self.next).filter(|i| i.cycle <= cycle)?.fault;
        self.next += 1;
        let outcome = if matches!(fault, InjectedFault::Stall { .. }) {
            Outcome::ForTheLoop
        } else if self.wire_faults_remote && fault.wire_fault().is_some() {
            Outcome::LeftToSegment
        } else if (self.inject)(bus, fault) {
            Outcome::Injected
        } else {
            Outcome::Refused
        };
        Some(DueFault { fault, outcome })
    }
}

/// Injects a bus fault into `bus`; false if the bus cannot inject it or it is not a bus fault.
fn inject_into_bus<B: FaultInjection>(bus: &mut B, fault: InjectedFault) -> bool {
    match fault {
        InjectedFault::DriveAlarm { axis, code } => bus.inject_alarm(axis, code),
        InjectedFault::RxLoss { axis, cycles } => bus.inject_rx_loss(axis, cycles),
        InjectedFault::CounterCorruption { axis, cycles } => {
            bus.inject_counter_corruption(axis, cycles)
        }
        InjectedFault::SubdeviceStall { axis, cycles } => bus.inject_subdevice_stall(axis, cycles),
        InjectedFault::FrameDelay { delay_ns, cycles } => bus.inject_frame_delay(delay_ns, cycles),
        InjectedFault::FrameCorruption { axis, cycles } => {
            bus.inject_frame_corruption(axis, cycles)
        }
        InjectedFault::DatagramDrop { cycles } => bus.inject_datagram_drop(cycles),
        InjectedFault::LinkLoss { axis, cycles } => bus.inject_link_loss(axis, cycles),
        InjectedFault::Stall { .. } | InjectedFault::PlannerStall { .. } => false,
    }
}
