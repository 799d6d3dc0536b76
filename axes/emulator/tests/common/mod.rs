//! Shared helpers: simulated drives of any model driven through their byte images.
#![allow(dead_code)]

use cellrt_cia402::pdo::objects::{INCREMENTAL_COUNTER_TX, STATUSWORD2, WATCHDOG_COUNTER_UL};
use cellrt_cia402::profiles::status_do::StatusDo;
use cellrt_cia402::{
    profile, Controlword, CycleTime, Cycles, DriveModel, FsaState, RxPdo, Statusword, TxPdo,
};
use cellrt_emulator::{SimDrive, SimDriveParams};

/// The TxPDO objects the Mitsubishi profiles add to CiA 402, read by object index.
pub trait VendorObjects {
    /// The counter echo (2021h MR-J3-T04, 2D24h MR-J4-TM); 0 where not carried.
    fn echo(&self) -> u8;
    /// 2011h Statusword2 (MR-J3-T04); 0 where not carried.
    fn statusword2(&self) -> u16;
    /// Status DO 1–3 (2D11h–2D13h); 0 where not carried.
    fn status_do(&self) -> StatusDo;
}

impl VendorObjects for TxPdo {
    fn echo(&self) -> u8 {
        self.extra(INCREMENTAL_COUNTER_TX)
            .or(self.extra(WATCHDOG_COUNTER_UL))
            .map_or(0, |v| v as u8)
    }

    fn statusword2(&self) -> u16 {
        self.extra_word(STATUSWORD2)
    }

    fn status_do(&self) -> StatusDo {
        StatusDo::of(self)
    }
}

/// A 1 ms MR-J5-G-N1 drive with default parameters.
pub fn j5(params: SimDriveParams) -> SimDrive {
    drive(DriveModel::MrJ5GN1, 1000, params)
}

/// A drive of `model` at `us` µs.
pub fn drive(model: DriveModel, us: u32, params: SimDriveParams) -> SimDrive {
    SimDrive::new(profile(model), params, CycleTime::from_micros(us).unwrap())
}

/// One exchange through the byte images; returns the decoded TxPDO.
pub fn exchange(drive: &mut SimDrive, rx: &RxPdo) -> TxPdo {
    let p = drive.profile().clone();
    let mut rxb = [0u8; 64];
    let mut txb = [0u8; 64];
    let (rn, tn) = (p.pdo.rx.byte_len(), p.pdo.tx.byte_len());
    p.pdo.rx.encode_rx(rx, &mut rxb[..rn]).unwrap();
    drive.cycle(&rxb[..rn], &mut txb[..tn], Cycles(1)).unwrap();
    p.pdo.tx.decode_tx(&txb[..tn]).unwrap()
}

/// One exchange in which the drive's RxPDO is lost.
pub fn lost(drive: &mut SimDrive) -> TxPdo {
    let p = drive.profile().clone();
    let mut txb = [0u8; 64];
    let tn = p.pdo.tx.byte_len();
    drive.cycle_lost(&mut txb[..tn], Cycles(1)).unwrap();
    p.pdo.tx.decode_tx(&txb[..tn]).unwrap()
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

thread_local! {
    static COUNTER: std::cell::Cell<u8> = const { std::cell::Cell::new(0) };
}

/// The next value of this thread's incremental counter (what a well-behaved master sends on
/// 2020h; ignored by maps without a counter).
pub fn next_counter() -> u8 {
    COUNTER.with(|c| {
        let v = c.get().wrapping_add(1);
        c.set(v);
        v
    })
}

/// Sends `cw` in csp with the target following the actual position and the counter
/// incrementing; returns the statusword.
pub fn send(d: &mut SimDrive, cw: u16) -> Statusword {
    let pos = d.tx_pdo().position_actual;
    let rx = RxPdo {
        counter: next_counter(),
        ..csp(Controlword(cw), pos)
    };
    exchange(d, &rx).statusword
}

/// Runs the start-up (NRTSO → SOD) with Disable Voltage.
pub fn boot(d: &mut SimDrive) {
    for _ in 0..3 {
        send(d, 0);
    }
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
}

/// Boots and enables via Shutdown → Switch On → Enable Operation.
pub fn enabled(d: &mut SimDrive) {
    boot(d);
    for cw in [0x06, 0x07, 0x0F] {
        send(d, cw);
    }
    assert_eq!(d.state(), FsaState::OperationEnabled);
}

/// Moves an enabled drive in csp at `step` counts per cycle for `n` cycles.
pub fn move_csp(d: &mut SimDrive, step: i32, n: i32) {
    let start = d.tx_pdo().position_actual;
    for k in 1..=n {
        let rx = RxPdo {
            counter: next_counter(),
            ..csp(
                Controlword::ENABLE_OPERATION,
                start.wrapping_add(step.wrapping_mul(k)),
            )
        };
        exchange(d, &rx);
    }
}

/// `sw & mask == value`.
pub fn masked(sw: Statusword, mask: u16, value: u16) -> bool {
    sw.0 & mask == value
}
