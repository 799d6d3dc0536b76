//! ESI import: the EtherCAT Slave Information files (ETG.2000 `EtherCATInfo` XML) every
//! EtherCAT device ships, read with `roxmltree`. cellrt takes from a file each device's
//! identity, mailbox protocols, PDOs (fixed or changeable, with their default entries), object
//! dictionary (access rights, PDO mappability, defaults), DC operation modes and the CiA 402
//! modes it supports (6502h).

pub mod compare;
pub mod conform;
pub mod device;
mod dictionary;
pub mod error;
pub mod number;
mod parse;
mod profile;
pub use profile::EsiProfile;
pub mod select;
mod xml;

use std::path::{Path, PathBuf};

pub use device::{
    CoeDetails, DcOpMode, EsiDevice, EsiObject, EsiPdo, MailboxProtocol, PdoMappable, SyncCycle,
};
pub use error::EsiError;
pub use select::DeviceSelector;

/// The devices of the ESI document `xml`.
pub fn parse(xml: &str) -> Result<Vec<EsiDevice>, EsiError> {
    parse::devices(xml)
}

/// An ESI file that could not be read or parsed.
#[derive(Debug, thiserror::Error)]
pub enum EsiFileError {
    /// The file cannot be read.
    #[error("{}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not a usable ESI.
    #[error("{}: {source}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        source: EsiError,
    },
}

/// The devices of the ESI file at `path` (UTF-8 or ISO-8859-1, as ESI files are written), read
/// whole: for files the caller trusts (cellrt's config and CLI read ESI files bounded).
pub fn load(path: &Path) -> Result<Vec<EsiDevice>, EsiFileError> {
    let bytes = std::fs::read(path).map_err(|source| EsiFileError::Read {
        path: path.to_owned(),
        source,
    })?;
    decode_file(path, bytes)
}

/// The devices of an ESI file's `bytes` (UTF-8, else ISO-8859-1), read from `path` (named in
/// errors) by a caller that bounds the read.
pub fn decode_file(path: &Path, bytes: Vec<u8>) -> Result<Vec<EsiDevice>, EsiFileError> {
    let text = match String::from_utf8(bytes) {
        Ok(t) => t,
        // ISO-8859-1: every byte is the code point of the same value.
        Err(e) => e.into_bytes().iter().map(|&b| char::from(b)).collect(),
    };
    parse(&text).map_err(|source| EsiFileError::Invalid {
        path: path.to_owned(),
        source,
    })
}

#[cfg(test)]
mod profile_files;
#[cfg(test)]
mod tests;
