//! The built-in live page (`http://ADDR/` beside the live view) in a real headless Chromium,
//! driven over the DevTools protocol: while the demo moves, the page shows the axes by name
//! with their FSA state, its count of received messages grows, an axis' position text changes
//! and its plot's pixels change (the plot scrolls), and the event log and the wakeup-latency
//! histogram fill. Without Chromium the test says plainly that it skipped.
//! `CELLRT_LIVE_PAGE_SCREENSHOT=FILE` also writes a screenshot of the page (the README's).

mod chromium;
mod common;

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

use base64::Engine as _;
use chromium::{Browser, Tab};
use common::demo_cell;
use serde_json::Value;

/// Moves back and forth for about 20 s, longer than the test needs (it stops the cell).
fn program() -> String {
    let far = "target = { x = 700.0, y = 500.0, z = -150.0, c = 180.0 }";
    let near = "target = { x = 100.0, y = 80.0, z = -20.0, c = 0.0 }";
    let mut p = String::from("[[step]]\ndo = \"power_on\"\n");
    for target in [far, near].repeat(3) {
        p += &format!("[[step]]\ndo = \"move\"\n{target}\n");
    }
    p + "[[step]]\ndo = \"wait\"\nseconds = 10\n[[step]]\ndo = \"power_off\"\n"
}

/// The longest the page may take to show each thing (a loaded machine is slow, never wrong).
const DEADLINE: Duration = Duration::from_secs(60);

/// What the page shows, read from its DOM (and the x plot's pixels as a data URL).
const SNAPSHOT: &str = r#"(() => {
  const text = (id) => document.getElementById(id)?.textContent ?? '';
  const axes = [...document.querySelectorAll('.axis')].map(a => ({
    name: a.dataset.axis,
    fsa: a.querySelector('.fsa')?.textContent,
    actual: a.querySelector('.actual')?.textContent,
    alarm: a.querySelector('.alarm')?.textContent,
    unit: a.querySelector('.unit')?.textContent,
    samples: Number(a.querySelector('canvas')?.dataset.samples),
  }));
  const x = document.querySelector('canvas[data-axis="x"]');
  return {
    link: text('link'),
    cell_state: text('cell-state'),
    received: Number(text('received')),
    events: [...document.querySelectorAll('#events li')].map(li => li.dataset.kind),
    latency: text('latency-stats'),
    axes,
    x_plot: x ? x.toDataURL() : '',
  };
})()"#;

/// The cell, and the live page's URL from its log.
struct Cell {
    child: Child,
    page: String,
    _dir: tempfile::TempDir,
}

impl Drop for Cell {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Runs the demo with the live page; `name` replaces the unique test name (the screenshot).
fn start_cell(name: Option<&str>) -> Cell {
    let dir = tempfile::tempdir().unwrap();
    let cfg = demo_cell(dir.path(), &program());
    let mut text = std::fs::read_to_string(&cfg).unwrap();
    if let Some(name) = name {
        let at = text.find("\nname = \"").unwrap() + 1;
        let end = at + text[at..].find('\n').unwrap();
        text.replace_range(at..end, &format!("name = \"{name}\""));
    }
    text.push_str("\n[live]\nlisten = \"127.0.0.1:0\"\npage_port = 0\n");
    std::fs::write(&cfg, text).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_cellrt"))
        .arg("run")
        .arg(&cfg)
        .env("NO_COLOR", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let lines = log_lines(child.stderr.take().unwrap());
    let end = Instant::now() + DEADLINE;
    let mut log = Vec::new();
    let page = loop {
        let line = lines
            .recv_timeout(end.saturating_duration_since(Instant::now()))
            .unwrap_or_else(|e| panic!("the cell logged no live page ({e}):\n{}", log.join("\n")));
        log.push(line.clone());
        if let Some(at) = line.find("live page on http://") {
            let url = &line[at + "live page on ".len()..];
            break url.split_whitespace().next().unwrap().to_string();
        }
    };
    Cell {
        child,
        page,
        _dir: dir,
    }
}

/// The cell's log lines (the rest are read and dropped so it never blocks on them).
fn log_lines(stderr: std::process::ChildStderr) -> Receiver<String> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines() {
            let Ok(line) = line else { break };
            let _ = tx.send(line);
        }
    });
    rx
}

/// Polls the page until `holds` accepts a snapshot; fails with the last one at the deadline.
fn until(browser: &mut Browser, tab: &Tab, what: &str, holds: impl Fn(&Value) -> bool) -> Value {
    let end = Instant::now() + DEADLINE;
    loop {
        let snap = browser.eval(tab, SNAPSHOT).unwrap();
        if holds(&snap) {
            return snap;
        }
        if Instant::now() > end {
            let mut shown = snap.clone();
            shown["x_plot"] = Value::from("…");
            panic!("the live page never showed {what}: {shown:#}");
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}

fn axis<'a>(snap: &'a Value, name: &str) -> &'a Value {
    snap["axes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == name)
        .unwrap_or(&Value::Null)
}

#[test]
fn the_live_page_plots_the_moving_demo_in_a_headless_chromium() {
    let mut browser = match Browser::launch() {
        Ok(b) => b,
        Err(why) => {
            println!("SKIPPED: the live page test needs a headless Chromium: {why}");
            return;
        }
    };
    let screenshot = std::env::var_os("CELLRT_LIVE_PAGE_SCREENSHOT");
    let cell = start_cell(screenshot.is_some().then_some("demo"));
    let tab = browser.open(&cell.page, 1400, 700).unwrap();

    let named = until(&mut browser, &tab, "the four axes by name", |s| {
        s["link"] == "connected" && ["x", "y", "z", "c"].iter().all(|n| !axis(s, n).is_null())
    });
    assert_eq!(
        named["axes"].as_array().unwrap().len(),
        4,
        "{}",
        named["axes"]
    );
    // Each value labelled with its axis' unit from the configuration.
    for (n, unit) in [
        ("x", " [mm]"),
        ("y", " [mm]"),
        ("z", " [mm]"),
        ("c", " [deg]"),
    ] {
        assert_eq!(axis(&named, n)["unit"], unit, "{}", named["axes"]);
    }
    until(&mut browser, &tab, "the axes enabled", |s| {
        ["x", "y", "z", "c"]
            .iter()
            .all(|n| axis(s, n)["fsa"] == "Operation enabled")
    });
    let first = until(&mut browser, &tab, "x moving", |s| {
        s["cell_state"] == "Moving" && axis(s, "x")["samples"].as_u64() > Some(200)
    });
    let later = until(&mut browser, &tab, "x's plot and position changing", |s| {
        s["received"].as_u64() > first["received"].as_u64()
            && axis(s, "x")["samples"].as_u64() > axis(&first, "x")["samples"].as_u64()
            && axis(s, "x")["actual"] != axis(&first, "x")["actual"]
            && s["x_plot"] != first["x_plot"]
    });
    assert_eq!(axis(&later, "x")["alarm"], "none");
    let filled = until(
        &mut browser,
        &tab,
        "events and the latency histogram",
        |s| {
            let kinds = s["events"].as_array().unwrap();
            kinds.iter().any(|k| k == "motion_started")
                && s["latency"].as_str().unwrap().contains("cycles: p50")
        },
    );
    println!(
        "live page {}: {} messages, x at {}, {}",
        cell.page,
        filled["received"],
        axis(&filled, "x")["actual"],
        filled["latency"]
    );
    if let Some(path) = screenshot {
        // A full plot window first.
        until(&mut browser, &tab, "a full plot", |s| {
            axis(s, "x")["samples"].as_u64() > Some(4500)
        });
        let png = browser.screenshot_base64(&tab).unwrap();
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(png)
            .unwrap();
        std::fs::write(path, bytes).unwrap();
    }
}
