//! Finds other real-time tasks that may run on the measured CPU: every thread in
//! `/proc/*/task/*` whose policy (`stat` field 41) is SCHED_FIFO or SCHED_RR and whose
//! `Cpus_allowed_list` (`status`) includes the CPU. A measurement that shares its CPU with
//! another RT task is contaminated: that task's run time shows up as our wakeup latency.

use std::path::Path;

use serde::Serialize;

/// `PF_KTHREAD` in `stat` field 9: the task is a kernel thread.
const PF_KTHREAD: u64 = 0x0020_0000;
/// `SCHED_FIFO` / `SCHED_RR` in `stat` field 41.
const SCHED_FIFO: u32 = 1;
const SCHED_RR: u32 = 2;

/// One real-time thread allowed on the CPU.
#[derive(Debug, Clone, Serialize, PartialEq, Eq)]
pub struct RtTask {
    /// Process id.
    pub pid: i32,
    /// Thread id.
    pub tid: i32,
    /// Thread name (`comm`).
    pub comm: String,
    /// "SCHED_FIFO" or "SCHED_RR".
    pub policy: String,
    /// RT priority, 1..=99.
    pub priority: u32,
    /// Whether it is a kernel thread.
    pub kernel: bool,
    /// Its allowed CPUs as the kernel prints them.
    pub cpus_allowed: String,
}

impl RtTask {
    /// Whether this task can disturb a measurement at `priority`: any user-space RT task does;
    /// a kernel thread does when its priority is not below ours, except the per-CPU stopper
    /// threads (`migration/N`), which every kernel has and which run only to move tasks.
    pub fn contaminates(&self, priority: u8) -> bool {
        if !self.kernel {
            return true;
        }
        self.priority >= u32::from(priority) && !self.comm.starts_with("migration/")
    }
}

/// What one scan found.
#[derive(Debug, Clone, Default, Serialize, PartialEq, Eq)]
pub struct Scan {
    /// RT tasks that can disturb the measurement.
    pub contaminating: Vec<RtTask>,
    /// RT tasks on the CPU judged harmless (kernel threads below our priority, `migration/N`).
    pub ignored: Vec<RtTask>,
}

impl Scan {
    /// Whether the measurement is contaminated.
    pub fn contaminated(&self) -> bool {
        !self.contaminating.is_empty()
    }

    /// Adds what `other` found, once per (pid, tid).
    pub fn merge(&mut self, other: Scan) {
        for t in other.contaminating {
            if !self.contaminating.iter().any(|s| s.tid == t.tid) {
                self.contaminating.push(t);
            }
        }
        for t in other.ignored {
            if !self.ignored.iter().any(|s| s.tid == t.tid) {
                self.ignored.push(t);
            }
        }
    }
}

/// Parses a kernel CPU list such as `0-3,8,10-11`.
pub fn parse_cpu_list(s: &str) -> Option<Vec<usize>> {
    let s = s.trim();
    let mut out = Vec::new();
    if s.is_empty() {
        return Some(out);
    }
    for part in s.split(',') {
        let part = part.trim();
        match part.split_once('-') {
            Some((a, b)) => {
                let (a, b): (usize, usize) = (a.parse().ok()?, b.parse().ok()?);
                if b < a {
                    return None;
                }
                out.extend(a..=b);
            }
            None => out.push(part.parse().ok()?),
        }
    }
    Some(out)
}

/// The online CPUs (`/sys/devices/system/cpu/online`).
pub fn online_cpus() -> Vec<usize> {
    std::fs::read_to_string("/sys/devices/system/cpu/online")
        .ok()
        .and_then(|s| parse_cpu_list(&s))
        .unwrap_or_else(|| {
            let n = std::thread::available_parallelism().map_or(1, |n| n.get());
            (0..n).collect()
        })
}

/// The fields of `/proc/<pid>/task/<tid>/stat` we need: (comm, flags, rt_priority, policy).
pub fn parse_stat(text: &str) -> Option<(String, u64, u32, u32)> {
    // comm may contain spaces and parentheses: it ends at the last ')'.
    let open = text.find('(')?;
    let close = text.rfind(')')?;
    let comm = text.get(open + 1..close)?.to_string();
    let rest: Vec<&str> = text.get(close + 1..)?.split_whitespace().collect();
    // rest[0] is field 3 (state), so field N is rest[N - 3].
    let flags = rest.get(9 - 3)?.parse().ok()?;
    let rt_priority = rest.get(40 - 3)?.parse().ok()?;
    let policy = rest.get(41 - 3)?.parse().ok()?;
    Some((comm, flags, rt_priority, policy))
}

fn cpus_allowed_list(status: &str) -> Option<&str> {
    status
        .lines()
        .find_map(|l| l.strip_prefix("Cpus_allowed_list:"))
        .map(str::trim)
}

/// Every RT thread allowed on `cpu`, except the threads in `exclude_tids` and every thread of
/// the processes in `exclude_pids` (the measurement itself); sorted into contaminating and
/// ignored for a measurement at `priority`. Tasks that vanish during the scan are skipped.
pub fn scan(cpu: usize, priority: u8, exclude_pids: &[i32], exclude_tids: &[i32]) -> Scan {
    scan_tasks(
        Path::new("/proc"),
        cpu,
        priority,
        exclude_pids,
        exclude_tids,
    )
}

/// [`scan`] over an arbitrary proc root (for tests).
pub fn scan_tasks(
    proc_root: &Path,
    cpu: usize,
    priority: u8,
    exclude_pids: &[i32],
    exclude_tids: &[i32],
) -> Scan {
    let mut out = Scan::default();
    for task in all_rt_tasks(proc_root) {
        if exclude_pids.contains(&task.pid) || exclude_tids.contains(&task.tid) {
            continue;
        }
        let on_cpu = parse_cpu_list(&task.cpus_allowed).is_some_and(|l| l.contains(&cpu));
        if !on_cpu {
            continue;
        }
        if task.contaminates(priority) {
            out.contaminating.push(task);
        } else {
            out.ignored.push(task);
        }
    }
    out
}

/// Every SCHED_FIFO / SCHED_RR thread under `proc_root`, on any CPU.
pub fn all_rt_tasks(proc_root: &Path) -> Vec<RtTask> {
    let mut out = Vec::new();
    let Ok(procs) = std::fs::read_dir(proc_root) else {
        return out;
    };
    for p in procs.flatten() {
        let Some(pid) = p.file_name().to_str().and_then(|s| s.parse::<i32>().ok()) else {
            continue;
        };
        let Ok(tasks) = std::fs::read_dir(p.path().join("task")) else {
            continue;
        };
        for t in tasks.flatten() {
            let Some(tid) = t.file_name().to_str().and_then(|s| s.parse::<i32>().ok()) else {
                continue;
            };
            if let Some(task) = read_task(&t.path(), pid, tid) {
                if task.policy == "SCHED_FIFO" || task.policy == "SCHED_RR" {
                    out.push(task);
                }
            }
        }
    }
    out
}

/// Reads one task directory; any policy.
pub fn read_task(dir: &Path, pid: i32, tid: i32) -> Option<RtTask> {
    let stat = std::fs::read_to_string(dir.join("stat")).ok()?;
    let (comm, flags, priority, policy) = parse_stat(&stat)?;
    let status = std::fs::read_to_string(dir.join("status")).ok()?;
    let cpus_allowed = cpus_allowed_list(&status)?.to_string();
    let policy = match policy {
        SCHED_FIFO => "SCHED_FIFO".to_string(),
        SCHED_RR => "SCHED_RR".to_string(),
        0 => "SCHED_OTHER".to_string(),
        p => format!("policy {p}"),
    };
    Some(RtTask {
        pid,
        tid,
        comm,
        policy,
        priority,
        kernel: flags & PF_KTHREAD != 0,
        cpus_allowed,
    })
}

/// The calling thread's id.
pub fn gettid() -> i32 {
    // SAFETY: gettid has no preconditions.
    unsafe { libc::gettid() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_lists() {
        assert_eq!(parse_cpu_list("0-1"), Some(vec![0, 1]));
        assert_eq!(parse_cpu_list("0,2-4,7\n"), Some(vec![0, 2, 3, 4, 7]));
        assert_eq!(parse_cpu_list(""), Some(vec![]));
        assert_eq!(parse_cpu_list("3-1"), None);
        assert_eq!(parse_cpu_list("x"), None);
    }

    #[test]
    fn stat_with_odd_comm() {
        let s = "42 (a) b (c)) S 2 0 0 0 -1 2129984 0 0 0 0 0 0 0 0 -51 0 1 0 20 0 0 \
                 18446744073709551615 0 0 0 0 0 0 0 2147483647 0 0 0 0 17 0 50 1 0 0 0 0 0 0 0 0 0 0 0";
        let (comm, flags, prio, pol) = parse_stat(s).unwrap();
        assert_eq!(comm, "a) b (c)");
        assert_eq!(flags, 2_129_984);
        assert_eq!((prio, pol), (50, 1));
    }

    #[test]
    fn kernel_threads_below_our_priority_and_stoppers_are_ignored() {
        let t = |comm: &str, prio, kernel| RtTask {
            pid: 1,
            tid: 1,
            comm: comm.into(),
            policy: "SCHED_FIFO".into(),
            priority: prio,
            kernel,
            cpus_allowed: "0".into(),
        };
        assert!(!t("migration/1", 99, true).contaminates(80));
        assert!(!t("irq/25-ACPI:Ged", 50, true).contaminates(80));
        assert!(t("irq/25-ACPI:Ged", 90, true).contaminates(80));
        assert!(t("cyclictest", 1, false).contaminates(80));
    }
}
