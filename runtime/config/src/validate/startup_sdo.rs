//! `[[axes.ethercat.startup_sdo]]`: an EtherCAT axis' start-up list (as TwinCAT's "Startup" tab
//! or an IgH SDO configuration): downloads bring-up makes in PRE-OP, before the PDO
//! configuration. Each is checked here against its type and, where the drive's dictionary
//! lists the object, against its access and range, so a bad entry is refused before anything
//! is sent.

use cellrt_cia402::profiles::{DataType, DriveProfile};
use cellrt_ethercat::master::StartupSdo;
use cellrt_fieldbus::mr_je_c::ObjectId;

use super::axis_key::AxisKey;
use crate::raw::RawAxis;
use crate::{ConfigError, Transport};

/// The types a start-up download may carry (1, 2 or 4 bytes: an expedited download).
const TYPES: [(&str, DataType); 7] = [
    ("bool", DataType::Bool),
    ("i8", DataType::I8),
    ("u8", DataType::U8),
    ("i16", DataType::I16),
    ("u16", DataType::U16),
    ("i32", DataType::I32),
    ("u32", DataType::U32),
];

/// The axis' start-up list, checked.
pub(super) fn startup_sdo(
    at: &AxisKey,
    a: &RawAxis,
    profile: &DriveProfile,
    transport: Transport,
) -> Result<Vec<StartupSdo>, ConfigError> {
    let list = &a.ethercat.startup_sdo;
    if !list.is_empty() && transport != Transport::Ethercat {
        return Err(at.err(
            "ethercat.startup_sdo",
            format!(
                "axis '{}' is not on EtherCAT: only an EtherCAT axis has a start-up list",
                a.name
            ),
        ));
    }
    list.iter()
        .enumerate()
        .map(|(k, e)| {
            let key = |field: &str| format!("ethercat.startup_sdo[{k}].{field}");
            let object: ObjectId = e.object.parse().map_err(|_| {
                at.err(
                    &key("object"),
                    format!(
                        "\"{}\" is no object (index in hex with an optional decimal sub-index, e.g. \"2001h\" or \"6085:0\")",
                        crate::echo::Echo(&e.object)
                    ),
                )
            })?;
            let listed = profile.object(object.index, object.sub);
            let data_type = match (&e.data_type, listed) {
                (Some(name), _) => TYPES
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, t)| *t)
                    .ok_or_else(|| {
                        let names: Vec<&str> = TYPES.iter().map(|(n, _)| *n).collect();
                        at.err(
                            &key("type"),
                            format!(
                                "\"{}\" is no type a start-up download carries (one of {})",
                                crate::echo::Echo(name),
                                names.join(", ")
                            ),
                        )
                    })?,
                (None, Some(o)) if o.data_type.value_range().is_some() => o.data_type,
                (None, _) => {
                    return Err(at.err(
                        &key("type"),
                        format!(
                            "the type of {object} is not in the {} dictionary: give type = \"u32\" (or another)",
                            profile.name
                        ),
                    ))
                }
            };
            if let Some(o) = listed {
                if !o.access.writable() {
                    return Err(at.err(
                        &key("object"),
                        format!("{object} ({}) is not writable ({:?})", o.name, o.access),
                    ));
                }
                if o.range.refuses(e.value) {
                    return Err(at.err(
                        &key("value"),
                        format!("{} is outside the range of {object} ({})", e.value, o.name),
                    ));
                }
            }
            let (lo, hi) = data_type.value_range().unwrap_or((0, 0));
            if e.value < lo || e.value > hi {
                return Err(at.err(
                    &key("value"),
                    format!(
                        "{} is outside {} ({lo}…{hi})",
                        e.value,
                        data_type.cia301_name()
                    ),
                ));
            }
            Ok(StartupSdo {
                index: object.index,
                sub: object.sub,
                data: e.value.to_le_bytes()[..data_type.bytes()].to_vec(),
            })
        })
        .collect()
}
