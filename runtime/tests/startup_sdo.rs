//! `[[axes.ethercat.startup_sdo]]`: the start-up list is written in PRE-OP before the PDO
//! configuration (checked in OP on the in-process emulated segment), a download the drive
//! refuses stops bring-up naming the axis, the entry, the object and the abort code, and a bad
//! entry is refused at load naming its key.

use std::path::{Path, PathBuf};

use cellrt_cia402::bus::AcyclicBus;
use cellrt_config::CellConfig;
use cellrt_runtime::host::cell_bus::CellBus;

fn config_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/ethercat-cell.toml")
}

/// `configs/ethercat-cell.toml` on the in-process segment with `list` as axis y's (MR-J4-TM)
/// start-up list.
fn cell_text(list: &str) -> String {
    let text = std::fs::read_to_string(config_path()).unwrap();
    let y = text.find("name = \"y\"").unwrap();
    let end = y + text[y..].find("[[axes]]").unwrap();
    format!("{}{list}\n{}", &text[..end], &text[end..])
        .replace("interface = \"ecat0\"", "interface = \"in-process\"")
}

fn parse(list: &str) -> Result<CellConfig, String> {
    CellConfig::parse(&config_path(), &cell_text(list)).map_err(|e| e.to_string())
}

#[test]
fn the_start_up_list_is_written_before_op() {
    let cell = parse(
        r#"
[[axes.ethercat.startup_sdo]]
object = "6085h"
value = 400
"#,
    )
    .unwrap();
    let y = cell
        .axes
        .on_loop()
        .iter()
        .position(|a| a.name == "y")
        .unwrap();
    let mut bus = CellBus::open(&cell).unwrap_or_else(|e| panic!("{e}"));
    // 6085h (quick stop deceleration, UNSIGNED32 in the dictionary) is 100 ms by default.
    assert_eq!(bus.sdo_upload(y, 0x6085, 0), Ok(400));
    bus.close().unwrap();
}

#[test]
fn a_refused_download_stops_bring_up_naming_the_entry() {
    let cell = parse(
        r#"
[[axes.ethercat.startup_sdo]]
object = "6085h"
value = 400

[[axes.ethercat.startup_sdo]]
object = "5FFFh:0"
value = 1
type = "u32"
"#,
    )
    .unwrap();
    let Err(e) = CellBus::open(&cell) else {
        panic!("bring-up must refuse the start-up list")
    };
    let e = e.to_string();
    for part in [
        "axis 'y'",
        "start-up SDO 5FFFh:00 := 1",
        "entry 2",
        "0x06020000",
    ] {
        assert!(e.contains(part), "{part:?} in {e}");
    }
}

#[test]
fn bad_entries_are_refused_at_load_naming_the_key() {
    let key = "axes[1].ethercat.startup_sdo[0]";
    for (entry, field, says) in [
        ("object = \"zz\"\nvalue = 1", "object", "is no object"),
        ("object = \"6041h\"\nvalue = 1", "object", "not writable"),
        (
            "object = \"6085h\"\nvalue = -1",
            "value",
            "outside UNSIGNED32",
        ),
        (
            "object = \"2002h\"\nvalue = 1",
            "type",
            "is not in the Mitsubishi MR-J4-TM dictionary",
        ),
        (
            "object = \"2001h\"\nvalue = 1\ntype = \"f32\"",
            "type",
            "\"f32\" is no type",
        ),
        (
            "object = \"2001h\"\nvalue = 70000\ntype = \"u16\"",
            "value",
            "outside UNSIGNED16",
        ),
        (
            "object = \"2001h\"\nvalue = 1\nsize = 4",
            "",
            "unknown field `size`",
        ),
    ] {
        let e = parse(&format!("[[axes.ethercat.startup_sdo]]\n{entry}\n")).unwrap_err();
        assert!(
            e.contains(&format!("{key}.{field}")) || field.is_empty(),
            "{entry}: {e}"
        );
        assert!(e.contains(says), "{entry}: {e}");
    }
}

/// An in-process EtherCAT cell with one MR-J4-TM axis in pp (`mode_group = "profile"`) whose
/// emulated drive comes out of the box in the cyclic group (`sim.mode_group = "cyclic"`,
/// [Pr. PA01] = 1000h), with `list` as its start-up list.
fn pa01_cell(list: &str) -> CellConfig {
    let text = format!(
        r#"
[cell]
name = "pa01-{}"
cycle_time_us = 1000
[ethercat]
interface = "in-process"
[[axes]]
name = "x"
drive = "mr-j4-tm"
transport = "ethercat"
mode = "pp"
mode_group = "profile"
motor = {{ rated_speed = 3000 }}
unit = "mm"
counts_per_unit = 419430.4
limits = {{ position = [0.0, 500.0], velocity = 100.0, acceleration = 1000.0, jerk = 10000.0 }}
sim = {{ initial_position = 100.0, mode_group = "cyclic" }}
{list}
"#,
        std::process::id()
    );
    CellConfig::parse(Path::new("pa01.toml"), &text).unwrap_or_else(|e| panic!("{e}"))
}

/// Issue 32's case: [Pr. PA01] = 1002h in the start-up list takes the emulated MR-J4-TM to the
/// profile group before the PDO configuration, and the segment reaches OP with the drive in
/// pp (6061h = 1); without it the PDO configuration fails naming PA01 as the likely cause.
#[test]
fn pa01_in_the_start_up_list_brings_an_mr_j4_tm_up_in_profile_mode() {
    let cell = pa01_cell(
        r#"
[[axes.ethercat.startup_sdo]]
object = "2001h"
value = 0x1002
"#,
    );
    let mut bus = CellBus::open(&cell).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(bus.sdo_upload(0, 0x2001, 0), Ok(0x1002));
    assert_eq!(bus.sdo_upload(0, 0x6061, 0), Ok(1), "pp");
    bus.close().unwrap();
    // Out of the box the drive has no 1601h: the PDO configuration fails and says why.
    let Err(e) = CellBus::open(&pa01_cell("")) else {
        panic!("an MR-J4-TM in its cyclic group cannot run pp")
    };
    let e = e.to_string();
    for part in ["axis 'x'", "0x1601:0", "[Pr. PA01] last digit 2", "2001h"] {
        assert!(e.contains(part), "{part:?} in {e}");
    }
}
