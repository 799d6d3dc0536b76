//! AxisMaster driving a simulated MR-J5-G-N1 through its PDO images.

mod common;

use cellrt_cia402::{
    profile, AxisMaster, Controlword, CycleTime, Cycles, DriveModel, FsaState, MasterParams,
    MasterRequest, MasterState, Statusword,
};
use cellrt_emulator::{SimDrive, SimDriveParams};
use common::{csp, exchange, j5};

fn params() -> MasterParams {
    let hold = profile(DriveModel::MrJ5GN1).fault_reset_hold(CycleTime::from_micros(1000).unwrap());
    MasterParams {
        fault_reset_hold: hold,
        transition_timeout: Cycles(100),
    }
}

/// One master/drive cycle; the target follows the actual position (TV-10 csp entry rule).
fn cycle(m: &mut AxisMaster, d: &mut SimDrive) -> Controlword {
    let last = *d.tx_pdo();
    let cw = m.update(last.statusword);
    exchange(d, &csp(cw, last.position_actual));
    cw
}

/// Runs until `done` or `max` cycles; returns the controlword stream.
fn run(
    m: &mut AxisMaster,
    d: &mut SimDrive,
    max: usize,
    done: impl Fn(&AxisMaster) -> bool,
) -> Vec<Controlword> {
    let mut cws = Vec::new();
    for _ in 0..max {
        cws.push(cycle(m, d));
        if done(m) {
            break;
        }
    }
    cws
}

/// Puts a fresh drive into `target` through its images (moving, for QSA and FRA).
fn drive_in(target: FsaState) -> SimDrive {
    let mut d = j5(SimDriveParams::default());
    if target == FsaState::NotReadyToSwitchOn {
        return d;
    }
    for _ in 0..3 {
        exchange(&mut d, &csp(Controlword(0), 0));
    }
    let words: &[u16] = match target {
        FsaState::SwitchOnDisabled => &[],
        FsaState::ReadyToSwitchOn => &[0x06],
        FsaState::SwitchedOn => &[0x06, 0x07],
        _ => &[0x06, 0x07, 0x0F],
    };
    for &w in words {
        exchange(&mut d, &csp(Controlword(w), 0));
    }
    if matches!(
        target,
        FsaState::QuickStopActive | FsaState::FaultReactionActive | FsaState::Fault
    ) {
        for k in 1..=100 {
            exchange(&mut d, &csp(Controlword::ENABLE_OPERATION, 1_000 * k));
        }
        match target {
            FsaState::QuickStopActive => {
                exchange(&mut d, &csp(Controlword::QUICK_STOP, 0));
            }
            FsaState::FaultReactionActive => d.inject_alarm(0x0999),
            _ => {
                d.inject_alarm(0x0999);
                for _ in 0..200 {
                    exchange(&mut d, &csp(Controlword(0), 0));
                }
            }
        }
    }
    assert_eq!(d.state(), target);
    d
}

#[test]
fn enable_reaches_operation_enabled_from_every_state() {
    for start in FsaState::ALL {
        let mut d = drive_in(start);
        let mut m = AxisMaster::new(params());
        m.request(MasterRequest::Enable);
        let cws = run(&mut m, &mut d, 200, |m| m.state() == MasterState::Enabled);
        assert_eq!(m.state(), MasterState::Enabled, "from {start}: {cws:?}");
        assert!(m.is_enabled());
        assert_eq!(d.state(), FsaState::OperationEnabled);
        assert!(cws.len() < 120, "from {start}: {} cycles", cws.len());
    }
}

#[test]
fn disable_is_a_clean_shutdown_to_ready_to_switch_on() {
    for start in FsaState::ALL {
        if start.is_fault() {
            continue;
        }
        let mut d = drive_in(start);
        let mut m = AxisMaster::new(params());
        m.request(MasterRequest::Disable);
        run(&mut m, &mut d, 200, |m| m.state() == MasterState::Disabled);
        assert_eq!(m.state(), MasterState::Disabled, "from {start}");
        assert_eq!(d.state(), FsaState::ReadyToSwitchOn, "from {start}");
    }
    // From OE the only word sent is Shutdown (transition 8), never Disable Voltage.
    let mut d = drive_in(FsaState::OperationEnabled);
    let mut m = AxisMaster::new(params());
    m.request(MasterRequest::Enable);
    run(&mut m, &mut d, 10, |m| m.is_enabled());
    m.request(MasterRequest::Disable);
    let cws = run(&mut m, &mut d, 10, |m| m.state() == MasterState::Disabled);
    assert!(cws.iter().all(|&c| c == Controlword::SHUTDOWN), "{cws:?}");
    assert!(d.alarm().is_none());
}

#[test]
fn fault_reset_is_held_exactly_the_hold_time() {
    for us in [125u32, 1000, 4000, 8000] {
        let ct = CycleTime::from_micros(us).unwrap();
        let p = profile(DriveModel::MrJ5GN1);
        let hold = p.fault_reset_hold(ct);
        let mut d = SimDrive::new(p, SimDriveParams::default(), ct);
        for _ in 0..3 {
            exchange(&mut d, &csp(Controlword(0), 0));
        }
        d.inject_alarm(0x0123);
        exchange(&mut d, &csp(Controlword(0), 0));
        assert_eq!(d.state(), FsaState::Fault);
        let mut m = AxisMaster::new(MasterParams {
            fault_reset_hold: hold,
            transition_timeout: Cycles(50),
        });
        m.request(MasterRequest::Enable);
        let cws = run(&mut m, &mut d, 300, |m| m.is_enabled());
        let first = cws.iter().position(|c| c.fault_reset()).unwrap();
        let run_len = cws[first..].iter().take_while(|c| c.fault_reset()).count();
        assert_eq!(Cycles(run_len as u32), hold, "{us} µs: {cws:?}");
        assert_eq!(cws.iter().filter(|c| c.fault_reset()).count(), run_len);
        assert!(cws[first..]
            .iter()
            .all(|c| *c == Controlword::FAULT_RESET || !c.fault_reset()));
        assert_eq!(m.state(), MasterState::Enabled);
    }
}

#[test]
fn fault_reset_after_bit7_high_primes_an_edge() {
    let mut m = AxisMaster::new(MasterParams {
        fault_reset_hold: Cycles(3),
        transition_timeout: Cycles(10),
    });
    let fault = Statusword::for_state(FsaState::Fault);
    m.request(MasterRequest::FaultReset);
    let cws: Vec<u16> = (0..5).map(|_| m.update(fault).0).collect();
    assert_eq!(cws, [0x80, 0x80, 0x80, 0x00, 0x00]);
    // A new reset while bit 7 is still high from the last word would not be an edge.
    let mut m = AxisMaster::new(MasterParams {
        fault_reset_hold: Cycles(2),
        transition_timeout: Cycles(10),
    });
    m.request(MasterRequest::FaultReset);
    m.update(fault);
    m.request(MasterRequest::Enable);
    let cws: Vec<u16> = (0..4).map(|_| m.update(fault).0).collect();
    assert_eq!(cws, [0x00, 0x80, 0x80, 0x00]);
}

#[test]
fn times_out_when_the_drive_never_answers() {
    let mut m = AxisMaster::new(MasterParams {
        fault_reset_hold: Cycles(10),
        transition_timeout: Cycles(5),
    });
    let sod = Statusword::for_state(FsaState::SwitchOnDisabled);
    m.request(MasterRequest::Enable);
    for _ in 0..6 {
        assert_eq!(m.update(sod), Controlword::SHUTDOWN);
        assert_eq!(m.state(), MasterState::Enabling);
    }
    assert_eq!(m.update(sod), Controlword::DISABLE_VOLTAGE);
    assert_eq!(m.state(), MasterState::TimedOut);
    m.update(sod);
    assert_eq!(m.state(), MasterState::TimedOut, "until a new request");
    m.request(MasterRequest::Enable);
    assert_eq!(m.update(sod), Controlword::SHUTDOWN);
    assert_eq!(m.state(), MasterState::Enabling);
    // Garbage statuswords do not count as progress either.
    let mut m = AxisMaster::new(MasterParams {
        fault_reset_hold: Cycles(1),
        transition_timeout: Cycles(3),
    });
    m.request(MasterRequest::Enable);
    for _ in 0..10 {
        m.update(Statusword(0x0001));
    }
    assert_eq!(m.state(), MasterState::TimedOut);
    assert_eq!(m.drive_state(), None);
}

#[test]
fn a_fault_while_enabled_latches_and_is_not_reset_automatically() {
    let mut d = drive_in(FsaState::SwitchOnDisabled);
    let mut m = AxisMaster::new(params());
    m.request(MasterRequest::Enable);
    run(&mut m, &mut d, 20, |m| m.is_enabled());
    d.inject_alarm(0x0555);
    let cws = run(&mut m, &mut d, 50, |_| false);
    assert_eq!(m.state(), MasterState::Faulted);
    assert!(m.fault());
    assert!(cws.iter().all(|c| !c.fault_reset()));
    m.request(MasterRequest::Enable); // repeated request from Faulted restarts: resets
    run(&mut m, &mut d, 100, |m| m.is_enabled());
    assert_eq!(m.state(), MasterState::Enabled);
}

#[test]
fn repeating_enable_every_cycle_does_not_restart() {
    let mut d = drive_in(FsaState::Fault);
    let mut m = AxisMaster::new(params());
    let mut resets = 0;
    for _ in 0..100 {
        m.request(MasterRequest::Enable);
        if cycle(&mut m, &mut d).fault_reset() {
            resets += 1;
        }
    }
    assert_eq!(Cycles(resets), params().fault_reset_hold);
    assert!(m.is_enabled());
}

#[test]
fn quick_stop_ends_disabled_in_switch_on_disabled() {
    let mut d = drive_in(FsaState::SwitchOnDisabled);
    let mut m = AxisMaster::new(params());
    m.request(MasterRequest::Enable);
    run(&mut m, &mut d, 20, |m| m.is_enabled());
    m.request(MasterRequest::QuickStop);
    assert_eq!(m.update(d.tx_pdo().statusword), Controlword::QUICK_STOP);
    run(&mut m, &mut d, 100, |m| m.state() == MasterState::Disabled);
    assert_eq!(m.state(), MasterState::Disabled);
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
}

#[test]
fn idle_master_sends_disable_voltage() {
    let mut m = AxisMaster::new(params());
    assert_eq!(m.state(), MasterState::Idle);
    let oe = Statusword::for_state(FsaState::OperationEnabled);
    assert_eq!(m.update(oe), Controlword::DISABLE_VOLTAGE);
    assert_eq!(m.drive_state(), Some(FsaState::OperationEnabled));
    assert!(m.is_enabled() && !m.fault());
}
