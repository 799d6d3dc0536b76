//! A network test bench: a veth pair with one end moved into a network namespace of its own,
//! so an emulated EtherCAT segment (in the namespace) and the controller (outside) talk over
//! real raw sockets. Needs root and iproute2's `ip`; [`VethNamespace::create`] says which is
//! missing instead of failing.

use std::process::{Command, Output};

/// A namespace with the far end of a veth pair; both are removed on drop.
#[derive(Debug)]
pub struct VethNamespace {
    /// The namespace name.
    pub namespace: String,
    /// The end in this namespace (the controller's).
    pub near: String,
    /// The end inside `namespace` (the emulated segment's).
    pub far: String,
}

/// Why a [`VethNamespace`] cannot be made here.
#[derive(Debug, thiserror::Error)]
pub enum NetnsError {
    /// Not running as root.
    #[error("needs root (CAP_NET_ADMIN for the namespace and the veth pair, CAP_NET_RAW for the sockets)")]
    NotRoot,
    /// iproute2's `ip` cannot be run.
    #[error("cannot run `ip` (iproute2): {0}")]
    NoIp(#[source] std::io::Error),
    /// An `ip` command failed.
    #[error("`ip {command}` failed: {stderr}")]
    Failed {
        /// The arguments given to `ip`.
        command: String,
        /// What `ip` printed on standard error.
        stderr: String,
    },
}

fn ip(args: &[&str]) -> Result<Output, NetnsError> {
    Command::new("ip")
        .args(args)
        .output()
        .map_err(NetnsError::NoIp)
}

fn ip_ok(args: &[&str]) -> Result<(), NetnsError> {
    let out = ip(args)?;
    if out.status.success() {
        Ok(())
    } else {
        Err(NetnsError::Failed {
            command: args.join(" "),
            stderr: String::from_utf8_lossy(&out.stderr).trim().to_string(),
        })
    }
}

impl VethNamespace {
    /// Creates namespace `crt-<tag>` and the pair `crt<tag>a` / `crt<tag>b` (names ≤ 15
    /// characters), both ends up. `Err` says why it cannot (not root, no `ip`, no netns).
    pub fn create(tag: &str) -> Result<VethNamespace, NetnsError> {
        // SAFETY: geteuid has no preconditions.
        if unsafe { libc::geteuid() } != 0 {
            return Err(NetnsError::NotRoot);
        }
        let tag: String = tag
            .chars()
            .filter(char::is_ascii_alphanumeric)
            .take(10)
            .collect();
        let ns = VethNamespace {
            namespace: format!("crt-{tag}"),
            near: format!("crt{tag}a"),
            far: format!("crt{tag}b"),
        };
        // Leftovers of an interrupted run.
        let _ = ip(&["netns", "del", &ns.namespace]);
        let _ = ip(&["link", "del", &ns.near]);
        ip_ok(&["netns", "add", &ns.namespace])?;
        ip_ok(&[
            "link", "add", &ns.near, "type", "veth", "peer", "name", &ns.far,
        ])?;
        ip_ok(&["link", "set", &ns.far, "netns", &ns.namespace])?;
        ip_ok(&["-n", &ns.namespace, "link", "set", "lo", "up"])?;
        ip_ok(&["-n", &ns.namespace, "link", "set", &ns.far, "up"])?;
        ip_ok(&["link", "set", &ns.near, "up"])?;
        Ok(ns)
    }

    /// A command that runs `program` inside the namespace.
    pub fn command(&self, program: &std::path::Path) -> Command {
        let mut c = Command::new("ip");
        c.args(["netns", "exec", &self.namespace]).arg(program);
        c
    }
}

impl Drop for VethNamespace {
    fn drop(&mut self) {
        let _ = ip(&["link", "del", &self.near]);
        let _ = ip(&["netns", "del", &self.namespace]);
    }
}
