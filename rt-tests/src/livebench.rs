//! `cellrt bench live`: what the live view costs. The loop cell of `cellrt bench loop` (N
//! simulated axes in motion, recording on) runs in rounds that take turns: without the live
//! view, with it and no viewer, with it and one viewer — a Foxglove WebSocket client on a thread
//! of this process, off the RT CPU, subscribed to every channel and reading every message, as
//! the built-in page does. Per round: the CPU time of the recorder thread, the live view's
//! feeder, its server (the SDK's tokio threads) and the viewer, from `/proc/self/task/*/stat`
//! over the motion, and the RT loop's wakeup latency and loop time.

use std::fmt::Write as _;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{self, RunOptions};
use cellrt_runtime::host::program::Program;
use cellrt_runtime::rt::histogram::Percentiles;
use serde::Serialize;

use crate::error::BenchError;
use crate::loopbench::{config_text, program_text, LoopOptions};
use crate::threadcpu::{CpuSample, ThreadCpu};

/// Time from the RT thread's start to the first CPU sample: power-on and the viewer's
/// connection are not part of the measurement.
const WARMUP: Duration = Duration::from_millis(1500);
/// Time before the run's end at which the second CPU sample is taken (the threads still run).
const BEFORE_END: Duration = Duration::from_millis(500);

/// What a round runs beside the cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LiveMode {
    /// No live view.
    Off,
    /// The live view and its page serve, nobody is connected.
    NoViewer,
    /// One viewer subscribed to every channel.
    OneViewer,
}

impl LiveMode {
    /// The modes in the order the rounds take them.
    pub const ALL: [LiveMode; 3] = [LiveMode::Off, LiveMode::NoViewer, LiveMode::OneViewer];

    fn label(self) -> &'static str {
        match self {
            LiveMode::Off => "live view off",
            LiveMode::NoViewer => "no viewer",
            LiveMode::OneViewer => "one viewer",
        }
    }
}

/// One round.
#[derive(Debug, Clone, Serialize)]
pub struct LiveRound {
    /// What ran beside the cell.
    pub mode: LiveMode,
    /// CPU of the threads over the measured span.
    pub cpu: ThreadCpu,
    /// Wakeup latency of the whole run.
    pub wakeup_latency: Percentiles,
    /// Loop time of the whole run.
    pub loop_time: Percentiles,
    /// Missed deadlines.
    pub overruns: u64,
    /// Records the RT thread could not hand to the recorder.
    pub dropped_records: u64,
    /// Messages the live view handed to its server.
    pub live_sent: u64,
    /// Messages dropped before the server (its feeder did not keep up).
    pub live_dropped: u64,
    /// Messages the viewer received.
    pub viewer_messages: u64,
}

/// The whole benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct LiveReport {
    /// The cell of each round.
    pub options: LoopOptions,
    /// Rounds per mode.
    pub rounds_per_mode: usize,
    /// Every round, in the order run.
    pub rounds: Vec<LiveRound>,
    /// `/proc/loadavg` before the first round and after the last (other load on the machine).
    pub load_average: [String; 2],
}

/// Runs `rounds` rounds of each mode, taking turns.
pub fn run(
    opts: &LoopOptions,
    rounds: usize,
    progress: &mut dyn FnMut(&LiveRound),
) -> Result<LiveReport, BenchError> {
    if rounds == 0 {
        return Err(BenchError::bad("--rounds must be at least 1"));
    }
    let least = WARMUP + BEFORE_END + Duration::from_secs(2);
    if opts.duration_s < least.as_secs_f64() {
        return Err(BenchError::bad(format!(
            "--duration: at least {} s (warm-up and the end are not measured)",
            least.as_secs_f64()
        )));
    }
    let before = load_average();
    let mut out = Vec::new();
    for r in 0..rounds * LiveMode::ALL.len() {
        let round = run_round(opts, LiveMode::ALL[r % LiveMode::ALL.len()], r)?;
        progress(&round);
        out.push(round);
    }
    Ok(LiveReport {
        options: *opts,
        rounds_per_mode: rounds,
        rounds: out,
        load_average: [before, load_average()],
    })
}

/// The 1, 5 and 15 min load averages.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_default()
}

/// A port free a moment ago, for the live view.
pub(crate) fn free_port() -> Result<u16, BenchError> {
    TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .map_err(|e| BenchError::failed(format!("no free port: {e}")))
}

fn run_round(opts: &LoopOptions, mode: LiveMode, n: usize) -> Result<LiveRound, BenchError> {
    let dir = tempfile::tempdir()
        .map_err(|e| BenchError::failed(format!("cannot create a temp dir: {e}")))?;
    let name = format!("bench-live-{}-{n}", std::process::id());
    let mut text = config_text(&name, opts);
    let live = SocketAddr::from(([127, 0, 0, 1], free_port()?));
    if mode != LiveMode::Off {
        let _ = write!(text, "\n[live]\nlisten = \"{live}\"\npage_port = 0\n");
    }
    let cfg_path = dir.path().join("bench.toml");
    let cell = CellConfig::parse(&cfg_path, &text).map_err(|e| BenchError::bad(e.to_string()))?;
    let program = Program::parse(
        &dir.path().join("bench-program.toml"),
        &program_text(opts.axes, opts.duration_s),
        &cell,
    )
    .map_err(|e| BenchError::failed(format!("generated program: {e}")))?;
    let record = dir.path().join(format!("{name}.mcap"));
    let duration = Duration::from_secs_f64(opts.duration_s);
    let cell_thread = std::thread::spawn(move || {
        controller::run(
            &cell,
            RunOptions {
                program: Some(program),
                duration: Some(duration),
                record: Some(record),
                shutdown: Arc::new(AtomicBool::new(false)),
                hook: None,
                external_planner: false,
            },
        )
    });
    let stop = Arc::new(AtomicBool::new(false));
    let received = Arc::new(AtomicU64::new(0));
    let viewer = (mode == LiveMode::OneViewer).then(|| {
        let (stop, received, rt_cpu) = (stop.clone(), received.clone(), opts.cpu);
        std::thread::Builder::new()
            .name("bench-viewer".into())
            .spawn(move || viewer(live, rt_cpu, &stop, &received))
    });
    let cpu = measure_cpu(duration);
    stop.store(true, Ordering::Release);
    let summary = cell_thread
        .join()
        .map_err(|_| BenchError::failed("the cell's thread panicked"))?
        .map_err(|e| BenchError::failed(e.to_string()))?;
    if let Some(Ok(v)) = viewer {
        v.join()
            .map_err(|_| BenchError::failed("the viewer panicked"))??;
    }
    Ok(LiveRound {
        mode,
        cpu: cpu?,
        wakeup_latency: summary.wakeup_latency,
        loop_time: summary.loop_time,
        overruns: summary.counters.overruns,
        dropped_records: summary.counters.dropped_records,
        live_sent: summary.live.as_ref().map_or(0, |l| l.messages_sent),
        live_dropped: summary.live.as_ref().map_or(0, |l| l.messages_dropped),
        viewer_messages: received.load(Ordering::Relaxed),
    })
}

/// Samples the threads' CPU time after the warm-up and shortly before the run's end.
fn measure_cpu(duration: Duration) -> Result<ThreadCpu, BenchError> {
    let end = Instant::now() + Duration::from_secs(30);
    while !CpuSample::take().has_thread("cellrt-rt") {
        if Instant::now() > end {
            return Err(BenchError::failed("the RT thread did not start"));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(WARMUP);
    let first = CpuSample::take();
    std::thread::sleep(duration.saturating_sub(WARMUP + BEFORE_END));
    let second = CpuSample::take();
    Ok(ThreadCpu::between(&first, &second))
}

/// The viewer: connects (retrying while the server starts), subscribes to every advertised
/// channel and reads until `stop`, counting the messages.
pub(crate) fn viewer(
    addr: SocketAddr,
    rt_cpu: usize,
    stop: &AtomicBool,
    received: &AtomicU64,
) -> Result<(), BenchError> {
    use tungstenite::client::IntoClientRequest;
    use tungstenite::Message;
    keep_off_cpu(rt_cpu);
    let end = Instant::now() + Duration::from_secs(10);
    let stream = loop {
        match TcpStream::connect(addr) {
            Ok(s) => break s,
            Err(_) if Instant::now() < end => std::thread::sleep(Duration::from_millis(20)),
            Err(e) => {
                return Err(BenchError::failed(format!(
                    "viewer: cannot connect to {addr}: {e}"
                )))
            }
        }
    };
    let mut request = format!("ws://{addr}")
        .into_client_request()
        .map_err(|e| BenchError::failed(format!("viewer: {e}")))?;
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        tungstenite::http::HeaderValue::from_static("foxglove.sdk.v1"),
    );
    let (mut ws, _) = tungstenite::client(request, stream)
        .map_err(|e| BenchError::failed(format!("viewer: handshake: {e}")))?;
    ws.get_ref()
        .set_read_timeout(Some(Duration::from_millis(100)))
        .map_err(|e| BenchError::failed(format!("viewer: {e}")))?;
    let mut next_id = 0u32;
    while !stop.load(Ordering::Acquire) {
        match ws.read() {
            Ok(Message::Binary(_)) => {
                received.fetch_add(1, Ordering::Relaxed);
            }
            Ok(Message::Text(t)) => {
                if let Some(sub) = subscription(&t, &mut next_id) {
                    ws.send(Message::text(sub))
                        .map_err(|e| BenchError::failed(format!("viewer: subscribe: {e}")))?;
                }
            }
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            // The cell ended the run.
            Err(_) => return Ok(()),
        }
    }
    // A closing handshake, so the server sees a viewer leave rather than a reset.
    let _ = ws.close(None);
    let end = Instant::now() + Duration::from_secs(1);
    while Instant::now() < end && ws.read().is_ok() {}
    Ok(())
}

/// The subscribe request for every channel of an `advertise` message.
fn subscription(text: &str, next_id: &mut u32) -> Option<String> {
    let doc: serde_json::Value = serde_json::from_str(text).ok()?;
    if doc["op"] != "advertise" {
        return None;
    }
    let subs: Vec<serde_json::Value> = doc["channels"]
        .as_array()?
        .iter()
        .map(|ch| {
            *next_id += 1;
            serde_json::json!({ "id": *next_id, "channelId": ch["id"] })
        })
        .collect();
    Some(serde_json::json!({ "op": "subscribe", "subscriptions": subs }).to_string())
}

/// Keeps the calling thread off the RT thread's CPU, as a viewer elsewhere would be.
fn keep_off_cpu(rt_cpu: usize) {
    // SAFETY: a zeroed cpu_set_t is a valid empty set; the calls only read and write it.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        for cpu in crate::procscan::online_cpus() {
            if cpu != rt_cpu {
                libc::CPU_SET(cpu, &mut set);
            }
        }
        let _ = libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// The rounds, then the medians per mode.
pub fn render(r: &LiveReport) -> String {
    let o = &r.options;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "== cellrt bench live: {} axes at {} µs, {} s per round, {} rounds per mode, recording on",
        o.axes, o.interval_us, o.duration_s, r.rounds_per_mode
    );
    let _ = writeln!(
        s,
        "load average {} before, {} after (1, 5, 15 min)",
        r.load_average[0], r.load_average[1]
    );
    let _ = writeln!(
        s,
        "| round | mode | recorder % | live feeder % | live server % | viewer % | process % | wakeup p50 µs | wakeup p99 µs | loop p99 µs | overruns | viewer msgs | sent | dropped |"
    );
    let _ = writeln!(
        s,
        "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for (i, x) in r.rounds.iter().enumerate() {
        let c = &x.cpu;
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {} | {} | {} | {} |",
            i + 1,
            x.mode.label(),
            c.recorder_pct,
            c.live_feeder_pct,
            c.live_server_pct,
            c.viewer_pct,
            c.process_pct,
            x.wakeup_latency.p50_us,
            x.wakeup_latency.p99_us,
            x.loop_time.p99_us,
            x.overruns,
            x.viewer_messages,
            x.live_sent,
            x.live_dropped
        );
    }
    let _ = writeln!(s, "\nmedians per mode:");
    let _ = writeln!(
        s,
        "| mode | recorder % | live feeder % | live server % | viewer % | wakeup p50 µs | wakeup p99 µs | wakeup p99.9 µs | loop p50 µs | loop p99 µs |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for mode in LiveMode::ALL {
        let rs: Vec<&LiveRound> = r.rounds.iter().filter(|x| x.mode == mode).collect();
        let m = |f: &dyn Fn(&LiveRound) -> f64| median(rs.iter().map(|x| f(x)).collect());
        let _ = writeln!(
            s,
            "| {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |",
            mode.label(),
            m(&|x| x.cpu.recorder_pct),
            m(&|x| x.cpu.live_feeder_pct),
            m(&|x| x.cpu.live_server_pct),
            m(&|x| x.cpu.viewer_pct),
            m(&|x| x.wakeup_latency.p50_us),
            m(&|x| x.wakeup_latency.p99_us),
            m(&|x| x.wakeup_latency.p999_us),
            m(&|x| x.loop_time.p50_us),
            m(&|x| x.loop_time.p99_us),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_viewer_subscribes_to_every_advertised_channel() {
        let mut id = 0;
        let sub = subscription(
            r#"{"op":"advertise","channels":[{"id":7,"topic":"/cell/cycle"},{"id":9,"topic":"/axis/a0"}]}"#,
            &mut id,
        )
        .unwrap();
        let v: serde_json::Value = serde_json::from_str(&sub).unwrap();
        assert_eq!(v["op"], "subscribe");
        assert_eq!(
            v["subscriptions"],
            serde_json::json!([{ "id": 1, "channelId": 7 }, { "id": 2, "channelId": 9 }])
        );
        assert!(subscription(r#"{"op":"serverInfo"}"#, &mut id).is_none());
    }

    #[test]
    fn medians() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
