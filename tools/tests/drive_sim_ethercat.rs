//! `cellrt drive-sim ethercat` without a cell configuration: `--drives` and `--esi` list the
//! SubDevices. Refusals of the command line (no root needed) exit 2 with one line naming the
//! problem; over a veth pair with the emulator in a network namespace (root only; skipped
//! plainly otherwise) `cellrt bus scan` finds the listed SubDevices with their identities.

mod common;

use std::ffi::OsStr;
use std::process::Command;

use cellrt_cia402::profiles::{profile, DriveModel};
use cellrt_ethercat::identity::SubDeviceIdentity;
use cellrt_rt_tests::netns::VethNamespace;

const CONFIGS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs");

fn cellrt(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(args)
        .output()
        .unwrap()
}

/// Runs `cellrt` with `args`, expects exit 2 and returns its stderr, which must be one line.
fn refused(args: &[&str]) -> String {
    let out = cellrt(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.starts_with("error: "), "{err}");
    err
}

/// [`refused`] for `cellrt drive-sim ethercat --interface nonexistent0` and `args`.
fn refused_listing(args: &[&str]) -> String {
    let mut all = vec!["drive-sim", "ethercat", "--interface", "nonexistent0"];
    all.extend(args);
    refused(&all)
}

#[test]
fn an_unknown_model_is_refused_naming_it_and_the_supported_ones() {
    let err = refused_listing(&["--drives", "mr-j4-tm,mr-j9-g"]);
    assert!(err.contains("\"mr-j9-g\""), "{err}");
    for m in DriveModel::ALL {
        assert!(err.contains(m.as_str()), "{m} listed: {err}");
    }
}

#[test]
fn an_empty_model_list_is_refused() {
    for drives in [&["--drives", ""][..], &["--drives"], &["--drives", ","]] {
        let err = refused_listing(drives);
        assert!(err.contains("--drives: no drive model given"), "{err}");
        assert!(err.contains("mr-j5w2-g-n1"), "{err}");
    }
}

#[test]
fn a_configuration_with_drives_or_esi_is_refused_as_a_conflict() {
    let cfg = format!("{CONFIGS}/ethercat-cell.toml");
    let esi = format!("{CONFIGS}/esi/cia402-example.xml");
    for args in [
        vec!["--config", &cfg, "--drives", "mr-j4-tm"],
        vec!["--config", &cfg, "--esi", &esi],
        vec!["--cell", &cfg, "--drives", "mr-j4-tm"],
    ] {
        let err = refused_listing(&args);
        assert!(err.contains("ethercat-cell.toml"), "{err}");
        assert!(err.contains("--drives/--esi, not both"), "{err}");
    }
    // The global --cell before the subcommand is the same configuration file.
    let err = refused(&[
        "--cell",
        &cfg,
        "drive-sim",
        "ethercat",
        "--interface",
        "nonexistent0",
        "--drives",
        "cia402",
    ]);
    assert!(err.contains("not both"), "{err}");
    let err = refused_listing(&["--config", &cfg, "--cell", &cfg]);
    assert!(err.contains("--config and --cell"), "{err}");
    let err = refused_listing(&["--config", &cfg, "--cycle-time-us", "2000"]);
    assert!(err.contains("--cycle-time-us"), "{err}");
}

#[test]
fn a_missing_interface_or_nothing_to_emulate_is_refused() {
    let err = refused(&["drive-sim", "ethercat", "--drives", "mr-j4-tm"]);
    assert!(err.contains("--interface IF"), "{err}");
    let err = refused_listing(&[]);
    assert!(
        err.contains("no drives to emulate") && err.contains("--config FILE"),
        "{err}"
    );
}

#[test]
fn the_configuration_file_is_read_from_config_and_from_the_older_cell() {
    for args in [
        &["drive-sim", "ethercat", "--config", "missing.toml"][..],
        &["drive-sim", "ethercat", "--cell", "missing.toml"],
        &["--cell", "missing.toml", "drive-sim", "ethercat"],
    ] {
        let mut all = args.to_vec();
        all.extend(["--interface", "nonexistent0"]);
        let err = refused(&all);
        assert!(err.contains("missing.toml"), "{err}");
    }
}

#[test]
fn a_model_that_does_not_run_the_cycle_or_a_bad_esi_file_is_refused_naming_it() {
    let err = refused_listing(&["--drives", "cia402,mr-j5w2-g-n1", "--cycle-time-us", "125"]);
    assert!(
        err.contains("mr-j5w2-g-n1") && err.contains("125 µs"),
        "{err}"
    );
    let err = refused_listing(&["--esi", "missing.xml"]);
    assert!(err.contains("--esi missing.xml"), "{err}");
    let j4 = format!("{CONFIGS}/esi/mr-j4-tm.xml");
    let err = refused_listing(&["--esi", &j4]);
    assert!(err.contains("use --drives mr-j4-tm"), "{err}");
}

#[test]
fn the_help_says_a_configuration_file_or_the_listed_drives_are_taken() {
    let out = cellrt(&["drive-sim", "ethercat", "--help"]);
    assert!(out.status.success());
    let help = String::from_utf8_lossy(&out.stdout);
    for part in [
        "--config <FILE>",
        "The cell configuration file (TOML)",
        "--cell <FILE>",
        "--drives [<MODEL,..>]",
        "--esi <FILE>",
        "--cycle-time-us <US>",
        "mr-j5w3-g-n1",
    ] {
        assert!(help.contains(part), "{part:?} in {help}");
    }
    assert!(!help.contains("the only running cell"), "{help}");
    let parent = cellrt(&["drive-sim", "--help"]);
    let help = String::from_utf8_lossy(&parent.stdout);
    assert!(!help.contains("the only running cell"), "{help}");
}

/// The bus scan's identity columns of a SubDevice at `position`.
fn identity_columns(position: usize, id: SubDeviceIdentity) -> String {
    format!(
        "{position:<4} {:#010x} {:#010x}",
        id.vendor_id, id.product_code
    )
}

/// Runs drive-sim with `drives` in a namespace and returns `cellrt bus scan`'s lines, or
/// `None` (said plainly) where no namespace can be made.
fn scan(tag: &str, drives: &[&OsStr]) -> Option<Vec<String>> {
    let ns = match VethNamespace::create(&format!("{tag}{}", std::process::id() % 100_000)) {
        Ok(ns) => ns,
        Err(why) => {
            eprintln!("SKIPPED: drive-sim --drives over veth in a network namespace: {why}");
            return None;
        }
    };
    let (mut sim, _lines) = common::spawn_drive_sim_with(&ns, drives);
    let out = cellrt(&["bus", "scan", "--interface", &ns.near]);
    let json = cellrt(&["bus", "scan", "--interface", &ns.near, "--json"]);
    let _ = nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(sim.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    );
    let status = sim.wait().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(status.success(), "drive-sim exit: {status}");
    // The same scan as JSON: one SubDevice per table row, each field apart.
    assert!(
        json.status.success(),
        "{}",
        String::from_utf8_lossy(&json.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let rows: Vec<String> = stdout.lines().map(str::to_owned).collect();
    let subdevices = doc["subdevices"].as_array().unwrap();
    assert_eq!(subdevices.len() + 2, rows.len(), "{doc}\n{stdout}");
    for (k, d) in subdevices.iter().enumerate() {
        assert_eq!(d["position"], k, "{doc}");
        let vendor = format!("{:#010x}", d["vendor_id"].as_u64().unwrap());
        assert!(rows[2 + k].contains(&vendor), "{doc}\n{stdout}");
        assert_eq!(d["al_state"], "INIT", "{doc}");
        assert!(
            d["mailbox"].as_array().unwrap().contains(&"CoE".into()),
            "{doc}"
        );
    }
    Some(rows)
}

#[test]
fn listed_drives_are_found_by_a_bus_scan_with_their_identities() {
    let Some(rows) = scan(
        "d",
        &["--drives".as_ref(), "mr-j4-tm,mr-j5w2-g-n1,cia402".as_ref()],
    ) else {
        return;
    };
    let all = rows.join("\n");
    assert!(rows[0].starts_with("3 SubDevice(s) on "), "{all}");
    let expected = [
        SubDeviceIdentity::of_profile(profile(DriveModel::MrJ4TM)),
        SubDeviceIdentity::of_profile(profile(DriveModel::MrJ5W2GN1)),
        SubDeviceIdentity {
            vendor_id: 0xCE11_0000,
            product_code: 0xCE11_0402,
            revision: 0,
            serial: 0,
        },
    ];
    for (i, id) in expected.into_iter().enumerate() {
        assert!(
            rows[2 + i].starts_with(&identity_columns(i, id)),
            "SubDevice {i}: {all}"
        );
        assert!(rows[2 + i].contains("INIT "), "{all}");
    }
}

#[test]
fn esi_devices_follow_the_listed_drives() {
    let esi = format!("{CONFIGS}/esi/cia402-example.xml");
    let Some(rows) = scan(
        "e",
        &[
            "--drives".as_ref(),
            "mr-jet-g-n1".as_ref(),
            "--esi".as_ref(),
            esi.as_ref(),
        ],
    ) else {
        return;
    };
    let all = rows.join("\n");
    assert!(rows[0].starts_with("2 SubDevice(s) on "), "{all}");
    let jet = SubDeviceIdentity::of_profile(profile(DriveModel::MrJetGN1));
    assert!(rows[2].starts_with(&identity_columns(0, jet)), "{all}");
    // configs/esi/cia402-example.xml: vendor CE110000h, product CE110403h, revision 10000h.
    assert!(
        rows[3].starts_with("1    0xce110000 0xce110403 0x00010000"),
        "{all}"
    );
}
