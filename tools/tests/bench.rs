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
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("p99.9"), "{stdout}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
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
