//! The live view does not depend on the recording (issue 33): a cell run in this process with
//! no recording file (`cellrt run --no-record --live`), and one with triggered capture between
//! triggers, serve every cycle and axis record to a Foxglove WebSocket client (a `tungstenite`
//! client on a thread of this test) subscribed to every channel. The client subscribes before
//! the axis is powered; the test then moves the axis by the operator service and waits until
//! the client has seen the axis record of the cycle the move ended at. Judged in cycles and
//! positions; the waits are timeouts only.

#[allow(dead_code)] // the shared support: this test asks the operator service through it
mod support;

use std::collections::{BTreeMap, HashMap};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use cellrt_config::CellConfig;
use cellrt_runtime::host::controller::{run, RunOptions, Summary};
use cellrt_runtime::host::operator::client::{running_cells, OperatorClient};
use cellrt_runtime::host::operator::wire::{Reply, Request};
use cellrt_runtime::host::record::proto;
use prost::Message as _;
use support::operator::{request, status};

/// Where the axis starts and where it is moved to, mm.
const START: f64 = 100.0;
const TARGET: f64 = 300.0;
/// How long a wait may take before the test fails (a timeout, not a measurement).
const PATIENCE: Duration = Duration::from_secs(60);

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

fn cell_text(name: &str, live: SocketAddr, recording: &str) -> String {
    format!(
        r#"
[cell]
name = "{name}"
cycle_time_us = 1000

[watchdogs]
max_consecutive_overruns = 0

[setpoints]
lookahead_ms = 1000

[live]
listen = "{live}"
page_port = 0

[recording]
{recording}

[[axes]]
name = "x"
drive = "mr-j4-tm"
mode = "csp"
unit = "mm"
counts_per_unit = 4194.304
limits = {{ position = [0.0, 800.0], velocity = 400.0, acceleration = 2000.0, jerk = 20000.0 }}
sim = {{ initial_position = {START} }}
"#
    )
}

/// What the viewer received: per topic, the decoded cycle numbers and the axis records.
#[derive(Default)]
struct Seen {
    topics: Vec<String>,
    cycles: Vec<u64>,
    axis: Vec<proto::AxisCycle>,
    events: usize,
}

/// A Foxglove WebSocket client subscribed to every advertised channel, reading until `stop`.
fn viewer(addr: SocketAddr, seen: &Mutex<Seen>, stop: &AtomicBool) {
    use tungstenite::client::IntoClientRequest;
    use tungstenite::Message;
    let end = Instant::now() + PATIENCE;
    let stream = loop {
        match TcpStream::connect(addr) {
            Ok(s) => break s,
            Err(e) => {
                assert!(Instant::now() < end, "the live view never listened: {e}");
                std::thread::sleep(Duration::from_millis(20));
            }
        }
    };
    let mut request = format!("ws://{addr}").into_client_request().unwrap();
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        tungstenite::http::HeaderValue::from_static("foxglove.sdk.v1"),
    );
    let (mut ws, _) = tungstenite::client(request, stream).expect("handshake");
    ws.get_ref()
        .set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    // Subscription id → topic.
    let mut topics: HashMap<u32, String> = HashMap::new();
    while !stop.load(Ordering::Acquire) {
        match ws.read() {
            Ok(Message::Binary(b)) => {
                // op 0x01 (message data), subscription id u32, log time u64, payload.
                assert_eq!(b[0], 0x01);
                let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
                let payload = &b[13..];
                let mut s = seen.lock().unwrap();
                match topics.get(&sub).map(String::as_str) {
                    Some("/cell/cycle") => s
                        .cycles
                        .push(proto::CycleStats::decode(payload).unwrap().cycle),
                    Some("/axis/x") => s.axis.push(proto::AxisCycle::decode(payload).unwrap()),
                    Some("/cell/events") => s.events += 1,
                    _ => {}
                }
            }
            Ok(Message::Text(t)) => {
                let doc: serde_json::Value = serde_json::from_str(&t).unwrap();
                if doc["op"] != "advertise" {
                    continue;
                }
                let mut subs = Vec::new();
                for ch in doc["channels"].as_array().unwrap() {
                    let id = topics.len() as u32 + 1;
                    let topic = ch["topic"].as_str().unwrap().to_string();
                    seen.lock().unwrap().topics.push(topic.clone());
                    topics.insert(id, topic);
                    subs.push(serde_json::json!({ "id": id, "channelId": ch["id"] }));
                }
                let sub = serde_json::json!({ "op": "subscribe", "subscriptions": subs });
                ws.send(Message::text(sub.to_string())).unwrap();
            }
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            // The cell ended the run.
            Err(_) => return,
        }
    }
    let _ = ws.close(None);
}

/// Waits (at most [`PATIENCE`]) until `done` holds of what the viewer has seen.
fn wait_seen(seen: &Mutex<Seen>, what: &str, done: impl Fn(&Seen) -> bool) {
    let end = Instant::now() + PATIENCE;
    loop {
        {
            let s = seen.lock().unwrap();
            if done(&s) {
                return;
            }
            assert!(
                Instant::now() < end,
                "the live view's client never {what}: {} cycle and {} axis messages, {} events, topics {:?}",
                s.cycles.len(),
                s.axis.len(),
                s.events,
                s.topics
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Runs the cell `name` (recording section `recording`, file `record`) with a viewer connected,
/// moves x from [`START`] to [`TARGET`] and returns what the viewer saw and the run's summary.
fn watch_a_move(name: &str, recording: &str, record: Option<PathBuf>) -> (Seen, Summary) {
    let live = SocketAddr::from(([127, 0, 0, 1], free_port()));
    let cell = CellConfig::parse(
        Path::new("live-without-recording.toml"),
        &cell_text(name, live, recording),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let shutdown = Arc::new(AtomicBool::new(false));
    let options = RunOptions {
        shutdown: shutdown.clone(),
        record,
        ..RunOptions::default()
    };
    let controller = std::thread::spawn(move || run(&cell, options));
    let seen = Arc::new(Mutex::new(Seen::default()));
    let stop = Arc::new(AtomicBool::new(false));
    let client = {
        let (seen, stop) = (seen.clone(), stop.clone());
        std::thread::spawn(move || viewer(live, &seen, &stop))
    };
    // Before any motion: the idle cell's cycles reach the viewer.
    wait_seen(&seen, "received a cycle record", |s| !s.cycles.is_empty());

    let end = Instant::now() + PATIENCE;
    while !running_cells().contains(&name.to_string()) {
        assert!(Instant::now() < end, "the cell never came up");
        std::thread::sleep(Duration::from_millis(20));
    }
    let c = OperatorClient::connect(Some(name)).unwrap();
    let power = Request::Power {
        on: true,
        axes: vec![],
    };
    assert!(matches!(request(&c, &power), Reply::Accepted { .. }));
    let mv = Request::Move {
        targets: BTreeMap::from([("x".to_string(), TARGET)]),
        relative: false,
        velocity: None,
        acceleration: None,
        jerk: None,
        clamp: false,
        line: false,
    };
    let mut done_at = None;
    let end = Instant::now() + PATIENCE;
    while done_at.is_none() {
        match request(&c, &mv) {
            Reply::Accepted { .. } => loop {
                let s = status(&c);
                let x = s.axes.iter().find(|a| a.name == "x").unwrap();
                if (x.position - TARGET).abs() < 1e-3
                    && x.velocity == 0.0
                    && s.active_command.is_none()
                {
                    done_at = Some(s.cycle);
                    break;
                }
                assert!(Instant::now() < end, "the move never ended: {s:?}");
                std::thread::sleep(Duration::from_millis(20));
            },
            // Powering on is still under way.
            r => {
                assert!(Instant::now() < end, "the move was never accepted: {r:?}");
                std::thread::sleep(Duration::from_millis(50));
            }
        }
    }
    let done_at = done_at.unwrap();
    wait_seen(&seen, "received the axis record of the move's end", |s| {
        s.axis.last().is_some_and(|a| a.cycle >= done_at)
    });
    stop.store(true, Ordering::Release);
    client.join().unwrap();
    shutdown.store(true, Ordering::Release);
    let summary = controller.join().unwrap().expect("cell runs");
    let seen = Arc::try_unwrap(seen).ok().unwrap().into_inner().unwrap();
    (seen, summary)
}

/// The viewer saw the whole move: every axis record in cycle order, starting at rest at
/// [`START`], moving, and at rest at [`TARGET`].
fn assert_saw_the_move(seen: &Seen, summary: &Summary) {
    for topic in ["/cell/cycle", "/cell/events", "/axis/x"] {
        assert!(seen.topics.iter().any(|t| t == topic), "{:?}", seen.topics);
    }
    assert!(seen.cycles.windows(2).all(|w| w[0] < w[1]));
    assert!(seen.axis.windows(2).all(|w| w[0].cycle < w[1].cycle));
    let first = seen.axis.first().unwrap();
    let last = seen.axis.last().unwrap();
    assert!(
        (first.actual_position - START).abs() < 1e-3,
        "{}",
        first.actual_position
    );
    assert!(
        (last.actual_position - TARGET).abs() < 1e-3,
        "{}",
        last.actual_position
    );
    assert!(seen.axis.iter().any(|a| a.setpoint_velocity > 1.0));
    let live = summary.live.as_ref().expect("a live view ran");
    assert!(
        live.messages_sent >= (seen.cycles.len() + seen.axis.len()) as u64,
        "{live:?}"
    );
}

#[test]
fn without_a_recording_the_live_view_gets_every_cycle() {
    let name = format!("live-norec-{}", std::process::id());
    let (seen, summary) = watch_a_move(&name, "enabled = false", None);
    assert_saw_the_move(&seen, &summary);
    assert!(
        summary.recording.files.is_empty(),
        "{:?}",
        summary.recording
    );
}

#[test]
fn triggered_capture_between_triggers_feeds_the_live_view() {
    let name = format!("live-trig-{}", std::process::id());
    let dir = tempfile::tempdir().unwrap();
    // A trigger that this run never meets: the capture stays between triggers.
    let recording = "mode = \"triggered\"\npre_s = 0.5\npost_s = 0.3\ntriggers = [\"drive_fault\"]";
    let (seen, summary) = watch_a_move(&name, recording, Some(dir.path().join("run.mcap")));
    assert_saw_the_move(&seen, &summary);
    assert!(
        summary.recording.files.is_empty(),
        "{:?}",
        summary.recording
    );
}
