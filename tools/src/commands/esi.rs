//! `cellrt esi show FILE.xml`: what cellrt takes from an ESI file (ETG.2000), device by device;
//! `cellrt esi compare FILE.xml AXIS`: a running cell's drive, its dictionary read through SDO
//! Information, against the file.

use std::fmt::Write as _;
use std::path::PathBuf;

use cellrt_cia402::profiles::Access;
use cellrt_ethercat::esi::{DcOpMode, EsiDevice, EsiObject, EsiPdo};
use clap::{Args, Subcommand};

use super::operate::Target;
use crate::exit::Exit;
use cellrt_cia402::bus::dictionary::DictionarySource;
use cellrt_runtime::host::operator::wire::{Reply, Request};

/// `cellrt esi`.
#[derive(Debug, Args)]
pub struct EsiArgs {
    /// What to do with the file.
    #[command(subcommand)]
    pub command: EsiCommand,
}

/// `cellrt esi` subcommands.
#[derive(Debug, Subcommand)]
pub enum EsiCommand {
    /// Print the identity, mailbox, PDOs, object dictionary, DC modes and drive modes cellrt
    /// takes from an ESI file; a file cellrt cannot use exits 2.
    Show {
        /// The ESI file (EtherCATInfo XML).
        file: PathBuf,
    },
    /// Compare an axis' drive on a running cell with an ESI file: its object dictionary, read
    /// from the drive by SDO Information (`cellrt sdo list`), against the file's. Lists the
    /// entries the file describes that the drive lacks or describes otherwise (size, access,
    /// PDO mapping), then those the file leaves out. Exit 0 if the drive conforms, 1 if not.
    Compare {
        /// The ESI file (EtherCATInfo XML) with one device.
        file: PathBuf,
        /// The axis whose drive to read.
        axis: String,
        /// Print the comparison as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// Runs `cellrt esi`.
pub fn run(args: EsiArgs, target: Target) -> Exit {
    let file = match args.command {
        EsiCommand::Show { file } => file,
        EsiCommand::Compare { file, axis, json } => return compare(&file, axis, json, &target),
    };
    match cellrt_config::input_file::read_esi(&file) {
        Ok(devices) => {
            print!("{}", show(&file, &devices));
            Exit::Ok
        }
        Err(e) => {
            eprintln!("error: {e}");
            Exit::BadInput
        }
    }
}

/// `cellrt esi compare FILE AXIS`: the drive's dictionary from the cell against the file's.
fn compare(file: &std::path::Path, axis: String, json: bool, target: &Target) -> Exit {
    let device = match cellrt_config::input_file::read_esi(file) {
        Ok(mut d) if d.len() == 1 => d.remove(0),
        Ok(d) => {
            let names: Vec<&str> = d.iter().map(|d| d.name.as_str()).collect();
            eprintln!(
                "error: {}: {} devices ({}); compare takes a file with one",
                file.display(),
                d.len(),
                names.join(", ")
            );
            return Exit::BadInput;
        }
        Err(e) => {
            eprintln!("error: {e}");
            return Exit::BadInput;
        }
    };
    if !device.has_dictionary() {
        eprintln!(
            "error: {}: the device has no object dictionary",
            file.display()
        );
        return Exit::BadInput;
    }
    let list = match super::sdo::ask(target, &Request::SdoList { axis: axis.clone() }, false) {
        Ok(Reply::SdoList(r)) => r,
        Ok(other) => return super::sdo::unexpected("sdo list", &other),
        Err(exit) => return exit,
    };
    if list.source != DictionarySource::SdoInformation {
        eprintln!(
            "error: axis '{axis}': its drive's dictionary cannot be read ({}); nothing to compare",
            list.fallback.as_deref().unwrap_or("no SDO Information")
        );
        return Exit::Rejected;
    }
    let c = cellrt_ethercat::esi::compare::compare(&device, &list.entries);
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&c).expect("the comparison serialises")
        );
    } else {
        print!("{}", comparison_text(file, &axis, &list.dictionary, &c));
    }
    if c.conforms() {
        Exit::Ok
    } else {
        Exit::Failed
    }
}

fn comparison_text(
    file: &std::path::Path,
    axis: &str,
    dictionary: &str,
    c: &cellrt_ethercat::esi::compare::DictionaryComparison,
) -> String {
    let verdict = if c.conforms() {
        "conforms"
    } else {
        "does NOT conform"
    };
    let mut s = format!(
        "axis '{axis}' ({dictionary}) {verdict} to {}: {} entries agree, {} missing on the drive, {} differ, {} not in the ESI\n",
        file.display(),
        c.agreeing,
        c.missing_on_drive.len(),
        c.mismatches.len(),
        c.not_in_esi.len()
    );
    for e in &c.missing_on_drive {
        let _ = writeln!(s, "  missing   {e}");
    }
    for m in &c.mismatches {
        let _ = writeln!(s, "  differs   {}: {}", m.entry, m.what);
    }
    if !c.not_in_esi.is_empty() {
        let ids: Vec<String> = c.not_in_esi.iter().map(|e| e.to_string()).collect();
        let _ = writeln!(s, "  not in the ESI (a note): {}", ids.join(" "));
    }
    s
}

/// The text `cellrt esi show` prints for `devices` of `file`.
pub fn show(file: &std::path::Path, devices: &[EsiDevice]) -> String {
    let mut s = format!("{}: {} device(s)\n", file.display(), devices.len());
    for (i, d) in devices.iter().enumerate() {
        let _ = writeln!(s, "\ndevice {} (line {}): {}", i + 1, d.line, d.name);
        device(&mut s, d);
    }
    s
}

fn device(s: &mut String, d: &EsiDevice) {
    let _ = writeln!(
        s,
        "  identity: vendor {:#010x} ({}), product code {:#010x}, revision {:#010x}, type {}",
        d.vendor_id, d.vendor_name, d.product_code, d.revision, d.type_name
    );
    if let Some(p) = d.profile_no {
        let _ = writeln!(s, "  profile: {p}");
    }
    let mut mailbox: Vec<String> = d.mailbox.iter().map(|p| p.as_str().to_owned()).collect();
    if let (Some(c), Some(first)) = (d.coe, mailbox.iter_mut().find(|m| *m == "CoE")) {
        let flags: Vec<&str> = [
            (c.sdo_info, "SDO info"),
            (c.pdo_assign, "PDO assign"),
            (c.pdo_config, "PDO config"),
            (c.complete_access, "complete access"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|&(_, n)| n)
        .collect();
        *first = format!("CoE ({})", flags.join(", "));
    }
    let _ = writeln!(s, "  mailbox: {}", none_if_empty(&mailbox.join(", ")));
    let modes = d
        .supported_modes()
        .map_or("not given (no 6502h default)".to_owned(), |m| {
            let v: Vec<&str> = m.iter().map(|m| m.as_str()).collect();
            v.join(", ")
        });
    let _ = writeln!(s, "  CiA 402 modes (6502h): {modes}");
    let dc: Vec<String> = d.dc_opmodes.iter().map(opmode).collect();
    let _ = writeln!(s, "  DC opmodes: {}", none_if_empty(&dc.join("; ")));
    for (kind, pdos) in [("RxPDO", &d.rx_pdos), ("TxPDO", &d.tx_pdos)] {
        for p in pdos {
            let _ = writeln!(s, "  {kind} {}", pdo(p));
        }
    }
    let _ = writeln!(s, "  object dictionary: {} entries", d.objects.len());
    for o in &d.objects {
        let _ = writeln!(s, "    {}", object(o));
    }
}

fn none_if_empty(t: &str) -> &str {
    if t.is_empty() {
        "none"
    } else {
        t
    }
}

fn opmode(m: &DcOpMode) -> String {
    let sync0 = match m.sync0 {
        _ if !m.uses_sync0() => "no SYNC0".to_owned(),
        None => "SYNC0".to_owned(),
        Some(c) if c.ns == 0 => format!("SYNC0 at {}× the bus cycle", c.factor.unwrap_or(1)),
        Some(c) => format!("SYNC0 fixed at {} ns", c.ns),
    };
    format!(
        "{} \"{}\" (AssignActivate {:#06x}, {sync0})",
        m.name, m.desc, m.assign_activate
    )
}

fn pdo(p: &EsiPdo) -> String {
    let mut attrs = vec![if p.fixed { "fixed" } else { "changeable" }.to_owned()];
    if p.mandatory {
        attrs.push("mandatory".into());
    }
    attrs.push(p.sm.map_or("not assigned by default".into(), |sm| format!("Sm {sm}")));
    let entries: Vec<String> = p
        .entries
        .iter()
        .map(|e| {
            if e.is_padding() {
                format!("padding/{}", e.bits)
            } else {
                format!("{:04X}h:{:02X}/{}", e.index, e.sub, e.bits)
            }
        })
        .collect();
    format!(
        "{:04X}h \"{}\" ({}): {}",
        p.index,
        p.name,
        attrs.join(", "),
        none_if_empty(&entries.join(", "))
    )
}

fn object(o: &EsiObject) -> String {
    let access = match o.access {
        Access::Ro => "ro",
        Access::Rw => "rw",
        Access::Wo => "wo",
        Access::Unstated => "--",
    };
    let pdo = match (o.pdo.rx, o.pdo.tx) {
        (true, true) => "RT",
        (true, false) => "R ",
        (false, true) => " T",
        (false, false) => "  ",
    };
    let mut line = format!(
        "{:04X}h:{:02X} {access} {pdo} {:<6} {:>3} bit  {}",
        o.index, o.sub, o.data_type, o.bits, o.name
    );
    if let Some(w) = &o.write_restriction {
        let _ = write!(line, " (write: {w})");
    }
    if let Some(v) = o.default {
        let _ = write!(line, " = {v} ({v:#x})");
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn show_prints_what_cellrt_takes_from_the_vendor_files() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../axes/ethercat/tests/data/esi");
        let path = dir.join("microchip-samd51-ethercat-slave.xml");
        let text = show(&path, &cellrt_ethercat::esi::load(&path).unwrap());
        for line in [
            "identity: vendor 0x000004d8 (Microchip - SAMD51 EtherCAT Slave FoE), product code 0x00009252, revision 0x00000001",
            "mailbox: CoE (SDO info, complete access), FoE",
            "RxPDO 1601h \"Outputs process data mapping\" (fixed, mandatory, Sm 2): 7010h:01/32",
            "DC \"DC-Synchron\" (AssignActivate 0x0300, SYNC0 at 1× the bus cycle)",
            "1C32h:02 ro    UDINT   32 bit  Cycle Time",
            "1C32h:01 rw    UINT    16 bit  Synchronization Type (write: PreOP) = 1 (0x1)",
            "7010h:01 rw R  UDINT   32 bit  Trigger = 0 (0x0)",
        ] {
            assert!(text.contains(line), "{line}\n{text}");
        }
        let path = dir.join("rt-labs-am335xice.xml");
        let text = show(&path, &cellrt_ethercat::esi::load(&path).unwrap());
        assert!(text.contains("DC opmodes: none"), "{text}");
        assert!(text.contains("CiA 402 modes (6502h): not given"), "{text}");
    }

    #[test]
    fn a_malformed_file_exits_2() {
        let dir = tempfile::tempdir().unwrap();
        let bad = dir.path().join("bad.xml");
        std::fs::write(&bad, "<EtherCATInfo><Vendor>").unwrap();
        let exit = run(
            EsiArgs {
                command: EsiCommand::Show { file: bad },
            },
            Target {
                cell: None,
                reply_timeout: 5.0,
            },
        );
        assert_eq!(exit.code(), 2);
    }
}
