//! What cellrt takes from one ESI `<Device>`: identity, mailbox, PDOs, object dictionary,
//! distributed-clock operation modes and the CiA 402 modes it supports.

use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::PdoEntry;
use cellrt_cia402::profiles::{Access, DataType};

/// 6502h Supported drive modes (CiA 402 §6.2.2): bit n set = the mode below is supported.
pub const SUPPORTED_DRIVE_MODES: u16 = 0x6502;

/// 6502h bit of each mode (CiA 402: bit 0 pp, 2 pv, 3 tq, 5 hm, 7 csp, 8 csv, 9 cst).
const MODE_BITS: [(u8, ModeOfOperation); 7] = [
    (0, ModeOfOperation::ProfilePosition),
    (2, ModeOfOperation::ProfileVelocity),
    (3, ModeOfOperation::ProfileTorque),
    (5, ModeOfOperation::Homing),
    (7, ModeOfOperation::CyclicSyncPosition),
    (8, ModeOfOperation::CyclicSyncVelocity),
    (9, ModeOfOperation::CyclicSyncTorque),
];

/// The modes a 6502h value lists.
pub fn modes_of_6502(value: i64) -> Vec<ModeOfOperation> {
    MODE_BITS
        .iter()
        .filter(|(bit, _)| value >> bit & 1 == 1)
        .map(|&(_, m)| m)
        .collect()
}

/// The 6502h value listing `modes`.
pub fn bits_of_modes(modes: &[ModeOfOperation]) -> i64 {
    MODE_BITS
        .iter()
        .filter(|(_, m)| modes.contains(m))
        .fold(0, |v, (bit, _)| v | 1 << bit)
}

/// A mailbox protocol a device offers (ETG.2000 `Device/Mailbox`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum MailboxProtocol {
    /// ADS over EtherCAT.
    AoE,
    /// Ethernet over EtherCAT.
    EoE,
    /// CANopen over EtherCAT.
    CoE,
    /// File access over EtherCAT.
    FoE,
    /// Servo profile over EtherCAT.
    SoE,
    /// Vendor-specific protocol over EtherCAT.
    VoE,
}

impl MailboxProtocol {
    /// Every protocol, by its ESI element name.
    pub const ALL: [(&'static str, MailboxProtocol); 6] = [
        ("AoE", Self::AoE),
        ("EoE", Self::EoE),
        ("CoE", Self::CoE),
        ("FoE", Self::FoE),
        ("SoE", Self::SoE),
        ("VoE", Self::VoE),
    ];

    /// The ESI element name, e.g. "CoE".
    pub fn as_str(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, p)| *p == self)
            .map_or("?", |(n, _)| n)
    }
}

/// The CoE details of `Device/Mailbox/CoE`: what the master may configure by SDO.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CoeDetails {
    /// SdoInfo: the object dictionary can be read from the device.
    pub sdo_info: bool,
    /// PdoAssign: 1C12h/1C13h can be written.
    pub pdo_assign: bool,
    /// PdoConfig: the mapping objects (1600h…, 1A00h…) can be written.
    pub pdo_config: bool,
    /// CompleteAccess: SDO complete access is supported.
    pub complete_access: bool,
}

/// One RxPdo or TxPdo of the device with its default entries.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EsiPdo {
    /// The mapping object, e.g. 1600h.
    pub index: u16,
    /// Its name.
    pub name: String,
    /// `Fixed`: the entries cannot be changed.
    pub fixed: bool,
    /// `Mandatory`: the PDO must be assigned.
    pub mandatory: bool,
    /// `Sm`: the sync manager it is assigned to by default; `None`: not assigned by default.
    pub sm: Option<u8>,
    /// The default entries (padding has index 0).
    pub entries: Vec<PdoEntry>,
    /// `Exclude`: PDOs that cannot be assigned together with this one.
    pub excludes: Vec<u16>,
}

/// Into which PDO direction an object may be mapped (`Flags/PdoMapping`: R, T, RT).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PdoMappable {
    /// May be mapped into an RxPDO (master → device).
    pub rx: bool,
    /// May be mapped into a TxPDO (device → master).
    pub tx: bool,
}

/// One object-dictionary entry (an object's sub-index) as the ESI describes it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EsiObject {
    /// Object index.
    pub index: u16,
    /// Sub-index (0 for a simple object).
    pub sub: u8,
    /// Name (the sub-item's name for a sub-index of a record or array).
    pub name: String,
    /// The ESI data type name, e.g. "UDINT".
    pub data_type: String,
    /// Size in bits.
    pub bits: u16,
    /// Access right (`Flags/Access`); [`Access::Unstated`] where the file gives none.
    pub access: Access,
    /// `WriteRestrictions` of the access, e.g. "PreOP".
    pub write_restriction: Option<String>,
    /// PDO mappability.
    pub pdo: PdoMappable,
    /// Default value (`DefaultValue` or `DefaultData` up to 8 bytes).
    pub default: Option<i64>,
}

impl EsiObject {
    /// The CoE data type of the entry's ESI type name (ETG.2000 base types), by size where the
    /// name is a bit string (BYTE, WORD, DWORD); [`DataType::Unstated`] for one no profile uses
    /// (64-bit, REAL).
    pub fn coe_type(&self) -> DataType {
        match (self.data_type.as_str(), self.bits) {
            ("BOOL", _) => DataType::Bool,
            ("SINT", _) => DataType::I8,
            ("INT", _) => DataType::I16,
            ("DINT", _) => DataType::I32,
            (n, b) if n.starts_with("STRING") => DataType::VisibleString {
                octets: u8::try_from(b / 8).unwrap_or(u8::MAX),
            },
            (_, 8) => DataType::U8,
            (_, 16) => DataType::U16,
            (_, 32) => DataType::U32,
            _ => DataType::Unstated,
        }
    }

    /// True if the master may write this entry (rw or wo).
    pub fn writable(&self) -> bool {
        matches!(self.access, Access::Rw | Access::Wo)
    }
}

/// A SYNC signal's cycle of a DC operation mode (`CycleTimeSync0`/`CycleTimeSync1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SyncCycle {
    /// The element value: a fixed cycle in ns, 0 = set by the master.
    pub ns: u32,
    /// `Factor`: the cycle is this multiple of the bus cycle (ETG.2000); `None` if absent.
    pub factor: Option<i32>,
}

/// One `Dc/OpMode`: a synchronisation mode the device offers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DcOpMode {
    /// Name, e.g. "DC".
    pub name: String,
    /// Description.
    pub desc: String,
    /// AssignActivate: the value of ESC register 0980h (0 = free run / SM-synchronous).
    pub assign_activate: u32,
    /// `CycleTimeSync0`.
    pub sync0: Option<SyncCycle>,
    /// `ShiftTimeSync0`, ns.
    pub shift_sync0_ns: Option<i64>,
    /// `CycleTimeSync1`.
    pub sync1: Option<SyncCycle>,
}

/// ESC 0980h bit 9 (0x0200 in AssignActivate): SYNC0 is generated.
const SYNC0_ACTIVE: u32 = 0x0200;

impl DcOpMode {
    /// True if the mode runs on SYNC0 (AssignActivate bit 9).
    pub fn uses_sync0(&self) -> bool {
        self.assign_activate & SYNC0_ACTIVE != 0
    }

    /// True if SYNC0 may run at `cycle_ns` = the bus cycle in this mode: a fixed SYNC0 time
    /// must equal it; a `Factor` of 1 (or a 0 value without a factor) follows the bus cycle.
    pub fn allows_cycle(&self, cycle_ns: u32) -> bool {
        match self.sync0 {
            None => true,
            Some(SyncCycle { ns: 0, factor }) => factor.is_none_or(|f| f == 1),
            Some(SyncCycle { ns, .. }) => ns == cycle_ns,
        }
    }
}

/// One device of an ESI file, as cellrt uses it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EsiDevice {
    /// `Vendor/Id`, 1018h:01.
    pub vendor_id: u32,
    /// `Vendor/Name`.
    pub vendor_name: String,
    /// `Type@ProductCode`, 1018h:02.
    pub product_code: u32,
    /// `Type@RevisionNo`, 1018h:03.
    pub revision: u32,
    /// The `Type` text (the order code).
    pub type_name: String,
    /// `Name` (English where given).
    pub name: String,
    /// `Profile/ProfileNo`, e.g. 402; `None` where not given.
    pub profile_no: Option<u32>,
    /// Mailbox protocols offered, in `ALL` order.
    pub mailbox: Vec<MailboxProtocol>,
    /// CoE details, if CoE is offered.
    pub coe: Option<CoeDetails>,
    /// RxPDOs (master → device).
    pub rx_pdos: Vec<EsiPdo>,
    /// TxPDOs (device → master).
    pub tx_pdos: Vec<EsiPdo>,
    /// The object dictionary, one row per sub-index, in file order; empty when the file
    /// describes none.
    pub objects: Vec<EsiObject>,
    /// DC operation modes; empty when the device offers no distributed clocks.
    pub dc_opmodes: Vec<DcOpMode>,
    /// Line of the `Device` element.
    pub line: u32,
}

impl EsiDevice {
    /// The dictionary entry `index:sub`.
    pub fn object(&self, index: u16, sub: u8) -> Option<&EsiObject> {
        self.objects
            .iter()
            .find(|o| o.index == index && o.sub == sub)
    }

    /// True if the file describes an object dictionary.
    pub fn has_dictionary(&self) -> bool {
        !self.objects.is_empty()
    }

    /// The CiA 402 modes the device supports: 6502h's default value, `None` where the file
    /// gives none.
    pub fn supported_modes(&self) -> Option<Vec<ModeOfOperation>> {
        self.object(SUPPORTED_DRIVE_MODES, 0)
            .and_then(|o| o.default)
            .map(modes_of_6502)
    }

    /// The PDO with mapping object `index` (either direction).
    pub fn pdo(&self, index: u16) -> Option<&EsiPdo> {
        self.rx_pdos
            .iter()
            .chain(&self.tx_pdos)
            .find(|p| p.index == index)
    }

    /// True if the mailbox offers `protocol`.
    pub fn offers(&self, protocol: MailboxProtocol) -> bool {
        self.mailbox.contains(&protocol)
    }

    /// A one-line identity, e.g. "vendor 0xA1E product 0x201 revision 0x1 (MR-J4-TM)".
    pub fn identity_text(&self) -> String {
        format!(
            "vendor {:#x}, product code {:#x}, revision {:#x} ({})",
            self.vendor_id, self.product_code, self.revision, self.type_name
        )
    }
}
