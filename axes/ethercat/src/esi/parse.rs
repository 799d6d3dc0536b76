//! Reading an `EtherCATInfo` document (ETG.2000) into [`EsiDevice`]s.

use roxmltree::{Document, Node};

use super::device::{CoeDetails, DcOpMode, EsiDevice, EsiPdo, MailboxProtocol, SyncCycle};
use super::dictionary;
use super::error::EsiError;
use super::xml::{child, child_text, children, english_name, text, At};
use cellrt_cia402::pdo::PdoEntry;

/// Every `Descriptions/Devices/Device` of the ESI document `xml`.
pub fn devices(xml: &str) -> Result<Vec<EsiDevice>, EsiError> {
    let doc = Document::parse(xml).map_err(|e| EsiError {
        element: "XML".into(),
        attribute: None,
        line: Some(e.pos().row),
        message: e.to_string(),
    })?;
    let at = At { doc: &doc };
    let root = doc.root_element();
    if root.tag_name().name() != "EtherCATInfo" {
        return Err(at.err(
            root,
            root.tag_name().name(),
            "the root element must be <EtherCATInfo> (ETG.2000)",
        ));
    }
    let vendor = at.child(root, "EtherCATInfo", "Vendor")?;
    let vendor_id = at.child_number(vendor, "Vendor", "Id")?;
    let vendor_id = at.fit::<u32>(vendor, "Vendor/Id", vendor_id)?;
    let vendor_name = english_name(vendor);
    let list = at.child(
        at.child(root, "EtherCATInfo", "Descriptions")?,
        "Descriptions",
        "Devices",
    )?;
    let out = children(list, "Device")
        .map(|d| device(&at, d, vendor_id, &vendor_name))
        .collect::<Result<Vec<_>, _>>()?;
    if out.is_empty() {
        return Err(at.err(list, "Descriptions/Devices", "holds no <Device>"));
    }
    Ok(out)
}

fn device(
    at: &At<'_, '_>,
    d: Node<'_, '_>,
    vendor_id: u32,
    vendor_name: &str,
) -> Result<EsiDevice, EsiError> {
    let ty = at.child(d, "Device", "Type")?;
    let code = |attr: &str| -> Result<u32, EsiError> {
        let v = at.attr_number(ty, "Device/Type", attr)?.ok_or_else(|| {
            at.err(ty, "Device/Type", "missing (required)")
                .in_attribute(attr)
        })?;
        at.fit::<u32>(ty, "Device/Type", v)
            .map_err(|e| e.in_attribute(attr))
    };
    let product_code = code("ProductCode")?;
    // RevisionNo is optional in ETG.2000; absent means 0.
    let revision = match ty.attribute("RevisionNo") {
        None => 0,
        Some(_) => code("RevisionNo")?,
    };
    let (mailbox, coe) = mailbox(at, d)?;
    let profile_no = children(d, "Profile")
        .filter_map(|p| child(p, "ProfileNo"))
        .map(|n| at.number(n, "Profile/ProfileNo"))
        .next()
        .transpose()?
        .map(|n| n as u32);
    Ok(EsiDevice {
        vendor_id,
        vendor_name: vendor_name.to_owned(),
        product_code,
        revision,
        type_name: text(ty),
        name: english_name(d),
        profile_no,
        mailbox,
        coe,
        rx_pdos: pdos(at, d, "RxPdo")?,
        tx_pdos: pdos(at, d, "TxPdo")?,
        objects: dictionary::objects(at, d)?,
        dc_opmodes: dc(at, d)?,
        line: at.line(d),
    })
}

fn mailbox(
    at: &At<'_, '_>,
    d: Node<'_, '_>,
) -> Result<(Vec<MailboxProtocol>, Option<CoeDetails>), EsiError> {
    let Some(mb) = child(d, "Mailbox") else {
        return Ok((Vec::new(), None));
    };
    let protocols = MailboxProtocol::ALL
        .iter()
        .filter(|(name, _)| child(mb, name).is_some())
        .map(|&(_, p)| p)
        .collect();
    let coe = match child(mb, "CoE") {
        None => None,
        Some(c) => {
            let b = |attr| at.attr_bool(c, "Mailbox/CoE", attr, false);
            Some(CoeDetails {
                sdo_info: b("SdoInfo")?,
                pdo_assign: b("PdoAssign")?,
                pdo_config: b("PdoConfig")?,
                complete_access: b("CompleteAccess")?,
            })
        }
    };
    Ok((protocols, coe))
}

fn pdos(at: &At<'_, '_>, d: Node<'_, '_>, kind: &str) -> Result<Vec<EsiPdo>, EsiError> {
    let path = format!("Device/{kind}");
    children(d, kind)
        .map(|p| {
            let index = at.child_number(p, &path, "Index")?;
            let index = at.fit::<u16>(p, &format!("{path}/Index"), index)?;
            let sm = at
                .attr_number(p, &path, "Sm")?
                .map(|s| at.fit::<u8>(p, &path, s).map_err(|e| e.in_attribute("Sm")))
                .transpose()?;
            let entry_path = format!("{path}/Entry");
            let entries = children(p, "Entry")
                .map(|e| {
                    let idx = at.child_number(e, &entry_path, "Index")?;
                    let idx = at.fit::<u16>(e, &format!("{entry_path}/Index"), idx)?;
                    let sub = at
                        .opt_child_number(e, &entry_path, "SubIndex")?
                        .unwrap_or(0);
                    let sub = at.fit::<u8>(e, &format!("{entry_path}/SubIndex"), sub)?;
                    let bits = at.child_number(e, &entry_path, "BitLen")?;
                    let bits = at.fit::<u16>(e, &format!("{entry_path}/BitLen"), bits)?;
                    Ok(if idx == 0 {
                        PdoEntry::padding(bits)
                    } else {
                        PdoEntry::object(idx, sub, bits)
                    })
                })
                .collect::<Result<Vec<_>, EsiError>>()?;
            let excludes = children(p, "Exclude")
                .map(|x| {
                    at.number(x, &format!("{path}/Exclude"))
                        .and_then(|v| at.fit::<u16>(x, &format!("{path}/Exclude"), v))
                })
                .collect::<Result<Vec<_>, _>>()?;
            Ok(EsiPdo {
                index,
                name: child_text(p, "Name"),
                fixed: at.attr_bool(p, &path, "Fixed", false)?,
                mandatory: at.attr_bool(p, &path, "Mandatory", false)?,
                sm,
                entries,
                excludes,
            })
        })
        .collect()
}

fn dc(at: &At<'_, '_>, d: Node<'_, '_>) -> Result<Vec<DcOpMode>, EsiError> {
    let Some(dc) = child(d, "Dc") else {
        return Ok(Vec::new());
    };
    const PATH: &str = "Dc/OpMode";
    children(dc, "OpMode")
        .map(|m| {
            let aa = at.child_number(m, PATH, "AssignActivate")?;
            let cycle = |name: &str| -> Result<Option<SyncCycle>, EsiError> {
                let Some(c) = child(m, name) else {
                    return Ok(None);
                };
                let p = format!("{PATH}/{name}");
                let ns = at.number(c, &p)?;
                let factor = at
                    .attr_number(c, &p, "Factor")?
                    .map(|f| {
                        at.fit::<i32>(c, &p, f)
                            .map_err(|e| e.in_attribute("Factor"))
                    })
                    .transpose()?;
                Ok(Some(SyncCycle {
                    ns: at.fit::<u32>(c, &p, ns)?,
                    factor,
                }))
            };
            Ok(DcOpMode {
                name: child_text(m, "Name"),
                desc: child_text(m, "Desc"),
                assign_activate: at.fit::<u32>(m, &format!("{PATH}/AssignActivate"), aa)?,
                sync0: cycle("CycleTimeSync0")?,
                shift_sync0_ns: at.opt_child_number(m, PATH, "ShiftTimeSync0")?,
                sync1: cycle("CycleTimeSync1")?,
            })
        })
        .collect()
}
