//! The EtherCAT identity (1018h) of each drive model: what the emulator presents and what the
//! master expects, with the manuals' gaps made explicit.

use cellrt_cia402::profiles::{profile, DriveModel, DriveProfile};

pub use cellrt_cia402::profiles::MITSUBISHI_VENDOR_ID;

/// The vendor ID presented by the emulator, and expected by the master, for a generic CiA 402
/// drive whose cell config gives no identity (a sim cell, a test): 0, which ETG assigns to no
/// vendor. Never a real drive's value: the configuration requires `[axes.ethercat] vendor_id`
/// and `product_code` for an EtherCAT axis of the generic model.
pub const UNCONFIGURED_VENDOR_ID: u32 = 0;
/// The product code presented for a generic CiA 402 drive without a configured identity.
pub const UNCONFIGURED_PRODUCT_CODE: u32 = 0;

/// The vendor ID of `model`'s maker where the profile's source does not give it (its
/// profile's [`cellrt_cia402::profiles::Identity::maker_vendor_id`]); `None` for the generic
/// CiA 402 model, which has no maker: its identity comes from the cell config.
pub fn maker_vendor_id(model: DriveModel) -> Option<u32> {
    profile(model).identity.maker_vendor_id
}

/// The vendor ID a profile presents and expects: its own, else its maker's, else
/// [`UNCONFIGURED_VENDOR_ID`].
const fn vendor_of(profile: &DriveProfile) -> u32 {
    match profile.vendor_id() {
        Some(v) => v,
        None => match profile.identity.maker_vendor_id {
            Some(v) => v,
            None => UNCONFIGURED_VENDOR_ID,
        },
    }
}

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
/// placeholder, not Mitsubishi's value (no ESI file was available to cellrt): its profile's
/// [`cellrt_cia402::profiles::Identity::emulator_product_code`].
pub fn emulator_product_code(model: DriveModel) -> u32 {
    profile(model).identity.emulator_product_code
}

impl SubDeviceIdentity {
    /// The identity the emulator presents for `profile`: the profile's values where it gives
    /// them (the manual's, or the cell config's via `DriveProfile::with_identity`), else the
    /// maker's vendor ID ([`maker_vendor_id`]) and [`emulator_product_code`]; revision 0 where
    /// unknown.
    pub fn of_profile(profile: &DriveProfile) -> Self {
        SubDeviceIdentity {
            vendor_id: vendor_of(profile),
            product_code: profile
                .product_code()
                .unwrap_or(profile.identity.emulator_product_code),
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
            vendor_id: vendor_of(profile),
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

    #[test]
    fn only_the_mitsubishi_models_have_mitsubishis_vendor_id() {
        for &m in DriveModel::ALL {
            let id = SubDeviceIdentity::of_profile(profile(m));
            if m == DriveModel::GenericCia402 {
                assert_eq!(maker_vendor_id(m), None);
                assert_eq!(id.vendor_id, UNCONFIGURED_VENDOR_ID);
            } else {
                assert_eq!(maker_vendor_id(m), Some(MITSUBISHI_VENDOR_ID), "{m}");
                assert_eq!(id.vendor_id, MITSUBISHI_VENDOR_ID, "{m}");
            }
        }
    }

    #[test]
    fn a_configured_identity_is_presented_and_expected() {
        let g =
            profile(DriveModel::GenericCia402).with_identity(Some(0xCE11_0000), Some(0x0002_0001));
        let id = SubDeviceIdentity::of_profile(&g);
        assert_eq!((id.vendor_id, id.product_code), (0xCE11_0000, 0x0002_0001));
        let expect = ExpectedIdentity::of_profile(&g);
        assert!(expect.matches(&id));
        assert_eq!(expect.product_code, Some(0x0002_0001));
        // Another vendor's drive, or another product, does not satisfy it.
        let unconfigured = SubDeviceIdentity::of_profile(profile(DriveModel::GenericCia402));
        assert!(!expect.matches(&unconfigured));
        assert!(!expect.matches(&SubDeviceIdentity {
            product_code: 0x0002_0002,
            ..id
        }));
        // A Mitsubishi model keeps its maker's vendor when only the product is given.
        let jet = profile(DriveModel::MrJetGN1).with_identity(None, Some(0x1234));
        let id = SubDeviceIdentity::of_profile(&jet);
        assert_eq!(
            (id.vendor_id, id.product_code),
            (MITSUBISHI_VENDOR_ID, 0x1234)
        );
        assert_eq!(
            profile(DriveModel::MrJ3T04).with_identity(None, None),
            *profile(DriveModel::MrJ3T04)
        );
    }
}
