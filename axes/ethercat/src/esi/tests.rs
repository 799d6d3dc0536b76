//! The parser against the public vendor files (axes/ethercat/tests/data/esi, see its README) and
//! against malformed documents.

use super::*;
use cellrt_cia402::mode::ModeOfOperation as M;
use cellrt_cia402::pdo::PdoEntry;
use cellrt_cia402::profiles::Access;

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/esi")
        .join(name)
}

#[test]
fn microchip_samd51_file() {
    let devices = load(&data("microchip-samd51-ethercat-slave.xml")).unwrap();
    let [d] = devices.as_slice() else {
        panic!("one device")
    };
    assert_eq!(
        (d.vendor_id, d.product_code, d.revision),
        (0x4D8, 0x9252, 1)
    );
    assert_eq!(d.type_name, "SAMD51 EtherCAT Slave");
    assert_eq!(d.profile_no, Some(5001));
    assert_eq!(d.mailbox, vec![MailboxProtocol::CoE, MailboxProtocol::FoE]);
    let coe = d.coe.unwrap();
    assert!(coe.sdo_info && coe.complete_access && !coe.pdo_assign && !coe.pdo_config);
    let rx = &d.rx_pdos[0];
    assert_eq!(
        (rx.index, rx.fixed, rx.mandatory, rx.sm),
        (0x1601, true, true, Some(2))
    );
    assert_eq!(rx.entries, vec![PdoEntry::object(0x7010, 1, 32)]);
    assert_eq!(d.tx_pdos[0].entries, vec![PdoEntry::object(0x6000, 1, 32)]);
    // DefaultData is little-endian: "D8040000" = 0x4D8.
    assert_eq!(d.object(0x1018, 1).unwrap().default, Some(0x4D8));
    assert_eq!(d.object(0x1000, 0).unwrap().default, Some(0x1389));
    // 1C32h:02 is read-only in this file; its sub 1 rw only in PRE-OP.
    let ct = d.object(0x1C32, 2).unwrap();
    assert_eq!((ct.access, ct.default), (Access::Ro, None));
    let st = d.object(0x1C32, 1).unwrap();
    assert_eq!(st.access, Access::Rw);
    assert_eq!(st.write_restriction.as_deref(), Some("PreOP"));
    assert_eq!(d.object(0x1C32, 5).unwrap().default, Some(100_000));
    // Array sub-items expand to their elements; lower-case PdoMapping is read.
    assert_eq!(d.object(0x1C12, 1).unwrap().default, Some(0x1601));
    assert_eq!(d.object(0x1C00, 4).unwrap().default, Some(4));
    let trig = d.object(0x7010, 1).unwrap();
    assert!(trig.pdo.rx && !trig.pdo.tx && trig.writable());
    assert!(d.object(0x6000, 1).unwrap().pdo.tx);
    // DC: SM-synchronous (no SYNC0) or SYNC0 at the bus cycle.
    let modes: Vec<(&str, u32, bool)> = d
        .dc_opmodes
        .iter()
        .map(|m| (m.name.as_str(), m.assign_activate, m.uses_sync0()))
        .collect();
    assert_eq!(modes, vec![("Synchron", 0, false), ("DC", 0x300, true)]);
    assert!(d.dc_opmodes[1].allows_cycle(1_000_000));
    assert_eq!(d.supported_modes(), None, "not a drive: no 6502h");
}

#[test]
fn rt_labs_am335xice_file() {
    let devices = load(&data("rt-labs-am335xice.xml")).unwrap();
    let d = &devices[0];
    assert_eq!(
        (d.vendor_id, d.product_code, d.revision),
        (0x1337, 0x9876, 0)
    );
    assert_eq!(d.vendor_name, "rt-labs");
    assert_eq!(d.name, "slave");
    assert_eq!(d.mailbox, vec![MailboxProtocol::CoE]);
    assert!(d.dc_opmodes.is_empty());
    assert_eq!(d.object(0x1600, 1).unwrap().default, Some(0x7000_0020));
    assert_eq!(d.object(0x1C12, 1).unwrap().default, Some(0x1600));
    let led = d.object(0x7000, 0).unwrap();
    assert!(led.pdo.rx && led.access == Access::Ro);
    assert_eq!(d.rx_pdos[0].entries, vec![PdoEntry::object(0x7000, 0, 32)]);
    assert!(d.rx_pdos[0].fixed);
}

const MINIMAL: &str = r##"<?xml version="1.0"?>
<EtherCATInfo>
  <Vendor><Id>#x0A1E</Id><Name>V</Name></Vendor>
  <Descriptions><Devices>
    <Device>
      <Type ProductCode="#x201" RevisionNo="#x10">A</Type>
      <Name LcId="1031">A de</Name><Name LcId="1033">A en</Name>
    </Device>
    <Device>
      <Type ProductCode="#x201" RevisionNo="#x11">A</Type>
    </Device>
  </Devices></Descriptions>
</EtherCATInfo>"##;

#[test]
fn a_device_is_picked_by_revision_or_name() {
    let ds = parse(MINIMAL).unwrap();
    assert_eq!(ds[0].name, "A en");
    assert_eq!(ds[0].line, 5);
    let any = DeviceSelector::default();
    assert!(any
        .pick(&ds)
        .unwrap_err()
        .to_string()
        .contains("2 devices match"));
    let rev = DeviceSelector {
        revision: Some(0x11),
        ..Default::default()
    };
    assert_eq!(rev.pick(&ds).unwrap().revision, 0x11);
    let name = DeviceSelector {
        name: Some("A en".into()),
        ..Default::default()
    };
    assert_eq!(name.pick(&ds).unwrap().revision, 0x10);
    let none = DeviceSelector {
        product_code: Some(0x999),
        ..Default::default()
    };
    let e = none.pick(&ds).unwrap_err().to_string();
    assert!(
        e.contains("product code 0x999") && e.contains("revision 0x11"),
        "{e}"
    );
}

#[test]
fn supported_modes_come_from_6502h() {
    assert_eq!(
        device::modes_of_6502(0x3A0),
        vec![
            M::Homing,
            M::CyclicSyncPosition,
            M::CyclicSyncVelocity,
            M::CyclicSyncTorque
        ]
    );
    assert_eq!(
        device::modes_of_6502(0x0D),
        vec![M::ProfilePosition, M::ProfileVelocity, M::ProfileTorque]
    );
}

/// Parses `xml` and returns the error text.
fn error_of(xml: &str) -> String {
    parse(xml).unwrap_err().to_string()
}

#[test]
fn malformed_files_name_the_element_and_line() {
    assert!(error_of("<EtherCATInfo><Vendor>").starts_with("line 1: <XML>"));
    assert!(error_of("<Info/>").contains("root element must be <EtherCATInfo>"));
    let e = error_of("<EtherCATInfo>\n<Descriptions/></EtherCATInfo>");
    assert!(e.contains("<EtherCATInfo/Vendor>: missing"), "{e}");
    let bad_id = MINIMAL.replace("#x0A1E", "#xZZ");
    assert_eq!(
        error_of(&bad_id),
        "line 3: <Vendor/Id>: \"#xZZ\" is not a number (#x… hex or decimal)"
    );
    let bad_code = MINIMAL.replace(
        "ProductCode=\"#x201\" RevisionNo=\"#x10\"",
        "RevisionNo=\"#x10\"",
    );
    assert_eq!(
        error_of(&bad_code),
        "line 6: <Device/Type> attribute ProductCode: missing (required)"
    );
    let pdo = MINIMAL.replace(
        "<Name LcId=\"1031\">",
        "<RxPdo Fixed=\"maybe\"><Index>#x1600</Index></RxPdo><Name LcId=\"1031\">",
    );
    assert!(error_of(&pdo).contains("<Device/RxPdo> attribute Fixed: \"maybe\" is not a boolean"));
    let entry = MINIMAL.replace(
        "<Name LcId=\"1031\">",
        "<TxPdo><Index>#x1A00</Index><Entry><Index>#x6041</Index></Entry></TxPdo><Name LcId=\"1031\">",
    );
    assert!(error_of(&entry).contains("<Device/TxPdo/Entry/BitLen>: missing"));
    let access = MINIMAL.replace(
        "<Name LcId=\"1031\">",
        "<Profile><Dictionary><Objects><Object><Index>#x6040</Index><Type>UINT</Type><Flags><Access>rx</Access></Flags></Object></Objects></Dictionary></Profile><Name LcId=\"1031\">",
    );
    assert!(error_of(&access)
        .contains("<Dictionary/Objects/Object/Flags/Access>: \"rx\" is not an access right"));
    let big = MINIMAL.replace("#x0A1E", "#x100000000");
    assert!(error_of(&big).contains("<Vendor/Id>: 4294967296 is out of range"));
    let empty = "<EtherCATInfo><Vendor><Id>1</Id></Vendor><Descriptions><Devices/></Descriptions></EtherCATInfo>";
    assert!(error_of(empty).contains("holds no <Device>"));
}

#[test]
fn conformance_refuses_fixed_missing_and_mandatory_pdos_and_fixed_sync0_cycles() {
    use super::conform::{check, ConflictSubject, Intent};
    use cellrt_cia402::profiles::{profile, DriveModel};
    let p = profile(DriveModel::GenericCia402);
    let intent = Intent {
        profile: p,
        modes: &[M::CyclicSyncPosition],
        cycle_ns: 1_000_000,
        writes: &[],
    };
    // Microchip: RxPDO 1601h only; the generic 1600h does not exist there.
    let mc = load(&data("microchip-samd51-ethercat-slave.xml"))
        .unwrap()
        .remove(0);
    let e = check(&mc, &intent).unwrap_err();
    assert_eq!(e.subject, ConflictSubject::RxPdo);
    assert!(
        e.message.contains("the ESI has no such PDO (it has 1601h)"),
        "{}",
        e.message
    );
    // rt-labs: 1600h is fixed with 7000h:00.
    let rt = load(&data("rt-labs-am335xice.xml")).unwrap().remove(0);
    let e = check(&rt, &intent).unwrap_err();
    assert!(
        e.message
            .contains("1600h is fixed in the ESI (Fixed) with 7000h:00/32"),
        "{}",
        e.message
    );
    // A mandatory PDO the configuration leaves out, and a SYNC0 fixed at 2 ms.
    let mut d = rt.clone();
    d.rx_pdos[0].fixed = false;
    d.rx_pdos[0].entries = p.pdo.rx.entries.to_vec();
    d.objects.clear();
    d.rx_pdos.push(EsiPdo {
        index: 0x1601,
        mandatory: true,
        ..d.rx_pdos[0].clone()
    });
    let e = check(&d, &intent).unwrap_err();
    assert!(
        e.message.contains("makes RxPDO 1601h mandatory"),
        "{}",
        e.message
    );
    d.rx_pdos.pop();
    d.tx_pdos.clear();
    d.dc_opmodes.push(DcOpMode {
        name: "DC".into(),
        desc: String::new(),
        assign_activate: 0x300,
        sync0: Some(SyncCycle {
            ns: 2_000_000,
            factor: None,
        }),
        shift_sync0_ns: None,
        sync1: None,
    });
    let e = check(&d, &intent).unwrap_err();
    assert_eq!(e.subject, ConflictSubject::CycleTime);
    assert!(check(
        &d,
        &Intent {
            cycle_ns: 2_000_000,
            ..intent
        }
    )
    .is_ok());
}

#[test]
fn what_an_esi_fixes_of_the_pdo_configuration() {
    use super::conform::FixedPdo;
    // rt-labs: 1600h Fixed; the others as the file says.
    let rt = load(&data("rt-labs-am335xice.xml")).unwrap().remove(0);
    let fixed = FixedPdo::of(&rt, 0x1600, 0x1A00);
    assert!(fixed.rx_mapping);
    let mut d = rt.clone();
    d.rx_pdos[0].fixed = false;
    d.tx_pdos.iter_mut().for_each(|p| p.fixed = false);
    d.objects.clear();
    let coe = d.coe.unwrap();
    d.coe = Some(CoeDetails {
        pdo_config: true,
        pdo_assign: true,
        ..coe
    });
    assert_eq!(FixedPdo::of(&d, 0x1600, 0x1A00), FixedPdo::default());
    // CoE PdoConfig false fixes both mappings; PdoAssign false both assignments.
    d.coe = Some(CoeDetails {
        pdo_config: false,
        pdo_assign: false,
        ..coe
    });
    let all = FixedPdo::of(&d, 0x1600, 0x1A00);
    assert_eq!(
        all,
        FixedPdo {
            rx_mapping: true,
            tx_mapping: true,
            rx_assignment: true,
            tx_assignment: true
        }
    );
}
