//! Which of the privileges a cell uses the process holds: root, or an unprivileged user with
//! file or ambient capabilities (`setcap`, systemd's `AmbientCapabilities=`), so the summary
//! says what a service got instead of leaving it to the RT set-up's refusals.

use serde::Serialize;

/// A capability a cell uses, with its bit in `/proc/self/status`' `CapEff`
/// (`linux/capability.h`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, strum::Display, strum::EnumIter)]
pub enum Capability {
    /// Raw packets: the EtherCAT MainDevice's socket (ethercrab).
    #[strum(serialize = "CAP_NET_RAW")]
    NetRaw,
    /// mlockall: the RT thread's memory stays resident.
    #[strum(serialize = "CAP_IPC_LOCK")]
    IpcLock,
    /// SCHED_FIFO priorities and CPU affinity of the RT and planner threads.
    #[strum(serialize = "CAP_SYS_NICE")]
    SysNice,
}

impl Capability {
    /// Its bit number.
    pub const fn bit(self) -> u32 {
        match self {
            Capability::NetRaw => 13,
            Capability::IpcLock => 14,
            Capability::SysNice => 23,
        }
    }

    /// What the cell does with it.
    pub const fn purpose(self) -> &'static str {
        match self {
            Capability::NetRaw => "EtherCAT raw socket",
            Capability::IpcLock => "memory locking",
            Capability::SysNice => "SCHED_FIFO",
        }
    }
}

/// The process' privileges, as the run's summary reports them.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Privileges {
    /// Effective user ID.
    pub uid: u32,
    /// The capabilities of [`Capability`] in the effective set.
    pub held: Vec<Capability>,
    /// Those not in it.
    pub missing: Vec<Capability>,
}

impl Privileges {
    /// The running process' (from `CapEff` in `/proc/self/status`; none if it cannot be read).
    pub fn of_process() -> Privileges {
        let eff = std::fs::read_to_string("/proc/self/status")
            .ok()
            .and_then(|s| cap_eff(&s))
            .unwrap_or(0);
        Privileges::from_mask(nix::unistd::geteuid().as_raw(), eff)
    }

    /// From an effective user ID and a `CapEff` mask.
    pub fn from_mask(uid: u32, eff: u64) -> Privileges {
        use strum::IntoEnumIterator;
        let (held, missing) = Capability::iter().partition(|c| eff & (1 << c.bit()) != 0);
        Privileges { uid, held, missing }
    }

    /// One line: "root" or "uid 65534 with CAP_SYS_NICE (SCHED_FIFO); without CAP_NET_RAW
    /// (EtherCAT raw socket)".
    pub fn describe(&self) -> String {
        let list = |caps: &[Capability]| {
            caps.iter()
                .map(|c| format!("{c} ({})", c.purpose()))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let who = if self.uid == 0 {
            "root".to_string()
        } else {
            format!("uid {}", self.uid)
        };
        match (self.held.is_empty(), self.missing.is_empty()) {
            (_, true) => format!("{who} with {}", list(&self.held)),
            (true, false) => format!("{who} without {}", list(&self.missing)),
            (false, false) => format!(
                "{who} with {}; without {}",
                list(&self.held),
                list(&self.missing)
            ),
        }
    }
}

/// The `CapEff:` mask of a `/proc/<pid>/status` text.
fn cap_eff(status: &str) -> Option<u64> {
    let hex = status.lines().find_map(|l| l.strip_prefix("CapEff:"))?;
    u64::from_str_radix(hex.trim(), 16).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cap_eff_is_read_from_the_status_text() {
        let status = "Name:\tcellrt\nCapInh:\t0000000000000000\nCapEff:\t0000000000806000\n";
        // 0x806000: bits 13 (CAP_NET_RAW), 14 (CAP_IPC_LOCK), 23 (CAP_SYS_NICE).
        assert_eq!(cap_eff(status), Some(0x80_6000));
        let p = Privileges::from_mask(65534, 0x80_6000);
        assert!(p.missing.is_empty());
        assert_eq!(
            p.describe(),
            "uid 65534 with CAP_NET_RAW (EtherCAT raw socket), CAP_IPC_LOCK (memory locking), \
             CAP_SYS_NICE (SCHED_FIFO)"
        );
    }

    #[test]
    fn a_user_without_capabilities_is_told_which_are_missing() {
        let p = Privileges::from_mask(1000, 1 << 23);
        assert_eq!(p.held, vec![Capability::SysNice]);
        assert_eq!(p.missing, vec![Capability::NetRaw, Capability::IpcLock]);
        assert!(p
            .describe()
            .starts_with("uid 1000 with CAP_SYS_NICE (SCHED_FIFO); without CAP_NET_RAW"));
        assert_eq!(cap_eff("Name:\tx\n"), None);
    }
}
