//! A headless Chromium driven over the DevTools protocol on a pipe (`--remote-debugging-pipe`:
//! the browser reads NUL-terminated JSON commands on fd 3 and writes answers and events on fd 4),
//! for the tests of pages the cell serves. No WebSocket client and no open debugging port.

use std::io::{BufRead, BufReader, PipeReader, PipeWriter, Write};
use std::os::fd::AsRawFd;
use std::os::unix::process::CommandExt;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use serde_json::{json, Value};

/// How long one DevTools command may take.
const ANSWER_TIMEOUT: Duration = Duration::from_secs(30);

/// The browser: `chromium`, or `$CELLRT_CHROMIUM`.
pub fn binary() -> String {
    std::env::var("CELLRT_CHROMIUM").unwrap_or_else(|_| "chromium".into())
}

/// A running headless Chromium; killed on drop.
pub struct Browser {
    child: Child,
    to_browser: PipeWriter,
    from_browser: Receiver<Value>,
    next_id: u64,
    _profile: tempfile::TempDir,
}

/// One tab, attached.
pub struct Tab {
    session: String,
}

impl Browser {
    /// Starts the browser, or says why it cannot (not installed).
    pub fn launch() -> Result<Browser, String> {
        let bin = binary();
        let found = Command::new(&bin)
            .arg("--version")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if !found {
            return Err(format!(
                "{bin} is not installed (apt-get install chromium, or set CELLRT_CHROMIUM)"
            ));
        }
        let profile = tempfile::tempdir().map_err(|e| e.to_string())?;
        let (browser_reads, we_write) = std::io::pipe().map_err(|e| e.to_string())?;
        let (we_read, browser_writes) = std::io::pipe().map_err(|e| e.to_string())?;
        let (r, w) = (browser_reads.as_raw_fd(), browser_writes.as_raw_fd());
        let mut cmd = Command::new(&bin);
        cmd.args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-dev-shm-usage",
            "--no-first-run",
            "--no-default-browser-check",
            "--hide-scrollbars",
            "--remote-debugging-pipe",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg("about:blank")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
        // SAFETY: only async-signal-safe calls between fork and exec: the pipe ends go to fd 3
        // and 4 (through copies above them, so that dup2 never meets its own target).
        unsafe {
            cmd.pre_exec(move || {
                use nix::libc;
                let r2 = libc::fcntl(r, libc::F_DUPFD, 10);
                let w2 = libc::fcntl(w, libc::F_DUPFD, 10);
                if r2 < 0 || w2 < 0 || libc::dup2(r2, 3) < 0 || libc::dup2(w2, 4) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let child = cmd.spawn().map_err(|e| format!("{bin}: {e}"))?;
        drop((browser_reads, browser_writes));
        Ok(Browser {
            child,
            to_browser: we_write,
            from_browser: read_messages(we_read),
            next_id: 0,
            _profile: profile,
        })
    }

    /// Sends `method` (to `tab`, or to the browser) and waits for its answer.
    pub fn call(
        &mut self,
        tab: Option<&Tab>,
        method: &str,
        params: Value,
    ) -> Result<Value, String> {
        self.next_id += 1;
        let id = self.next_id;
        let mut msg = json!({ "id": id, "method": method, "params": params });
        if let Some(t) = tab {
            msg["sessionId"] = json!(t.session);
        }
        let mut bytes = serde_json::to_vec(&msg).expect("JSON");
        bytes.push(0);
        self.to_browser
            .write_all(&bytes)
            .map_err(|e| format!("{method}: the browser went away: {e}"))?;
        let end = Instant::now() + ANSWER_TIMEOUT;
        loop {
            let left = end.saturating_duration_since(Instant::now());
            let answer = match self.from_browser.recv_timeout(left) {
                Ok(a) => a,
                Err(RecvTimeoutError::Timeout) => return Err(format!("{method}: no answer")),
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(format!("{method}: the browser went away"))
                }
            };
            if answer["id"] != json!(id) {
                continue; // an event, or an answer to another command
            }
            if let Some(e) = answer.get("error") {
                return Err(format!("{method}: {e}"));
            }
            return Ok(answer["result"].clone());
        }
    }

    /// Opens `url` in a new tab of `width` × `height` CSS pixels.
    pub fn open(&mut self, url: &str, width: u32, height: u32) -> Result<Tab, String> {
        let target = self.call(None, "Target.createTarget", json!({ "url": "about:blank" }))?;
        let attached = self.call(
            None,
            "Target.attachToTarget",
            json!({ "targetId": target["targetId"], "flatten": true }),
        )?;
        let tab = Tab {
            session: attached["sessionId"]
                .as_str()
                .ok_or("Target.attachToTarget: no sessionId")?
                .to_string(),
        };
        self.call(
            Some(&tab),
            "Emulation.setDeviceMetricsOverride",
            json!({ "width": width, "height": height, "deviceScaleFactor": 1, "mobile": false }),
        )?;
        self.call(Some(&tab), "Page.navigate", json!({ "url": url }))?;
        Ok(tab)
    }

    /// The value of the JavaScript expression `expr` in `tab` (JSON-serialisable values).
    pub fn eval(&mut self, tab: &Tab, expr: &str) -> Result<Value, String> {
        let r = self.call(
            Some(tab),
            "Runtime.evaluate",
            json!({ "expression": expr, "returnByValue": true }),
        )?;
        if let Some(e) = r.get("exceptionDetails") {
            return Err(format!("{expr}: {e}"));
        }
        Ok(r["result"]["value"].clone())
    }

    /// A PNG screenshot of `tab`, base64 as the protocol gives it.
    pub fn screenshot_base64(&mut self, tab: &Tab) -> Result<String, String> {
        let r = self.call(
            Some(tab),
            "Page.captureScreenshot",
            json!({ "format": "png" }),
        )?;
        r["data"]
            .as_str()
            .map(str::to_string)
            .ok_or_else(|| "Page.captureScreenshot: no data".into())
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The browser's messages, parsed on a thread of their own.
fn read_messages(from: PipeReader) -> Receiver<Value> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut from = BufReader::new(from);
        let mut buf = Vec::new();
        while from.read_until(0, &mut buf).is_ok_and(|n| n > 0) {
            if buf.last() == Some(&0) {
                buf.pop();
            }
            if let Ok(v) = serde_json::from_slice(&buf) {
                if tx.send(v).is_err() {
                    break;
                }
            }
            buf.clear();
        }
    });
    rx
}
