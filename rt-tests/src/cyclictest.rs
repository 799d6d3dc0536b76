//! Running Debian's `cyclictest` with the same thread set-up as `cellrt bench latency`
//! (`-m -p PRIO -a CPU -i INTERVAL -D DURATION --clock=0`, absolute timer, one thread) and
//! parsing its `--histfile` histogram (1 µs buckets, then the `# Total/Min/Avg/Max/Histogram
//! Overflows` summary lines).

use std::path::Path;
use std::process::{Child, Command, Stdio};

use serde::Serialize;

use crate::error::BenchError;
use crate::hist::UsHistogram;

/// Histogram range passed to `-h`, µs: samples above it are counted as overflows.
pub const HISTOGRAM_US: u64 = 100_000;

/// A parsed `cyclictest -h` histogram of one thread.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Parsed {
    /// Buckets, with overflows counted in the bucket at [`Parsed::range_us`].
    pub hist: UsHistogram,
    /// `# Total:` (samples cyclictest counted).
    pub total: u64,
    /// `# Histogram Overflows:`.
    pub overflows: u64,
    /// Histogram range (number of bucket lines).
    pub range_us: u64,
}

/// The installed cyclictest's version line (`cyclictest V 2.40`).
pub fn version(bin: &Path) -> String {
    Command::new(bin)
        .arg("--help")
        .output()
        .ok()
        .and_then(|o| {
            let text = String::from_utf8_lossy(&o.stdout).to_string()
                + &String::from_utf8_lossy(&o.stderr);
            text.lines()
                .find(|l| l.starts_with("cyclictest V"))
                .map(|l| l.trim().to_string())
        })
        .unwrap_or_else(|| "cyclictest (unknown version)".into())
}

/// The argument list for one run.
pub fn args(
    interval_us: u64,
    duration_s: u64,
    priority: u8,
    cpu: usize,
    histfile: &Path,
) -> Vec<String> {
    vec![
        "-m".into(),
        "-p".into(),
        priority.to_string(),
        "-a".into(),
        cpu.to_string(),
        "-t".into(),
        "1".into(),
        "-i".into(),
        interval_us.to_string(),
        "-D".into(),
        duration_s.to_string(),
        "--clock=0".into(),
        "-q".into(),
        format!("--histogram={HISTOGRAM_US}"),
        format!("--histfile={}", histfile.display()),
    ]
}

/// Starts cyclictest (stdout and stderr discarded: the histogram goes to `histfile`).
pub fn spawn(bin: &Path, args: &[String]) -> Result<Child, BenchError> {
    Command::new(bin)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| BenchError::failed(format!("cannot start {}: {e}", bin.display())))
}

/// Waits for a cyclictest started by [`spawn`] and parses its histogram file.
pub fn finish(child: Child, histfile: &Path) -> Result<Parsed, BenchError> {
    let out = child
        .wait_with_output()
        .map_err(|e| BenchError::failed(format!("cyclictest: {e}")))?;
    if !out.status.success() {
        return Err(BenchError::failed(format!(
            "cyclictest failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    let text = std::fs::read_to_string(histfile).map_err(|e| {
        BenchError::failed(format!(
            "cannot read cyclictest's histogram {}: {e}",
            histfile.display()
        ))
    })?;
    parse_histogram(&text)
}

fn summary_value(line: &str, key: &str) -> Option<u64> {
    line.strip_prefix(key)?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Parses the text of `cyclictest -h N` (one thread): `NNNNNN CCCCCC` bucket lines, then
/// `# Total`, `# Min Latencies`, `# Max Latencies`, `# Histogram Overflows`.
pub fn parse_histogram(text: &str) -> Result<Parsed, BenchError> {
    let mut p = Parsed::default();
    let mut min = None;
    let mut max = None;
    let mut lines = 0u64;
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        if line.starts_with('#') {
            if let Some(v) = summary_value(line, "# Total:") {
                p.total = v;
            } else if let Some(v) = summary_value(line, "# Min Latencies:") {
                min = Some(v);
            } else if let Some(v) = summary_value(line, "# Max Latencies:") {
                max = Some(v);
            } else if let Some(v) = summary_value(line, "# Histogram Overflows:") {
                p.overflows = v;
            }
            continue;
        }
        let mut f = line.split_whitespace();
        let (Some(us), Some(n)) = (f.next(), f.next()) else {
            return Err(bad_line(line));
        };
        if f.next().is_some() {
            return Err(BenchError::failed(format!(
                "cyclictest histogram has more than one thread column: {line:?}"
            )));
        }
        let us: u64 = us.parse().map_err(|_| bad_line(line))?;
        let n: u64 = n.parse().map_err(|_| bad_line(line))?;
        p.hist.add(us, n);
        lines += 1;
    }
    let (Some(min), Some(max)) = (min, max) else {
        return Err(BenchError::failed(
            "cyclictest histogram without '# Min Latencies' / '# Max Latencies' lines",
        ));
    };
    p.range_us = lines;
    // Overflows are above the range: count them at its top so the percentiles see them.
    p.hist.add(lines, p.overflows);
    if !p.hist.is_empty() {
        p.hist.min_us = min as f64;
        p.hist.max_us = max as f64;
    }
    Ok(p)
}

fn bad_line(line: &str) -> BenchError {
    BenchError::failed(format!(
        "unexpected line in cyclictest's histogram: {line:?}"
    ))
}

/// The command line, for reports.
#[derive(Debug, Clone, Serialize)]
pub struct Invocation {
    /// `cyclictest V x.y`.
    pub version: String,
    /// Arguments of one round (the histogram file name varies).
    pub command: String,
}
