//! `drive = "mr-je-c"` axes at load: the shipped mixed cell, the keys each transport needs, and
//! every bad key named.

use std::path::Path;
use std::time::Duration;

use super::je_c_axis::{JecCommandError, JecMode, JecTransport};
use super::*;

fn mixed() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/mixed-cell.toml"
    ))
    .expect("configs/mixed-cell.toml")
}

fn parse(text: &str) -> Result<CellConfig, ConfigError> {
    CellConfig::parse(Path::new("cell.toml"), text)
}

/// The mixed cell with the outfeed's table (axes[3].je_c) replaced.
fn outfeed(transport: &str, je_c: &str) -> Result<CellConfig, ConfigError> {
    let text = mixed();
    let at = text.find("name = \"outfeed\"").unwrap();
    let (head, tail) = text.split_at(at);
    let tail = tail
        .replace(
            "transport = \"modbus-tcp\"",
            &format!("transport = \"{transport}\""),
        )
        .lines()
        .map(|l| {
            if l.starts_with("je_c = ") {
                format!("je_c = {{ {je_c} }}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    parse(&format!("{head}{tail}"))
}

fn refused(r: Result<CellConfig, ConfigError>, key: &str, says: &str) {
    let e = r.expect_err(key);
    assert_eq!(e.key, key, "{e}");
    assert!(e.message.contains(says), "{e}");
}

#[test]
fn the_mixed_cell_keeps_its_je_c_axes_off_the_rt_loop() {
    let c = parse(&mixed()).unwrap();
    assert_eq!(c.axes.names(), "x, y, infeed, outfeed");
    assert_eq!(c.axes.loop_names(), "x, y");
    assert_eq!(c.axes.count(), 4);
    assert_eq!(c.axes.on_loop().len(), 2);
    let backends: Vec<_> = c.axes.iter().map(|a| a.backend()).collect();
    assert_eq!(
        backends,
        [
            Backend::Streamed,
            Backend::Streamed,
            Backend::Link,
            Backend::Link
        ]
    );
    let [infeed, outfeed] = c.axes.on_link() else {
        panic!()
    };
    assert_eq!(infeed.transport, JecTransport::CcLink(None));
    assert!(infeed.emulate);
    assert_eq!(infeed.mode, JecMode::Pp);
    assert_eq!(infeed.period, Duration::from_millis(10));
    assert_eq!(infeed.drive_timeout, Some(Duration::from_millis(500)));
    assert_eq!(infeed.watchdog_missed, 5);
    assert_eq!(outfeed.transport, JecTransport::ModbusTcp(None));
    // watchdogs.communication_reaction's default.
    assert_eq!(
        outfeed.watchdog_reaction,
        c.watchdogs.communication_reaction
    );
    // 200 mm/s = 2 rev/s = 120 r/min = 12000 × 0.01 r/min; 3000 r/min = 5000 mm/s, reached at
    // 1000 mm/s² in 5000 ms (6083h is a time constant to the rated speed).
    assert_eq!(infeed.drive_speed(200.0), 12_000);
    assert_eq!(infeed.ramp_ms(1000.0), 5000);
}

#[test]
fn each_transport_takes_its_keys() {
    let c = outfeed("slmp", "address = \"192.168.3.20\"").unwrap();
    let a = &c.axes.on_link()[1];
    assert_eq!(
        a.transport,
        JecTransport::Slmp(Some("192.168.3.20:5010".parse().unwrap()))
    );
    assert!(!a.emulate);
    let c = outfeed("cclink-ief-basic", "address = \"192.168.3.20\"").unwrap();
    assert_eq!(
        c.axes.on_link()[1].transport,
        JecTransport::CcLink(Some("192.168.3.20:61450".parse().unwrap()))
    );
    let c = outfeed(
        "modbus-rtu",
        "serial = \"/dev/ttyUSB0\", station = 7, baud = 57600",
    )
    .unwrap();
    assert_eq!(
        c.axes.on_link()[1].transport,
        JecTransport::ModbusRtu {
            serial: Some("/dev/ttyUSB0".into()),
            station: 7,
            baud: 57_600
        }
    );
}

#[test]
fn bad_je_c_keys_are_named() {
    let k = "axes[3]";
    refused(
        outfeed("ethercat", "emulate = true"),
        &format!("{k}.transport"),
        "modbus-rtu",
    );
    refused(
        outfeed("slmp", ""),
        &format!("{k}.je_c.address"),
        "IP address is needed",
    );
    refused(
        outfeed("slmp", "address = \"drive-1\""),
        &format!("{k}.je_c.address"),
        "not an IP",
    );
    refused(
        outfeed("slmp", "emulate = true, period_ms = 5"),
        &format!("{k}.je_c.period_ms"),
        "at least 10 ms",
    );
    refused(
        outfeed("slmp", "emulate = true, station = 3"),
        &format!("{k}.je_c.station"),
        "no RS-485 line",
    );
    refused(
        outfeed("modbus-rtu", "emulate = true"),
        &format!("{k}.je_c.station"),
        "station number",
    );
    refused(
        outfeed("modbus-rtu", "emulate = true, station = 0"),
        &format!("{k}.je_c.station"),
        "0 never answers",
    );
    refused(
        outfeed("modbus-rtu", "station = 1"),
        &format!("{k}.je_c.serial"),
        "serial device",
    );
    refused(
        outfeed("modbus-rtu", "emulate = true, station = 1, baud = 1200"),
        &format!("{k}.je_c.baud"),
        "PC71",
    );
    refused(
        outfeed(
            "modbus-rtu",
            "emulate = true, station = 1, address = \"10.0.0.1\"",
        ),
        &format!("{k}.je_c.address"),
        "serial line",
    );
    refused(
        outfeed("modbus-tcp", "emulate = true, drive_timeout_ms = 1500"),
        &format!("{k}.je_c.drive_timeout_ms"),
        "PN10",
    );
    // The parameters' ranges (MR-JE-C manual §5.2.3): PN02 0–1000 ms, PN10 and PF46 0–60 s.
    refused(
        outfeed(
            "cclink-ief-basic",
            "emulate = true, drive_timeout_ms = 2000",
        ),
        &format!("{k}.je_c.drive_timeout_ms"),
        "outside the cclink-ief-basic time-out [Pr. PN02]'s range 0–1000 ms",
    );
    refused(
        outfeed("modbus-tcp", "emulate = true, drive_timeout_ms = 61000"),
        &format!("{k}.je_c.drive_timeout_ms"),
        "range 0–60000 ms",
    );
    refused(
        outfeed(
            "modbus-tcp",
            "emulate = true, watchdog_reaction = \"brake\"",
        ),
        &format!("{k}.je_c.watchdog_reaction"),
        "quick_stop",
    );
    refused(
        outfeed("modbus-tcp", "emulate = true, colour = 1"),
        &format!("{k}.je_c.colour"),
        "unknown field",
    );
    let no_table = mixed().replace(
        "je_c = { emulate = true, period_ms = 20, drive_timeout_ms = 1000, watchdog_missed = 3 }",
        "",
    );
    refused(parse(&no_table), &format!("{k}.je_c"), "[axes.je_c]");
    let csp = mixed().replacen("mode = \"pp\"", "mode = \"csp\"", 1);
    refused(parse(&csp), "axes[2].mode", "no cyclic synchronous modes");
    let on_a_servo = mixed().replacen(
        "sim = { initial_position = 50.0 }",
        "sim = { initial_position = 50.0 }\nje_c = { emulate = true }",
        1,
    );
    refused(parse(&on_a_servo), "axes[0].je_c", "mr-je-c");
    let twice = mixed().replace("name = \"outfeed\"", "name = \"infeed\"");
    refused(parse(&twice), "axes[3].name", "duplicate");
}

/// The tq command of the mixed cell's outfeed in the drive's units (MR-JE-C manual §7.3): 6071h
/// and 6087h in 0.1 % (of rated torque, per second), 2D20h in 0.01 r/min. 8 % → 80; the
/// default slope 1000 %/s → 10000; 150 mm/s at 1310.72 pos units/mm and 131072 pos units/rev
/// is 1.5 rev/s = 90 r/min → 9000. Beyond limits.torque (20 %), and NaN, are refused.
#[test]
fn a_je_c_torque_command_carries_the_manuals_units() {
    use cellrt_fieldbus::mr_je_c::cell::AxisCommand;
    let c = parse(&mixed()).unwrap();
    let outfeed = &c.axes.on_link()[1];
    assert_eq!(
        outfeed.torque_command(8.0),
        Ok(AxisCommand::Torque {
            torque: 80,
            slope: 10_000,
            velocity_limit: 9_000,
        })
    );
    assert_eq!(outfeed.speed_limit(), 9_000);
    for bad in [20.5, -21.0, f64::NAN, f64::INFINITY] {
        let e = outfeed.torque_command(bad).unwrap_err();
        assert!(
            matches!(e, JecCommandError::TorqueOutsideLimit { max: 20.0, .. }),
            "{bad}: {e}"
        );
        assert!(
            e.to_string().contains("outside the torque limit ±20 %"),
            "{bad}: {e}"
        );
    }
    // The infeed has no limits.torque.
    let e = c.axes.on_link()[0].torque_command(5.0).unwrap_err();
    assert_eq!(
        e,
        JecCommandError::NoTorqueLimit {
            axis: c.axes.on_link()[0].name.clone()
        }
    );
    assert!(e.to_string().contains("needs limits.torque"), "{e}");
}

/// The outfeed of the mixed cell in `mode`, with `je_c` as its table.
fn outfeed_in(mode: &str, je_c: &str) -> Result<CellConfig, ConfigError> {
    let text = mixed();
    let at = text.find("name = \"outfeed\"").unwrap();
    let (head, tail) = text.split_at(at);
    let tail = tail
        .replace("mode = \"pp\"", &format!("mode = \"{mode}\""))
        .lines()
        .filter(|l| !l.starts_with("je_c = "))
        .collect::<Vec<_>>()
        .join("\n");
    parse(&format!("{head}{tail}\n{je_c}\n"))
}

/// Point tables: in the axis' units, defaults from its limits, written at start-up to 2801h
/// subs 1–4 and 7 in the drive's units (pos units, 0.01 r/min, ms to the rated speed).
#[test]
fn point_tables_load_in_units_and_reach_the_drive_in_its_own() {
    let c = outfeed_in(
        "point_table",
        "[axes.je_c]\nemulate = true\n[[axes.je_c.point_table]]\nposition = 100.0\nvelocity = 100.0\n[[axes.je_c.point_table]]\nposition = -50.0\nacceleration = 500.0\nm_code = 7",
    )
    .unwrap();
    let a = &c.axes.on_link()[1];
    assert_eq!(a.mode, JecMode::PointTable);
    let p = a.positioning_parameters();
    let value = |index: u16, sub: u8| {
        p.iter()
            .find(|(id, _)| *id == cellrt_fieldbus::mr_je_c::ObjectId::new(index, sub))
            .map(|(_, v)| v.as_i64().unwrap())
    };
    // 100 mm = 131072 pos units; 100 mm/s = 1 rev/s = 60 r/min = 6000 × 0.01 r/min.
    assert_eq!(value(0x2801, 1), Some(131_072));
    assert_eq!(value(0x2801, 2), Some(6000));
    // 800 mm/s² (the limit): 3000 r/min = 5000 mm/s in 6250 ms.
    assert_eq!(
        (value(0x2801, 3), value(0x2801, 4)),
        (Some(6250), Some(6250))
    );
    // Table 2: 150 mm/s (the limit), 500 mm/s² for both ramps, M code 7.
    assert_eq!(value(0x2802, 1), Some(-65_536));
    assert_eq!(value(0x2802, 2), Some(9000));
    assert_eq!(
        (value(0x2802, 3), value(0x2802, 4)),
        (Some(10_000), Some(10_000))
    );
    assert_eq!(value(0x2802, 7), Some(7));
    assert_eq!(p.len(), 10);
}

#[test]
fn positioning_axes_are_checked_at_load() {
    let base = "[axes.je_c]\nemulate = true";
    refused(
        outfeed_in("point_table", base),
        "axes[3].je_c.point_table",
        "give 1–255 [[axes.je_c.point_table]]",
    );
    refused(
        outfeed_in(
            "point_table",
            &format!("{base}\n[[axes.je_c.point_table]]\nposition = 600.0"),
        ),
        "axes[3].je_c.point_table[0].position",
        "outside the position range [-500, 500]",
    );
    refused(
        outfeed_in(
            "point_table",
            &format!("{base}\n[[axes.je_c.point_table]]\nposition = 1.0\nvelocity = 151.0"),
        ),
        "axes[3].je_c.point_table[0].velocity",
        "at most the axis' limit 150",
    );
    refused(
        outfeed_in(
            "pp",
            &format!("{base}\n[[axes.je_c.point_table]]\nposition = 1.0"),
        ),
        "axes[3].je_c.point_table",
        "point tables are for mode = \"point_table\"",
    );
    refused(
        outfeed_in("indexer", base),
        "axes[3].je_c.stations",
        "give je_c.stations",
    );
    refused(
        outfeed_in("indexer", &format!("{base}\nstations = 256")),
        "axes[3].je_c.stations",
        "[Pr. PT28] takes 2–255",
    );
    refused(
        outfeed_in("pp", &format!("{base}\nstations = 8")),
        "axes[3].je_c.stations",
        "stations are for mode = \"indexer\"",
    );
    // The mixed cell's outfeed counts 1310.72 per mm.
    refused(
        outfeed_in(
            "indexer",
            &format!("{base}\nstations = 8\nwatchdog_reaction = \"quick_stop\""),
        ),
        "axes[3].counts_per_unit",
        "counts in stations",
    );
    refused(
        outfeed_in(
            "indexer",
            &format!("{base}\nstations = 8\nwatchdog_reaction = \"controlled_stop\""),
        ),
        "axes[3].je_c.watchdog_reaction",
        "the Halt bit is disabled",
    );
    let jog = outfeed_in("jog", base).unwrap();
    assert_eq!(jog.axes.on_link()[1].mode, JecMode::Jog);
    let e = jog.axes.on_link()[1].move_target(10.0).unwrap_err();
    assert!(matches!(e, JecCommandError::JogAxisHasNoTargets { .. }));
    assert!(e.to_string().contains("moves by jog only"));
}

/// 607Ah takes −999999…999999 pos units (MR-JE-C manual §7.3): a position range beyond it in
/// pos units is refused at load, not by the drive mid-run.
#[test]
fn a_position_range_beyond_607ah_is_refused_at_load() {
    let text = mixed().replace(
        "position = [-500.0, 500.0], velocity = 150.0",
        "position = [-800.0, 500.0], velocity = 150.0",
    );
    refused(
        parse(&text),
        "axes[3].limits.position",
        "[-1048576, 655360] pos units, beyond Target position 607Ah's setting range -999999…999999",
    );
}

/// An MR-JE-C axis homes with method 37 only (the home where the motor stands, MR-JE-C manual
/// §7.3 6098h): none named or 37 gives 37; another method or a Controlword2 edge is refused,
/// one refusal for the program's home step and the operator's.
#[test]
fn homing_is_method_37_or_refused() {
    let cell = parse(&mixed()).unwrap();
    let a = &cell.axes.on_link()[0];
    assert_eq!(a.homing_method(None, false), Ok(37));
    assert_eq!(a.homing_method(Some(37), false), Ok(37));
    let e = a.homing_method(Some(35), false).unwrap_err();
    assert!(matches!(
        e,
        je_c_axis::JecHomingError::Method { method: 35, .. }
    ));
    assert_eq!(
        e.to_string(),
        format!("method 35: MR-JE-C axis '{}' homes with method 37 only (the home where the motor stands; the MR-JE-C manual lists no other)", a.name)
    );
    let e = a.homing_method(None, true).unwrap_err();
    assert!(matches!(
        e,
        je_c_axis::JecHomingError::Controlword2Edge { .. }
    ));
}

#[test]
fn implausible_je_c_motor_figures_are_refused_naming_the_key() {
    refused(
        outfeed("modbus-tcp", "emulate = true, counts_per_rev = 1e18"),
        "axes[3].je_c.counts_per_rev",
        "268435456",
    );
    refused(
        outfeed("modbus-tcp", "emulate = true, rated_speed = 1e18"),
        "axes[3].je_c.rated_speed",
        "20000",
    );
    refused(
        outfeed("modbus-tcp", "emulate = true, counts_per_rev = 1e-3"),
        "axes[3].je_c.counts_per_rev",
        "268435456",
    );
}
