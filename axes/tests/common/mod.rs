//! Shared helpers: one simulated MR-J5 axis driven through its byte images.
#![allow(dead_code)]

use cellrt_axes::{
    profile, Controlword, CycleTime, Cycles, DriveModel, RxPdo, SimDrive, SimDriveParams, TxPdo,
};

/// A 1 ms MR-J5-G-N1 drive with default parameters.
pub fn j5(params: SimDriveParams) -> SimDrive {
    SimDrive::new(
        profile(DriveModel::MrJ5GN1),
        params,
        CycleTime::from_micros(1000).unwrap(),
    )
}

/// One exchange through the byte images; returns the decoded TxPDO.
pub fn exchange(drive: &mut SimDrive, rx: &RxPdo) -> TxPdo {
    let p = drive.profile();
    let mut rxb = [0u8; 24];
    let mut txb = [0u8; 24];
    p.rx_pdo.encode_rx(rx, &mut rxb).unwrap();
    drive.cycle(&rxb, &mut txb, Cycles(1)).unwrap();
    p.tx_pdo.decode_tx(&txb).unwrap()
}

/// An RxPDO in csp with controlword `cw` and target `pos`.
pub fn csp(cw: Controlword, pos: i32) -> RxPdo {
    RxPdo {
        mode: 8,
        controlword: cw,
        target_position: pos,
        ..RxPdo::default()
    }
}
