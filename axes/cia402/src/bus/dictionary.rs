//! A drive's object dictionary as listed for the operator (`cellrt sdo list`): per entry its
//! index, sub-index, name, data type, size, access and PDO mappability, and where the list
//! came from — the live drive's SDO Information or the drive profile's own table.

use serde::{Deserialize, Serialize};

use crate::profiles::facts::{Access, DataType, OdEntry, Pdo};

/// Where a listed dictionary came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DictionarySource {
    /// The live drive's SDO Information service (CoE, ETG.1000.6 §5.6.3).
    SdoInformation,
    /// The drive profile's own table (or the axis' ESI): the drive offers no SDO Information.
    Profile,
}

/// Which PDOs an entry may be mapped into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PdoMappable {
    /// Neither: SDO only.
    No,
    /// RxPDO (master → drive).
    Rx,
    /// TxPDO (drive → master).
    Tx,
    /// Either.
    RxTx,
    /// Not stated by the source.
    Unstated,
}

impl PdoMappable {
    /// From the two mappability bits of an object access word or an ESI entry.
    pub fn from_bits(rx: bool, tx: bool) -> PdoMappable {
        match (rx, tx) {
            (false, false) => Self::No,
            (true, false) => Self::Rx,
            (false, true) => Self::Tx,
            (true, true) => Self::RxTx,
        }
    }

    /// As the listing prints it.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::No => "-",
            Self::Rx => "RxPDO",
            Self::Tx => "TxPDO",
            Self::RxTx => "RxPDO+TxPDO",
            Self::Unstated => "unstated",
        }
    }
}

impl From<Pdo> for PdoMappable {
    fn from(p: Pdo) -> Self {
        match p {
            Pdo::Rx => Self::Rx,
            Pdo::Tx => Self::Tx,
            Pdo::No => Self::No,
            Pdo::Unstated => Self::Unstated,
        }
    }
}

/// One entry (an object's sub-index) of a listed dictionary.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct DictionaryEntry {
    /// Object index.
    pub index: u16,
    /// Sub-index.
    pub sub: u8,
    /// Name.
    pub name: String,
    /// CiA 301 type name (e.g. "UNSIGNED16"; "type 0008h" for one no profile uses).
    pub data_type: String,
    /// Size of a value in bits, `None` where not stated.
    pub bits: Option<u16>,
    /// Access.
    pub access: Access,
    /// The states a write is taken in where it is not OP (e.g. "PreOP"); `None`: any, or not
    /// stated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub write_restriction: Option<String>,
    /// PDO mappability.
    pub pdo: PdoMappable,
}

impl DictionaryEntry {
    /// The entry of a profile's table.
    pub fn from_profile(o: &OdEntry) -> DictionaryEntry {
        DictionaryEntry {
            index: o.index,
            sub: o.sub,
            name: o.name.to_string(),
            data_type: o.data_type.cia301_name().to_string(),
            bits: o.data_type.bits(),
            access: o.access,
            write_restriction: None,
            pdo: o.pdo.into(),
        }
    }
}

/// The name of CiA 301 data type index `index` with values `bits` wide.
pub fn data_type_name(index: u16, bits: u16) -> String {
    DataType::from_cia301_index(index, bits)
        .map_or_else(|| format!("type {index:04X}h"), |t| t.cia301_name().into())
}

/// The access an object access word's read and write bits (any state) make.
pub fn access_of(readable: bool, writable: bool) -> Access {
    match (readable, writable) {
        (true, true) => Access::Rw,
        (true, false) => Access::Ro,
        (false, true) => Access::Wo,
        (false, false) => Access::Unstated,
    }
}
