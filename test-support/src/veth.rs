//! A veth pair for tests that put an emulated EtherCAT segment on a real link: created with
//! `ip` from iproute2 (needs CAP_NET_ADMIN), both ends up, deleted on drop.

use std::process::Command;

/// A veth pair `NAME` / `NAMEp`.
pub struct VethPair(String);

impl VethPair {
    /// Creates the pair `name` / `{name}p` (replacing a leftover one) and sets both ends up;
    /// `None` where `ip` is missing or refuses (no CAP_NET_ADMIN).
    pub fn create(name: &str) -> Option<VethPair> {
        let ip = |args: &[&str]| {
            Command::new("ip")
                .args(args)
                .status()
                .is_ok_and(|s| s.success())
        };
        let _ = Command::new("ip").args(["link", "del", name]).output();
        let peer = format!("{name}p");
        if !ip(&["link", "add", name, "type", "veth", "peer", "name", &peer]) {
            return None;
        }
        (ip(&["link", "set", name, "up"]) && ip(&["link", "set", &peer, "up"]))
            .then(|| VethPair(name.to_owned()))
    }

    /// The master's end.
    pub fn name(&self) -> &str {
        &self.0
    }

    /// The peer's end (where the emulated segment serves).
    pub fn peer(&self) -> String {
        format!("{}p", self.0)
    }
}

impl Drop for VethPair {
    fn drop(&mut self) {
        let _ = Command::new("ip").args(["link", "del", &self.0]).output();
    }
}
