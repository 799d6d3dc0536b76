//! A drive profile as an ESI device describes it: its identity and the modes it supports.

use std::sync::Mutex;

use super::device::EsiDevice;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::{DriveProfile, Identity};

/// A drive profile as an ESI device describes it.
pub trait EsiProfile {
    /// This profile presenting the ESI device's 1018h identity and offering only the modes its
    /// 6502h lists.
    fn with_esi(&'static self, device: &EsiDevice) -> &'static DriveProfile;
}

impl EsiProfile for DriveProfile {
    /// This profile presenting the ESI device's 1018h identity (vendor, product code,
    /// revision) and offering only the modes the ESI's 6502h lists (all of the profile's where
    /// the file gives no 6502h). Built once per distinct result and kept for the life of the
    /// process, like [`DriveProfile::with_identity`].
    fn with_esi(&'static self, device: &EsiDevice) -> &'static DriveProfile {
        let identity = Identity {
            vendor_id: Some(device.vendor_id),
            product_code: Some(device.product_code),
            revision: Some(device.revision),
            source: "the axis' ESI file",
        };
        let modes: Vec<ModeOfOperation> = match device.supported_modes() {
            Some(listed) => self
                .modes
                .iter()
                .copied()
                .filter(|m| listed.contains(m))
                .collect(),
            None => self.modes.to_vec(),
        };
        if identity == self.identity && modes == self.modes {
            return self;
        }
        static DESCRIBED: Mutex<Vec<&'static DriveProfile>> = Mutex::new(Vec::new());
        let mut known = DESCRIBED.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(p) = known.iter().find(|p| {
            p.model == self.model
                && p.rx_pdo == self.rx_pdo
                && p.tx_pdo == self.tx_pdo
                && p.identity == identity
                && p.modes == modes.as_slice()
        }) {
            return p;
        }
        let p: &'static DriveProfile = Box::leak(Box::new(DriveProfile {
            identity,
            modes: Box::leak(modes.into_boxed_slice()),
            ..*self
        }));
        known.push(p);
        p
    }
}
