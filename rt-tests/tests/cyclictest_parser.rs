//! The cyclictest histogram parser on output captured from cyclictest 2.40
//! (`cyclictest -m -p 80 -a 1 -t 1 -i 1000 -D 1 --clock=0 -q --histogram=60 --histfile=F`).

use cellrt_rt_tests::cyclictest::{args, parse_histogram};

const SAMPLE: &str = include_str!("data/cyclictest-2.40-h60.txt");

#[test]
fn parses_buckets_summary_and_overflows() {
    let p = parse_histogram(SAMPLE).expect("parses");
    assert_eq!(p.total, 992);
    assert_eq!(p.overflows, 8);
    assert_eq!(p.range_us, 60);
    // Every sample counted once: the buckets plus the overflows (kept at the top of the range).
    assert_eq!(p.hist.count(), 1000);
    assert_eq!(p.hist.buckets.get(&60), Some(&8));
    let q = p.hist.percentiles();
    assert_eq!(q.min_us, 10.0);
    assert_eq!(
        q.max_us, 173.0,
        "max comes from '# Max Latencies', not the range"
    );
    assert!(q.min_us <= q.p50_us && q.p50_us <= q.p99_us && q.p99_us <= q.max_us);
    // 8 of 1000 overflowed, so p99.9 is in the overflow bucket but p99 is not.
    assert_eq!(q.p999_us, 60.0);
    assert!(q.p99_us < 60.0);
}

#[test]
fn rejects_garbage_and_multi_thread_output() {
    assert!(parse_histogram("hello world\n").is_err());
    assert!(
        parse_histogram("000001 000002\n").is_err(),
        "no summary lines"
    );
    let two = "000001 000002 000003\n# Min Latencies: 00001\n# Max Latencies: 00001\n";
    assert!(parse_histogram(two).is_err());
}

#[test]
fn command_line_matches_the_cellrt_loop_setup() {
    let a = args(250, 10, 80, 1, std::path::Path::new("/tmp/h"));
    let line = a.join(" ");
    for want in [
        "-m",
        "-p 80",
        "-a 1",
        "-t 1",
        "-i 250",
        "-D 10",
        "--clock=0",
        "--histfile=/tmp/h",
    ] {
        assert!(line.contains(want), "{want} missing in {line}");
    }
    assert!(!line.contains("-r"), "absolute timer (no -r)");
}
