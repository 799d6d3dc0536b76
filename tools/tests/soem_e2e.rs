//! An independent MainDevice brings the emulated drives up: SOEM (PyPI `pysoem`,
//! `tools/tests/python/soem_conformance.py`) against `cellrt drive-sim ethercat` over a veth
//! pair with the drives in a network namespace. Every model: the four single-axis Mitsubishi
//! drives, an MR-J5W2-G-N1 and an MR-J5W3-G-N1 station and the generic CiA 402 drive. SOEM scans,
//! reads the identities, maps the PDOs with its own `config_map`, configures DC SYNC0, reaches
//! OP, enables each axis in csp, moves it a known distance (checked in 6064h) and returns to
//! INIT. Before that, in PRE-OP, it walks each station's SDO Information (Get OD List, Object
//! and Entry Descriptions) and checks every entry the model's profile declares is listed with
//! its data type and access. Needs root (the namespace, raw sockets) and `$CELLRT_PYTHON` with pysoem (CI installs
//! it); says SKIPPED otherwise, and under CI a missing pysoem fails.

mod common;

use std::process::Command;

use cellrt_cia402::profiles::{profile, Access, DataType, DriveModel};
use cellrt_rt_tests::netns::VethNamespace;

/// The move of each axis, counts.
const DISTANCE: i64 = 2000;
/// The cycle SOEM runs and writes to 1C32h:02 (within every model's list: MR-J3-T04 §5.2
/// 0.5/1/2 ms, MR-J4-TM §1.6 up to 2 ms).
const CYCLE_US: u32 = 2000;

/// The stations, in line order (`drive-sim ethercat --drives`): every model the emulator
/// has ([`DriveModel::ALL`]: the single-axis Mitsubishi drives, an MR-J5W2-G-N1 and an
/// MR-J5W3-G-N1 unit, the generic CiA 402 drive, last).
const STATION_MODELS: &[DriveModel] = DriveModel::ALL;

/// Per station, every entry its model's profile declares, on each axis' index of the unit,
/// with the type and access the profile states (the script checks them against SDO
/// Information with its own CiA 301 codes).
fn declared_dictionaries() -> serde_json::Value {
    let stations: Vec<serde_json::Value> = STATION_MODELS
        .iter()
        .map(|&m| {
            let p = profile(m);
            let mut seen = std::collections::BTreeSet::new();
            let mut entries = Vec::new();
            for o in p.all_objects() {
                for slot in 0..p.axes_per_unit {
                    let Some(index) = p.axis_object(o.index, slot) else {
                        continue;
                    };
                    if !seen.insert((index, o.sub)) {
                        continue;
                    }
                    let data_type = match o.data_type {
                        DataType::Bool => "BOOL",
                        DataType::I8 => "I8",
                        DataType::I16 => "I16",
                        DataType::I32 => "I32",
                        DataType::U8 => "U8",
                        DataType::U16 => "U16",
                        DataType::U32 => "U32",
                        DataType::VisibleString { .. } => "STRING",
                        DataType::Unstated => "unstated",
                    };
                    let access = match o.access {
                        Access::Ro => "ro",
                        Access::Rw => "rw",
                        Access::Wo => "wo",
                        Access::Unstated => "unstated",
                    };
                    entries.push(serde_json::json!({
                        "index": index, "sub": o.sub, "type": data_type, "access": access,
                    }));
                }
            }
            serde_json::json!({ "model": p.name, "entries": entries })
        })
        .collect();
    serde_json::Value::Array(stations)
}

/// The Python with pysoem, or why there is none.
fn python() -> Result<String, String> {
    let python = std::env::var("CELLRT_PYTHON").unwrap_or_else(|_| "python3".into());
    let ok = Command::new(&python)
        .args(["-c", "import pysoem"])
        .output()
        .is_ok_and(|o| o.status.success());
    ok.then_some(python.clone())
        .ok_or(format!("{python} lacks pysoem (pip install pysoem)"))
}

#[test]
fn soem_maps_every_model_reaches_op_and_moves_each_axis() {
    if !nix::unistd::geteuid().is_root() {
        eprintln!("SKIPPED: the SOEM test needs root (a network namespace, raw sockets)");
        return;
    }
    let python = match python() {
        Ok(p) => p,
        Err(why) => {
            assert!(
                std::env::var_os("CI").is_none(),
                "CI must run the SOEM test: {why}"
            );
            eprintln!("SKIPPED: {why}");
            return;
        }
    };
    let ns = match VethNamespace::create(&format!("so{}", std::process::id() % 100_000)) {
        Ok(ns) => ns,
        Err(why) => {
            eprintln!("SKIPPED: {why}");
            return;
        }
    };
    run_soem(&python, &ns);
}

/// One run against a fresh drive-sim. The Python loop is no real-time master: drive-sim
/// excuses gaps in its frames as stalls of this machine (`--excuse-host-stalls`), so a drive
/// alarms only for what the script did wrong, not for when the machine let it run.
fn run_soem(python: &str, ns: &VethNamespace) {
    let dir = tempfile::tempdir().unwrap();
    let declared = dir.path().join("declared.json");
    std::fs::write(&declared, declared_dictionaries().to_string()).unwrap();
    // The emulator as a standalone target: the models listed, no cell configuration.
    let names: Vec<&str> = STATION_MODELS.iter().map(|m| m.as_str()).collect();
    let (list, cycle) = (names.join(","), CYCLE_US.to_string());
    let args = [
        "--drives",
        list.as_str(),
        "--cycle-time-us",
        cycle.as_str(),
        "--excuse-host-stalls",
    ];
    let args: Vec<&std::ffi::OsStr> = args.iter().map(std::ffi::OsStr::new).collect();
    let (mut drives, lines) = common::spawn_drive_sim_with(ns, &args);
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/python/soem_conformance.py"
    );
    let out = Command::new(python)
        .arg(script)
        .arg(&ns.near)
        .arg(CYCLE_US.to_string())
        .arg(DISTANCE.to_string())
        .arg(&declared)
        .output()
        .unwrap();
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(drives.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    )
    .unwrap();
    drives.wait().unwrap();
    let drive_sim: Vec<String> = lines.map_while(Result::ok).collect();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let report: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap_or_else(|e| {
        panic!(
            "no report ({e}): {stdout}\n{}\ndrive-sim: {drive_sim:?}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let alarms: Vec<&str> = drive_sim
        .iter()
        .flat_map(|l| l.split("alarm 0x").skip(1))
        .map(|a| a.get(..4).unwrap_or(a))
        .collect();
    assert!(
        alarms.is_empty() && report.get("error").is_none(),
        "drive alarms {alarms:?}: {report}\ndrive-sim: {drive_sim:?}"
    );
    assert!(
        out.status.success() && report.get("error").is_none(),
        "{report}\ndrive-sim: {drive_sim:?}"
    );
    // Seven stations: the J5W2 and J5W3 are one SubDevice each.
    assert_eq!(report["found"], 7, "{report}");
    let slaves = report["slaves"].as_array().unwrap();
    assert_eq!(
        slaves[0]["name"],
        profile(STATION_MODELS[0]).name,
        "{report}"
    );
    assert_eq!(
        STATION_MODELS.last(),
        Some(&DriveModel::GenericCia402),
        "the generic drive last"
    );
    assert!(
        slaves[..6].iter().all(|s| s["vendor"] == 0xA1E),
        "Mitsubishi's vendor ID 00000A1Eh in every SII: {report}"
    );
    assert_eq!(slaves[6]["vendor"], 0xCE11_0000u32, "{report}");
    // An upload of a missing object: SOEM reports the abort code 0602 0000h, not a packet
    // error (an abort framed as an SDO response reads as a data length).
    assert_eq!(
        report["missing_object"],
        serde_json::json!(vec![0x0602_0000u32; 7]),
        "{report}"
    );
    // SDO Information: every declared entry found with its type and access.
    let info = report["sdo_info"].as_array().unwrap();
    eprintln!("SDO Information as SOEM read it: {}", report["sdo_info"]);
    assert_eq!(info.len(), 7, "{report}");
    for (station, want) in info.iter().zip(declared_dictionaries().as_array().unwrap()) {
        assert_eq!(station["problems"], serde_json::json!([]), "{report}");
        assert_eq!(
            station["checked"].as_u64(),
            Some(want["entries"].as_array().unwrap().len() as u64),
            "{report}"
        );
        assert!(station["objects"].as_u64().unwrap() > 20, "{station}");
    }
    assert_eq!(report["dc"], true);
    assert_eq!(
        (&report["op"], &report["init"]),
        (&true.into(), &true.into())
    );
    let axes = report["axes"].as_array().unwrap();
    assert_eq!(
        axes.len(),
        4 + 2 + 3 + 1,
        "every axis of every station: {report}"
    );
    for a in axes {
        let moved = a["end"].as_i64().unwrap() - a["start"].as_i64().unwrap();
        assert!((moved - DISTANCE).abs() <= 1, "moved {moved}: {a}");
    }
    assert!(
        report["emergencies"].as_array().unwrap().is_empty(),
        "{report}"
    );
    // One line per station, each back in INIT without an alarm.
    let stations: Vec<&String> = drive_sim
        .iter()
        .filter(|l| l.contains("AL state"))
        .collect();
    assert_eq!(stations.len(), 7, "{drive_sim:?}");
    assert!(
        stations
            .iter()
            .all(|l| l.contains("AL state INIT") && !l.contains("alarm")),
        "every station back in INIT, no alarm: {drive_sim:?}"
    );
}
