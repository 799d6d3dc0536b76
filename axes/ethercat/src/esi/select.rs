//! Choosing one device of an ESI file that describes several (revisions, variants).

use super::device::EsiDevice;

/// Which device of a file an axis means: by product code and revision, or by name (the
/// `Type` order code or the `Name`); all `None` takes the file's only device.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct DeviceSelector {
    /// 1018h:02.
    pub product_code: Option<u32>,
    /// 1018h:03.
    pub revision: Option<u32>,
    /// `Type` text or `Name`.
    pub name: Option<String>,
}

/// Why an ESI file's devices hold not exactly one that a selector names.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PickError {
    /// None matches.
    #[error("no device of the file matches {selector} (the file has: {devices})")]
    NoMatch {
        /// The selector, as it reads.
        selector: String,
        /// The file's devices, by identity.
        devices: String,
    },
    /// More than one matches.
    #[error("{count} devices match {selector}; name one by esi_device (Type or Name) or esi_product_code / esi_revision (the file has: {devices})")]
    Several {
        /// How many match.
        count: usize,
        /// The selector, as it reads.
        selector: String,
        /// The file's devices, by identity.
        devices: String,
    },
}

impl DeviceSelector {
    /// True if `d` is one this selector accepts.
    pub fn accepts(&self, d: &EsiDevice) -> bool {
        self.product_code.is_none_or(|p| p == d.product_code)
            && self.revision.is_none_or(|r| r == d.revision)
            && self
                .name
                .as_deref()
                .is_none_or(|n| n == d.type_name || n == d.name)
    }

    /// The one device of `devices` this selector names, or why there is not exactly one.
    pub fn pick<'a>(&self, devices: &'a [EsiDevice]) -> Result<&'a EsiDevice, PickError> {
        let found: Vec<&EsiDevice> = devices.iter().filter(|d| self.accepts(d)).collect();
        let list = || {
            let v: Vec<String> = devices.iter().map(EsiDevice::identity_text).collect();
            v.join("; ")
        };
        match found.as_slice() {
            [one] => Ok(one),
            [] => Err(PickError::NoMatch {
                selector: self.to_string(),
                devices: list(),
            }),
            _ => Err(PickError::Several {
                count: found.len(),
                selector: self.to_string(),
                devices: list(),
            }),
        }
    }
}

impl std::fmt::Display for DeviceSelector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut parts = Vec::new();
        if let Some(p) = self.product_code {
            parts.push(format!("product code {p:#x}"));
        }
        if let Some(r) = self.revision {
            parts.push(format!("revision {r:#x}"));
        }
        if let Some(n) = &self.name {
            parts.push(format!("name {n:?}"));
        }
        if parts.is_empty() {
            f.write_str("any device")
        } else {
            f.write_str(&parts.join(", "))
        }
    }
}
