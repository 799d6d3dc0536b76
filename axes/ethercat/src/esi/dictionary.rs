//! `Profile/Dictionary`: the data types and objects of a device, flattened to one
//! [`EsiObject`] per sub-index with its access right, PDO mappability and default.

use std::collections::HashMap;

use roxmltree::Node;

use super::device::{EsiObject, PdoMappable};
use super::error::EsiError;
use super::number::{hex_dec, le_hex_bytes};
use super::xml::{child, child_text, children, text, At};
use cellrt_cia402::profiles::Access;

/// A `DataType` of the dictionary: its size and, for records and arrays, its sub-items.
struct DataTypeDef<'a, 'input> {
    bits: u16,
    sub_items: Vec<Node<'a, 'input>>,
    /// `ArrayInfo` (LBound, Elements) of an array type.
    array: Option<(u8, u8)>,
}

/// `Flags` of an object or sub-item: access, its write restriction, PDO mapping.
#[derive(Clone)]
struct Flags {
    access: Access,
    write_restriction: Option<String>,
    pdo: PdoMappable,
}

const NO_FLAGS: Flags = Flags {
    access: Access::Unstated,
    write_restriction: None,
    pdo: PdoMappable {
        rx: false,
        tx: false,
    },
};

/// Every object of the `Dictionary` elements under `device`'s `Profile`s.
pub(super) fn objects(at: &At<'_, '_>, device: Node<'_, '_>) -> Result<Vec<EsiObject>, EsiError> {
    let mut out = Vec::new();
    for profile in children(device, "Profile") {
        let Some(dict) = child(profile, "Dictionary") else {
            continue;
        };
        let types = data_types(at, dict)?;
        if let Some(objs) = child(dict, "Objects") {
            for obj in children(objs, "Object") {
                object(at, &types, obj, &mut out)?;
            }
        }
    }
    Ok(out)
}

fn data_types<'a, 'input>(
    at: &At<'a, 'input>,
    dict: Node<'a, 'input>,
) -> Result<HashMap<String, DataTypeDef<'a, 'input>>, EsiError> {
    const PATH: &str = "Dictionary/DataTypes/DataType";
    let mut types = HashMap::new();
    let Some(list) = child(dict, "DataTypes") else {
        return Ok(types);
    };
    for dt in children(list, "DataType") {
        let name = text(at.child(dt, PATH, "Name")?);
        let bits = at.child_number(dt, PATH, "BitSize")?;
        let bits = at.fit::<u16>(dt, &format!("{PATH}/BitSize"), bits)?;
        let array = match child(dt, "ArrayInfo") {
            None => None,
            Some(ai) => {
                let p = format!("{PATH}/ArrayInfo");
                let lb = at.child_number(ai, &p, "LBound")?;
                let n = at.child_number(ai, &p, "Elements")?;
                Some((
                    at.fit::<u8>(ai, &format!("{p}/LBound"), lb)?,
                    at.fit::<u8>(ai, &format!("{p}/Elements"), n)?,
                ))
            }
        };
        types.insert(
            name,
            DataTypeDef {
                bits,
                sub_items: children(dt, "SubItem").collect(),
                array,
            },
        );
    }
    Ok(types)
}

fn flags(at: &At<'_, '_>, node: Node<'_, '_>, path: &str) -> Result<Option<Flags>, EsiError> {
    let Some(f) = child(node, "Flags") else {
        return Ok(None);
    };
    let (access, write_restriction) = match child(f, "Access") {
        None => (Access::Unstated, None),
        Some(a) => {
            let t = text(a);
            let access = match t.to_ascii_lowercase().as_str() {
                "ro" => Access::Ro,
                "rw" => Access::Rw,
                "wo" => Access::Wo,
                _ => {
                    return Err(at.err(
                        a,
                        &format!("{path}/Flags/Access"),
                        format!("{t:?} is not an access right (ro, rw, wo)"),
                    ))
                }
            };
            (access, a.attribute("WriteRestrictions").map(str::to_owned))
        }
    };
    let pdo = match child(f, "PdoMapping") {
        None => PdoMappable::default(),
        Some(m) => {
            let t = text(m).to_ascii_uppercase();
            if t.is_empty() || !t.chars().all(|c| c == 'R' || c == 'T') {
                return Err(at.err(
                    m,
                    &format!("{path}/Flags/PdoMapping"),
                    format!("{t:?} is not a PDO mapping (R, T, RT)"),
                ));
            }
            PdoMappable {
                rx: t.contains('R'),
                tx: t.contains('T'),
            }
        }
    };
    Ok(Some(Flags {
        access,
        write_restriction,
        pdo,
    }))
}

/// `Info/DefaultValue` or `Info/DefaultData` of `node`, where given and numeric.
fn default_of(info: Option<Node<'_, '_>>) -> Option<i64> {
    let info = info?;
    if let Some(v) = child(info, "DefaultValue") {
        return hex_dec(&text(v));
    }
    child(info, "DefaultData").and_then(|d| le_hex_bytes(&text(d)))
}

/// True for a data type whose default is a number (not a STRING or OCTET_STRING).
fn numeric(type_name: &str) -> bool {
    !type_name.contains("STRING")
}

/// One `Object`, appended to `out` as its sub-index rows.
fn object(
    at: &At<'_, '_>,
    types: &HashMap<String, DataTypeDef<'_, '_>>,
    obj: Node<'_, '_>,
    out: &mut Vec<EsiObject>,
) -> Result<(), EsiError> {
    const PATH: &str = "Dictionary/Objects/Object";
    let index = at.child_number(obj, PATH, "Index")?;
    let index = at.fit::<u16>(obj, &format!("{PATH}/Index"), index)?;
    let name = child_text(obj, "Name");
    let type_name = text(at.child(obj, PATH, "Type")?);
    let bits = at.opt_child_number(obj, PATH, "BitSize")?.unwrap_or(0);
    let bits = at.fit::<u16>(obj, &format!("{PATH}/BitSize"), bits)?;
    let own = flags(at, obj, PATH)?.unwrap_or(NO_FLAGS);
    let info = child(obj, "Info");
    let def = types.get(&type_name).filter(|t| !t.sub_items.is_empty());
    let Some(def) = def else {
        let default = default_of(info).filter(|_| numeric(&type_name));
        out.push(EsiObject {
            index,
            sub: 0,
            name,
            data_type: type_name,
            bits,
            access: own.access,
            write_restriction: own.write_restriction,
            pdo: own.pdo,
            default,
        });
        return Ok(());
    };
    // A record or array: one row per sub-item (an array sub-item without SubIdx expands to
    // its elements), the defaults from `Info/SubItem` by name, else by position.
    let info_items: Vec<Node<'_, '_>> = info
        .map(|i| children(i, "SubItem").collect())
        .unwrap_or_default();
    let sub_path = "Dictionary/DataTypes/DataType/SubItem";
    let mut rows: Vec<(u8, String, String, u16, Flags)> = Vec::new();
    for si in &def.sub_items {
        let si_name = child_text(*si, "Name");
        let si_type = child_text(*si, "Type");
        let si_bits = at.opt_child_number(*si, sub_path, "BitSize")?.unwrap_or(0);
        let si_bits = at.fit::<u16>(*si, &format!("{sub_path}/BitSize"), si_bits)?;
        let f = flags(at, *si, sub_path)?.unwrap_or_else(|| own.clone());
        match at.opt_child_number(*si, sub_path, "SubIdx")? {
            Some(s) => {
                let s = at.fit::<u8>(*si, &format!("{sub_path}/SubIdx"), s)?;
                rows.push((s, si_name, si_type, si_bits, f));
            }
            None => {
                let Some((lbound, elements)) = types.get(&si_type).and_then(|t| t.array) else {
                    return Err(at.err(
                        *si,
                        &format!("{sub_path}/SubIdx"),
                        format!("missing, and type {si_type:?} is no array with ArrayInfo"),
                    ));
                };
                let el_bits = types
                    .get(&si_type)
                    .map_or(0, |t| t.bits / u16::from(elements.max(1)));
                for k in 0..elements {
                    let s = lbound.saturating_add(k);
                    rows.push((
                        s,
                        format!("{si_name}[{s}]"),
                        si_type.clone(),
                        el_bits,
                        f.clone(),
                    ));
                }
            }
        }
    }
    let names: Vec<String> = rows.iter().map(|r| r.1.clone()).collect();
    for (pos, (sub, row_name, row_type, row_bits, f)) in rows.into_iter().enumerate() {
        // By name; else the item at the same position, unless that one names another row.
        let item = info_items
            .iter()
            .find(|i| child_text(**i, "Name") == row_name)
            .or_else(|| {
                info_items
                    .get(pos)
                    .filter(|i| !names.contains(&child_text(**i, "Name")))
            })
            .copied();
        let default = item
            .and_then(|i| default_of(child(i, "Info")))
            .filter(|_| numeric(&row_type));
        out.push(EsiObject {
            index,
            sub,
            name: row_name,
            data_type: row_type,
            bits: row_bits,
            access: f.access,
            write_restriction: f.write_restriction,
            pdo: f.pdo,
            default,
        });
    }
    Ok(())
}
