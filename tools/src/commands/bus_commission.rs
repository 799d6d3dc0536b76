//! `cellrt bus sdo|pdos|states|sii`: commissioning an EtherCAT segment without a cell, as the
//! IgH `ethercat` tool does: SDO upload and download in PRE-OP, the PDO assignment the
//! SubDevices hold, AL state requests per SubDevice, and the SII EEPROM. Each command holds the
//! interface's lock (`cell_lock::InterfaceLock`) while it runs, so it refuses while a cell runs
//! on the interface (and a cell refuses while it runs).

use std::time::Duration;

use cellrt_cia402::profiles::{profile, DataType, DriveModel, DriveProfile};
use cellrt_ethercat::identity::SubDeviceIdentity;
use cellrt_ethercat::master::commission::{
    AssignedPdo, Commissioning, FoundSubDevice, PdoAssignment, SdoFailure,
};
use cellrt_ethercat::master::scan::sii_words;
use cellrt_ethercat::master::{object_type, RawSocketLink};
use cellrt_ethercat::register::{al_code, AlState, AlStatus};
use cellrt_fieldbus::mr_je_c::ObjectId;
use cellrt_runtime::host::cell_lock::{CellLockError, InterfaceLock};
use cellrt_runtime::host::operator::sdo::object_text;
use clap::{Args, Subcommand, ValueEnum};

use crate::exit::Exit;

/// How long a frame may take to come back (no cycle runs; generous for a loaded host).
const FRAME_TIMEOUT: Duration = Duration::from_millis(100);

/// The interface and, where one SubDevice is meant, its position.
#[derive(Debug, Args)]
pub struct Station {
    /// The network interface the SubDevices are wired to.
    #[arg(long, value_name = "IF")]
    pub interface: String,
    /// The SubDevice's position in the line (0 = next to the master).
    #[arg(long, short = 'p', value_name = "N", default_value_t = 0)]
    pub position: usize,
}

/// `cellrt bus sdo` subcommands.
#[derive(Debug, Subcommand)]
pub enum BusSdoCommand {
    /// Upload one object from a SubDevice in PRE-OP: its value typed by `--type`, else by the
    /// SubDevice's SDO Information, else by its model's dictionary, else as bytes.
    Read {
        /// Interface and position.
        #[command(flatten)]
        station: Station,
        /// The object: index in hex with an optional decimal sub-index, e.g. 1018:1.
        object: ObjectId,
        /// The object's type, where the SubDevice does not say it.
        #[arg(long = "type", value_enum)]
        data_type: Option<SdoType>,
        /// Print the value as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Download one value (decimal, or hex as 0x1EA5 / 1EA5h) to a SubDevice in PRE-OP,
    /// range-checked against its type first.
    Write {
        /// Interface and position.
        #[command(flatten)]
        station: Station,
        /// The object: index in hex with an optional decimal sub-index, e.g. 2001:0.
        object: ObjectId,
        /// The value.
        #[arg(allow_hyphen_values = true, value_parser = crate::numbers::integer)]
        value: i64,
        /// The object's type, where the SubDevice does not say it.
        #[arg(long = "type", value_enum)]
        data_type: Option<SdoType>,
    },
}

/// `cellrt bus sii` subcommands.
#[derive(Debug, Subcommand)]
pub enum BusSiiCommand {
    /// Read words of a SubDevice's SII EEPROM (ETG.2010), as a hex dump or to a file.
    Read {
        /// Interface and position.
        #[command(flatten)]
        station: Station,
        /// The first word address (decimal, or hex as 0x40).
        #[arg(long, default_value = "0", value_parser = crate::numbers::integer)]
        word: i64,
        /// How many words.
        #[arg(long, default_value = "64", value_parser = crate::numbers::integer)]
        words: i64,
        /// Write the bytes (little-endian words) to this file instead of the dump.
        #[arg(long, value_name = "FILE")]
        out: Option<std::path::PathBuf>,
    },
}

/// A CiA 301 basic type named on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SdoType {
    /// BOOLEAN.
    Bool,
    /// INTEGER8.
    I8,
    /// UNSIGNED8.
    U8,
    /// INTEGER16.
    I16,
    /// UNSIGNED16.
    U16,
    /// INTEGER32.
    I32,
    /// UNSIGNED32.
    U32,
    /// VISIBLE_STRING (read only).
    String,
}

impl SdoType {
    fn data_type(self) -> DataType {
        match self {
            SdoType::Bool => DataType::Bool,
            SdoType::I8 => DataType::I8,
            SdoType::U8 => DataType::U8,
            SdoType::I16 => DataType::I16,
            SdoType::U16 => DataType::U16,
            SdoType::I32 => DataType::I32,
            SdoType::U32 => DataType::U32,
            SdoType::String => DataType::VisibleString { octets: 0 },
        }
    }
}

/// An AL state named on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum StateArg {
    /// INIT.
    Init,
    /// PRE-OP.
    Preop,
    /// BOOT.
    Boot,
    /// SAFE-OP.
    Safeop,
    /// OP.
    Op,
}

impl StateArg {
    fn al(self) -> AlState {
        match self {
            StateArg::Init => AlState::Init,
            StateArg::Preop => AlState::PreOp,
            StateArg::Boot => AlState::Bootstrap,
            StateArg::Safeop => AlState::SafeOp,
            StateArg::Op => AlState::Op,
        }
    }
}

/// Takes the interface's lock and opens its raw socket; the exit where either fails.
fn open(interface: &str) -> Result<(InterfaceLock, RawSocketLink), Exit> {
    let lock = InterfaceLock::acquire(interface).map_err(|e| {
        eprintln!("error: {e}");
        match e {
            CellLockError::InterfaceName { .. } => Exit::BadInput,
            CellLockError::InterfaceBusy { .. } => Exit::Rejected,
            _ => Exit::Failed,
        }
    })?;
    let link = RawSocketLink::open(interface, FRAME_TIMEOUT).map_err(|e| {
        eprintln!("error: EtherCAT interface '{interface}': {e}");
        Exit::of_open_error(&e)
    })?;
    Ok((lock, link))
}

/// Opens the segment in PRE-OP and checks that `position` is on it.
fn commissioning(station: &Station) -> Result<(InterfaceLock, Commissioning), Exit> {
    let (lock, link) = open(&station.interface)?;
    let c = Commissioning::open(Box::new(link)).map_err(|e| {
        eprintln!("error: EtherCAT segment on '{}': {e}", station.interface);
        Exit::Failed
    })?;
    if station.position >= c.len() {
        eprintln!(
            "error: --position {}: no SubDevice there ({} on '{}')",
            station.position,
            c.len(),
            station.interface
        );
        return Err(Exit::BadInput);
    }
    Ok((lock, c))
}

/// The segment in PRE-OP for a command on all SubDevices or the one at `position`.
fn segment_session(
    interface: &str,
    position: Option<usize>,
) -> Result<(InterfaceLock, Commissioning), Exit> {
    commissioning(&Station {
        interface: interface.to_string(),
        position: position.unwrap_or(0),
    })
}

/// The drive model a SubDevice's identity names, if cellrt knows it.
fn model_of(identity: &SubDeviceIdentity) -> Option<&'static DriveProfile> {
    DriveModel::ALL.iter().map(|m| profile(*m)).find(|p| {
        let id = SubDeviceIdentity::of_profile(p);
        p.identity.maker_vendor_id.is_some()
            && id.vendor_id == identity.vendor_id
            && id.product_code == identity.product_code
    })
}

/// The type of `index:sub` on the SubDevice and where it came from.
fn resolve_type(
    c: &mut Commissioning,
    found: &FoundSubDevice,
    object: ObjectId,
    given: Option<SdoType>,
) -> Option<(DataType, String)> {
    if let Some(t) = given {
        return Some((t.data_type(), "--type".into()));
    }
    if let Some((t, name)) = c.entry_type(found.position, object.index, object.sub) {
        return Some((t, format!("SDO Information: {name}")));
    }
    let p = model_of(&found.identity)?;
    p.object(object.index, object.sub)?;
    Some((
        object_type(p, object.index, object.sub),
        format!("{} dictionary", p.model.as_str()),
    ))
}

/// The integer `bytes` hold as `t` (little-endian, sign-extended for a signed type).
fn integer(bytes: &[u8], t: DataType) -> i64 {
    let mut le = [0u8; 8];
    let n = bytes.len().min(8);
    le[..n].copy_from_slice(&bytes[..n]);
    let raw = u64::from_le_bytes(le);
    let bits = (n * 8) as u32;
    match t {
        DataType::I8 | DataType::I16 | DataType::I32 if (1..64).contains(&bits) => {
            let shift = 64 - bits;
            ((raw << shift) as i64) >> shift
        }
        _ => raw as i64,
    }
}

/// Runs `cellrt bus sdo`.
pub fn sdo(command: BusSdoCommand) -> Exit {
    match command {
        BusSdoCommand::Read {
            station,
            object,
            data_type,
            json,
        } => sdo_read(&station, object, data_type, json),
        BusSdoCommand::Write {
            station,
            object,
            value,
            data_type,
        } => sdo_write(&station, object, value, data_type),
    }
}

/// The segment in PRE-OP, the SubDevice at `station`'s position and `object` named on it.
fn object_session(
    station: &Station,
    object: ObjectId,
) -> Result<(InterfaceLock, Commissioning, FoundSubDevice, String), Exit> {
    let (lock, c) = commissioning(station)?;
    let found = c.subdevices()[station.position].clone();
    let what = format!(
        "SubDevice {} ({}) {}",
        found.position,
        found.name,
        object_text(object.index, object.sub)
    );
    Ok((lock, c, found, what))
}

fn sdo_read(station: &Station, object: ObjectId, given: Option<SdoType>, json: bool) -> Exit {
    let (_lock, mut c, found, what) = match object_session(station, object) {
        Ok(session) => session,
        Err(exit) => return exit,
    };
    let bytes = match c.upload(station.position, object.index, object.sub) {
        Ok(b) => b,
        Err(e) => return sdo_failed(&what, &e),
    };
    let typed = resolve_type(&mut c, &found, object, given);
    let hex_bytes: Vec<String> = bytes.iter().map(|b| format!("{b:02X}")).collect();
    let (value, shown) = match typed {
        Some((DataType::VisibleString { .. }, _)) => {
            let text = String::from_utf8_lossy(&bytes)
                .trim_end_matches('\0')
                .to_string();
            (serde_json::json!(text), format!("{text:?}"))
        }
        Some((t, _)) => {
            let v = integer(&bytes, t);
            (
                serde_json::json!(v),
                format!(
                    "{v} (0x{})",
                    hex_bytes.iter().rev().cloned().collect::<String>()
                ),
            )
        }
        None => (
            serde_json::Value::Null,
            format!("bytes {} (type unknown: give --type)", hex_bytes.join(" ")),
        ),
    };
    if json {
        let (type_name, from) = typed
            .as_ref()
            .map(|(t, from)| (t.cia301_name(), from.as_str()))
            .unwrap_or(("unknown", "none"));
        println!(
            "{}",
            serde_json::json!({
                "position": found.position,
                "name": found.name,
                "index": object.index,
                "sub": object.sub,
                "object": object_text(object.index, object.sub),
                "type": type_name,
                "type_from": from,
                "value": value,
                "bytes": bytes,
            })
        );
    } else {
        let t = typed
            .map(|(t, from)| format!(" {} [{from}]", t.cia301_name()))
            .unwrap_or_default();
        println!("{what} = {shown}{t}");
    }
    Exit::Ok
}

fn sdo_write(station: &Station, object: ObjectId, value: i64, given: Option<SdoType>) -> Exit {
    let (_lock, mut c, found, what) = match object_session(station, object) {
        Ok(session) => session,
        Err(exit) => return exit,
    };
    let Some((t, from)) = resolve_type(&mut c, &found, object, given) else {
        eprintln!("error: {what}: its type is not known (no SDO Information, no model cellrt knows): give --type");
        return Exit::BadInput;
    };
    if t.value_range().is_none() {
        eprintln!(
            "error: {what}: a {} is not written as a number",
            t.cia301_name()
        );
        return Exit::BadInput;
    }
    let (lo, hi) = t.value_range().unwrap_or((0, 0));
    if value < lo || value > hi {
        eprintln!(
            "error: {what}: {value} is outside {} ({lo}…{hi}; type from {from}); nothing was sent",
            t.cia301_name()
        );
        return Exit::BadInput;
    }
    let bytes = value.to_le_bytes();
    match c.download(
        station.position,
        object.index,
        object.sub,
        &bytes[..t.bytes()],
    ) {
        Ok(()) => {
            println!("{what} written: {value} ({} [{from}])", t.cia301_name());
            Exit::Ok
        }
        Err(e) => sdo_failed(&what, &e),
    }
}

/// The exit of a failed transfer, said in one line.
fn sdo_failed(what: &str, e: &SdoFailure) -> Exit {
    eprintln!("refused by the SubDevice: {what}: {e}");
    match e {
        SdoFailure::Abort { .. } => Exit::Rejected,
        SdoFailure::NoSubDevice { .. } => Exit::BadInput,
    }
}

/// Runs `cellrt bus pdos`: every SubDevice's PDO assignment (or one's with `--position`).
pub fn pdos(interface: &str, position: Option<usize>, json: bool) -> Exit {
    let (_lock, mut c) = match segment_session(interface, position) {
        Ok(c) => c,
        Err(exit) => return exit,
    };
    let subdevices = c.subdevices();
    let chosen: Vec<FoundSubDevice> = subdevices
        .into_iter()
        .filter(|d| position.is_none_or(|p| p == d.position))
        .collect();
    let mut docs = Vec::new();
    let mut text = String::new();
    for d in &chosen {
        let what = format!("SubDevice {} ({})", d.position, d.name);
        let assignment = match c.pdo_assignment(d.position) {
            Ok(a) => a,
            Err(e) => return sdo_failed(&format!("{what} PDO assignment"), &e),
        };
        let model = model_of(&d.identity);
        text.push_str(&pdo_text(&what, &assignment, model));
        docs.push(serde_json::json!({
            "position": d.position,
            "name": d.name,
            "rx": pdo_json(&assignment.rx, model),
            "tx": pdo_json(&assignment.tx, model),
        }));
    }
    if json {
        println!(
            "{}",
            serde_json::json!({ "interface": interface, "subdevices": docs })
        );
    } else {
        print!("{text}");
    }
    Exit::Ok
}

/// The name of a mapped object in `model`'s dictionary, where it is listed.
fn entry_name(model: Option<&DriveProfile>, index: u16, sub: u8) -> Option<&'static str> {
    model.and_then(|p| p.object(index, sub)).map(|o| o.name)
}

/// A mapping word's index, sub-index and bit length (ETG.1000.6 §5.6.7.4.7).
fn entry_parts(word: u32) -> (u16, u8, u8) {
    ((word >> 16) as u16, (word >> 8) as u8, word as u8)
}

fn pdo_text(what: &str, a: &PdoAssignment, model: Option<&DriveProfile>) -> String {
    use std::fmt::Write;
    let mut out = format!("{what}\n");
    for (side, sm, pdos) in [("RxPDO", "SM2", &a.rx), ("TxPDO", "SM3", &a.tx)] {
        for pdo in pdos {
            let bits: u32 = pdo.entries.iter().map(|w| u32::from(*w as u8)).sum();
            let _ = writeln!(
                out,
                "  {sm} {side} {:04X}h ({} entries, {} bytes)",
                pdo.index,
                pdo.entries.len(),
                bits.div_ceil(8)
            );
            for &word in &pdo.entries {
                let (index, sub, bits) = entry_parts(word);
                let name = if index == 0 {
                    "(gap)"
                } else {
                    entry_name(model, index, sub).unwrap_or("")
                };
                let _ = writeln!(out, "    {} {bits:>2} bit  {name}", object_text(index, sub));
            }
        }
    }
    out
}

fn pdo_json(pdos: &[AssignedPdo], model: Option<&DriveProfile>) -> serde_json::Value {
    pdos.iter()
        .map(|p| {
            let entries: Vec<serde_json::Value> = p
                .entries
                .iter()
                .map(|&w| {
                    let (index, sub, bits) = entry_parts(w);
                    serde_json::json!({
                        "index": index,
                        "sub": sub,
                        "bits": bits,
                        "name": entry_name(model, index, sub),
                    })
                })
                .collect();
            serde_json::json!({ "index": p.index, "entries": entries })
        })
        .collect()
}

/// Runs `cellrt bus states`: each SubDevice's AL state after requesting `state` from one
/// (`position`) or all of them, or as they are.
pub fn states(
    interface: &str,
    position: Option<usize>,
    state: Option<StateArg>,
    timeout: Duration,
    json: bool,
) -> Exit {
    let (_lock, mut c) = match segment_session(interface, position) {
        Ok(c) => c,
        Err(exit) => return exit,
    };
    let subdevices = c.subdevices();
    let mut rows = Vec::new();
    let mut refused = false;
    for d in &subdevices {
        let asked = state.filter(|_| position.is_none_or(|p| p == d.position));
        let status = match asked {
            Some(s) => c.request_state(d.position, s.al(), timeout),
            None => c.al_status(d.position),
        };
        let status = match status {
            Ok(s) => s,
            Err(e) => {
                eprintln!("error: EtherCAT link '{interface}': {e}");
                return Exit::Failed;
            }
        };
        let reached = asked.is_none_or(|s| status.state == Some(s.al()) && !status.error);
        refused |= !reached;
        rows.push((d, asked, status, reached));
    }
    if json {
        let docs: Vec<serde_json::Value> = rows
            .iter()
            .map(|(d, asked, s, reached)| {
                serde_json::json!({
                    "position": d.position,
                    "name": d.name,
                    "requested": asked.map(|a| a.al().as_str()),
                    "al_state": s.state.map(AlState::as_str),
                    "al_error": s.error,
                    "al_status_code": s.code,
                    "al_status": al_code::name(s.code),
                    "reached": reached,
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::json!({ "interface": interface, "subdevices": docs })
        );
    } else {
        for (d, asked, s, reached) in &rows {
            let mut line = format!("{:<3} {:<24} {}", d.position, d.name, state_text(s));
            if let Some(a) = asked {
                line.push_str(&format!(
                    "  (requested {}{})",
                    a.al().as_str(),
                    if *reached { "" } else { ": not reached" }
                ));
            }
            println!("{line}");
        }
    }
    if refused {
        Exit::Rejected
    } else {
        Exit::Ok
    }
}

/// An AL status in words: the state, the error flag and the code's meaning.
fn state_text(s: &AlStatus) -> String {
    let state = s.state.map_or("unknown", AlState::as_str);
    if s.error || s.code != 0 {
        format!(
            "{state}{} AL status code {:#06x} {}",
            if s.error { "+ERROR" } else { "" },
            s.code,
            al_code::name(s.code)
        )
    } else {
        state.to_string()
    }
}

/// Runs `cellrt bus sii`.
pub fn sii(command: BusSiiCommand) -> Exit {
    let BusSiiCommand::Read {
        station,
        word,
        words,
        out,
    } = command;
    let (Ok(at), Ok(n)) = (u16::try_from(word), u16::try_from(words)) else {
        eprintln!("error: --word {word} --words {words}: SII word addresses are 0…0xffff");
        return Exit::BadInput;
    };
    if n == 0 || u32::from(at) + u32::from(n) > 0x1_0000 {
        eprintln!(
            "error: --word {word} --words {words}: give 1 or more words ending at 0xffff at most"
        );
        return Exit::BadInput;
    }
    let (_lock, mut link) = match open(&station.interface) {
        Ok(l) => l,
        Err(exit) => return exit,
    };
    let data = match sii_words(&mut link, station.position, at, n) {
        Ok(d) => d,
        Err(e @ cellrt_ethercat::master::scan::ScanError::NoSubDevice { .. }) => {
            eprintln!("error: --position {}: {e}", station.position);
            return Exit::BadInput;
        }
        Err(e) => {
            eprintln!("error: SII read on '{}': {e}", station.interface);
            return Exit::Failed;
        }
    };
    let bytes: Vec<u8> = data.iter().flat_map(|w| w.to_le_bytes()).collect();
    if let Some(path) = out {
        if let Err(e) = std::fs::write(&path, &bytes) {
            eprintln!("error: cannot write {}: {e}", path.display());
            return Exit::Failed;
        }
        return Exit::Ok;
    }
    for (k, chunk) in data.chunks(8).enumerate() {
        let words: Vec<String> = chunk.iter().map(|w| format!("{w:04x}")).collect();
        println!("{:04x}: {}", usize::from(at) + 8 * k, words.join(" "));
    }
    Exit::Ok
}
