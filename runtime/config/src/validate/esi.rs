//! `esi`, `esi_device`, `esi_product_code`, `esi_revision`: the drive's ESI file, the device
//! in it, and what it forbids the axis' configuration (refused before the bus is touched).

use std::path::Path;
use std::sync::Arc;

use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::objects::MODES_OF_OPERATION;
use cellrt_cia402::profiles::DriveModel;
use cellrt_cia402::{CycleTime, DriveProfile};
use cellrt_ethercat::esi::conform::{self, ConflictSubject, Intent};
use cellrt_ethercat::esi::{DeviceSelector, EsiDevice};

use crate::raw::RawAxis;
use crate::ConfigError;

/// The ESI device an axis names, loaded relative to the config `file`; `None` without `esi`.
/// `key` is the axis' key (`axes[i]`).
pub(super) fn load_device(
    file: &Path,
    key: &str,
    a: &RawAxis,
    drive: DriveModel,
) -> Result<Option<Arc<EsiDevice>>, ConfigError> {
    let err = |sub: &str, msg: String| ConfigError::new(file, format!("{key}.{sub}"), msg);
    let Some(rel) = &a.esi else {
        for (sub, given) in [
            ("esi_device", a.esi_device.is_some()),
            ("esi_product_code", a.esi_product_code.is_some()),
            ("esi_revision", a.esi_revision.is_some()),
        ] {
            if given {
                return Err(err(
                    sub,
                    format!("axis '{}': {sub} needs esi (the ESI file)", a.name),
                ));
            }
        }
        return Ok(None);
    };
    if drive != DriveModel::GenericCia402 {
        return Err(err(
            "esi",
            format!(
                "axis '{}': esi is for drive = \"cia402\"; the facts of {drive} are its profile's (configs/esi holds its ESI, checked against the profile)",
                a.name
            ),
        ));
    }
    let path = file.parent().unwrap_or(Path::new(".")).join(rel);
    let devices = crate::input_file::read_esi(&path).map_err(|e| err("esi", e.to_string()))?;
    let selector = DeviceSelector {
        product_code: a.esi_product_code,
        revision: a.esi_revision,
        name: a.esi_device.clone(),
    };
    let device = selector
        .pick(&devices)
        .map_err(|m| err("esi", format!("{}: {m}", path.display())))?;
    for (sub, given, esi) in [
        ("ethercat.vendor_id", a.ethercat.vendor_id, device.vendor_id),
        (
            "ethercat.product_code",
            a.ethercat.product_code,
            device.product_code,
        ),
    ] {
        if let Some(v) = given.filter(|v| *v != esi) {
            return Err(err(
                sub,
                format!(
                    "axis '{}': {v:#x} differs from the ESI's {esi:#x} ({})",
                    a.name,
                    device.identity_text()
                ),
            ));
        }
    }
    Ok(Some(Arc::new(device.clone())))
}

/// Refuses what `device` forbids the axis running `profile` in `mode` at `cycle`, naming the
/// key to change.
pub(super) fn check(
    file: &Path,
    key: &str,
    name: &str,
    device: &EsiDevice,
    profile: &DriveProfile,
    mode: ModeOfOperation,
    cycle: CycleTime,
) -> Result<(), ConfigError> {
    let writes: &[(u16, u8)] = if profile.pdo.rx.maps(MODES_OF_OPERATION) {
        &[]
    } else {
        &[(MODES_OF_OPERATION, 0)]
    };
    let intent = Intent {
        profile,
        modes: &[mode],
        cycle_ns: cycle.as_nanos() as u32,
        writes,
    };
    conform::check(device, &intent).map_err(|c| {
        let k = match c.subject {
            ConflictSubject::Device | ConflictSubject::Object => format!("{key}.esi"),
            ConflictSubject::Mode => format!("{key}.mode"),
            ConflictSubject::RxPdo => format!("{key}.pdo.rx"),
            ConflictSubject::TxPdo => format!("{key}.pdo.tx"),
            ConflictSubject::CycleTime => "cell.cycle_time_us".to_owned(),
        };
        ConfigError::new(
            file,
            k,
            format!(
                "axis '{name}': the ESI forbids it ({}): {}",
                device.identity_text(),
                c.message
            ),
        )
    })
}
