//! `cellrt sdo` end to end: reads and writes on a running cell's drives over the in-process
//! emulated EtherCAT segment (the mailbox worker carries them) and on the simulated drives, and
//! each refusal, by the cell before anything is sent or by the drive with its abort code; and
//! `cellrt sdo list`, from the drive's SDO Information or, where it has none, the profile.

mod common;

use std::path::Path;

use cellrt_cia402::bus::{DictionaryEntry, DictionarySource, PdoMappable};
use cellrt_cia402::profiles::Access;
use cellrt_ethercat::master::abort_meaning;
use cellrt_runtime::host::operator::sdo_list::SdoListReply;
use cellrt_runtime::host::operator::wire::{Reply, SdoAnswer};
use common::cell::Cell;

/// A shipped configuration running for `cellrt sdo`.
struct SdoCell(Cell);

impl SdoCell {
    /// Starts `config` (a shipped configuration) under a unique name with `extra` arguments.
    fn start(dir: &Path, config: &str, old_name: &str, extra: &[&str]) -> SdoCell {
        let ready = ["sdo", "read", "x", "6041"];
        SdoCell(Cell::shipped(dir, config, old_name, extra, "", &ready))
    }

    /// Runs `cellrt sdo ARGS --cell NAME`; returns exit code, stdout, stderr.
    fn sdo(&self, args: &[&str]) -> (i32, String, String) {
        let args: Vec<&str> = std::iter::once("sdo").chain(args.iter().copied()).collect();
        self.0.cli(&args)
    }

    /// The printed line of a successful `cellrt sdo ARGS`.
    fn ok(&self, args: &[&str]) -> String {
        let (code, out, err) = self.sdo(args);
        assert_eq!(code, 0, "cellrt sdo {args:?}: {out}{err}");
        out.trim().to_string()
    }

    /// Expects a refusal (exit 3) whose message contains `why`; returns the message.
    fn refused(&self, args: &[&str], why: &str) -> String {
        let args: Vec<&str> = std::iter::once("sdo").chain(args.iter().copied()).collect();
        self.0.refused(&args, why)
    }
}

/// configs/ethercat-cell.toml on the in-process emulated segment.
fn ethercat_cell(dir: &Path) -> SdoCell {
    SdoCell::start(
        dir,
        "ethercat-cell.toml",
        "ethercat",
        &["--interface", "in-process"],
    )
}

/// The value of a printed read, "AXIS OBJ NAME (TYPE) = DEC (0xHEX)", with the hex checked.
fn read_value(line: &str) -> i64 {
    let (_, rest) = line.split_once(" = ").expect(line);
    let (dec, hex) = rest.split_once(" (0x").expect(line);
    let v: i64 = dec.parse().expect(line);
    let h = u64::from_str_radix(hex.trim_end_matches(')'), 16).expect(line);
    assert_eq!(
        h,
        v as u64 & ((1 << (4 * (hex.len() as u32 - 1))) - 1),
        "{line}"
    );
    v
}

#[test]
fn sdo_reads_and_writes_the_emulated_ethercat_drives_and_refuses_what_must_not_be_sent() {
    let dir = tempfile::tempdir().unwrap();
    let cell = ethercat_cell(dir.path());
    // y is an MR-J4-TM in csp, not powered: CiA 402 Switch on disabled (xxxx xxxx x1xx 0000).
    let line = cell.ok(&["read", "y", "6041"]);
    assert!(
        line.starts_with("y 6041h:00 Statusword (UNSIGNED16) = "),
        "{line}"
    );
    assert_eq!(read_value(&line) & 0x4F, 0x40, "{line}");
    assert_eq!(
        cell.ok(&["read", "y", "6061"]),
        "y 6061h:00 Modes of operation display (INTEGER8) = 8 (0x08)"
    );
    // MR-J4-TM manual §4.10: 607Ch is 0 without absolute position detection.
    assert_eq!(
        cell.ok(&["read", "y", "607Ch"]),
        "y 607Ch:00 Home offset (INTEGER32) = 0 (0x00000000)"
    );
    // 6085h Quick stop deceleration (MR-J4-TM manual §8.1, default 100 ms), written and read back.
    assert_eq!(read_value(&cell.ok(&["read", "y", "0x6085"])), 100);
    assert_eq!(
        cell.ok(&["write", "y", "6085", "250"]),
        "y 6085h:00 Quick stop deceleration (UNSIGNED32) written: 250 (0x000000FA)"
    );
    let (code, out, _) = cell.sdo(&["read", "y", "6085", "--json"]);
    assert_eq!(code, 0);
    match serde_json::from_str::<Reply>(&out).unwrap() {
        Reply::Sdo(r) => {
            assert_eq!((r.index, r.sub, r.bits), (0x6085, 0, 32));
            assert_eq!(r.outcome, SdoAnswer::Read { value: 250 });
        }
        other => panic!("{other:?}"),
    }
    // Refused by the drive: the cycle time of a SubDevice in OP (abort code and its meaning).
    let e = cell.refused(&["write", "y", "1C32:2", "500000"], "abort code 0x08000022");
    assert!(e.contains(abort_meaning(0x0800_0022)), "{e}");
    assert_eq!(read_value(&cell.ok(&["read", "y", "1C32:2"])), 1_000_000);
    // Refused by the cell before anything is sent.
    cell.refused(
        &["write", "y", "607C", "5"],
        "sdo: 607Ch:00 of axis 'y' (Home offset) is read-only",
    );
    cell.refused(
        &["read", "y", "2FFF"],
        "sdo: object 2FFFh:00 is not in the object dictionary of axis 'y'",
    );
    cell.refused(
        &["write", "y", "6098", "99"],
        "takes -43..37 (stated range): 99 is out of it",
    );
    cell.refused(
        &["write", "y", "6085", "-1"],
        "takes UNSIGNED32: -1 is out of its range 0..4294967295",
    );
    cell.refused(&["write", "y", "6040", "6"], "RxPDO");
    cell.refused(&["read", "w", "6041"], "unknown axis 'w'");
    // Nothing was written by the refusals.
    assert_eq!(read_value(&cell.ok(&["read", "y", "6085"])), 250);
    // Every drive of the segment answers (x MR-J3-T04, z MR-JET-G-N1, c MR-J5-G-N1).
    for axis in ["x", "z", "c"] {
        let line = cell.ok(&["read", axis, "6041"]);
        assert_eq!(read_value(&line) & 0x4F, 0x40, "{line}");
    }
    // A malformed object is a command-line error.
    assert_eq!(cell.sdo(&["read", "y", "60G1"]).0, 2);
}

#[test]
fn sdo_reads_the_simulated_drives() {
    let dir = tempfile::tempdir().unwrap();
    let cell = SdoCell::start(dir.path(), "demo.toml", "demo", &[]);
    let line = cell.ok(&["read", "y", "6041"]);
    assert!(
        line.starts_with("y 6041h:00 Statusword (UNSIGNED16)"),
        "{line}"
    );
    assert_eq!(read_value(&line) & 0x4F, 0x40, "{line}");
    cell.refused(
        &["read", "y", "2FFF"],
        "is not in the object dictionary of axis 'y' (Mitsubishi MR-J5-G-N1)",
    );
}

#[test]
fn sdo_on_an_esi_axis_follows_the_esi_dictionary() {
    let dir = tempfile::tempdir().unwrap();
    let cell = SdoCell::start(dir.path(), "cia402-esi.toml", "cia402-esi", &[]);
    assert_eq!(
        cell.ok(&["read", "x", "6061"]),
        "x 6061h:00 Modes of operation display (INTEGER8) = 8 (0x08)"
    );
    // 6098h is rw in configs/esi/cia402-example.xml (SINT).
    assert_eq!(
        cell.ok(&["write", "x", "6098", "35"]),
        "x 6098h:00 Homing method (INTEGER8) written: 35 (0x23)"
    );
    assert_eq!(read_value(&cell.ok(&["read", "x", "6098"])), 35);
    cell.refused(
        &["write", "x", "6098", "-129"],
        "takes INTEGER8: -129 is out of its range -128..127",
    );
    cell.refused(
        &["write", "x", "6502", "1"],
        "6502h:00 of axis 'x' (Supported drive modes) is read-only",
    );
    cell.refused(
        &["read", "x", "2000"],
        "is not in the object dictionary of axis 'x' (ESI device Example CiA 402 servo drive)",
    );
    // The configuration maps 6060h in the RxPDO.
    cell.refused(&["write", "x", "6060", "8"], "RxPDO");
    // The emulated drive lists the ESI's dictionary by SDO Information.
    let r = listed(&cell, "x");
    assert_eq!(
        (r.source, r.dictionary.as_str()),
        (
            DictionarySource::SdoInformation,
            "ESI device Example CiA 402 servo drive"
        )
    );
    let modes = entry(&r, 0x6098, 0);
    assert_eq!(
        (modes.data_type.as_str(), modes.access),
        ("INTEGER8", Access::Rw)
    );
}

#[test]
fn sdo_reads_around_a_homing_neither_fail_it_nor_wait_for_it() {
    let dir = tempfile::tempdir().unwrap();
    let cell = ethercat_cell(dir.path());
    let (code, out, err) = common::cellrt_on_cell(&cell.0.name, &["power", "on"]);
    assert_eq!(code, 0, "{out}{err}");
    for round in 0..2 {
        let name = cell.0.name.clone();
        // Reads of y's 6061h while y homes (its 6098h write and mode changes are SDOs too).
        let reads = std::thread::spawn(move || {
            (0..15)
                .map(|_| common::cellrt_on_cell(&name, &["sdo", "read", "y", "6061"]))
                .collect::<Vec<_>>()
        });
        let (code, out, err) = common::cellrt_on_cell(&cell.0.name, &["home", "y"]);
        assert_eq!(code, 0, "homing {round}: {out}{err}");
        for (code, out, err) in reads.join().unwrap() {
            match code {
                0 => assert!(
                    out.starts_with("y 6061h:00 Modes of operation display"),
                    "{out}"
                ),
                _ => assert!(
                    err.contains("sdo: the cell is homing; try again when the homing has ended"),
                    "{out}{err}"
                ),
            }
        }
    }
}

/// The `sdo list --json` reply of `axis`.
fn listed(cell: &SdoCell, axis: &str) -> Box<SdoListReply> {
    let (code, out, err) = cell.sdo(&["list", axis, "--json"]);
    assert_eq!(code, 0, "sdo list {axis}: {out}{err}");
    match serde_json::from_str::<Reply>(&out).unwrap() {
        Reply::SdoList(r) => r,
        other => panic!("{other:?}"),
    }
}

/// The listed entry `index:sub`.
fn entry(r: &SdoListReply, index: u16, sub: u8) -> &DictionaryEntry {
    r.entries
        .iter()
        .find(|e| (e.index, e.sub) == (index, sub))
        .unwrap_or_else(|| panic!("{index:04X}h:{sub:02X} not listed: {r:?}"))
}

#[test]
fn sdo_list_reads_the_emulated_mr_j4_tm_dictionary_from_sdo_information() {
    let dir = tempfile::tempdir().unwrap();
    let cell = ethercat_cell(dir.path());
    let r = listed(&cell, "y");
    assert_eq!(r.source, DictionarySource::SdoInformation, "{r:?}");
    assert_eq!(r.fallback, None);
    let status = entry(&r, 0x6041, 0);
    assert_eq!(status.name, "Statusword");
    assert_eq!(
        (
            status.data_type.as_str(),
            status.bits,
            status.access,
            status.pdo
        ),
        ("UNSIGNED16", Some(16), Access::Ro, PdoMappable::Tx)
    );
    // The identity object's four entries, each UNSIGNED32.
    for sub in 1..=4 {
        let e = entry(&r, 0x1018, sub);
        assert_eq!(
            (e.data_type.as_str(), e.bits),
            ("UNSIGNED32", Some(32)),
            "{e:?}"
        );
    }
    // 1C32h:02 is written only before OP (the drive refuses it in OP, as the test above shows).
    let cycle = entry(&r, 0x1C32, 2);
    assert_eq!(
        (cycle.access, cycle.write_restriction.as_deref()),
        (Access::Rw, Some("PreOP"))
    );
    // Written every cycle by the master: RxPDO-mappable and writable.
    let control = entry(&r, 0x6040, 0);
    assert_eq!((control.access, control.pdo), (Access::Rw, PdoMappable::Rx));
    // In index order, each entry once.
    assert!(r
        .entries
        .windows(2)
        .all(|w| (w[0].index, w[0].sub) < (w[1].index, w[1].sub)));
    // The table says where the list came from and shows the row.
    let table = cell.ok(&["list", "y"]);
    let first = table.lines().next().unwrap();
    assert!(
        first.starts_with(&format!(
            "y: {} entries from the drive's SDO Information",
            r.entries.len()
        )),
        "{first}"
    );
    let row = table
        .lines()
        .find(|l| l.starts_with("6041h:00"))
        .expect(&table);
    let cols: Vec<&str> = row.split_whitespace().collect();
    assert_eq!(
        cols,
        ["6041h:00", "Statusword", "UNSIGNED16", "16", "ro", "TxPDO"]
    );
    // Every drive of the segment lists its own (x MR-J3-T04, z MR-JET-G-N1).
    for axis in ["x", "z"] {
        assert_eq!(listed(&cell, axis).source, DictionarySource::SdoInformation);
    }
    // An unknown axis is refused naming it; the cell's axes are listed.
    let e = cell.refused(&["list", "w"], "unknown axis 'w'");
    assert!(e.contains("(the cell has x, y"), "{e}");
}

#[test]
fn sdo_list_on_a_simulated_drive_is_the_profiles_dictionary_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let cell = SdoCell::start(dir.path(), "demo.toml", "demo", &[]);
    let r = listed(&cell, "y");
    assert_eq!(r.source, DictionarySource::Profile);
    assert!(
        r.fallback.as_deref().unwrap().contains("simulated drive"),
        "{r:?}"
    );
    assert_eq!(r.dictionary, "Mitsubishi MR-J5-G-N1");
    assert_eq!(entry(&r, 0x6041, 0).name, "Statusword");
    let first = cell.ok(&["list", "y"]);
    let first = first.lines().next().unwrap();
    assert!(
        first.contains("from the profile's dictionary (Mitsubishi MR-J5-G-N1), not the drive: a simulated drive"),
        "{first}"
    );
}

#[test]
fn sdo_list_on_an_mr_je_c_is_its_dictionary_table_beside_the_ethercat_drives_own() {
    let dir = tempfile::tempdir().unwrap();
    let cell = SdoCell::start(dir.path(), "mixed-cell.toml", "mixed", &[]);
    let r = listed(&cell, "infeed");
    assert_eq!(r.source, DictionarySource::Profile);
    assert!(r.fallback.as_deref().unwrap().contains("MR-JE-C"), "{r:?}");
    // MR-JE-C manual §7.3: 6041h Statusword, UNSIGNED16, ro.
    let status = entry(&r, 0x6041, 0);
    assert_eq!(
        (status.data_type.as_str(), status.access),
        ("UNSIGNED16", Access::Ro)
    );
    assert_eq!(listed(&cell, "x").source, DictionarySource::SdoInformation);
}

/// `cellrt esi compare`: the emulated MR-J4-TM's dictionary, read by SDO Information, conforms
/// to its model's shipped ESI (written from the same profile); a copy of the ESI that says
/// 6041h is read-write and describes an object the drive lacks does not (exit 1), naming both;
/// a simulated axis has no dictionary to read (exit 3).
#[test]
fn esi_compare_holds_the_live_dictionary_against_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let cell = ethercat_cell(dir.path());
    let esi = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs/esi/mr-j4-tm.xml");
    let (code, out, err) = cell.0.cli(&["esi", "compare", esi, "y"]);
    assert_eq!(code, 0, "{out}{err}");
    let first = out.lines().next().unwrap_or_default();
    assert!(
        first.starts_with("axis 'y' (")
            && first.contains(" conforms to ")
            && first.contains(", 0 missing on the drive, 0 differ,"),
        "{out}"
    );
    let text = std::fs::read_to_string(esi).unwrap();
    let statusword = "<Index>#x6041</Index><Name>Statusword</Name><Type>UINT</Type><BitSize>16</BitSize><Flags><Access>ro</Access>";
    assert!(text.contains(statusword));
    let extra = "<Object><Index>#x5FFE</Index><Name>Not on the drive</Name><Type>UINT</Type><BitSize>16</BitSize><Flags><Access>rw</Access></Flags></Object>\n";
    let tampered = text
        .replace(
            statusword,
            &statusword.replace("<Access>ro<", "<Access>rw<"),
        )
        .replacen(
            "<Object><Index>#x6041</Index>",
            &format!("{extra}<Object><Index>#x6041</Index>"),
            1,
        );
    let copy = dir.path().join("tampered.xml");
    std::fs::write(&copy, tampered).unwrap();
    let (code, out, err) = cell.0.cli(&["esi", "compare", copy.to_str().unwrap(), "y"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("does NOT conform"), "{out}");
    assert!(out.contains("  missing   5FFEh:00"), "{out}");
    assert!(
        out.contains("  differs   6041h:00: access: ESI rw, drive ro"),
        "{out}"
    );
    let (code, _, err) = cell.0.cli(&["esi", "compare", esi, "w"]);
    assert_eq!(code, 3, "{err}");
}
