//! The EtherCAT identity (1018h) of each drive model: what the emulator presents and what the
//! master expects, with the manuals' gaps made explicit.

use crate::profiles::{DriveModel, DriveProfile};

/// Mitsubishi Electric's EtherCAT vendor ID (mr-j3-t04.md §1.1, manual §8.1(4): "A1Eh";
/// mr-j4-tm.md §1.1 [EXT] gives the same value).
pub const MITSUBISHI_VENDOR_ID: u32 = 0x0000_0A1E;

/// 1018h:01–04 as a SubDevice reports it (SII words 08h–0Fh and the CoE object).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SubDeviceIdentity {
    /// 1018h:01 Vendor ID.
    pub vendor_id: u32,
    /// 1018h:02 Product code.
    pub product_code: u32,
    /// 1018h:03 Revision number.
    pub revision: u32,
    /// 1018h:04 Serial number.
    pub serial: u32,
}

/// The product code the emulator presents for a model whose manual gives none — a named
/// placeholder, not Mitsubishi's value (the ESI files are not in `shared/seeds/`). MR-J4-TM
/// uses the [EXT] value of mr-j4-tm.md §1.1 (0x201, unverified).
pub const fn emulator_product_code(model: DriveModel) -> u32 {
    match model {
        DriveModel::MrJ3T04 => 0x0000_0102,
        DriveModel::MrJ4TM => 0x0000_0201,
        DriveModel::MrJetGN1 => 0xCE11_0301,
        DriveModel::MrJ5GN1 => 0xCE11_0501,
        DriveModel::MrJ5W2GN1 => 0xCE11_0502,
        DriveModel::MrJ5W3GN1 => 0xCE11_0503,
    }
}

impl SubDeviceIdentity {
    /// The identity the emulator presents for `profile`: the manual's values where it gives
    /// them, else Mitsubishi's vendor ID and [`emulator_product_code`]; revision 0 where unknown.
    pub fn of_profile(profile: &DriveProfile) -> Self {
        SubDeviceIdentity {
            vendor_id: profile.vendor_id().unwrap_or(MITSUBISHI_VENDOR_ID),
            product_code: profile
                .product_code()
                .unwrap_or(emulator_product_code(profile.model)),
            revision: profile.identity.revision.unwrap_or(0),
            serial: 0,
        }
    }
}

/// What the master requires of a SubDevice configured as a given model: the vendor ID always,
/// the product code where a source documents it or the cell config names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ExpectedIdentity {
    /// Required 1018h:01.
    pub vendor_id: u32,
    /// Required 1018h:02, `None`: any.
    pub product_code: Option<u32>,
}

impl ExpectedIdentity {
    /// The expectation for `profile` without overrides.
    pub fn of_profile(profile: &DriveProfile) -> Self {
        ExpectedIdentity {
            vendor_id: profile.vendor_id().unwrap_or(MITSUBISHI_VENDOR_ID),
            product_code: profile.product_code(),
        }
    }

    /// True if `found` satisfies this expectation.
    pub fn matches(&self, found: &SubDeviceIdentity) -> bool {
        found.vendor_id == self.vendor_id
            && self.product_code.is_none_or(|p| p == found.product_code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profiles::profile;

    #[test]
    fn the_emulated_identity_satisfies_the_expectation_of_every_model() {
        for &m in DriveModel::ALL {
            let p = profile(m);
            let id = SubDeviceIdentity::of_profile(p);
            assert!(ExpectedIdentity::of_profile(p).matches(&id), "{m:?}");
        }
        let j3 = profile(DriveModel::MrJ3T04);
        let j4 = SubDeviceIdentity::of_profile(profile(DriveModel::MrJ4TM));
        assert!(!ExpectedIdentity::of_profile(j3).matches(&j4));
    }
}
