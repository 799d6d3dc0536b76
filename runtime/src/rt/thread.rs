//! RT thread setup. Each privilege is requested separately; what the OS refuses is reported once,
//! by name, and the loop runs best effort (docs/architecture.md, rule 5).

use serde::Serialize;

use cellrt_config::RtConfig;

/// Stack the RT thread touches before the loop so it never page-faults on stack growth.
pub const PREFAULT_STACK_BYTES: usize = 256 * 1024;

/// What took effect when the RT thread was set up.
#[derive(Debug, Clone, Default, Serialize, PartialEq, Eq)]
pub struct RtReport {
    /// CPU the thread is pinned to, if pinning was asked for and worked.
    pub cpu: Option<usize>,
    /// "SCHED_FIFO" or "SCHED_OTHER".
    pub policy: String,
    /// SCHED_FIFO priority in effect (0 under SCHED_OTHER).
    pub priority: u8,
    /// The planner thread's SCHED_FIFO priority in effect (0: SCHED_OTHER, or no planner).
    pub planner_priority: u8,
    /// Whether mlockall(MCL_CURRENT | MCL_FUTURE) took effect.
    pub memory_locked: bool,
    /// Bytes of stack prefaulted.
    pub stack_prefaulted: usize,
    /// Whether `/dev/cpu_dma_latency` is held at 0 µs (no deep C-states) while running.
    pub cpu_dma_latency_zero: bool,
    /// CPUs cellrt's other threads were moved to, keeping `cpu` for the RT thread (empty: not
    /// reserved, see [`ReservedCpu`]).
    pub other_threads_cpus: Vec<usize>,
    /// One line per refused privilege.
    pub refused: Vec<String>,
}

impl RtReport {
    /// One line for the start-up banner.
    pub fn describe(&self) -> String {
        format!(
            "RT thread: cpu {}{}, {} priority {}, memory {}, stack prefault {} KiB, cpu_dma_latency {}{}",
            self.cpu
                .map(|c| c.to_string())
                .unwrap_or_else(|| "any".into()),
            if self.other_threads_cpus.is_empty() {
                String::new()
            } else {
                format!(
                    " (reserved; other threads on {})",
                    self.other_threads_cpus
                        .iter()
                        .map(|c| c.to_string())
                        .collect::<Vec<_>>()
                        .join(",")
                )
            },
            self.policy,
            self.priority,
            if self.memory_locked {
                "locked"
            } else {
                "not locked"
            },
            self.stack_prefaulted / 1024,
            if self.cpu_dma_latency_zero {
                "0 µs"
            } else {
                "not held"
            },
            if self.planner_priority > 0 {
                format!("; planner SCHED_FIFO priority {}", self.planner_priority)
            } else {
                String::new()
            }
        )
    }
}

/// The OS refused SCHED_FIFO to the planner thread, which then stays SCHED_OTHER.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("planner thread SCHED_FIFO priority {priority} refused ({errno}); it runs SCHED_OTHER")]
pub struct PlannerPriorityRefused {
    /// The priority asked for.
    pub priority: u8,
    /// Why the OS refused it.
    pub errno: nix::errno::Errno,
}

/// Puts the calling (planner) thread under SCHED_FIFO at `priority`; the refusal, named, if
/// the OS says no (the thread then stays SCHED_OTHER).
pub fn raise_planner_thread(priority: u8) -> Result<(), PlannerPriorityRefused> {
    let param = libc::sched_param {
        sched_priority: i32::from(priority),
    };
    // SAFETY: pthread_self() is the calling thread and `param` is a valid sched_param.
    let rc = unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) };
    if rc == 0 {
        Ok(())
    } else {
        Err(PlannerPriorityRefused {
            priority,
            errno: nix::errno::Errno::from_raw(rc),
        })
    }
}

/// Applies `cfg` to the calling thread. Never fails: refusals are listed in the report.
pub fn setup_current_thread(cfg: &RtConfig) -> RtReport {
    let mut report = RtReport {
        policy: "SCHED_OTHER".into(),
        ..RtReport::default()
    };

    if let Some(cpu) = cfg.cpu {
        let ok = core_affinity::set_for_current(core_affinity::CoreId { id: cpu });
        if ok {
            report.cpu = Some(cpu);
        } else {
            report.refused.push(format!(
                "CPU affinity to CPU {cpu} refused; the thread may migrate"
            ));
        }
    }

    let param = libc::sched_param {
        sched_priority: i32::from(cfg.priority),
    };
    // SAFETY: pthread_self() is the calling thread and `param` is a valid sched_param.
    let rc = unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) };
    if rc == 0 {
        report.policy = "SCHED_FIFO".into();
        report.priority = cfg.priority;
    } else {
        let err = nix::errno::Errno::from_raw(rc);
        report.refused.push(format!(
            "SCHED_FIFO priority {} refused ({err}); running SCHED_OTHER (run as root, grant CAP_SYS_NICE, or set an rtprio limit)",
            cfg.priority
        ));
    }

    if cfg.lock_memory {
        use nix::sys::mman::{mlockall, MlockAllFlags};
        match mlockall(MlockAllFlags::MCL_CURRENT | MlockAllFlags::MCL_FUTURE) {
            Ok(()) => report.memory_locked = true,
            Err(e) => report.refused.push(format!(
                "mlockall refused ({e}); pages may fault in the loop (run as root, grant CAP_IPC_LOCK, or raise the memlock limit)"
            )),
        }
    }

    prefault_stack();
    report.stack_prefaulted = PREFAULT_STACK_BYTES;
    report
}

/// Touches [`PREFAULT_STACK_BYTES`] of stack so later growth does not fault.
#[inline(never)]
fn prefault_stack() {
    let mut buf = [0u8; PREFAULT_STACK_BYTES];
    for i in (0..buf.len()).step_by(4096) {
        // SAFETY: i is in bounds; the volatile write keeps the touch from being optimised away.
        unsafe { std::ptr::write_volatile(buf.as_mut_ptr().add(i), 1) };
    }
    std::hint::black_box(&buf);
}

/// Moves the calling thread (and so every thread it spawns afterwards) off the RT thread's CPU
/// while it lives, when [`RtConfig::reserve_cpu`] is set and another CPU is online; restores
/// the previous affinity on drop. The RT thread pins itself back to its CPU.
#[derive(Debug)]
pub struct ReservedCpu {
    /// The affinity to restore, if it was changed.
    previous: Option<nix::sched::CpuSet>,
    /// The CPUs the other threads run on (empty when nothing was changed).
    pub others: Vec<usize>,
    /// Why the reservation did not take effect, if it was asked for and did not.
    pub refused: Option<String>,
}

impl ReservedCpu {
    /// Applies the reservation for `cfg` to the calling thread.
    pub fn apply(cfg: &RtConfig) -> Self {
        use nix::sched::{sched_getaffinity, sched_setaffinity, CpuSet};
        use nix::unistd::Pid;
        let mut r = ReservedCpu {
            previous: None,
            others: Vec::new(),
            refused: None,
        };
        let (Some(rt_cpu), true) = (cfg.cpu, cfg.reserve_cpu) else {
            return r;
        };
        let Ok(previous) = sched_getaffinity(Pid::from_raw(0)) else {
            r.refused = Some("reserving the RT CPU: cannot read this thread's affinity".into());
            return r;
        };
        let mut set = CpuSet::new();
        let mut others = Vec::new();
        for cpu in 0..CpuSet::count() {
            if cpu != rt_cpu && previous.is_set(cpu).unwrap_or(false) && set.set(cpu).is_ok() {
                others.push(cpu);
            }
        }
        if others.is_empty() {
            r.refused = Some(format!(
                "reserving CPU {rt_cpu} for the RT thread: no other CPU is available; other threads share it"
            ));
            return r;
        }
        match sched_setaffinity(Pid::from_raw(0), &set) {
            Ok(()) => {
                r.previous = Some(previous);
                r.others = others;
            }
            Err(e) => {
                r.refused = Some(format!(
                    "reserving CPU {rt_cpu} for the RT thread refused ({e}); other threads share it"
                ))
            }
        }
        r
    }
}

impl Drop for ReservedCpu {
    fn drop(&mut self) {
        if let Some(prev) = self.previous.take() {
            let _ = nix::sched::sched_setaffinity(nix::unistd::Pid::from_raw(0), &prev);
        }
    }
}

/// Keeps `/dev/cpu_dma_latency` at 0 µs while it lives (the PM QoS request ends when the file
/// is closed), as cyclictest does: no deep C-state exit latency in the wakeup path.
#[derive(Debug)]
pub struct DmaLatencyGuard {
    _file: Option<std::fs::File>,
}

/// Requests 0 µs CPU DMA latency; records the outcome in `report`.
pub fn hold_cpu_dma_latency_zero(report: &mut RtReport) -> DmaLatencyGuard {
    use std::io::Write;
    const PATH: &str = "/dev/cpu_dma_latency";
    let file = std::fs::OpenOptions::new()
        .write(true)
        .open(PATH)
        .and_then(|mut f| f.write_all(&0i32.to_ne_bytes()).map(|()| f));
    match file {
        Ok(f) => {
            report.cpu_dma_latency_zero = true;
            DmaLatencyGuard { _file: Some(f) }
        }
        Err(e) => {
            report.refused.push(format!(
                "{PATH} refused ({e}); CPU idle states may add wakeup latency (run as root)"
            ));
            DmaLatencyGuard { _file: None }
        }
    }
}

#[cfg(test)]
mod reserved_cpu_tests {
    use super::*;
    use nix::sched::sched_getaffinity;
    use nix::unistd::Pid;

    fn cfg(cpu: Option<usize>, reserve: bool) -> RtConfig {
        RtConfig {
            planner_priority: None,
            cpu,
            priority: 80,
            lock_memory: false,
            reserve_cpu: reserve,
            missed_deadlines: Default::default(),
        }
    }

    #[test]
    fn reserving_moves_this_thread_off_the_rt_cpu_and_drop_restores_it() {
        let before = sched_getaffinity(Pid::from_raw(0)).unwrap();
        let allowed: Vec<usize> = (0..nix::sched::CpuSet::count())
            .filter(|&c| before.is_set(c).unwrap_or(false))
            .collect();
        let rt_cpu = allowed[0];
        {
            let r = ReservedCpu::apply(&cfg(Some(rt_cpu), true));
            if allowed.len() < 2 {
                eprintln!("SKIPPED the move check: this thread may run on one CPU only");
                assert!(r.others.is_empty());
                assert!(r.refused.as_deref().unwrap_or("").contains("no other CPU"));
                return;
            }
            assert_eq!(r.others, allowed[1..].to_vec());
            let now = sched_getaffinity(Pid::from_raw(0)).unwrap();
            assert!(!now.is_set(rt_cpu).unwrap(), "still allowed on the RT CPU");
            assert!(r.refused.is_none());
        }
        let after = sched_getaffinity(Pid::from_raw(0)).unwrap();
        assert_eq!(after, before, "affinity restored on drop");
    }

    #[test]
    fn nothing_changes_without_a_cpu_or_when_not_asked() {
        let before = sched_getaffinity(Pid::from_raw(0)).unwrap();
        for c in [cfg(None, true), cfg(Some(0), false)] {
            let r = ReservedCpu::apply(&c);
            assert!(r.others.is_empty() && r.refused.is_none());
            assert_eq!(sched_getaffinity(Pid::from_raw(0)).unwrap(), before);
        }
    }
}
