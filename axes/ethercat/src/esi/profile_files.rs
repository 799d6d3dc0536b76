//! The ESI files of the emulated Mitsubishi models (configs/esi/*.xml) agree with their
//! profiles: identity, CiA 402 modes (6502h), default PDOs (changeable on every model:
//! `DriveProfile::with_pdo_maps`), the object dictionary (access, PDO mappability, defaults;
//! axis A's indexes on the multi-axis units) and the cycle. The files are written from the profiles by
//! [`render`]; `CELLRT_WRITE_ESI=1 cargo test -p cellrt-ethercat esi::profile_files` rewrites them
//! after a profile changes (review the diff).

use std::fmt::Write as _;
use std::path::PathBuf;

use super::device::{bits_of_modes, SUPPORTED_DRIVE_MODES};
use super::{load, EsiDevice};
use crate::identity::SubDeviceIdentity;
use cellrt_cia402::profiles::mapping::PdoDirection;
use cellrt_cia402::profiles::{profile, Access, DataType, DriveModel, DriveProfile, OdEntry, Pdo};

const MODELS: [DriveModel; 6] = [
    DriveModel::MrJ3T04,
    DriveModel::MrJ4TM,
    DriveModel::MrJetGN1,
    DriveModel::MrJ5GN1,
    DriveModel::MrJ5W2GN1,
    DriveModel::MrJ5W3GN1,
];

/// 6502h bits 0–15: the CiA 402 modes (16–31 are the manufacturer's).
const STANDARD_MODE_BITS: i64 = 0xFFFF;

fn file_of(model: DriveModel) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../configs/esi")
        .join(format!("{}.xml", model.as_str()))
}

fn esi_type(t: DataType) -> Option<(&'static str, u16)> {
    Some(match t {
        DataType::Bool => ("BOOL", 1),
        DataType::I8 => ("SINT", 8),
        DataType::I16 => ("INT", 16),
        DataType::I32 => ("DINT", 32),
        DataType::U8 => ("USINT", 8),
        DataType::U16 => ("UINT", 16),
        DataType::U32 => ("UDINT", 32),
        // No EtherCAT profile has a string object; unstated types have no ESI type.
        DataType::VisibleString { .. } | DataType::Unstated => return None,
    })
}

fn hex(v: i64) -> String {
    if v < 0 {
        v.to_string()
    } else {
        format!("#x{v:X}")
    }
}

fn xml_text(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// `Flags` of entry `o` of `p`: its access and where the profile lets it be mapped.
fn flags(p: &DriveProfile, o: &OdEntry) -> String {
    let access = match o.access {
        Access::Ro => "<Access>ro</Access>",
        Access::Rw => "<Access>rw</Access>",
        Access::Wo => "<Access>wo</Access>",
        Access::Unstated => "",
    };
    let rx = p.mappable(PdoDirection::Rx, o.index, o.sub);
    let tx = p.mappable(PdoDirection::Tx, o.index, o.sub);
    let map = match (rx, tx) {
        (true, true) => "<PdoMapping>RT</PdoMapping>",
        (true, false) => "<PdoMapping>R</PdoMapping>",
        (false, true) => "<PdoMapping>T</PdoMapping>",
        (false, false) => "",
    };
    format!("<Flags>{access}{map}</Flags>")
}

/// The objects of `p` an ESI can describe (a stated data type), sorted; 6502h lists the
/// unit's modes (the multi-axis MR-J5 units share the 1-axis table, whose 6502h also lists
/// pv and tq, which they cannot use: MR-J5-G-N1 manual §1.2, §6.1 *2).
fn described(p: &DriveProfile) -> Vec<OdEntry> {
    let parameters = p.parameters.table.iter().map(|r| &r.object);
    let mut v: Vec<OdEntry> = p
        .objects
        .iter()
        .chain(p.parameters.objects)
        .chain(parameters)
        .filter(|o| esi_type(o.data_type).is_some())
        .map(|o| match (o.index, o.sub) {
            // Bits 16–31 are the manufacturer's modes (CiA 402 §6.2.2): kept as the row has them.
            (SUPPORTED_DRIVE_MODES, 0) => OdEntry {
                default: Some(
                    o.default.unwrap_or(0) & !STANDARD_MODE_BITS | bits_of_modes(&p.cycle.modes),
                ),
                ..*o
            },
            _ => *o,
        })
        .collect();
    v.sort_by_key(|o| (o.index, o.sub));
    v.dedup_by_key(|o| (o.index, o.sub));
    v
}

/// `model`'s profile as an ESI document.
fn render(model: DriveModel) -> String {
    let p = profile(model);
    let id = SubDeviceIdentity::of_profile(p);
    let objs = described(p);
    let mut types = String::new();
    let mut objects = String::new();
    let mut i = 0;
    while i < objs.len() {
        let index = objs[i].index;
        let group: Vec<&OdEntry> = objs[i..].iter().take_while(|o| o.index == index).collect();
        i += group.len();
        if let [o] = group.as_slice() {
            if o.sub == 0 {
                let (t, bits) = esi_type(o.data_type).unwrap_or(("UDINT", 32));
                let def = o.default.map_or(String::new(), |d| {
                    format!("<Info><DefaultValue>{}</DefaultValue></Info>", hex(d))
                });
                let _ = writeln!(objects, "          <Object><Index>#x{index:04X}</Index><Name>{}</Name><Type>{t}</Type><BitSize>{bits}</BitSize>{def}{}</Object>", xml_text(o.name), flags(p, o));
                continue;
            }
        }
        let dt = format!("DT{index:04X}");
        let mut offs = 0u16;
        let _ = writeln!(
            types,
            "          <DataType><Name>{dt}</Name><BitSize>{}</BitSize>",
            group
                .iter()
                .map(|o| esi_type(o.data_type).map_or(0, |t| t.1))
                .sum::<u16>()
        );
        let mut info = String::new();
        for o in &group {
            let (t, bits) = esi_type(o.data_type).unwrap_or(("UDINT", 32));
            let name = format!("{} ({:02X}h)", xml_text(o.name), o.sub);
            let _ = writeln!(types, "            <SubItem><SubIdx>{}</SubIdx><Name>{name}</Name><Type>{t}</Type><BitSize>{bits}</BitSize><BitOffs>{offs}</BitOffs>{}</SubItem>", o.sub, flags(p, o));
            offs += bits;
            if let Some(d) = o.default {
                let _ = write!(info, "<SubItem><Name>{name}</Name><Info><DefaultValue>{}</DefaultValue></Info></SubItem>", hex(d));
            }
        }
        types.push_str("          </DataType>\n");
        let info = if info.is_empty() {
            info
        } else {
            format!("<Info>{info}</Info>")
        };
        let _ = writeln!(objects, "          <Object><Index>#x{index:04X}</Index><Name>{}</Name><Type>{dt}</Type><BitSize>{offs}</BitSize>{info}</Object>", xml_text(group[0].name));
    }
    let pdo = |kind: &str, map: &cellrt_cia402::pdo::PdoMap, sm: u8| {
        let mut s = format!("      <{kind} Fixed=\"0\" Mandatory=\"1\" Sm=\"{sm}\">\n        <Index>#x{:04X}</Index><Name>{kind} {:04X}h</Name>\n", map.index, map.index);
        for e in map.entries.iter() {
            let _ = writeln!(s, "        <Entry><Index>#x{:04X}</Index><SubIndex>{}</SubIndex><BitLen>{}</BitLen></Entry>", e.index, e.sub, e.bits);
        }
        let _ = writeln!(s, "      </{kind}>");
        s
    };
    let min_cycle_ns = p
        .cycle
        .cycle_times_us
        .iter()
        .min()
        .map_or(0, |us| u64::from(*us) * 1000);
    let assign_activate = crate::register::DC_ASSIGN_ACTIVATE_SYNC0;
    let sdo_info = p.comm.sdo_info.offered;
    format!(
        r##"<?xml version="1.0" encoding="UTF-8"?>
<!-- {name}: written by cellrt from its profile (axes/cia402/src/profiles), the facts of the manual;
     not Mitsubishi's ESI. Product codes the manual does not give are cellrt's placeholders.
     Checked against the profile by axes/ethercat/src/esi/profile_files.rs. -->
<EtherCATInfo Version="1.11">
  <Vendor><Id>#x{vendor:08X}</Id><Name>Mitsubishi Electric</Name></Vendor>
  <Descriptions>
    <Groups><Group><Type>Servo</Type><Name>Servo amplifiers</Name></Group></Groups>
    <Devices>
    <Device Physics="YY">
      <Type ProductCode="#x{product:08X}" RevisionNo="#x{revision:08X}">{model}</Type>
      <Name LcId="1033">{name}</Name>
      <GroupType>Servo</GroupType>
      <Profile>
        <ProfileNo>402</ProfileNo>
        <Dictionary>
        <DataTypes>
{types}        </DataTypes>
        <Objects>
{objects}        </Objects>
        </Dictionary>
      </Profile>
{rx}{tx}      <Mailbox DataLinkLayer="true"><CoE SdoInfo="{sdo_info}" PdoAssign="{assign}" PdoConfig="1"/></Mailbox>
      <Dc>
        <OpMode><Name>DC</Name><Desc>DC SYNC0, cycle {cycles}; 1C32h:05 minimum {min_cycle_ns} ns</Desc><AssignActivate>#x{assign_activate:04X}</AssignActivate><CycleTimeSync0 Factor="1">0</CycleTimeSync0></OpMode>
      </Dc>
    </Device>
    </Devices>
  </Descriptions>
</EtherCATInfo>
"##,
        name = xml_text(p.name),
        vendor = id.vendor_id,
        product = id.product_code,
        revision = id.revision,
        model = model.as_str(),
        rx = pdo("RxPdo", &p.pdo.rx, 2),
        tx = pdo("TxPdo", &p.pdo.tx, 3),
        assign =
            u8::from(p.pdo.rules.assignment != cellrt_cia402::profiles::PdoAssignment::ReadOnly),
        cycles = p.cycle_times_text(),
    )
}

fn check(model: DriveModel, d: &EsiDevice) {
    let p = profile(model);
    let id = SubDeviceIdentity::of_profile(p);
    let m = model.as_str();
    assert_eq!(
        (d.vendor_id, d.product_code, d.revision),
        (id.vendor_id, id.product_code, id.revision),
        "{m}"
    );
    assert!(d.offers(super::MailboxProtocol::CoE), "{m}");
    assert_eq!(d.rx_pdos[0].index, p.pdo.rx.index, "{m}");
    assert_eq!(d.rx_pdos[0].entries, p.pdo.rx.entries, "{m}");
    assert_eq!(d.tx_pdos[0].index, p.pdo.tx.index, "{m}");
    assert_eq!(d.tx_pdos[0].entries, p.pdo.tx.entries, "{m}");
    let mut want = p.cycle.modes.to_vec();
    want.sort_by_key(|m| m.as_i8());
    // A model whose manual gives no 6502h row (MR-J4-TM) has none in its ESI either.
    if let Some(mut got) = d.supported_modes() {
        got.sort_by_key(|m| m.as_i8());
        assert_eq!(got, want, "{m}: 6502h");
    } else {
        assert!(
            p.object(SUPPORTED_DRIVE_MODES, 0).is_none(),
            "{m}: 6502h missing"
        );
    }
    if !p.is_multi_axis() && p.object(SUPPORTED_DRIVE_MODES, 0).is_some() {
        let row = p.object(SUPPORTED_DRIVE_MODES, 0).and_then(|o| o.default);
        assert_eq!(
            row.map(|r| r & STANDARD_MODE_BITS),
            Some(bits_of_modes(&p.cycle.modes)),
            "{m}: the profile's 6502h row"
        );
    }
    for o in described(p) {
        let e = d
            .object(o.index, o.sub)
            .unwrap_or_else(|| panic!("{m}: {:04X}h:{:02X} missing", o.index, o.sub));
        assert_eq!(
            e.access, o.access,
            "{m}: {:04X}h:{:02X} access",
            o.index, o.sub
        );
        assert_eq!(
            e.default, o.default,
            "{m}: {:04X}h:{:02X} default",
            o.index, o.sub
        );
        assert_eq!(
            e.bits,
            esi_type(o.data_type).unwrap().1,
            "{m}: {:04X}h:{:02X}",
            o.index,
            o.sub
        );
        assert_eq!(
            (e.pdo.rx, e.pdo.tx),
            (
                p.mappable(PdoDirection::Rx, o.index, o.sub),
                p.mappable(PdoDirection::Tx, o.index, o.sub)
            ),
            "{m}: {:04X}h:{:02X} PdoMapping",
            o.index,
            o.sub
        );
        if o.pdo == Pdo::Rx {
            assert!(e.pdo.rx, "{m}: {:04X}h RxPDO object", o.index);
        }
    }
    assert_eq!(
        d.objects.len(),
        described(p).len(),
        "{m}: no objects besides the profile's"
    );
    let dc = &d.dc_opmodes[0];
    for us in p.cycle.cycle_times_us {
        assert!(dc.allows_cycle(us * 1000), "{m}: {us} µs");
    }
}

#[test]
fn the_mitsubishi_esi_files_agree_with_their_profiles() {
    let write = std::env::var_os("CELLRT_WRITE_ESI").is_some();
    for model in MODELS {
        let path = file_of(model);
        if write {
            std::fs::write(&path, render(model)).unwrap();
        }
        let devices = load(&path).unwrap_or_else(|e| panic!("{e} (CELLRT_WRITE_ESI=1 writes it)"));
        check(model, &devices[0]);
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            render(model),
            "{}: differs from the profile; CELLRT_WRITE_ESI=1 rewrites it",
            path.display()
        );
    }
}
