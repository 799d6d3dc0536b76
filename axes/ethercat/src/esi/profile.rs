//! A drive profile as an ESI device describes it: its identity and the modes it supports.

use super::device::EsiDevice;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::{CycleFacts, DriveProfile, Identity};

/// A drive profile as an ESI device describes it.
pub trait EsiProfile {
    /// This profile presenting the ESI device's 1018h identity and offering only the modes its
    /// 6502h lists.
    fn with_esi(&self, device: &EsiDevice) -> DriveProfile;
}

impl EsiProfile for DriveProfile {
    /// This profile presenting the ESI device's 1018h identity (vendor, product code,
    /// revision) and offering only the modes the ESI's 6502h lists (all of the profile's where
    /// the file gives no 6502h): an owned profile, built when the configuration is read.
    fn with_esi(&self, device: &EsiDevice) -> DriveProfile {
        let identity = Identity {
            vendor_id: Some(device.vendor_id),
            product_code: Some(device.product_code),
            revision: Some(device.revision),
            source: "the axis' ESI file",
            ..self.identity
        };
        let modes = match device.supported_modes() {
            Some(listed) => {
                let kept: Vec<ModeOfOperation> = self
                    .cycle
                    .modes
                    .iter()
                    .copied()
                    .filter(|m| listed.contains(m))
                    .collect();
                if kept == *self.cycle.modes {
                    self.cycle.modes.clone()
                } else {
                    kept.into()
                }
            }
            None => self.cycle.modes.clone(),
        };
        DriveProfile {
            identity,
            cycle: CycleFacts {
                modes,
                ..self.cycle.clone()
            },
            ..self.clone()
        }
    }
}
