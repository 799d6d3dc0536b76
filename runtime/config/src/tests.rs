use std::path::Path;

use super::*;

fn demo_text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/demo.toml"
    ))
    .expect("configs/demo.toml")
    .replace("cpu = 1 ", "# cpu = 1 ")
}

fn parse(text: &str) -> Result<CellConfig, ConfigError> {
    CellConfig::parse(Path::new("cell.toml"), text)
}

#[test]
fn demo_config_is_valid_and_typed() {
    let c = parse(&demo_text()).expect("demo parses");
    assert_eq!(c.name, "demo");
    assert_eq!(c.cycle_time.as_micros(), 1000);
    assert_eq!(c.axes.loop_names(), "x, y, z, c");
    assert_eq!(c.axes.on_loop()[3].unit, "deg");
    assert_eq!(c.axes.on_loop()[0].scaling.counts_per_unit(), 1000.0);
    // Defaults: stop deceleration = acceleration, following-error limit = 0.1 s at full speed.
    assert_eq!(
        c.axes.on_loop()[0].stop_deceleration,
        c.axes.on_loop()[0].limits.acceleration
    );
    assert_eq!(c.axes.on_loop()[0].following_error_limit, 40.0);
    assert_eq!(
        c.program,
        Some(Path::new("demo-program.toml").to_path_buf())
    );
}

#[test]
fn every_allowed_cycle_time_parses() {
    for us in [125, 250, 500, 1000, 2000, 4000, 8000] {
        let text = demo_text().replace("cycle_time_us = 1000", &format!("cycle_time_us = {us}"));
        assert_eq!(parse(&text).unwrap().cycle_time.as_micros(), us);
    }
}

#[test]
fn unknown_compression_names_the_key() {
    let text = demo_text().replace(r#"compression = "zstd""#, r#"compression = "gzip""#);
    let e = parse(&text).unwrap_err();
    assert_eq!(e.key, "recording.compression");
    assert!(e.message.contains("gzip"), "{e}");
}

#[test]
fn position_range_beyond_32_bit_counts_is_refused() {
    let text = demo_text().replace("position = [0.0, 800.0]", "position = [0.0, 8000000.0]");
    let e = parse(&text).unwrap_err();
    assert_eq!(e.key, "axes[0].limits.position");
    assert!(e.message.contains("32-bit"), "{e}");
}

#[test]
fn bad_cell_name_and_priority_are_refused() {
    let e = parse(&demo_text().replace(r#"name = "demo""#, r#"name = "de mo""#)).unwrap_err();
    assert_eq!(e.key, "cell.name");
    let e = parse(&demo_text().replace("priority = 80", "priority = 0")).unwrap_err();
    assert_eq!(e.key, "rt.priority");
}

#[test]
fn missed_deadlines_are_skipped_by_default_stretched_on_request_and_bad_names_refused() {
    assert_eq!(
        parse(&demo_text()).unwrap().rt.missed_deadlines,
        MissedDeadlines::Skip
    );
    let stretch = demo_text().replace(
        "priority = 80",
        "priority = 80\nmissed_deadlines = \"stretch\"",
    );
    assert_eq!(
        parse(&stretch).unwrap().rt.missed_deadlines,
        MissedDeadlines::Stretch
    );
    let e = parse(&stretch.replace("\"stretch\"", "\"catch_up\"")).unwrap_err();
    assert_eq!(e.key, "rt.missed_deadlines");
    assert!(
        e.message.contains("\"skip\", \"stretch\"") && e.message.contains("catch_up"),
        "{e}"
    );
}

#[test]
fn the_planner_thread_runs_below_the_rt_thread_or_sched_other() {
    assert_eq!(parse(&demo_text()).unwrap().rt.planner_priority, Some(40));
    let e =
        parse(&demo_text().replace("planner_priority = 40", "planner_priority = 80")).unwrap_err();
    assert_eq!(e.key, "rt.planner_priority");
    assert!(e.message.contains("below the RT thread's (80)"), "{e}");
    let off = parse(&demo_text().replace("planner_priority = 40", "planner_priority = 0")).unwrap();
    assert_eq!(off.rt.planner_priority, None);
    let default = parse(&demo_text().replace("planner_priority = 40", "")).unwrap();
    assert_eq!(
        default.rt.planner_priority, None,
        "SCHED_OTHER unless asked for"
    );
}

#[test]
fn initial_position_outside_range_is_refused() {
    let text = demo_text().replacen(
        "sim = { initial_position = 50.0 }",
        "sim = { initial_position = 900.0 }",
        1,
    );
    let e = parse(&text).unwrap_err();
    assert_eq!(e.key, "axes[0].sim.initial_position");
}

#[test]
fn errors_render_file_line_key_message() {
    let e = parse("[cell]\nname = \"a\"\ncycle_time_us = 1000\nbogus = 1\n").unwrap_err();
    let s = e.to_string();
    assert!(s.starts_with("cell.toml:"), "{s}");
    assert!(s.contains("bogus"), "{s}");
}

#[test]
fn lookahead_beyond_the_setpoint_buffer_is_refused() {
    let text = demo_text()
        .replace("cycle_time_us = 1000", "cycle_time_us = 125")
        .replace("lookahead_ms = 100", "lookahead_ms = 1000");
    let e = parse(&text).unwrap_err();
    assert_eq!(e.key, "setpoints.lookahead_ms");
    assert!(e.message.contains("setpoint buffer"), "{e}");
    // 1000 ms fits at 1 ms cycles.
    parse(&demo_text().replace("lookahead_ms = 100", "lookahead_ms = 1000")).unwrap();
}

#[test]
fn the_start_slip_defaults_to_100_ms_within_the_buffer_and_is_checked() {
    let c = parse(&demo_text()).unwrap();
    assert_eq!(c.setpoints.max_start_slip, Cycles(100));
    // At 125 µs the buffer holds 252 blocks of 16 cycles = 4032 cycles: 500 ms of lookahead
    // leaves 32 cycles, and the default takes what is left instead of 800.
    let fast = demo_text()
        .replace("cycle_time_us = 1000", "cycle_time_us = 125")
        .replace("lookahead_ms = 100", "lookahead_ms = 500");
    assert_eq!(parse(&fast).unwrap().setpoints.max_start_slip, Cycles(32));
    let slip = |v: &str| {
        demo_text().replace(
            "start_delay_ms = 20",
            &format!("start_delay_ms = 20\nmax_start_slip_ms = {v}"),
        )
    };
    assert_eq!(
        parse(&slip("0")).unwrap().setpoints.max_start_slip,
        Cycles(0)
    );
    assert_eq!(
        parse(&slip("2.5")).unwrap().setpoints.max_start_slip,
        Cycles(3)
    );
    for bad in ["-1", "nan", "4000"] {
        let e = parse(&slip(bad)).unwrap_err();
        assert_eq!(e.key, "setpoints.max_start_slip_ms", "{bad}: {e}");
    }
    let e = parse(&slip("4000")).unwrap_err();
    assert!(e.message.contains("room for 3932 more cycles"), "{e}");
}

#[test]
fn recording_rotation_and_flush_are_validated() {
    let with = |extra: &str| {
        demo_text().replace(
            r#"compression = "zstd""#,
            &format!("compression = \"zstd\"\n{extra}"),
        )
    };
    let c = parse(&with(
        "rotate_mib = 64\nrotate_seconds = 600\nflush_ms = 100",
    ))
    .unwrap();
    assert_eq!(c.recording.rotate_bytes, Some(64 * 1024 * 1024));
    assert_eq!(c.recording.rotate_seconds, Some(600.0));
    assert_eq!(c.recording.flush_ms, 100);
    let d = parse(&demo_text()).unwrap();
    assert_eq!(d.recording.rotate_bytes, None);
    assert_eq!(d.recording.rotate_seconds, None);
    assert_eq!(d.recording.flush_ms, 200);
    for (extra, key) in [
        ("rotate_mib = 0", "recording.rotate_mib"),
        ("rotate_seconds = 0.5", "recording.rotate_seconds"),
        ("rotate_seconds = nan", "recording.rotate_seconds"),
        ("flush_ms = 5", "recording.flush_ms"),
    ] {
        let e = parse(&with(extra)).unwrap_err();
        assert_eq!(e.key, key, "{extra}: {e}");
    }
}

fn ethercat_text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/ethercat-cell.toml"
    ))
    .expect("configs/ethercat-cell.toml")
}

#[test]
fn the_ethercat_cell_is_valid_and_typed() {
    let c = parse(&ethercat_text()).expect("ethercat cell parses");
    let ec = c.ethercat.as_ref().expect("[ethercat]");
    assert_eq!(ec.interface, EthercatInterface::Nic("ecat0".into()));
    assert_eq!(ec.frame_timeout, std::time::Duration::from_micros(500));
    assert!(c
        .axes
        .on_loop()
        .iter()
        .all(|a| a.transport == Transport::Ethercat));
    // The MR-J3-T04 identity from its manual; the others: Mitsubishi's vendor, any product.
    assert_eq!(
        c.axes.on_loop()[0].ethercat_identity.product_code,
        Some(0x102)
    );
    assert_eq!(c.axes.on_loop()[3].ethercat_identity.product_code, None);
    let mut c = c;
    c.set_ethercat_interface("in-process").unwrap();
    assert_eq!(c.ethercat.unwrap().interface, EthercatInterface::InProcess);
    let mut demo = parse(&demo_text()).unwrap();
    let e = demo.set_ethercat_interface("eth0").unwrap_err().to_string();
    assert!(e.contains("no EtherCAT axes"), "{e}");
}

#[test]
fn ethercat_bad_input_names_the_key_and_the_reason() {
    let cases: [(String, &str, &str); 7] = [
        (
            ethercat_text().replacen("transport = \"ethercat\"", "transport = \"profinet\"", 1),
            "axes[0].transport",
            "available: sim, ethercat",
        ),
        (
            ethercat_text().replacen("transport = \"ethercat\"", "transport = \"sim\"", 1),
            "axes[0].transport",
            "a cell runs one transport",
        ),
        (
            ethercat_text()
                .replace("[ethercat]", "[unused]")
                .replace("interface = \"ecat0\"", "")
                .replace("frame_timeout_us = 500", "")
                .replace("[unused]", ""),
            "axes[0].transport",
            "no [ethercat] section",
        ),
        (
            demo_text() + "\n[ethercat]\ninterface = \"eth0\"\n",
            "ethercat",
            "no axis has transport",
        ),
        (
            ethercat_text().replace("interface = \"ecat0\"", "interface = \"a/b\""),
            "ethercat.interface",
            "not a network interface name",
        ),
        (
            ethercat_text().replace("frame_timeout_us = 500", "frame_timeout_us = 5"),
            "ethercat.frame_timeout_us",
            "10..=1000000",
        ),
        (
            ethercat_text().replacen(
                "sim = { initial_position",
                "sim = { motor_speed_factor = 0.5, initial_position",
                1,
            ),
            "axes[0].sim.motor_speed_factor",
            "must be 1..=10",
        ),
    ];
    for (text, key, reason) in cases {
        let e = parse(&text).unwrap_err();
        assert_eq!(e.key, key, "{e}");
        assert!(e.message.contains(reason), "{e}");
    }
}

/// An MR-J5-G-N1 axis with the motor resolution its manual does not give.
const J5_WITH_MOTOR: &str = "drive = \"mr-j5-g-n1\"\nmotor = { counts_per_rev = 67108864 }";

/// A multi-axis amplifier over EtherCAT: its axes keep their amplifier slots (one SubDevice);
/// a cycle of 0.125 ms, which the J5W2/W3 do not run (MR-J5-G-N1 manual §2.1, §4.1, §6.2, §6.3, TV-6), is refused
/// naming the axis.
#[test]
fn a_multi_axis_unit_over_ethercat_keeps_its_slots_and_refuses_125_us() {
    let text = ethercat_text().replacen(
        "drive = \"mr-j5-g-n1\"",
        "drive = \"mr-j5w2-g-n1\"\namplifier = \"w2\"\namplifier_axis = 1",
        1,
    );
    let c = parse(&text).expect("a J5W2 axis over EtherCAT");
    let slot = c.axes.on_loop()[3]
        .amplifier
        .as_ref()
        .expect("amplifier slot");
    assert_eq!((slot.label.as_str(), slot.slot), ("w2", 1));
    assert!(c.axes.on_loop()[0].amplifier.is_none());

    let text: String = text
        .lines()
        .filter(|l| !l.starts_with("pdo = "))
        .map(|l| format!("{l}\n"))
        .collect();
    let text = text
        .replacen("cycle_time_us = 1000", "cycle_time_us = 125", 1)
        .replace("drive = \"mr-j3-t04\"", J5_WITH_MOTOR)
        .replace("drive = \"mr-j4-tm\"", J5_WITH_MOTOR)
        .replace("drive = \"mr-jet-g-n1\"", "drive = \"mr-j5-g-n1\"");
    let e = parse(&text).unwrap_err();
    assert_eq!(e.key, "axes[3].drive", "{e}");
    assert!(
        e.message.contains("'c'") && e.message.contains("125"),
        "{e}"
    );
}

/// `[axes.pdo]`: a mapping other than the model's default, checked against the model's rules and
/// against what the axis' mode needs; the axis' profile runs it.
#[test]
fn a_pdo_mapping_from_the_config_is_checked_and_runs_in_the_axis_profile() {
    // The example cell's x (MR-J3-T04) already has a mapping: replace it.
    let with = |pdo: &str| {
        let text = ethercat_text();
        let line = text
            .lines()
            .find(|l| l.starts_with("pdo = "))
            .expect("the example cell maps axis x")
            .to_owned();
        text.replacen(&line, &format!("pdo = {{ {pdo} }}"), 1)
    };
    let c = parse(&ethercat_text()).expect("the example cell's csp-only RxPDO of the MR-J3-T04");
    let x = &c.axes.on_loop()[0].profile;
    assert_eq!(x.pdo.rx.byte_len(), 10);
    assert_eq!(x.pdo.rx.offset_of(0x607A, 0), Some(6));
    assert_eq!(x.pdo.rx.index, 0x1614);
    assert_eq!(
        x.pdo.tx,
        cellrt_cia402::profile(cellrt_cia402::DriveModel::MrJ3T04)
            .pdo
            .tx
    );
    assert!(!x.default_mapping() && c.axes.on_loop()[1].profile.default_mapping());
    for (pdo, key, reason) in [
        ("rx = [0x60400010, 0x60410010, 0x607A0020]", "axes[0].pdo.rx", "cannot map object 6041h:00 into the RxPDO"),
        ("rx = [0x60400010, 0x60FF0020]", "axes[0].pdo.rx", "must map 607Ah for mode csp"),
        ("tx = [0x60410010, 0x606C0020]", "axes[0].pdo.tx", "must map 6064h"),
        ("rx = [0x60400010, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020]", "axes[0].pdo.rx", "34 bytes, the drive takes at most 30"),
        ("rx = [0x60400010, 0x0000000C, 0x607A0020]", "axes[0].pdo.rx", "not byte aligned"),
        ("rxpdo = []", "axes[0].pdo", "unknown field"),
    ] {
        let Err(e) = parse(&with(pdo)) else {
            panic!("{pdo}: accepted");
        };
        assert!(e.key.starts_with(key), "{pdo}: {e}");
        assert!(e.to_string().contains(reason), "{pdo}: {e}");
    }
}

fn generic_text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/cia402-generic.toml"
    ))
    .expect("configs/cia402-generic.toml")
}

/// The example cell of the generic CiA 402 model: two EtherCAT axes on the in-process segment,
/// the configured identity in the expectation and in the profile the emulator presents, x
/// remapped (csp-only RxPDO), y on the default maps.
#[test]
fn the_generic_cia402_cell_is_valid_and_carries_its_identity() {
    use cellrt_ethercat::identity::SubDeviceIdentity;
    let c = parse(&generic_text()).expect("cia402-generic parses");
    assert_eq!(
        c.ethercat.as_ref().unwrap().interface,
        EthercatInterface::InProcess
    );
    assert_eq!(c.axes.loop_names(), "x, y");
    for a in c.axes.on_loop() {
        assert_eq!(a.drive, cellrt_cia402::DriveModel::GenericCia402);
        assert_eq!(a.transport, Transport::Ethercat);
        assert_eq!(a.ethercat_identity.vendor_id, 0xCE11_0000);
        assert_eq!(a.ethercat_identity.product_code, Some(0xCE11_0402));
        let presented = SubDeviceIdentity::of_profile(&a.profile);
        assert!(a.ethercat_identity.matches(&presented), "{}", a.name);
        assert_eq!(presented.vendor_id, 0xCE11_0000);
    }
    let (x, y) = (&c.axes.on_loop()[0], &c.axes.on_loop()[1]);
    assert_eq!(x.mode, ModeOfOperation::CyclicSyncPosition);
    assert_eq!(x.profile.pdo.rx.index, 0x1600);
    assert_eq!(x.profile.pdo.rx.byte_len(), 8);
    assert_eq!(x.profile.pdo.rx.offset_of(0x607A, 0), Some(4));
    assert!(!x.profile.default_mapping());
    assert_eq!(y.mode, ModeOfOperation::CyclicSyncTorque);
    assert!(y.profile.default_mapping());
    assert_eq!(
        y.profile.pdo.rx,
        cellrt_cia402::profile(cellrt_cia402::DriveModel::GenericCia402)
            .pdo
            .rx
    );
}

/// `drive = "cia402"` has no identity of its own: on EtherCAT both keys are required and the
/// error names the missing one; on the simulated transport they are optional.
#[test]
fn a_generic_cia402_axis_on_ethercat_needs_the_subdevices_identity() {
    let text = generic_text();
    let without = |key: &str| {
        text.replacen(
            "ethercat = { vendor_id = 0xCE110000, product_code = 0xCE110402 }",
            &match key {
                "vendor_id" => "ethercat = { product_code = 0xCE110402 }".to_string(),
                "product_code" => "ethercat = { vendor_id = 0xCE110000 }".to_string(),
                _ => String::new(),
            },
            1,
        )
    };
    for (missing, key) in [
        ("both", "axes[0].ethercat.vendor_id"),
        ("vendor_id", "axes[0].ethercat.vendor_id"),
        ("product_code", "axes[0].ethercat.product_code"),
    ] {
        let e = parse(&without(missing)).unwrap_err();
        assert_eq!(e.key, key, "{missing}: {e}");
        assert!(
            e.message
                .contains("drive 'cia402' needs the SubDevice's identity")
                && e.message.contains("axis 'x'"),
            "{missing}: {e}"
        );
    }
    // The second axis is checked too.
    let second = text
        .rsplitn(
            2,
            "ethercat = { vendor_id = 0xCE110000, product_code = 0xCE110402 }",
        )
        .collect::<Vec<_>>();
    let text2 = format!("{}{}", second[1], second[0]);
    let e = parse(&text2).unwrap_err();
    assert_eq!(e.key, "axes[1].ethercat.vendor_id", "{e}");
    // Simulated drives: no identity needed (nothing on the wire to check).
    let sim = without("both")
        .replace("transport = \"ethercat\"", "transport = \"sim\"")
        .replace("[ethercat]\n", "[unused_ethercat]\n");
    let sim = sim
        .lines()
        .filter(|l| {
            !l.starts_with("interface = ")
                && !l.starts_with("frame_timeout_us")
                && *l != "[unused_ethercat]"
        })
        .collect::<Vec<_>>()
        .join("\n");
    let c = parse(&sim).expect("a simulated generic cell needs no identity");
    assert!(c.ethercat.is_none());
    assert_eq!(c.axes.on_loop()[0].transport, Transport::Sim);
    // A Mitsubishi model keeps its maker's identity without the keys.
    let c = parse(&ethercat_text()).unwrap();
    assert_eq!(c.axes.on_loop()[1].ethercat_identity.vendor_id, 0xA1E);
}

/// A generic axis with a custom `[axes.pdo]`: every CiA 402 mappable object is accepted, the
/// CiA 301 limits and the mode's objects are enforced, errors name the key.
#[test]
fn a_generic_cia402_axis_takes_a_custom_mapping_checked_against_cia402() {
    let with = |pdo: &str| {
        generic_text().replacen(
            "pdo = { rx = [0x60400010, 0x60600008, 0x00000008, 0x607A0020] }",
            &format!("pdo = {{ {pdo} }}"),
            1,
        )
    };
    // csp with touch probe and position offset; a TxPDO with the digital inputs, touch-probe
    // status and the following error.
    let c = parse(&with(
        "rx = [0x60400010, 0x607A0020, 0x60B00020, 0x60B80010], \
         tx = [0x60410010, 0x60640020, 0x60F40020, 0x60FD0020, 0x60B90010, 0x603F0010]",
    ))
    .expect("CiA 402 mappable objects");
    let x = &c.axes.on_loop()[0].profile;
    assert_eq!(x.pdo.rx.byte_len(), 12);
    assert_eq!(x.pdo.tx.byte_len(), 18);
    assert_eq!(x.pdo.tx.offset_of(0x60FD, 0), Some(10));
    assert_eq!(x.pdo.tx.index, 0x1A00);
    // The identity survives the remapping.
    assert_eq!(x.vendor_id(), Some(0xCE11_0000));
    for (pdo, key, reason) in [
        (
            "rx = [0x60400010, 0x607A0020, 0x20010010]",
            "axes[0].pdo.rx",
            "cia402 cannot map object 2001h:00 into the RxPDO",
        ),
        (
            "rx = [0x60400010, 0x607A0020, 0x605A0010]",
            "axes[0].pdo.rx",
            "605Ah:00",
        ),
        (
            "tx = [0x60410010, 0x60640020, 0x607A0020]",
            "axes[0].pdo.tx",
            "607Ah:00 into the TxPDO",
        ),
        (
            "rx = [0x60400010, 0x60FF0020]",
            "axes[0].pdo.rx",
            "must map 607Ah for mode csp",
        ),
        (
            "rx = [0x60400010, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020, 0x607A0020]",
            "axes[0].pdo.rx",
            "66 bytes, the drive takes at most 64",
        ),
    ] {
        let Err(e) = parse(&with(pdo)) else {
            panic!("{pdo}: accepted");
        };
        assert_eq!(e.key, key, "{pdo}: {e}");
        assert!(e.to_string().contains(reason), "{pdo}: {e}");
    }
    // cst on the generic axis y needs 6071h and 60FFh in its RxPDO.
    let text = generic_text();
    let y_at = text.find("name = \"y\"").expect("axis y");
    let e = parse(&format!(
        "{}{}\npdo = {{ rx = [0x60400010, 0x60FF0020] }}\n",
        &text[..y_at],
        &text[y_at..]
    ))
    .unwrap_err();
    assert_eq!(e.key, "axes[1].pdo.rx", "{e}");
    assert!(e.message.contains("6071h"), "{e}");
}

/// The EtherCAT cell on the in-process segment with `inject` appended.
fn ethercat_in_process_with(inject: &str) -> String {
    ethercat_text().replace("interface = \"ecat0\"", "interface = \"in-process\"") + inject
}

#[test]
fn the_wire_faults_parse_on_the_emulated_segment() {
    let c = parse(&ethercat_in_process_with(
        "\n[[inject]]\nat_ms = 100\nfault = \"frame_delay\"\ndelay_us = 250\nduration_ms = 20\n\
         [[inject]]\nat_ms = 200\nfault = \"frame_corruption\"\nduration_ms = 5\naxis = \"z\"\n\
         [[inject]]\nat_ms = 300\nfault = \"frame_corruption\"\nduration_ms = 5\n\
         [[inject]]\nat_ms = 400\nfault = \"datagram_drop\"\nduration_ms = 3\n\
         [[inject]]\nat_ms = 500\nfault = \"link_loss\"\nduration_ms = 30\naxis = \"y\"\n\
         [[inject]]\nat_ms = 600\nfault = \"link_loss\"\nduration_ms = 30\n",
    ))
    .expect("parses");
    let faults: Vec<InjectedFault> = c.inject.iter().map(|i| i.fault).collect();
    assert_eq!(
        faults,
        [
            InjectedFault::FrameDelay {
                delay_ns: 250_000,
                cycles: 20
            },
            InjectedFault::FrameCorruption { axis: 2, cycles: 5 },
            InjectedFault::FrameCorruption { axis: 0, cycles: 5 },
            InjectedFault::DatagramDrop { cycles: 3 },
            InjectedFault::LinkLoss {
                axis: 1,
                cycles: 30
            },
            InjectedFault::LinkLoss {
                axis: 0,
                cycles: 30
            },
        ]
    );
    let names: Vec<&str> = faults.iter().map(InjectedFault::name).collect();
    assert_eq!(
        names,
        [
            "frame_delay",
            "frame_corruption",
            "frame_corruption",
            "datagram_drop",
            "link_loss",
            "link_loss"
        ]
    );
}

#[test]
fn wire_fault_bad_input_names_the_key() {
    let cases: [(&str, &str, &str); 8] = [
        (
            "fault = \"frame_delay\"\nduration_ms = 20",
            "inject[0].delay_us",
            "needs delay_us",
        ),
        (
            "fault = \"frame_delay\"\ndelay_us = 0\nduration_ms = 20",
            "inject[0].delay_us",
            "must be > 0",
        ),
        (
            "fault = \"frame_delay\"\ndelay_us = 100",
            "inject[0].duration_ms",
            "needs duration_ms",
        ),
        (
            "fault = \"link_loss\"\nduration_ms = 5\ndelay_us = 3",
            "inject[0].delay_us",
            "only fault 'frame_delay'",
        ),
        (
            "fault = \"link_loss\"\nduration_ms = 5\naxis = \"w\"",
            "inject[0].axis",
            "no axis named 'w'",
        ),
        (
            "fault = \"frame_corruption\"\nduration_ms = -1",
            "inject[0].duration_ms",
            "must be > 0",
        ),
        (
            "fault = \"datagram_drop\"",
            "inject[0].duration_ms",
            "needs duration_ms",
        ),
        (
            "fault = \"frame_drop\"\nduration_ms = 5",
            "inject[0].fault",
            "link_loss",
        ),
    ];
    for (body, key, says) in cases {
        let text = ethercat_in_process_with(&format!("\n[[inject]]\nat_ms = 10\n{body}\n"));
        let e = parse(&text).unwrap_err();
        assert_eq!(e.key, key, "{body}: {e}");
        assert!(e.message.contains(says), "{body}: {e}");
    }
}

#[test]
fn wire_faults_are_left_to_the_segment_on_a_network_interface_and_refused_without_ethercat() {
    for fault in [
        "fault = \"frame_delay\"\ndelay_us = 100",
        "fault = \"frame_corruption\"",
        "fault = \"datagram_drop\"",
        "fault = \"link_loss\"",
        "fault = \"subdevice_stall\"\naxis = \"x\"",
        "fault = \"rx_loss\"\naxis = \"x\"",
    ] {
        let inject = format!("\n[[inject]]\nat_ms = 10\nduration_ms = 5\n{fault}\n");
        // On the NIC of configs/ethercat-cell.toml: the far end's emulator injects it.
        let c = parse(&(ethercat_text() + &inject)).expect(fault);
        assert_eq!(c.faults_left_to_segment(), c.inject, "{fault}");
        let schedule = c.wire_schedule();
        assert_eq!(schedule.len(), 1, "{fault}");
        assert_eq!(schedule[0].cycle, 10);
        assert_eq!(schedule[0].fault.frames(), 5);
        assert_eq!(
            schedule[0].fault.name(),
            c.inject[0].fault.name(),
            "{fault}"
        );
        // In-process the master's link injects it.
        let mut c = parse(&ethercat_in_process_with(&inject)).expect(fault);
        assert!(c.faults_left_to_segment().is_empty());
        // Moved to a NIC by --interface: left to the segment there.
        c.set_ethercat_interface("eth1").unwrap();
        assert_eq!(c.faults_left_to_segment().len(), 1, "{fault}");
        if fault.contains("rx_loss") {
            // On sim drives rx_loss is the simulated bus's own fault.
            let c = parse(&(demo_text() + &inject)).expect(fault);
            assert!(c.wire_schedule().is_empty() && c.faults_left_to_segment().is_empty());
            continue;
        }
        // On sim drives.
        let e = parse(&(demo_text() + &inject)).unwrap_err();
        assert_eq!(e.key, "inject[0].fault", "{fault}: {e}");
        assert!(e.message.contains("no EtherCAT axes"), "{fault}: {e}");
    }
    // The faults the controller injects itself are not the segment's.
    let c = parse(
        &(ethercat_text() + "\n[[inject]]\nat_ms = 10\nfault = \"stall\"\nduration_ms = 1\n"),
    )
    .expect("stall");
    assert!(c.wire_schedule().is_empty() && c.faults_left_to_segment().is_empty());
}

#[test]
fn the_communication_watchdog_defaults_and_its_counter_levels_are_checked() {
    let c = parse(&demo_text()).unwrap();
    assert_eq!(c.watchdogs.comm, CommWatchdogConfig::default());
    assert_eq!(
        (
            c.watchdogs.comm.max_lost_frames,
            c.watchdogs.comm.max_cycles_out_of_op
        ),
        (3, 1)
    );
    let with = |extra: &str| demo_text().replace("[watchdogs]", &format!("[watchdogs]\n{extra}"));
    let c = parse(&with(
        "max_lost_frames = 0\ncounter_continuous_errors = 5\ncounter_intermittent_errors = 4\n\
         counter_intermittent_window = 200",
    ))
    .unwrap();
    assert_eq!(c.watchdogs.comm.max_lost_frames, 0);
    let model = cellrt_cia402::profiles::mr_j3_t04::MASTER_COUNTER_CHECK;
    let params = c.watchdogs.comm.counter_params(model);
    assert_eq!(
        (
            params.echo_lag,
            params.detector.continuous,
            params.detector.intermittent
        ),
        (model.echo_lag, 5, 4)
    );
    let e = parse(&with("counter_continuous_errors = 5")).unwrap_err();
    assert_eq!(e.key, "watchdogs.counter_intermittent_errors", "{e}");
    let e = parse(&with(
        "counter_continuous_errors = 5\ncounter_intermittent_errors = 17\ncounter_intermittent_window = 9",
    ))
    .unwrap_err();
    assert_eq!(e.key, "watchdogs.counter_intermittent_errors", "{e}");
    assert!(e.message.contains("16"), "{e}");
    let e = parse(&with(
        "counter_continuous_errors = 5\ncounter_intermittent_errors = 2\ncounter_intermittent_window = 0",
    ))
    .unwrap_err();
    assert_eq!(e.key, "watchdogs.counter_intermittent_window", "{e}");
    let e = parse(&with("max_lost_frames = -1")).unwrap_err();
    assert!(e.key.contains("max_lost_frames"), "{e}");
}

/// `[axes.ethercat] distributed_clocks` (default on) and the emulated SubDevice's departures in
/// `[axes.sim]` (a read-only 1C32h:02 holds the cell's cycle); unknown values, and the sim keys
/// on a Mitsubishi model, are refused naming the key.
#[test]
fn distributed_clocks_and_the_emulated_subdevice_variant_are_read_and_checked() {
    use cellrt_emulator::ethercat::{CycleTimeObject, EmulatedDc, SubDeviceVariant};
    let c = parse(&generic_text()).unwrap();
    assert!(c.axes.on_loop().iter().all(|a| a.distributed_clocks));
    assert_eq!(
        c.axes.on_loop()[0].sim.subdevice,
        SubDeviceVariant::default()
    );
    let text = generic_text()
        .replacen(
            "product_code = 0xCE110402 }",
            "product_code = 0xCE110402, distributed_clocks = false }",
            1,
        )
        .replacen(
            "sim = { initial_position = 50.0 }",
            "sim = { initial_position = 50.0, cycle_time_object = \"read-only\", following_error_object = false, distributed_clocks = \"required\" }",
            1,
        );
    let c = parse(&text).unwrap();
    assert!(!c.axes.on_loop()[0].distributed_clocks && c.axes.on_loop()[1].distributed_clocks);
    assert_eq!(
        c.axes.on_loop()[0].sim.subdevice,
        SubDeviceVariant {
            cycle_time: CycleTimeObject::ReadOnly(1_000_000),
            following_error_object: false,
            distributed_clocks: EmulatedDc::Required,
            sdo_response_delay_ns: 0,
        }
    );
    for (from, to, key, reason) in [
        (
            "sim = { initial_position = 50.0 }",
            "sim = { initial_position = 50.0, cycle_time_object = \"ro\" }",
            "axes[0].sim.cycle_time_object",
            "available: read-write, read-only, absent",
        ),
        (
            "sim = { initial_position = 50.0 }",
            "sim = { initial_position = 50.0, distributed_clocks = \"yes\" }",
            "axes[0].sim.distributed_clocks",
            "available: optional, required, absent",
        ),
    ] {
        let e = parse(&generic_text().replacen(from, to, 1)).unwrap_err();
        assert_eq!(e.key, key, "{e}");
        assert!(e.message.contains(reason), "{e}");
    }
    let e = parse(&ethercat_text().replacen(
        "sim = { initial_position",
        "sim = { following_error_object = false, initial_position",
        1,
    ))
    .unwrap_err();
    assert_eq!(e.key, "axes[0].sim.following_error_object", "{e}");
    assert!(e.message.contains("only for drive = \"cia402\""), "{e}");
}

#[test]
fn the_emulated_sdo_answer_time_is_for_ethercat_axes_and_bounded() {
    let with = |text: String, v: &str| {
        text.replacen(
            "sim = { initial_position = 50.0 }",
            &format!("sim = {{ initial_position = 50.0, sdo_response_ms = {v} }}"),
            1,
        )
    };
    let c = parse(&with(ethercat_text(), "50")).unwrap();
    assert_eq!(
        c.axes.on_loop()[0].sim.subdevice.sdo_response_delay_ns,
        50_000_000
    );
    for bad in ["-1", "1001", "nan"] {
        let e = parse(&with(ethercat_text(), bad)).unwrap_err();
        assert_eq!(e.key, "axes[0].sim.sdo_response_ms", "{bad}: {e}");
    }
    let sim =
        with(ethercat_text(), "50").replacen("transport = \"ethercat\"", "transport = \"sim\"", 1);
    let e = parse(&sim).unwrap_err();
    assert!(e.message.contains("only for transport"), "{e}");
}

#[test]
fn implausible_motor_and_mechanics_figures_are_refused_naming_the_key() {
    // Axis x of the demo: 10000 pos units/rev, 1000 pos units/mm (a 10 mm lead), 400 mm/s.
    let x_motor = "motor = { counts_per_rev = 10000 }";
    let with_motor = |motor: &str| demo_text().replacen(x_motor, motor, 1);
    for (motor, key, says) in [
        (
            "motor = { counts_per_rev = 1e18 }",
            "axes[0].motor.counts_per_rev",
            "268435456",
        ),
        (
            "motor = { counts_per_rev = 0.5 }",
            "axes[0].motor.counts_per_rev",
            "268435456",
        ),
        (
            "motor = { counts_per_rev = 10000, max_speed = 1e18 }",
            "axes[0].motor.max_speed",
            "20000",
        ),
        (
            "motor = { counts_per_rev = 10000, rated_speed = 1e18 }",
            "axes[0].motor.rated_speed",
            "20000",
        ),
        (
            "motor = { counts_per_rev = 10000, rated_speed = 1e-300 }",
            "axes[0].motor.rated_speed",
            "20000",
        ),
        // Less than one position unit per revolution.
        (
            "motor = { counts_per_rev = 1e-3 }",
            "axes[0].motor.counts_per_rev",
            "position units per motor revolution",
        ),
        // 400 mm/s at 1000 pos units/mm and 100 per revolution: 240000 r/min.
        (
            "motor = { counts_per_rev = 100 }",
            "axes[0].limits.velocity",
            "the fastest a real motor can be",
        ),
    ] {
        let e = parse(&with_motor(motor)).expect_err(motor);
        assert_eq!(e.key, key, "{motor}: {e}");
        assert!(e.message.contains(says), "{motor}: {e}");
        assert_eq!(e.to_string().lines().count(), 1, "{e}");
    }
    // The gear ratio over the lead: 1e-300 pos units/mm at 10000 per revolution.
    let text =
        with_motor(x_motor).replacen("counts_per_unit = 1000", "counts_per_unit = 1e-300", 1);
    let e = parse(&text).unwrap_err();
    assert_eq!(e.key, "axes[0].counts_per_unit", "{e}");
    assert!(e.message.contains("gear ratio over a lead"), "{e}");
    // The manuals' figures pass: the 26-bit MR-J5 encoder, a 6000 r/min motor.
    let text = with_motor("motor = { counts_per_rev = 67108864, max_speed = 6000 }").replacen(
        "counts_per_unit = 1000",
        "counts_per_unit = 6710886.4",
        1,
    );
    let text = text.replacen("position = [0.0, 800.0]", "position = [0.0, 300.0]", 1);
    parse(&text).unwrap();
}
