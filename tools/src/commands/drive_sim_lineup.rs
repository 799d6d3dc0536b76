//! `cellrt drive-sim ethercat --drives … --esi …`: the SubDevices to emulate without a cell
//! configuration, one per listed model and one per ESI file, in line in that order.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use cellrt_cia402::profiles::{profile, DriveModel, DriveProfile, SharedProfile};
use cellrt_cia402::CycleTime;
use cellrt_ethercat::esi::{EsiDevice, EsiProfile};
use cellrt_ethercat::identity::SubDeviceIdentity;
use cellrt_runtime::host::cell_bus::EmulatedStation;

/// 1018h:01 of `--drives cia402`: the placeholder identity the shipped examples give a generic
/// drive (configs/cia402-generic.toml `[axes.ethercat]`), no registered vendor's.
pub const GENERIC_VENDOR_ID: u32 = 0xCE11_0000;
/// 1018h:02 of `--drives cia402`, the examples' placeholder as [`GENERIC_VENDOR_ID`].
pub const GENERIC_PRODUCT_CODE: u32 = 0xCE11_0402;

/// The SubDevices `--drives` and `--esi` list, before the segment is built.
#[derive(Debug)]
pub struct Lineup {
    /// The models of `--drives`, in order.
    pub models: Vec<DriveModel>,
    /// The files of `--esi`, in order (behind the models).
    pub esi: Vec<PathBuf>,
    /// The drives' cycle time.
    pub cycle: CycleTime,
}

/// One SubDevice of the line and the name drive-sim's messages give it.
#[derive(Debug)]
pub struct LinedStation {
    /// The model, or the ESI device's type (order code).
    pub name: String,
    /// The emulated SubDevice.
    pub station: EmulatedStation,
}

/// The models of a `--drives` list (comma-separated configuration names); an empty list or an
/// unknown name is refused, naming it and the supported ones.
pub fn models(list: &str) -> Result<Vec<DriveModel>, String> {
    if list.split(',').all(|n| n.trim().is_empty()) {
        return Err(format!(
            "--drives: no drive model given; supported models: {}",
            DriveModel::names()
        ));
    }
    list.split(',')
        .map(|n| n.trim().parse().map_err(|e| format!("--drives: {e}")))
        .collect()
}

impl Lineup {
    /// The SubDevices in line order: each model's unit with default settings, then each ESI
    /// file's device; a model that does not run the cycle time, or an ESI file that is not
    /// one usable CiA 402 device, is refused, naming it.
    pub fn stations(&self) -> Result<Vec<LinedStation>, String> {
        let mut line = Vec::with_capacity(self.models.len() + self.esi.len());
        for &model in &self.models {
            let p = model_profile(model);
            self.check_cycle(&format!("--drives: {model}"), &p)?;
            line.push(LinedStation {
                name: model.as_str().to_owned(),
                station: EmulatedStation::of_model(&p, self.cycle),
            });
        }
        for path in &self.esi {
            let device = esi_device(path)?;
            let p = esi_profile(path, &device)?;
            self.check_cycle(&format!("--esi {}", path.display()), &p)?;
            let mut station = EmulatedStation::of_model(&p, self.cycle);
            let name = device.type_name.clone();
            station.esi = Some(Arc::new(device));
            line.push(LinedStation { name, station });
        }
        Ok(line)
    }

    /// Refuses a profile that does not run the cycle time.
    fn check_cycle(&self, what: &str, p: &DriveProfile) -> Result<(), String> {
        if p.supports_cycle_time(self.cycle) {
            return Ok(());
        }
        Err(format!(
            "{what} ({}) does not support a {} µs cycle (allowed: {}); choose --cycle-time-us",
            p.name,
            self.cycle.as_micros(),
            p.cycle_times_text()
        ))
    }
}

/// The profile of a listed model: the built-in one, the generic drive with the examples'
/// placeholder identity.
fn model_profile(model: DriveModel) -> SharedProfile {
    let p = profile(model);
    match model {
        DriveModel::GenericCia402 => {
            SharedProfile::new(p.with_identity(Some(GENERIC_VENDOR_ID), Some(GENERIC_PRODUCT_CODE)))
        }
        _ => p.into(),
    }
}

/// The one device an ESI file describes.
fn esi_device(path: &Path) -> Result<EsiDevice, String> {
    let mut devices =
        cellrt_config::input_file::read_esi(path).map_err(|e| format!("--esi {e}"))?;
    if devices.len() != 1 {
        let v: Vec<String> = devices.iter().map(EsiDevice::identity_text).collect();
        return Err(format!(
            "--esi {}: describes {} devices, drive-sim emulates a file's only one (the file has: {})",
            path.display(),
            devices.len(),
            v.join("; ")
        ));
    }
    Ok(devices.remove(0))
}

/// The generic CiA 402 drive as the ESI `device` describes it: its identity, its modes and,
/// where the file gives them, its default RxPDO 1600h and TxPDO 1A00h. The ESI of a built-in
/// model is refused: `--drives` emulates that model as its manual describes it.
fn esi_profile(path: &Path, device: &EsiDevice) -> Result<SharedProfile, String> {
    if let Some(model) = DriveModel::ALL.iter().find(|&&m| {
        let id = SubDeviceIdentity::of_profile(profile(m));
        (id.vendor_id, id.product_code) == (device.vendor_id, device.product_code)
    }) {
        return Err(format!(
            "--esi {}: {} is the built-in model {model}: use --drives {model}",
            path.display(),
            device.identity_text()
        ));
    }
    let p = profile(DriveModel::GenericCia402).with_esi(device);
    let default = |pdos: &[cellrt_ethercat::esi::EsiPdo], index: u16| {
        pdos.iter()
            .find(|pdo| pdo.index == index)
            .map(|pdo| pdo.entries.clone())
    };
    let rx = default(&device.rx_pdos, p.pdo.rx.index);
    let tx = default(&device.tx_pdos, p.pdo.tx.index);
    if rx.is_none() && tx.is_none() {
        return Ok(SharedProfile::new(p));
    }
    let rx = rx.unwrap_or_else(|| p.pdo.rx.entries.to_vec());
    let tx = tx.unwrap_or_else(|| p.pdo.tx.entries.to_vec());
    p.with_pdo_maps(&rx, &tx)
        .map(SharedProfile::new)
        .map_err(|e| {
            format!(
                "--esi {}: {}: its default PDOs do not fit a CiA 402 drive: {e}",
                path.display(),
                device.identity_text()
            )
        })
}
