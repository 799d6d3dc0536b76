//! `esi`: a generic CiA 402 axis described by an ESI file (configs/esi/cia402-example.xml),
//! and what that file forbids, refused with the key to change.

use std::path::Path;

use super::*;
use cellrt_cia402::mode::ModeOfOperation as M;

fn text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/cia402-esi.toml"
    ))
    .expect("configs/cia402-esi.toml")
}

fn parse(text: &str) -> Result<CellConfig, ConfigError> {
    CellConfig::parse(
        Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../configs/cia402-esi.toml"
        )),
        text,
    )
}

fn refused(text: &str) -> ConfigError {
    parse(text).expect_err("refused")
}

#[test]
fn the_esi_gives_identity_and_modes() {
    let c = parse(&text()).unwrap();
    let a = &c.axes.on_loop()[0];
    let esi = a.esi.as_ref().expect("esi");
    assert_eq!(esi.type_name, "EX-402");
    assert_eq!(a.ethercat_identity.vendor_id, 0xCE11_0000);
    assert_eq!(a.ethercat_identity.product_code, Some(0xCE11_0403));
    assert_eq!(a.profile.identity.revision, Some(0x0001_0000));
    assert_eq!(
        *a.profile.cycle.modes,
        [M::Homing, M::CyclicSyncPosition, M::CyclicSyncVelocity]
    );
}

#[test]
fn what_the_esi_forbids_is_refused_with_its_key() {
    // A mode the drive lacks (6502h: hm, csp, csv).
    let cst = text()
        .replace("mode = \"csp\"", "mode = \"cst\"")
        .replace("0x60FF0020]", "0x60FF0020, 0x60710010]")
        .replace("jerk = 20000.0 }", "jerk = 20000.0, torque = 100.0 }");
    let e = refused(&cst);
    assert_eq!(e.key, "axes[0].mode", "{e}");
    assert!(
        e.message
            .contains("has no mode cst (allowed: hm, csp, csv)"),
        "{e}"
    );
    // The default TxPDO maps 60F4h, which the drive does not have.
    let no_tx = text().replace(", tx = [0x60410010, 0x60610008, 0x00000008, 0x60640020, 0x606C0020, 0x60770010, 0x603F0010]", "");
    let e = refused(&no_tx);
    assert_eq!(e.key, "axes[0].pdo.tx", "{e}");
    assert!(e.message.contains("60F4h:00"), "{e}");
    // An object CiA 402 lets the RxPDO carry, which this drive does not: 607Ch (SDO only).
    let e = refused(&text().replace("0x607A0020, 0x60FF0020]", "0x607A0020, 0x607C0020]"));
    assert_eq!(e.key, "axes[0].pdo.rx", "{e}");
    assert!(
        e.message.contains(
            "607Ch:00 (Home offset); the ESI marks it not mappable into the RxPDO (PdoMapping none)"
        ),
        "{e}"
    );
    // Below 1C32h:05 (250 µs).
    let e = refused(&text().replace("cycle_time_us = 1000", "cycle_time_us = 125"));
    assert_eq!(e.key, "cell.cycle_time_us", "{e}");
    assert!(
        e.message
            .contains("minimum cycle time (1C32h:05 = 250000 ns)"),
        "{e}"
    );
    // 6060h written in PRE-OP when the RxPDO does not carry it: it must be writable.
    assert!(parse(&text().replace(
        "0x60400010, 0x60600008, 0x00000008, 0x607A0020, 0x60FF0020]",
        "0x60400010, 0x607A0020]"
    ))
    .is_ok());
}

#[test]
fn a_bad_esi_or_device_choice_names_the_key() {
    let e = refused(&text().replace("esi/cia402-example.xml", "esi/missing.xml"));
    assert_eq!(e.key, "axes[0].esi", "{e}");
    let e = refused(&text().replace(
        "esi = \"esi/cia402-example.xml\"",
        "esi = \"esi/cia402-example.xml\"\nesi_revision = 2",
    ));
    assert_eq!(e.key, "axes[0].esi", "{e}");
    assert!(
        e.message
            .contains("no device of the file matches revision 0x2"),
        "{e}"
    );
    let e = refused(&text().replace(
        "esi = \"esi/cia402-example.xml\"",
        "esi_device = \"EX-402\"",
    ));
    assert_eq!(e.key, "axes[0].esi_device", "{e}");
    let e = refused(&text().replace(
        "esi = \"esi/cia402-example.xml\"",
        "esi = \"esi/cia402-example.xml\"\nethercat = { vendor_id = 2 }",
    ));
    assert_eq!(e.key, "axes[0].ethercat.vendor_id", "{e}");
    let e = refused(&text().replace("drive = \"cia402\"", "drive = \"mr-j4-tm\""));
    assert_eq!(e.key, "axes[0].esi", "{e}");
    // A malformed file: the element and line of the fault.
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.xml");
    std::fs::write(
        &bad,
        "<EtherCATInfo>\n<Vendor><Id>#xQ</Id></Vendor></EtherCATInfo>",
    )
    .unwrap();
    let e = refused(&text().replace("esi/cia402-example.xml", bad.to_str().unwrap()));
    assert_eq!(e.key, "axes[0].esi", "{e}");
    assert!(e.message.contains("line 2: <Vendor/Id>"), "{e}");
}
