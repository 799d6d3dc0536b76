//! An emulated station described by an ESI file: its object dictionary decides which objects
//! exist and what may be read or written (CiA 301 abort codes), before the simulated drive
//! serves the request.

use crate::sim::sdo::SdoAbort;
use cellrt_cia402::profiles::Access;
use cellrt_ethercat::esi::EsiDevice;

/// A value to upload, little-endian.
type Value = Vec<u8>;

/// The ESI's verdict on `index:sub`: the entry, or the abort for a missing one.
fn entry(d: &EsiDevice, index: u16, sub: u8) -> Result<&cellrt_ethercat::esi::EsiObject, SdoAbort> {
    d.object(index, sub)
        .ok_or(if d.objects.iter().any(|o| o.index == index) {
            SdoAbort::NO_SUBINDEX
        } else {
            SdoAbort::NO_OBJECT
        })
}

/// True for the aborts a simulated drive gives for an object it does not model.
fn unmodelled(a: SdoAbort) -> bool {
    a == SdoAbort::NO_OBJECT || a == SdoAbort::NO_SUBINDEX
}

/// An SDO upload through the station's ESI dictionary `esi` (when it has one), else `serve`
/// with the station's context `ctx`.
pub fn upload<C>(
    esi: Option<&EsiDevice>,
    ctx: &mut C,
    index: u16,
    sub: u8,
    serve: fn(&mut C, u16, u8) -> Result<Value, SdoAbort>,
) -> Result<Value, SdoAbort> {
    let Some(d) = esi.filter(|d| d.has_dictionary()) else {
        return serve(ctx, index, sub);
    };
    let e = entry(d, index, sub)?;
    if e.access == Access::Wo {
        return Err(SdoAbort::WRITE_ONLY);
    }
    match serve(ctx, index, sub) {
        Err(a) if unmodelled(a) => {
            let v = e.default.unwrap_or(0).to_le_bytes();
            let n = usize::from(e.bits.div_ceil(8)).clamp(1, 8);
            Ok(v[..n].to_vec())
        }
        other => other,
    }
}

/// An SDO download through the station's ESI dictionary `esi` (when it has one), else `serve`
/// with the station's context `ctx`.
pub fn download<C>(
    esi: Option<&EsiDevice>,
    ctx: &mut C,
    index: u16,
    sub: u8,
    data: &[u8],
    serve: fn(&mut C, u16, u8, &[u8]) -> Result<(), SdoAbort>,
) -> Result<(), SdoAbort> {
    let Some(d) = esi.filter(|d| d.has_dictionary()) else {
        return serve(ctx, index, sub, data);
    };
    let e = entry(d, index, sub)?;
    if e.access == Access::Ro {
        return Err(SdoAbort::READ_ONLY);
    }
    match serve(ctx, index, sub, data) {
        Err(a) if unmodelled(a) => Ok(()),
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ethercat::coe::{self, CoeContext, PdoConfig, SegmentedUpload};
    use crate::sim::drive::{SimDrive, SimDriveParams};
    use cellrt_cia402::cycles::CycleTime;
    use cellrt_cia402::profiles::{profile, DriveModel};
    use cellrt_ethercat::identity::SubDeviceIdentity;
    use cellrt_ethercat::register::AlState;

    /// configs/esi/cia402-example.xml behind the emulated CoE server, in PRE-OP: an SDO write
    /// to a read-only object aborts 0601 0002h, to an object the ESI lacks 0602 0000h.
    #[test]
    fn the_esi_decides_existence_and_access() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../configs/esi/cia402-example.xml");
        let device = cellrt_ethercat::esi::load(&path).unwrap().remove(0);
        let p = cellrt_cia402::SharedProfile::new(cellrt_ethercat::esi::EsiProfile::with_esi(
            profile(DriveModel::GenericCia402),
            &device,
        ));
        let cycle = CycleTime::from_micros(1000).unwrap();
        let mut drives = vec![SimDrive::new(p.clone(), SimDriveParams::default(), cycle)];
        let mut pdo = PdoConfig::new(&drives);
        let (mut counter, mut upload_state) = (0u8, SegmentedUpload::default());
        let mut fragments = std::collections::VecDeque::new();
        let variant = super::super::SubDeviceVariant::default();
        let mut ctx = CoeContext {
            variant: &variant,
            identity: SubDeviceIdentity::of_profile(&p),
            drives: &mut drives,
            al_state: AlState::PreOp,
            pdo: &mut pdo,
            counter: &mut counter,
            upload: &mut upload_state,
            esi: Some(&device),
            info_fragments: &mut fragments,
        };
        let write = |ctx: &mut CoeContext<'_>, i, s, d: &[u8]| {
            download(ctx.esi, ctx, i, s, d, coe::download).map_err(|e| e.0)
        };
        let read = |ctx: &mut CoeContext<'_>, i, s| {
            upload(ctx.esi, ctx, i, s, coe::upload).map_err(|e| e.0)
        };
        // 6502h (ro), 1018h (ro): 0601 0002h; 60F4h and 6081h are not in this ESI: 0602 0000h.
        assert_eq!(write(&mut ctx, 0x6502, 0, &[0; 4]), Err(0x0601_0002));
        assert_eq!(write(&mut ctx, 0x1018, 2, &[0; 4]), Err(0x0601_0002));
        assert_eq!(read(&mut ctx, 0x60F4, 0), Err(0x0602_0000));
        assert_eq!(write(&mut ctx, 0x6081, 0, &[0; 4]), Err(0x0602_0000));
        assert_eq!(read(&mut ctx, 0x1C32, 3), Err(0x0609_0011));
        // What the ESI has: 1018h from the file, 6098h writable, 1C32h:05 its default.
        assert_eq!(
            read(&mut ctx, 0x1018, 2),
            Ok(0xCE11_0403u32.to_le_bytes().to_vec())
        );
        assert_eq!(write(&mut ctx, 0x6098, 0, &[37]), Ok(()));
        assert_eq!(
            read(&mut ctx, 0x1C32, 5),
            Ok(250_000u32.to_le_bytes().to_vec())
        );
        // Without the ESI the generic drive serves 6081h.
        ctx.esi = None;
        assert_eq!(write(&mut ctx, 0x6081, 0, &[0; 4]), Ok(()));
    }
}
