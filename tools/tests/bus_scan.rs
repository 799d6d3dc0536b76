//! `cellrt bus scan` over a veth pair against `cellrt drive-sim ethercat` in a network
//! namespace (root only; skipped plainly otherwise): the example generic CiA 402 cell's two
//! SubDevices are listed with the configured identity, the SII name, INIT and no AL error,
//! CoE and DC, and the scan leaves them in INIT. Bad arguments exit 2.

mod common;

use cellrt_rt_tests::netns::VethNamespace;
use common::unique_cell_name;

fn cellrt() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_cellrt"))
}

#[test]
fn a_scan_lists_the_emulated_subdevices_without_configuring_them() {
    let ns = match VethNamespace::create(&format!("s{}", std::process::id() % 100_000)) {
        Ok(ns) => ns,
        Err(why) => {
            eprintln!("SKIPPED: bus scan over veth in a network namespace: {why}");
            return;
        }
    };
    let dir = tempfile::tempdir().unwrap();
    let configs = concat!(env!("CARGO_MANIFEST_DIR"), "/../configs");
    let text = std::fs::read_to_string(format!("{configs}/cia402-generic.toml"))
        .unwrap()
        .replace(
            "name = \"cia402-generic\"",
            &format!("name = \"{}\"", unique_cell_name()),
        );
    std::fs::copy(
        format!("{configs}/cia402-generic-program.toml"),
        dir.path().join("cia402-generic-program.toml"),
    )
    .unwrap();
    let cfg = dir.path().join("cell.toml");
    std::fs::write(&cfg, text).unwrap();
    let (mut drives, _lines) = common::spawn_drive_sim(&ns, &cfg);
    let out = cellrt()
        .args(["bus", "scan", "--interface", &ns.near])
        .output()
        .unwrap();
    let _ = nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(drives.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    );
    let _ = drives.wait();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<&str> = stdout.lines().collect();
    assert_eq!(
        rows[0],
        format!("2 SubDevice(s) on {}", ns.near),
        "{stdout}"
    );
    for (i, row) in rows[2..].iter().enumerate() {
        let identity = format!("{i:<4} 0xce110000 0xce110402");
        for part in [
            identity.as_str(),
            "generic CiA 402 drive",
            "INIT ",
            "0x0000 no error",
            "CoE",
        ] {
            assert!(row.contains(part), "{part:?} in {row}");
        }
        assert!(row.ends_with("yes"), "{row}");
    }
}

#[test]
fn a_scan_without_an_interface_is_bad_input() {
    let out = cellrt().args(["bus", "scan"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--interface"));
}
