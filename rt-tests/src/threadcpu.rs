//! CPU time of this process' threads by name, for benchmarks that cost a thread's work: from
//! `/proc/self/task/*/schedstat` (time on the CPU, ns) where the kernel keeps it, else from
//! `stat` (`utime` + `stime`, fields 14 and 15, in clock ticks).

use std::collections::HashMap;
use std::time::Instant;

use serde::Serialize;

/// One reading of every thread: tid → (name, CPU time in ns).
pub struct CpuSample {
    at: Instant,
    threads: HashMap<i32, (String, u64)>,
}

impl CpuSample {
    /// Reads every thread of this process now (threads that end while reading are left out).
    pub fn take() -> CpuSample {
        let mut threads = HashMap::new();
        if let Ok(dir) = std::fs::read_dir("/proc/self/task") {
            for t in dir.flatten() {
                let tid = t.file_name().to_string_lossy().parse::<i32>().ok();
                let stat = std::fs::read_to_string(t.path().join("stat")).ok();
                let Some((tid, (name, ticks))) = tid.zip(stat.as_deref().and_then(parse_stat))
                else {
                    continue;
                };
                let ns = std::fs::read_to_string(t.path().join("schedstat"))
                    .ok()
                    .and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok())
                    .unwrap_or_else(|| ticks.saturating_mul(1_000_000_000 / clock_ticks()));
                threads.insert(tid, (name, ns));
            }
        }
        CpuSample {
            at: Instant::now(),
            threads,
        }
    }

    /// Whether a thread named `name` runs.
    pub fn has_thread(&self, name: &str) -> bool {
        self.threads.values().any(|(n, _)| n == name)
    }
}

/// Clock ticks per second of `stat`'s times.
fn clock_ticks() -> u64 {
    // SAFETY: sysconf has no preconditions.
    (unsafe { libc::sysconf(libc::_SC_CLK_TCK) }).max(1) as u64
}

/// `(comm, utime + stime)` of a `stat` line (the name may hold spaces and parentheses).
fn parse_stat(text: &str) -> Option<(String, u64)> {
    let open = text.find('(')?;
    let close = text.rfind(')')?;
    let name = text.get(open + 1..close)?.to_string();
    // Fields from 3 (state) on: utime is field 14, stime 15.
    let rest: Vec<&str> = text.get(close + 1..)?.split_whitespace().collect();
    let utime: u64 = rest.get(11)?.parse().ok()?;
    let stime: u64 = rest.get(12)?.parse().ok()?;
    Some((name, utime + stime))
}

/// CPU use between two samples, % of one CPU, by the threads a live-view benchmark tells
/// apart (thread names as the kernel keeps them, at most 15 bytes).
#[derive(Debug, Clone, Default, Serialize)]
pub struct ThreadCpu {
    /// Span, s.
    pub span_s: f64,
    /// `cellrt-recorder`: drains the records, encodes them, writes MCAP, offers them live.
    pub recorder_pct: f64,
    /// `cellrt-live`: hands the recorder's messages to the WebSocket server.
    pub live_feeder_pct: f64,
    /// The Foxglove SDK's tokio threads (`tokio-rt-worker`): the WebSocket server.
    pub live_server_pct: f64,
    /// `bench-viewer`: the benchmark's own viewer.
    pub viewer_pct: f64,
    /// `cellrt-rt`.
    pub rt_pct: f64,
    /// Every thread of the process.
    pub process_pct: f64,
}

impl ThreadCpu {
    /// The CPU each group used from `a` to `b` (a thread started in between counts whole).
    pub fn between(a: &CpuSample, b: &CpuSample) -> ThreadCpu {
        let span_s = b.at.duration_since(a.at).as_secs_f64().max(1e-9);
        let pct = |ns: u64| ns as f64 / 1e9 / span_s * 100.0;
        let mut out = ThreadCpu {
            span_s,
            ..ThreadCpu::default()
        };
        let mut total = 0;
        for (tid, (name, ns)) in &b.threads {
            let used = ns.saturating_sub(a.threads.get(tid).map_or(0, |(_, t)| *t));
            total += used;
            let slot = match name.as_str() {
                "cellrt-recorder" => &mut out.recorder_pct,
                "cellrt-live" => &mut out.live_feeder_pct,
                "bench-viewer" => &mut out.viewer_pct,
                "cellrt-rt" => &mut out.rt_pct,
                n if n.starts_with("tokio-") => &mut out.live_server_pct,
                _ => continue,
            };
            *slot += pct(used);
        }
        out.process_pct = pct(total);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_lines_with_odd_names() {
        let line = "4242 (a (b) c) S 1 2 3 4 5 6 7 8 9 10 120 30 0 0 20 0 1 0";
        assert_eq!(parse_stat(line), Some(("a (b) c".to_string(), 150)));
        assert_eq!(parse_stat("4242 (x) S 1"), None);
    }

    #[test]
    fn a_busy_thread_shows_by_name() {
        let a = CpuSample::take();
        let end = Instant::now() + std::time::Duration::from_millis(300);
        let t = std::thread::Builder::new()
            .name("cellrt-recorder".into())
            .spawn(move || {
                let mut x = 0u64;
                while Instant::now() < end {
                    x = x.wrapping_add(std::hint::black_box(1));
                }
                x
            })
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(200));
        let b = CpuSample::take();
        t.join().unwrap();
        let cpu = ThreadCpu::between(&a, &b);
        assert!(cpu.recorder_pct > 0.0, "{cpu:?}");
        assert!(cpu.process_pct >= cpu.recorder_pct, "{cpu:?}");
    }
}
