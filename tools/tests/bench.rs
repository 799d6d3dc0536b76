//! `cellrt bench`: bad arguments exit 2 with one `error:` line naming the option, and a short
//! `bench latency` run writes a sane JSON report. No assertion on latency values (the test
//! machine is noisy).

use std::process::Command;

fn cellrt(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .args(args)
        .output()
        .expect("cellrt runs")
}

/// The run exited 0; its stdout and the JSON report it wrote to `json`.
fn succeeded_with_json(
    out: &std::process::Output,
    json: &std::path::Path,
) -> (String, serde_json::Value) {
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    (stdout, v)
}

#[test]
fn bad_arguments_exit_2_naming_the_option() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["latency", "--interval", "10", "--duration", "1"],
            "--interval",
        ),
        (
            &["latency", "--interval", "2000000", "--duration", "1"],
            "--interval",
        ),
        (
            &["latency", "--interval", "1000", "--duration", "0"],
            "--duration",
        ),
        (
            &["latency", "--interval", "1000", "--duration", "-2"],
            "--duration",
        ),
        (
            &[
                "latency",
                "--interval",
                "1000",
                "--duration",
                "1",
                "--priority",
                "0",
            ],
            "--priority",
        ),
        (
            &[
                "latency",
                "--interval",
                "1000",
                "--duration",
                "1",
                "--priority",
                "100",
            ],
            "--priority",
        ),
        (
            &[
                "latency",
                "--interval",
                "1000",
                "--duration",
                "1",
                "--cpu",
                "9999",
            ],
            "--cpu",
        ),
        (
            &[
                "compare",
                "--interval",
                "1000",
                "--duration",
                "1",
                "--rounds",
                "0",
            ],
            "--rounds",
        ),
        (
            &[
                "compare",
                "--interval",
                "1000",
                "--duration",
                "1",
                "--plot",
                "x.png",
            ],
            "--plot",
        ),
        (
            &[
                "loop",
                "--axes",
                "0",
                "--interval",
                "1000",
                "--duration",
                "1",
            ],
            "--axes",
        ),
        (
            &[
                "loop",
                "--axes",
                "300",
                "--interval",
                "1000",
                "--duration",
                "1",
            ],
            "--axes",
        ),
        (
            &[
                "loop",
                "--axes",
                "4",
                "--interval",
                "300",
                "--duration",
                "1",
            ],
            "--interval",
        ),
    ];
    for (args, option) in cases {
        let mut full = vec!["bench"];
        full.extend_from_slice(args);
        let out = cellrt(&full);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{full:?}: {stderr}");
        let errors: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("error: "))
            .collect();
        assert_eq!(errors.len(), 1, "{full:?}: {stderr}");
        assert!(errors[0].contains(option), "{full:?}: {stderr}");
    }
    // clap's own usage errors are exit code 2 as well.
    let out = cellrt(&["bench", "latency", "--interval", "abc", "--duration", "1"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn short_latency_run_writes_sane_json() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("latency.json");
    let out = cellrt(&[
        "bench",
        "latency",
        "--interval",
        "1000",
        "--duration",
        "0.2",
        "--json",
        json.to_str().unwrap(),
    ]);
    let (stdout, v) = succeeded_with_json(&out, &json);
    assert!(stdout.contains("p99.9"), "{stdout}");
    let w = &v["wakeup_latency"];
    let count = w["count"].as_u64().unwrap();
    let overruns = v["overruns"].as_u64().unwrap();
    // 0.2 s at 1 ms: 200 deadlines, each either a wakeup or a skipped overrun.
    assert!(
        (100..=210).contains(&(count + overruns)),
        "count {count} + overruns {overruns}"
    );
    let f = |k: &str| w[k].as_f64().unwrap();
    assert!(f("min_us") <= f("p50_us"), "{w}");
    assert!(
        f("p50_us") <= f("p99_us") && f("p99_us") <= f("p999_us"),
        "{w}"
    );
    assert!(f("p999_us") <= f("max_us") * 1.001 + 0.001, "{w}");
    assert_eq!(v["options"]["interval_us"], 1000);
    let buckets: u64 = v["histogram_ns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b[1].as_u64().unwrap())
        .sum();
    assert_eq!(buckets, count);
    assert!(v["rt"]["policy"].is_string());
}

#[test]
fn bench_ipc_measures_both_paths_and_refuses_bad_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("ipc.json");
    let out = cellrt(&[
        "bench",
        "ipc",
        "--axes",
        "2",
        "--rounds",
        "1",
        "--count",
        "50",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(r["payload_bytes"], 16 * 2 * 24);
    for side in ["cellrt", "raw"] {
        assert_eq!(r[side]["count"], 50, "{r}");
        let p50 = r[side]["p50_us"].as_f64().unwrap();
        let p99 = r[side]["p99_us"].as_f64().unwrap();
        assert!(p50 > 0.0 && p50 <= p99, "{side}: {r}");
    }
    let out = cellrt(&["bench", "ipc", "--axes", "0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--axes"));
}

#[test]
fn bench_ethercat_refuses_bad_arguments_naming_the_option() {
    let cases: &[(&[&str], &str)] = &[
        (&["--interval", "300", "--duration", "2"], "--interval"),
        (&["--interval", "1000", "--duration", "0"], "--duration"),
        (
            &["--interval", "1000", "--duration", "2", "--rounds", "0"],
            "--rounds",
        ),
        (
            &["--interval", "1000", "--duration", "2", "--rounds", "4"],
            "--duration",
        ),
        (
            &[
                "--interval",
                "1000",
                "--duration",
                "10",
                "--latency-duration",
                "-1",
            ],
            "--latency-duration",
        ),
        (
            &["--interval", "1000", "--duration", "10", "--priority", "0"],
            "--priority",
        ),
    ];
    for (args, option) in cases {
        let mut full = vec!["bench", "ethercat", "--in-process"];
        full.extend_from_slice(args);
        let out = cellrt(&full);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{full:?}: {stderr}");
        assert!(
            stderr
                .lines()
                .any(|l| l.starts_with("error:") && l.contains(option)),
            "{full:?}: {stderr}"
        );
    }
}

/// An in-process segment of four drives: every cyclic frame returns with the right working
/// counter, each round reports exchange time and both wakeup latencies, and the totals add up.
/// No assertion on the values (the machine is noisy).
#[test]
fn bench_ethercat_in_process_counts_frames_and_reports_every_round() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("ethercat.json");
    let out = cellrt(&[
        "bench",
        "ethercat",
        "--in-process",
        "--interval",
        "1000",
        "--duration",
        "2",
        "--rounds",
        "2",
        "--latency-duration",
        "0.2",
        "--json",
        json.to_str().unwrap(),
    ]);
    let (stdout, v) = succeeded_with_json(&out, &json);
    assert!(stdout.contains("exchange time µs"), "{stdout}");
    assert_eq!(
        v["models"],
        serde_json::json!(["mr-j3-t04", "mr-j4-tm", "mr-jet-g-n1", "mr-j5-g-n1"])
    );
    let rounds = v["ethercat"].as_array().unwrap();
    assert_eq!(rounds.len(), 2);
    assert_eq!(v["latency"].as_array().unwrap().len(), 2);
    let mut sent = 0;
    for r in rounds {
        let cycles = r["cycles"].as_u64().unwrap();
        let overruns = r["overruns"].as_u64().unwrap();
        // 1 s per round at 1 ms, whatever the runs it took, plus each run's final stop.
        assert!(
            (900..=1600).contains(&(cycles + overruns)),
            "{cycles} + {overruns}"
        );
        assert_eq!(r["frames"]["lost"], 0, "{r}");
        assert_eq!(r["frames"]["wkc_errors"], 0, "{r}");
        let x = &r["exchange_time"];
        assert_eq!(x["count"].as_u64().unwrap(), cycles, "{r}");
        assert!(x["p50_us"].as_f64().unwrap() > 0.0, "{r}");
        assert!(x["p50_us"].as_f64() <= x["p99_us"].as_f64(), "{r}");
        sent += r["frames"]["frames"].as_u64().unwrap();
    }
    assert_eq!(v["frames"]["frames"].as_u64().unwrap(), sent);
    assert!(v["bench_latency"]["count"].as_u64().unwrap() >= 100, "{v}");
    assert_eq!(
        v["exchange_time"]["count"].as_u64().unwrap(),
        rounds
            .iter()
            .map(|r| r["cycles"].as_u64().unwrap())
            .sum::<u64>()
    );
}

/// `cellrt bench je-c`: every path is sampled once per tick (answered or counted lost), each
/// transport is compared with its raw echo, and bad arguments are refused naming the option.
#[test]
fn bench_je_c_samples_every_path_each_tick() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("je-c.json");
    let out = cellrt(&[
        "bench",
        "je-c",
        "--duration",
        "0.2",
        "--json",
        json.to_str().unwrap(),
    ]);
    let (stdout, v) = succeeded_with_json(&out, &json);
    let ticks = v["ticks"].as_u64().unwrap();
    assert_eq!(ticks, 20, "{stdout}");
    let paths = v["paths"].as_array().unwrap();
    let names: Vec<&str> = paths.iter().map(|p| p["path"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "cclink",
            "cclink-bare",
            "udp-echo",
            "slmp-udp",
            "slmp-tcp",
            "modbus-tcp",
            "tcp-echo",
            "modbus-rtu",
            "pty-echo"
        ]
    );
    for p in paths {
        let count = p["round_trip"]["count"].as_u64().unwrap();
        assert_eq!(count + p["lost"].as_u64().unwrap(), ticks, "{p}");
    }
    assert_eq!(paths[0]["against"][0], "udp-echo");
    assert_eq!(paths[1]["against"][0], "udp-echo");
    assert_eq!(paths[7]["against"][0], "pty-echo");
    for (args, option) in [
        (&["--duration", "0"][..], "--duration"),
        (&["--interval-ms", "0"][..], "--interval-ms"),
        (&["--paths", "cclink,foo"][..], "--paths"),
    ] {
        let out = cellrt(&[&["bench", "je-c"][..], args].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(option), "{args:?}: {err}");
    }
}

/// `cellrt bench soak`: a short run with 1 s rotation samples the memory every second, writes
/// a part per second (the completed ones pruned as it goes), and refuses a zero period.
#[test]
fn bench_soak_samples_memory_and_rotates() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("soak.json");
    // A 2-axis soak sampled every second with `args`, its result as JSON.
    let soak = |args: &[&str]| {
        let base = [
            "bench",
            "soak",
            "--axes",
            "2",
            "--interval",
            "1000",
            "--sample",
            "1",
        ];
        let file = ["--json", json.to_str().unwrap()];
        cellrt(&[&base[..], args, &file[..]].concat())
    };
    let out = soak(&["--duration", "3", "--rotate", "1"]);
    let (stdout, v) = succeeded_with_json(&out, &json);
    let rss = v["rss"].as_array().unwrap();
    assert!(rss.len() >= 2, "{stdout}");
    assert!(
        rss.iter().all(|s| s["rss_kib"].as_u64().unwrap() > 0),
        "{stdout}"
    );
    assert!(v["files"].as_u64().unwrap() >= 3, "{stdout}");
    assert!(v["cycles"].as_u64().unwrap() > 0, "{stdout}");
    assert!(stdout.contains("RSS KiB"), "{stdout}");
    // Open files and threads are sampled with the memory; the live view's client read the
    // per-cycle messages.
    assert!(
        rss.iter()
            .all(|s| s["fds"].as_u64().unwrap() > 2 && s["threads"].as_u64().unwrap() > 2),
        "{stdout}"
    );
    assert!(
        v["clients"]["live_messages"].as_u64().unwrap() > 0,
        "{stdout}"
    );
    assert!(stdout.contains("live view client"), "{stdout}");
    // Without rotation the whole run is one file.
    let out = soak(&["--duration", "2", "--no-rotate"]);
    let (stdout, v) = succeeded_with_json(&out, &json);
    assert_eq!(v["files"], 1, "{stdout}");
    assert!(stdout.contains("not rotated"), "{stdout}");
    for (args, option) in [
        (&["--rotate", "0"][..], "--rotate"),
        (&["--axes", "0"][..], "--axes"),
    ] {
        let base = ["bench", "soak", "--interval", "1000", "--duration", "1"];
        let out = cellrt(&[&base[..], args].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(option), "{args:?}: {err}");
    }
}

/// `cellrt bench live`: each mode's rounds in turn; the viewer's round receives messages and
/// costs the server CPU, the round without the live view sends nothing; bad rounds and too
/// short a duration are refused.
#[test]
fn bench_live_takes_turns_and_counts_the_viewer() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("live.json");
    let out = cellrt(&[
        "bench",
        "live",
        "--axes",
        "2",
        "--interval",
        "1000",
        "--duration",
        "4",
        "--rounds",
        "1",
        "--json",
        json.to_str().unwrap(),
    ]);
    let (stdout, v) = succeeded_with_json(&out, &json);
    let rounds = v["rounds"].as_array().unwrap();
    let modes: Vec<&str> = rounds.iter().map(|r| r["mode"].as_str().unwrap()).collect();
    assert_eq!(modes, ["off", "no_viewer", "one_viewer"], "{stdout}");
    assert_eq!(rounds[0]["live_sent"], 0, "{stdout}");
    assert!(rounds[1]["live_sent"].as_u64().unwrap() > 1000, "{stdout}");
    assert_eq!(rounds[1]["viewer_messages"], 0, "{stdout}");
    assert!(
        rounds[2]["viewer_messages"].as_u64().unwrap() > 1000,
        "{stdout}"
    );
    assert!(
        rounds[2]["cpu"]["live_server_pct"].as_f64().unwrap() > 0.0,
        "{stdout}"
    );
    assert!(rounds
        .iter()
        .all(|r| r["cpu"]["recorder_pct"].as_f64().unwrap() > 0.0));
    assert!(stdout.contains("medians per mode"), "{stdout}");
    for (args, option) in [
        (&["--rounds", "0", "--duration", "4"][..], "--rounds"),
        (&["--duration", "2"][..], "--duration"),
    ] {
        let base = ["bench", "live", "--axes", "2", "--interval", "1000"];
        let out = cellrt(&[&base[..], args].concat());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(option), "{args:?}: {err}");
    }
}
