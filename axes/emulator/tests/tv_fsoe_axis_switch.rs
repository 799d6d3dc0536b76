//! Test vectors MR-JET-G-N1 TV-12 (docs/test-vectors.md) (FSoE: the safety process data of the MR-JET-G-N1
//! and the master's side of it) and MR-J5-G-N1 TV-14 (docs/test-vectors.md) (the axis-selection switch SW3),
//! against the simulated drives. Items the specs mark "not stated" / [inferred] are tested only
//! as the simulator's named, documented parameters.

mod common;

use cellrt_cia402::fsoe::{
    decode_commands, ConnectionParams, FsoeError, FsoeFrame, FsoeMaster, FsoeMasterConfig,
    SafetyRequest, SafetyStatus, WatchdogRule,
};
use cellrt_cia402::profiles::mr_j5_g_n1::AL_011_2;
use cellrt_cia402::profiles::mr_jet_g_n1::{AL_584_1, FSOE};
use cellrt_cia402::{profile, Controlword, CycleTime, DriveModel, FsaState, RxPdo, Statusword};
use cellrt_emulator::sim::drive::AxisSwitch;
use cellrt_emulator::sim::fsoe::{FsoeSlaveParams, StoStop};
use cellrt_emulator::sim::sdo::SdoAbort;
use cellrt_emulator::{SimDrive, SimDriveParams};
use common::{boot, csp, drive, exchange, masked, next_counter, send};

use cellrt_test_support::counting_alloc::{thread_heap_calls, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

fn switch(sw3_1: bool, sw3_2: bool) -> SimDriveParams {
    SimDriveParams {
        axis_switch: AxisSwitch { sw3_1, sw3_2 },
        ..SimDriveParams::default()
    }
}

/// Runs a few cycles with Disable Voltage and returns the last statusword.
fn idle(d: &mut cellrt_emulator::SimDrive) -> cellrt_cia402::Statusword {
    let mut sw = d.tx_pdo().statusword;
    for _ in 0..5 {
        sw = send(d, 0x0000);
    }
    sw
}

#[test]
fn tv_14_sw3_1_off_sw3_2_on_raises_al_011_2_on_a_1_axis_mr_j5() {
    let mut d = drive(DriveModel::MrJ5GN1, 1000, switch(false, true));
    let sw = idle(&mut d);
    assert_eq!(d.alarm(), Some(AL_011_2));
    assert_eq!(d.tx_pdo().error_code, AL_011_2, "603Fh");
    assert_eq!(d.state(), FsaState::Fault);
    assert!(masked(sw, 0x414F, 0x0008), "Fault: {sw}");
    // The switch is read at power-on ([inferred]): a Fault Reset cannot remove the cause.
    send(&mut d, 0x0080);
    let sw = idle(&mut d);
    assert_eq!(d.state(), FsaState::Fault, "{sw}");
    assert_eq!(d.alarm(), Some(AL_011_2));
    // Enable commands are refused while the alarm stands.
    for cw in [0x06, 0x07, 0x0F] {
        send(&mut d, cw);
    }
    assert_eq!(d.state(), FsaState::Fault);
    // A valid setting takes effect at the next power-on.
    d.set_axis_switch(AxisSwitch::default());
    assert_eq!(d.alarm(), Some(AL_011_2), "not before the power cycle");
    d.power_cycle();
    boot(&mut d);
    assert_eq!(d.alarm(), None);
    assert_eq!(d.tx_pdo().error_code, 0);
}

#[test]
fn tv_14_every_other_sw3_setting_starts_cleanly_on_a_1_axis_mr_j5() {
    for (a, b) in [(false, false), (true, false), (true, true)] {
        let mut d = drive(DriveModel::MrJ5GN1, 1000, switch(a, b));
        boot(&mut d);
        assert_eq!(d.alarm(), None, "SW3-1 {a}, SW3-2 {b}");
    }
    // The default is a valid setting.
    let mut d = drive(DriveModel::MrJ5GN1, 1000, SimDriveParams::default());
    boot(&mut d);
    assert_eq!(d.alarm(), None);
}

#[test]
fn tv_14_setting_changed_at_run_time_raises_at_the_next_power_on() {
    let mut d = drive(DriveModel::MrJ5GN1, 1000, SimDriveParams::default());
    boot(&mut d);
    d.set_axis_switch(AxisSwitch {
        sw3_1: false,
        sw3_2: true,
    });
    idle(&mut d);
    assert_eq!(d.alarm(), None, "SW3 is read at power-on only");
    d.power_cycle();
    idle(&mut d);
    assert_eq!(d.alarm(), Some(AL_011_2));
    assert_eq!(d.state(), FsaState::Fault);
}

#[test]
fn tv_14_multi_axis_and_other_models_have_no_stated_sw3_rule() {
    // MR-J5-G-N1 manual §2.2, §3.1, §4.3, §4.4: "Multi-axis SW3 settings are not given"; the other models have no SW3
    // rule in their manuals.
    for model in [
        DriveModel::MrJ5W2GN1,
        DriveModel::MrJ5W3GN1,
        DriveModel::MrJetGN1,
        DriveModel::MrJ4TM,
    ] {
        let mut d = drive(model, 1000, switch(false, true));
        boot(&mut d);
        assert_eq!(d.alarm(), None, "{model}");
        assert!(cellrt_cia402::profile(model).invalid_axis_switch.is_none());
    }
}

// ---------------------------------------------------------------------------------------------
// MR-JET-G-N1 TV-12: FSoE (MR-JET-G-N1 manual §4.3, §9.3, §7, §11 TV-12)
// ---------------------------------------------------------------------------------------------

const US: u32 = 1000;

fn jet_fsoe(slave: FsoeSlaveParams) -> SimDrive {
    drive(
        DriveModel::MrJetGN1,
        US,
        SimDriveParams {
            fsoe: Some(slave),
            ..SimDriveParams::default()
        },
    )
}

fn master(address: u16, watchdog_ms: u16) -> FsoeMaster {
    FsoeMaster::new(
        profile(DriveModel::MrJetGN1),
        CycleTime::from_micros(US).unwrap(),
        FsoeMasterConfig::new(address, watchdog_ms),
    )
    .unwrap()
}

/// A drive with FSoE and its master, exchanging both the normal and the safety PDOs.
struct Rig {
    d: SimDrive,
    m: FsoeMaster,
    /// The last safety frame the master sent.
    sent: [u8; 11],
}

impl Rig {
    /// Connected with PSC07 = master address = 1 and a 16 ms watchdog.
    fn new(slave: FsoeSlaveParams) -> Rig {
        let mut r = Rig {
            d: jet_fsoe(slave),
            m: master(1, 16),
            sent: [0; 11],
        };
        r.d.fsoe_connect(&r.m.connection_params()).unwrap();
        r
    }

    /// One safety exchange; returns the slave's status as the master decodes it.
    fn safety(&mut self) -> SafetyStatus {
        let mut tx = [0u8; 11];
        self.m.write_frame(&mut self.sent).unwrap();
        self.d.fsoe_exchange(&self.sent, &mut tx).unwrap();
        self.m.read_frame(&tx).unwrap()
    }

    /// One bus cycle: safety frame, then `cw` in csp holding the position.
    fn step(&mut self, cw: u16) -> (Statusword, SafetyStatus) {
        let s = self.safety();
        (send(&mut self.d, cw), s)
    }

    /// One bus cycle with a csp target `pos`.
    fn step_to(&mut self, cw: u16, pos: i32) -> (Statusword, SafetyStatus) {
        let s = self.safety();
        let rx = RxPdo {
            counter: next_counter(),
            ..csp(Controlword(cw), pos)
        };
        (exchange(&mut self.d, &rx).statusword, s)
    }

    /// Requests `req` and runs until the slave reports STOS = `sto` (at most `limit` cycles);
    /// returns the cycles it took.
    fn until_sto(&mut self, req: SafetyRequest, sto: bool, cw: u16, limit: u32) -> u32 {
        self.m.request(req);
        for n in 1..=limit {
            if self.step(cw).1.sto == sto {
                return n;
            }
        }
        panic!("STOS did not become {sto} within {limit} cycles");
    }

    /// Boots, requests the run command and enables: Operation enabled, STOS = 0.
    fn running(slave: FsoeSlaveParams) -> Rig {
        let mut r = Rig::new(slave);
        r.until_sto(SafetyRequest::RUN, false, 0, 50);
        for cw in [0x00, 0x06, 0x07, 0x0F] {
            r.step(cw);
        }
        assert_eq!(r.d.state(), FsaState::OperationEnabled);
        r
    }
}

/// The number of STO response cycles a test waits at most: T_Ref (the safety refresh
/// response processing time, §7.3) in cycles. The manual does not state the delay (TV-12).
fn t_ref_cycles() -> u32 {
    FSOE.t_ref_us / US
}

#[test]
fn tv_12_run_command_is_0x63_0xef_0x01_0x00() {
    let mut m = master(1, 16);
    m.request(SafetyRequest::RUN);
    let mut f = [0xAAu8; 11];
    let sd = m.write_frame(&mut f).unwrap();
    assert_eq!(sd, [0x63, 0xEF, 0x01, 0x00]);
    // SafeData[0..4] sit at bytes 1, 2, 5, 6 of the 11-byte 1608h frame (§5.4).
    assert_eq!((f[1], f[2], f[5], f[6]), (0x63, 0xEF, 0x01, 0x00));
    // Every function bit is 1 (cancelled); each one cleared alone activates exactly that one.
    let c = &FSOE.commands;
    let named = [
        ("STOC", c.sto),
        ("SS1C", c.ss1),
        ("SDIPC", c.sdip),
        ("SDINC", c.sdin),
        ("SLS1C", c.sls[0]),
        ("SLS2C", c.sls[1]),
        ("SLS3C", c.sls[2]),
        ("SLS4C", c.sls[3]),
        ("SLT1C", c.slt[0]),
        ("SLT2C", c.slt[1]),
        ("SLT3C", c.slt[2]),
        ("SLT4C", c.slt[3]),
    ];
    for (name, bit) in named {
        assert!(bit.get(&sd), "{name} = 1 in the run command");
        let mut one = sd;
        bit.set(&mut one, false);
        let (req, ack) = decode_commands(c, &one);
        assert!(!ack);
        let active = [req.sto, req.ss1, req.sdip, req.sdin]
            .into_iter()
            .chain(req.sls)
            .chain(req.slt)
            .filter(|&a| a)
            .count();
        assert_eq!(active, 1, "{name}");
    }
    // The §7.2 positions: STOC b0.0, SS1C b0.1, SDIPC b0.5, SDINC b0.6, SLS b1.0–3, SLT1–3
    // b1.5–7, SLT4 b2.0, with their F701h sub-indexes.
    assert_eq!((c.sto.byte, c.sto.bit, c.sto.sub), (0, 0, 0x01));
    assert_eq!((c.sdip.byte, c.sdip.bit, c.sdip.sub), (0, 5, 0x04));
    assert_eq!(
        (c.error_ack.byte, c.error_ack.bit, c.error_ack.sub),
        (0, 7, 0x06)
    );
    assert_eq!((c.slt[3].byte, c.slt[3].bit, c.slt[3].sub), (2, 0, 0x0F));
    let (req, ack) = decode_commands(c, &sd);
    assert_eq!((req, ack), (SafetyRequest::RUN, false));
}

#[test]
fn tv_12_run_command_lets_the_drive_enable_and_move() {
    let mut r = Rig::running(FsoeSlaveParams::default());
    let (sw, s) = r.step(0x0F);
    assert!(masked(sw, 0x416F, 0x0027), "{sw}");
    assert!(!s.sto && !s.error, "{s:?}");
    assert!(!s.ss1 && !s.sdip && !s.sdin && s.sls == [false; 4] && s.slt == [false; 4]);
    let start = r.d.tx_pdo().position_actual;
    for k in 1..=300 {
        r.step_to(0x0F, start + 500 * k);
    }
    assert!(
        r.d.tx_pdo().position_actual - start > 100_000,
        "the motor moved"
    );
    assert!(!r.d.safe_torque_off());
}

#[test]
fn tv_12_sto_request_0x62_sets_stos_and_the_drive_loses_torque() {
    let mut r = Rig::running(FsoeSlaveParams::default());
    let start = r.d.tx_pdo().position_actual;
    for k in 1..=200 {
        r.step_to(0x0F, start + 1_000 * k);
    }
    let v0 = r.d.plant().velocity();
    assert!(v0 > 0.0, "moving before STO");
    r.m.request(SafetyRequest::STO);
    let n = r.until_sto(SafetyRequest::STO, true, 0x0F, t_ref_cycles());
    assert_eq!(r.sent[1], 0x62, "SafeData[0] of the STO request");
    assert!(n >= 1);
    // Energy cut: not in Operation enabled (nor switched on), no torque, the motor coasts.
    let pos = r.d.tx_pdo().position_actual;
    for k in 1..=20 {
        let (sw, s) = r.step_to(0x0F, pos + 1_000 * k);
        assert!(s.sto);
        assert!(!masked(sw, 0x006F, 0x0027), "not Operation enabled: {sw}");
        assert_eq!(r.d.state(), FsaState::SwitchOnDisabled);
        assert_eq!(r.d.tx_pdo().torque_actual, 0, "6077h");
        assert_eq!(r.d.plant().acceleration(), 0.0);
    }
    assert!(r.d.safe_torque_off());
    // Enable commands are refused while STO is active.
    for cw in [0x06, 0x07, 0x0F] {
        r.step(cw);
        assert_eq!(r.d.state(), FsaState::SwitchOnDisabled);
    }
    // Run command again: STO cancelled, the drive can be enabled again.
    r.until_sto(SafetyRequest::RUN, false, 0x00, t_ref_cycles());
    for cw in [0x06, 0x07, 0x0F] {
        r.step(cw);
    }
    assert_eq!(r.d.state(), FsaState::OperationEnabled);
}

#[test]
fn tv_12_sto_with_a_dynamic_brake_stop_also_gives_no_drive_torque() {
    let mut r = Rig::running(FsoeSlaveParams {
        sto_stop: StoStop::DynamicBrake,
        ..FsoeSlaveParams::default()
    });
    let start = r.d.tx_pdo().position_actual;
    for k in 1..=200 {
        r.step_to(0x0F, start + 1_000 * k);
    }
    r.until_sto(SafetyRequest::STO, true, 0x0F, t_ref_cycles());
    for _ in 0..200 {
        r.step(0x0F);
        assert_ne!(r.d.state(), FsaState::OperationEnabled);
    }
    assert_eq!(r.d.plant().velocity(), 0.0, "braked to standstill");
}

#[test]
fn tv_12_sto_delay_is_a_named_parameter() {
    // The delay before STOS = 1 is not stated (TV-12): `sto_delay_cycles`.
    for delay in [0u32, 5] {
        let mut r = Rig::running(FsoeSlaveParams {
            sto_delay_cycles: delay,
            ..FsoeSlaveParams::default()
        });
        r.m.request(SafetyRequest::STO);
        let mut states = Vec::new();
        for _ in 0..delay + 3 {
            let (_, s) = r.step(0x0F);
            states.push((r.d.state(), s.sto));
        }
        let cut = states
            .iter()
            .position(|(st, _)| *st != FsaState::OperationEnabled)
            .unwrap();
        assert_eq!(cut as u32, delay, "{states:?}");
        // STOS is reported in the next safety frame after the torque cut.
        assert!(states[cut + 1].1 && !states[cut].1, "{states:?}");
    }
}

#[test]
fn tv_12_error_ack_is_a_rising_edge_0x63_then_0xe3() {
    let mut m = master(1, 16);
    m.request(SafetyRequest::RUN);
    let mut f = [0u8; 11];
    assert_eq!(m.write_frame(&mut f).unwrap()[0], 0x63);
    m.acknowledge_errors();
    assert_eq!(m.write_frame(&mut f).unwrap()[0], 0xE3, "bit 7 rising");
    assert_eq!(
        m.write_frame(&mut f).unwrap()[0],
        0x63,
        "one edge per request"
    );
    // Two requests in a row still give a 0 between the two edges.
    m.acknowledge_errors();
    assert_eq!(m.write_frame(&mut f).unwrap()[0], 0xE3);
    m.acknowledge_errors();
    assert_eq!(m.write_frame(&mut f).unwrap()[0], 0x63);
    assert_eq!(m.write_frame(&mut f).unwrap()[0], 0xE3);
}

/// Drives the slave with raw SafeData[0] values (the rest of the run command).
fn raw(d: &mut SimDrive, sd0: u8) -> SafetyStatus {
    let f = FsoeFrame {
        command: 0,
        safe_data: [sd0, 0xEF, 0x01, 0x00],
        crc: [0, 0],
        connection_id: 1,
    };
    let (mut rx, mut tx) = ([0u8; 11], [0u8; 11]);
    f.encode(&FSOE.frame, &mut rx).unwrap();
    d.fsoe_exchange(&rx, &mut tx).unwrap();
    send(d, 0);
    let back = FsoeFrame::decode(&FSOE.frame, &tx).unwrap();
    cellrt_cia402::fsoe::decode_status(&FSOE.status, &back.safe_data)
}

#[test]
fn tv_12_error_ack_clears_the_error_only_on_the_edge() {
    let params = ConnectionParams {
        slave_address: 1,
        connection_id: 1,
        watchdog_ms: 16,
        comm_param_len: 2,
        app_param_len: 0,
    };
    let mut d = jet_fsoe(FsoeSlaveParams::default());
    d.fsoe_connect(&params).unwrap();
    for _ in 0..5 {
        raw(&mut d, 0xE3); // Error Ack held at 1
    }
    // An error: the safety frames stop for longer than the watchdog.
    for _ in 0..40 {
        send(&mut d, 0);
    }
    d.fsoe_connect(&params).unwrap();
    // The level 1 is not an edge: the error stays and holds STO (`error_holds_sto`).
    for _ in 0..5 {
        let s = raw(&mut d, 0xE3);
        assert!(s.error && s.sto, "{s:?}");
    }
    let s = raw(&mut d, 0x63);
    assert!(s.error, "no acknowledge yet");
    raw(&mut d, 0xE3); // the rising edge
    let s = raw(&mut d, 0x63);
    assert!(!s.error, "{s:?}");
    assert!(
        !raw(&mut d, 0x63).sto,
        "STO cancelled once the error is gone"
    );
}

#[test]
fn tv_12_watchdog_of_15_ms_is_refused_by_the_master() {
    let p = profile(DriveModel::MrJetGN1);
    let at = |us: u32| CycleTime::from_micros(us).unwrap();
    let e = FsoeMaster::new(p, at(250), FsoeMasterConfig::new(1, 15)).unwrap_err();
    assert_eq!(
        e,
        FsoeError::WatchdogTooShort {
            watchdog_ms: 15,
            minimum_ms: 16
        }
    );
    let text = e.to_string();
    assert!(text.contains("15 ms") && text.contains("16 ms"), "{text}");
    // 16 ms = T_Ref + 4 × T_Com = 15 + 4 × 0.25 is the minimum (§7.3), at every cycle.
    assert_eq!(FSOE.t_ref_us + 4 * FSOE.t_com_min_us, 16_000);
    for us in [250, 500, 1000, 8000] {
        assert!(FsoeMaster::new(p, at(us), FsoeMasterConfig::new(1, 16)).is_ok());
    }
    // [inferred] The cycle-scaled rule, where chosen: 1 ms needs 19 ms, 8 ms 47 ms.
    let scaled = |wd: u16| FsoeMasterConfig {
        watchdog_rule: WatchdogRule::ScaledWithCycle,
        ..FsoeMasterConfig::new(1, wd)
    };
    assert!(matches!(
        FsoeMaster::new(p, at(1000), scaled(18)),
        Err(FsoeError::WatchdogTooShort { minimum_ms: 19, .. })
    ));
    assert!(FsoeMaster::new(p, at(1000), scaled(19)).is_ok());
    assert!(matches!(
        FsoeMaster::new(p, at(8000), scaled(46)),
        Err(FsoeError::WatchdogTooShort { minimum_ms: 47, .. })
    ));
    assert!(FsoeMaster::new(p, at(250), scaled(16)).is_ok());
}

#[test]
fn tv_12_the_slave_shows_the_watchdog_it_received_in_e901h_04() {
    let mut r = Rig::new(FsoeSlaveParams::default());
    assert_eq!(r.d.sdo_upload(0xE901, 0x04), Ok(16));
    assert_eq!(r.d.sdo_upload(0xE901, 0x07), Ok(2));
    assert_eq!(r.d.sdo_upload(0xE901, 0x08), Ok(0));
    let m = FsoeMaster::new(
        profile(DriveModel::MrJetGN1),
        CycleTime::from_micros(US).unwrap(),
        FsoeMasterConfig::new(1, 100),
    )
    .unwrap();
    r.d.fsoe_connect(&m.connection_params()).unwrap();
    assert_eq!(r.d.sdo_upload(0xE901, 0x04), Ok(100));
}

#[test]
fn tv_12_psc07_different_from_the_master_address_raises_al_584_1() {
    let mut d = jet_fsoe(FsoeSlaveParams {
        psc07_address: 7,
        ..FsoeSlaveParams::default()
    });
    boot(&mut d);
    let m = master(8, 16);
    let e = d.fsoe_connect(&m.connection_params()).unwrap_err();
    assert_eq!(
        e,
        FsoeError::AddressMismatch {
            master: 8,
            psc07: 7,
            alarm: AL_584_1
        }
    );
    assert!(e.to_string().contains("AL.584.1"), "{e}");
    for _ in 0..5 {
        send(&mut d, 0);
    }
    assert_eq!(d.alarm(), Some(AL_584_1));
    assert_eq!(d.tx_pdo().error_code, AL_584_1, "603Fh");
    assert_eq!(d.state(), FsaState::Fault);
    let s = d.fsoe_status().unwrap();
    assert!(s.sto && s.error, "{s:?}");
    // The matching address connects.
    let mut ok = jet_fsoe(FsoeSlaveParams {
        psc07_address: 7,
        ..FsoeSlaveParams::default()
    });
    assert_eq!(ok.fsoe_connect(&master(7, 16).connection_params()), Ok(()));
    send(&mut ok, 0);
    assert_eq!(ok.alarm(), None);
}

#[test]
fn fsoe_needs_a_cycle_of_0_25_ms_or_more() {
    // [inferred] (§1.3): no FSoE at 0.125 ms, configurable.
    let p = profile(DriveModel::MrJetGN1);
    let fast = CycleTime::from_micros(125).unwrap();
    let e = FsoeMaster::new(p, fast, FsoeMasterConfig::new(1, 16)).unwrap_err();
    assert_eq!(
        e,
        FsoeError::CycleTooShort {
            cycle_us: 125,
            minimum_us: 250
        }
    );
    assert!(e.to_string().contains("125 µs"), "{e}");
    let cfg = FsoeMasterConfig {
        min_cycle_us: Some(125),
        ..FsoeMasterConfig::new(1, 16)
    };
    assert!(FsoeMaster::new(p, fast, cfg).is_ok(), "configurable");
    // The slave refuses the connection at 0.125 ms unless configured otherwise.
    let params = FsoeMaster::new(
        p,
        CycleTime::from_micros(250).unwrap(),
        FsoeMasterConfig::new(1, 16),
    )
    .unwrap()
    .connection_params();
    let slave = |min| {
        drive(
            DriveModel::MrJetGN1,
            125,
            SimDriveParams {
                fsoe: Some(FsoeSlaveParams {
                    min_cycle_us: min,
                    ..FsoeSlaveParams::default()
                }),
                ..SimDriveParams::default()
            },
        )
    };
    assert!(matches!(
        slave(None).fsoe_connect(&params),
        Err(FsoeError::CycleTooShort { cycle_us: 125, .. })
    ));
    assert_eq!(slave(Some(125)).fsoe_connect(&params), Ok(()));
}

#[test]
fn fsoe_before_the_connection_the_drive_is_in_sto() {
    // [background] ETG.5100: safe state until the connection runs.
    let mut d = jet_fsoe(FsoeSlaveParams::default());
    boot(&mut d);
    for cw in [0x06, 0x07, 0x0F] {
        send(&mut d, cw);
    }
    assert_eq!(d.state(), FsaState::SwitchOnDisabled);
    assert!(d.safe_torque_off());
    assert!(d.fsoe_status().unwrap().sto);
    // Without FSoE configured, the same drive enables (no STO from the network).
    let mut plain = drive(DriveModel::MrJetGN1, US, SimDriveParams::default());
    boot(&mut plain);
    for cw in [0x06, 0x07, 0x0F] {
        send(&mut plain, cw);
    }
    assert_eq!(plain.state(), FsaState::OperationEnabled);
    assert!(plain.fsoe_status().is_none());
}

#[test]
fn fsoe_watchdog_expiry_is_sto_with_error_as_the_named_default() {
    // The reaction is not in the manual (§7.3); [background] ETG.5100 fail-safe state.
    let mut r = Rig::running(FsoeSlaveParams::default());
    // 16 ms at 1 ms: 16 cycles without a safety frame are still within the watchdog.
    for _ in 0..16 {
        send(&mut r.d, 0x0F);
    }
    assert_eq!(r.d.state(), FsaState::OperationEnabled);
    assert!(!r.d.safe_torque_off());
    send(&mut r.d, 0x0F);
    assert!(r.d.safe_torque_off());
    assert_ne!(r.d.state(), FsaState::OperationEnabled);
    assert!(r.d.fsoe_status().unwrap().error);
    assert_eq!(r.d.alarm(), None, "no alarm named: `watchdog_alarm` = None");
    // With an alarm configured, the drive raises it.
    let mut r = Rig::running(FsoeSlaveParams {
        watchdog_alarm: Some(0x7777),
        ..FsoeSlaveParams::default()
    });
    for _ in 0..20 {
        send(&mut r.d, 0x0F);
    }
    assert_eq!(r.d.alarm(), Some(0x7777));
    assert_eq!(r.d.state(), FsaState::Fault);
}

#[test]
fn fsoe_sbcs_and_ssms_follow_their_named_parameters_only() {
    // SBCS following STO is [inferred] (TV-12): not asserted generically.
    for follows in [false, true] {
        let mut r = Rig::new(FsoeSlaveParams {
            sbc_follows_sto: follows,
            ..FsoeSlaveParams::default()
        });
        let s = r.step(0).1;
        assert!(s.sto);
        assert_eq!(s.sbc, follows);
    }
    // SSM disabled: SSMS = 0 (§7.2); with an SSM speed, 1 at standstill.
    let mut r = Rig::new(FsoeSlaveParams::default());
    assert!(!r.step(0).1.ssm);
    let mut r = Rig::new(FsoeSlaveParams {
        ssm_speed: Some(100.0),
        ..FsoeSlaveParams::default()
    });
    assert!(r.step(0).1.ssm);
}

#[test]
fn fsoe_sub_function_commands_come_back_at_their_status_bits() {
    let mut r = Rig::new(FsoeSlaveParams::default());
    let req = SafetyRequest {
        ss1: true,
        sdin: true,
        sls: [false, true, false, false],
        slt: [false, false, false, true],
        ..SafetyRequest::RUN
    };
    r.m.request(req);
    r.step(0);
    let mut tx = [0u8; 11];
    r.m.write_frame(&mut r.sent).unwrap();
    r.d.fsoe_exchange(&r.sent, &mut tx).unwrap();
    let s = r.m.read_frame(&tx).unwrap();
    assert!(s.ss1 && s.sdin && !s.sdip, "{s:?}");
    assert_eq!(s.sls, [false, true, false, false]);
    assert_eq!(s.slt, [false, false, false, true]);
    // §7.2 status positions: SS1S b1.0, SDINS b1.3, SLS2S b1.5, SLT4S b2.5.
    assert_eq!(tx[2], 0b0010_1001, "SafeData[1]");
    assert_eq!(tx[5] & 0b0011_1100, 0b0010_0000, "SafeData[2] SLT bits");
    // The slave echoes the master's ConnectionID (opaque, see the module doc).
    assert_eq!(u16::from_le_bytes([tx[9], tx[10]]), 1);
}

#[test]
fn fsoe_objects_by_sdo() {
    let mut r = Rig::new(FsoeSlaveParams::default());
    r.m.request(SafetyRequest::STO);
    r.step(0);
    r.step(0);
    assert_eq!(r.d.sdo_upload(0x1608, 0), Ok(0x24));
    assert_eq!(r.d.sdo_upload(0x1A08, 0), Ok(0x24));
    assert_eq!(r.d.sdo_upload(0xF601, 0x01), Ok(1), "STOS");
    assert_eq!(
        r.d.sdo_upload(0xF701, 0x01),
        Ok(0),
        "STOC = 0: STO requested"
    );
    assert_eq!(r.d.sdo_upload(0xF701, 0x02), Ok(1), "SS1C cancelled");
    assert_eq!(r.d.sdo_upload(0xE700, 0x02), Ok(1), "master ConnectionID");
    assert_eq!(r.d.sdo_upload(0xF601, 0x03), Err(SdoAbort::NO_SUBINDEX));
    assert_eq!(
        r.d.sdo_download(0xE901, 0x04, &[15, 0]),
        Err(SdoAbort::READ_ONLY)
    );
    // A drive without FSoE has none of these objects.
    let plain = drive(DriveModel::MrJetGN1, US, SimDriveParams::default());
    assert_eq!(plain.sdo_upload(0x1608, 0), Err(SdoAbort::NO_OBJECT));
}

#[test]
fn fsoe_bad_input_is_an_error_not_a_panic() {
    let mut r = Rig::new(FsoeSlaveParams::default());
    let mut tx = [0u8; 11];
    for n in [0usize, 10, 12] {
        let rx = vec![0u8; n];
        assert_eq!(
            r.d.fsoe_exchange(&rx, &mut tx),
            Err(FsoeError::FrameLength {
                expected: 11,
                actual: n
            })
        );
        let mut out = vec![0u8; n];
        assert!(r.m.write_frame(&mut out).is_err());
        assert!(r.m.read_frame(&out).is_err());
    }
    let mut short = [0u8; 10];
    assert!(r.d.fsoe_exchange(&[0u8; 11], &mut short).is_err());
    // Models without FSoE, and an address outside PSC07's range.
    let j5 = profile(DriveModel::MrJ5GN1);
    let ct = CycleTime::from_micros(US).unwrap();
    let e = FsoeMaster::new(j5, ct, FsoeMasterConfig::new(1, 16)).unwrap_err();
    assert!(e.to_string().contains("mr-j5-g-n1"), "{e}");
    let mut d = drive(
        DriveModel::MrJ5GN1,
        US,
        SimDriveParams {
            fsoe: Some(FsoeSlaveParams::default()),
            ..SimDriveParams::default()
        },
    );
    assert!(matches!(
        d.fsoe_connect(&r.m.connection_params()),
        Err(FsoeError::NotSupported { .. })
    ));
    assert!(d.fsoe_exchange(&[0u8; 11], &mut tx).is_err());
    let jet = profile(DriveModel::MrJetGN1);
    assert!(matches!(
        FsoeMaster::new(jet, ct, FsoeMasterConfig::new(0, 16)),
        Err(FsoeError::AddressOutOfRange { address: 0, .. })
    ));
    // PSA01.0 / PSA01.1 must be set before connecting (§7.1).
    for (p0, p1, want) in [
        (false, true, FsoeError::SafetyDisabled),
        (true, false, FsoeError::NotNetworkMode),
    ] {
        let mut d = jet_fsoe(FsoeSlaveParams {
            psa01_0_enabled: p0,
            psa01_1_network: p1,
            ..FsoeSlaveParams::default()
        });
        assert_eq!(d.fsoe_connect(&r.m.connection_params()), Err(want));
    }
}

#[test]
fn fsoe_safety_pdo_layout_matches_section_5_4() {
    let f = &FSOE;
    assert_eq!(
        (f.rx_pdo, f.tx_pdo, f.mapping_entries),
        (0x1608, 0x1A08, 0x24)
    );
    assert_eq!(f.frame.len, 11);
    // Every byte of the 11 is used exactly once.
    let mut used = [0u8; 11];
    used[usize::from(f.frame.command)] += 1;
    for b in f.frame.safe_data {
        used[usize::from(b)] += 1;
    }
    for b in f.frame.crc.into_iter().chain([f.frame.connection_id]) {
        used[usize::from(b)] += 1;
        used[usize::from(b) + 1] += 1;
    }
    assert_eq!(used, [1; 11]);
    let s = &f.status;
    assert_eq!((s.sto.byte, s.sto.bit, s.sto.sub), (0, 0, 0x01));
    assert_eq!((s.error.byte, s.error.bit, s.error.sub), (0, 7, 0x04));
    assert_eq!((s.sbc.byte, s.sbc.bit, s.sbc.sub), (2, 0, 0x0D));
    assert_eq!((s.slt[3].byte, s.slt[3].bit, s.slt[3].sub), (2, 5, 0x12));
    assert_eq!(f.watchdog_min_ms, 16);
}

#[test]
fn fsoe_cycle_is_allocation_free() {
    let mut r = Rig::running(FsoeSlaveParams::default());
    let before = thread_heap_calls();
    for k in 0..2_000 {
        if k == 1_000 {
            r.m.request(SafetyRequest::STO);
        }
        if k == 1_500 {
            r.m.request(SafetyRequest::RUN);
            r.m.acknowledge_errors();
        }
        r.step(0x0F);
    }
    assert_eq!(thread_heap_calls() - before, 0);
}
