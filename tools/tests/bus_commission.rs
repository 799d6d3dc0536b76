//! `cellrt bus sdo|pdos|states|sii` against `cellrt drive-sim ethercat` over a veth pair, with
//! no cell running (root only: a network namespace; skipped plainly otherwise): SDO upload and
//! download in PRE-OP, the PDO assignment the emulated drives hold, AL state requests per
//! SubDevice, the SII EEPROM, and the refusal while something else holds the interface.

mod common;

use std::process::{Command, Output};

use cellrt_cia402::profiles::{profile, DriveModel};
use cellrt_ethercat::identity::SubDeviceIdentity;
use cellrt_rt_tests::netns::VethNamespace;
use cellrt_runtime::host::cell_lock::InterfaceLock;

fn cellrt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(args)
        .output()
        .unwrap()
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

fn json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", text(out));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// An MR-J4-TM at position 0 and a generic CiA 402 drive at 1, served by drive-sim in a
/// namespace; `None` (said plainly) where no namespace can be made.
fn segment(tag: &str) -> Option<(VethNamespace, Sim)> {
    let ns = match VethNamespace::create(&format!("{tag}{}", std::process::id() % 100_000)) {
        Ok(ns) => ns,
        Err(why) => {
            eprintln!("SKIPPED: cellrt bus commissioning over veth in a network namespace: {why}");
            return None;
        }
    };
    let sim = common::spawn_drive_sim_with(&ns, &["--drives".as_ref(), "mr-j4-tm,cia402".as_ref()]);
    Some((ns, sim))
}

/// drive-sim and its stderr (kept open: it logs until it stops).
type Sim = (
    std::process::Child,
    std::io::Lines<std::io::BufReader<std::process::ChildStderr>>,
);

fn stop((mut sim, _lines): Sim) {
    let _ = nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(sim.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    );
    let status = sim.wait().unwrap();
    assert!(status.success(), "drive-sim exit: {status}");
}

#[test]
fn sdo_upload_and_download_in_pre_op_without_a_cell() {
    let Some((ns, sim)) = segment("bs") else {
        return;
    };
    let iface = ns.near.as_str();
    let j4 = SubDeviceIdentity::of_profile(profile(DriveModel::MrJ4TM));
    // 1018h:01 and :02, typed by the drive's SDO Information.
    for (object, value) in [("1018:1", j4.vendor_id), ("1018:2", j4.product_code)] {
        let doc = json(&cellrt(&[
            "bus",
            "sdo",
            "read",
            "--interface",
            iface,
            "-p",
            "0",
            object,
            "--json",
        ]));
        assert_eq!(doc["value"], u64::from(value), "{doc}");
        assert_eq!(doc["type"], "UNSIGNED32", "{doc}");
        assert!(
            doc["type_from"]
                .as_str()
                .unwrap()
                .starts_with("SDO Information"),
            "{doc}"
        );
    }
    // 6085h (quick stop deceleration, UNSIGNED32) written and read back.
    let out = cellrt(&[
        "bus",
        "sdo",
        "write",
        "--interface",
        iface,
        "-p",
        "0",
        "6085:0",
        "400",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let doc = json(&cellrt(&[
        "bus",
        "sdo",
        "read",
        "--interface",
        iface,
        "-p",
        "0",
        "6085",
        "--json",
    ]));
    assert_eq!(doc["value"], 400, "{doc}");
    let plain = cellrt(&["bus", "sdo", "read", "--interface", iface, "6085"]);
    assert!(
        text(&plain).contains("6085h:00 = 400 (0x00000190) UNSIGNED32"),
        "{}",
        text(&plain)
    );
    // Refused before sending: outside the type; refused by the drive: no such object.
    let out = cellrt(&[
        "bus",
        "sdo",
        "write",
        "--interface",
        iface,
        "-p",
        "0",
        "6085:0",
        "-1",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("outside UNSIGNED32"), "{}", text(&out));
    let out = cellrt(&[
        "bus",
        "sdo",
        "read",
        "--interface",
        iface,
        "-p",
        "0",
        "5FFF",
    ]);
    assert_eq!(out.status.code(), Some(3), "{}", text(&out));
    assert!(text(&out).contains("0x06020000"), "{}", text(&out));
    let out = cellrt(&[
        "bus",
        "sdo",
        "read",
        "--interface",
        iface,
        "-p",
        "7",
        "1000",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("--position 7"), "{}", text(&out));
    stop(sim);
}

#[test]
fn pdo_assignment_states_and_sii_without_a_cell() {
    let Some((ns, sim)) = segment("bp") else {
        return;
    };
    let iface = ns.near.as_str();
    // The MR-J4-TM's default maps, word for word, with the profile's names.
    let doc = json(&cellrt(&[
        "bus",
        "pdos",
        "--interface",
        iface,
        "-p",
        "0",
        "--json",
    ]));
    let j4 = profile(DriveModel::MrJ4TM);
    for (side, map) in [("rx", &j4.pdo.rx), ("tx", &j4.pdo.tx)] {
        let pdos = doc["subdevices"][0][side].as_array().unwrap();
        assert_eq!(pdos.len(), 1, "{doc}");
        assert_eq!(pdos[0]["index"], map.index, "{doc}");
        let words: Vec<u64> = pdos[0]["entries"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| {
                e["index"].as_u64().unwrap() << 16
                    | e["sub"].as_u64().unwrap() << 8
                    | e["bits"].as_u64().unwrap()
            })
            .collect();
        let expected: Vec<u64> = map
            .entries
            .iter()
            .map(|e| u64::from(e.mapping_word()))
            .collect();
        assert_eq!(words, expected, "{side}: {doc}");
    }
    let first = j4.pdo.rx.entries[0];
    assert_eq!(
        doc["subdevices"][0]["rx"][0]["entries"][0]["name"],
        j4.object(first.index, first.sub).unwrap().name,
        "{doc}"
    );
    // States: all in PRE-OP after the session; INIT asked of SubDevice 1 alone.
    let doc = json(&cellrt(&[
        "bus",
        "states",
        "--interface",
        iface,
        "-p",
        "1",
        "--state",
        "init",
        "--json",
    ]));
    let states: Vec<&str> = doc["subdevices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["al_state"].as_str().unwrap())
        .collect();
    assert_eq!(states, ["PRE-OP", "INIT"], "{doc}");
    assert_eq!(doc["subdevices"][1]["reached"], true, "{doc}");
    // PRE-OP → OP is no transition (ETG.1000.6): refused with 0011h, exit 3.
    let out = cellrt(&[
        "bus",
        "states",
        "--interface",
        iface,
        "-p",
        "0",
        "--state",
        "op",
    ]);
    assert_eq!(out.status.code(), Some(3), "{}", text(&out));
    let t = text(&out);
    assert!(t.contains("PRE-OP+ERROR AL status code 0x0011"), "{t}");
    assert!(t.contains("(requested OP: not reached)"), "{t}");
    // SII words 08h–0Bh: vendor ID and product code, low word first (ETG.2010 Table 2).
    let out = cellrt(&[
        "bus",
        "sii",
        "read",
        "--interface",
        iface,
        "-p",
        "0",
        "--word",
        "8",
        "--words",
        "4",
    ]);
    let id = SubDeviceIdentity::of_profile(j4);
    let line = format!(
        "0008: {:04x} {:04x} {:04x} {:04x}",
        id.vendor_id & 0xFFFF,
        id.vendor_id >> 16,
        id.product_code & 0xFFFF,
        id.product_code >> 16
    );
    assert_eq!(text(&out).trim(), line, "{}", text(&out));
    let out = cellrt(&[
        "bus",
        "sii",
        "read",
        "--interface",
        iface,
        "--word",
        "0xfff0",
        "--words",
        "32",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    // While another holder has the interface (a cell, another bus command): exit 3, naming it.
    let held = InterfaceLock::acquire(iface).unwrap();
    let out = cellrt(&["bus", "pdos", "--interface", iface]);
    assert_eq!(out.status.code(), Some(3), "{}", text(&out));
    assert!(
        text(&out).contains(&format!("is in use by process {}", std::process::id())),
        "{}",
        text(&out)
    );
    drop(held);
    stop(sim);
}
