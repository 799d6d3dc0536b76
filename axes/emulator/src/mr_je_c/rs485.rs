//! Simulated MR-JE-C drives on one RS-485 line, served over a serial device (a real port, or the
//! master side of a pseudo-terminal whose other side the controller opens): Modbus RTU frames
//! delimited by the line's silence (MR-JE-C manual §4.5, §4.7), each frame offered to every
//! drive on the line (only the addressed station answers, a broadcast none, §4.6, §4.9.2). A
//! burst longer than an RTU frame is discarded. The virtual clock is the time since the line
//! started and advances every 10 ms while the line is quiet, so [Pr. PF46] expires.

use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serialport::SerialPort;

use super::{rtu, MrJeC};
use cellrt_fieldbus::modbus::rtu::MAX_FRAME;
use cellrt_fieldbus::modbus::serial::LineSettings;

/// How often the clock advances while the line is quiet.
const TICK: Duration = Duration::from_millis(10);

struct Shared {
    drives: Mutex<Vec<MrJeC>>,
    stop: AtomicBool,
    start: Instant,
    /// Frames discarded as longer than an RTU frame.
    overlong: std::sync::atomic::AtomicU64,
}

impl Shared {
    fn drives(&self) -> MutexGuard<'_, Vec<MrJeC>> {
        self.drives.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A running RS-485 line.
pub struct Rs485Line {
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

impl Rs485Line {
    /// Serves `drives` (each with [Pr. PN08] set to RS-485 and its own station number) on
    /// `port`, framed by `line`'s silence.
    pub fn start(
        drives: Vec<MrJeC>,
        port: Box<dyn SerialPort>,
        line: LineSettings,
    ) -> io::Result<Rs485Line> {
        let shared = Arc::new(Shared {
            drives: Mutex::new(drives),
            stop: AtomicBool::new(false),
            start: Instant::now(),
            overlong: Default::default(),
        });
        let s = shared.clone();
        let thread = std::thread::Builder::new()
            .name("rs485-line".into())
            .spawn(move || serve(port, &line, &s))?;
        Ok(Rs485Line {
            shared,
            thread: Some(thread),
        })
    }

    /// The drives on the line (locked: frames wait meanwhile).
    pub fn drives(&self) -> MutexGuard<'_, Vec<MrJeC>> {
        self.shared.drives()
    }

    /// The line's clock: time since start.
    pub fn now(&self) -> Duration {
        self.shared.start.elapsed()
    }

    /// Bursts discarded as longer than an RTU frame.
    pub fn overlong_frames(&self) -> u64 {
        self.shared.overlong.load(Ordering::Relaxed)
    }

    /// Stops the line and waits for its thread.
    pub fn stop(mut self) {
        self.halt();
    }

    fn halt(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Rs485Line {
    fn drop(&mut self) {
        self.halt();
    }
}

fn serve(mut port: Box<dyn SerialPort>, line: &LineSettings, s: &Shared) {
    let _ = port.set_timeout(line.silence());
    let mut frame = [0u8; MAX_FRAME];
    let mut have = 0usize;
    let mut overlong = false;
    let mut ticked = Instant::now();
    while !s.stop.load(Ordering::Relaxed) {
        match port.read(&mut frame[have..]) {
            Ok(k) if k > 0 => {
                have += k;
                if have == MAX_FRAME {
                    // Longer than any frame: wait for the silence, then drop it all.
                    overlong = true;
                    have = 0;
                }
                continue;
            }
            Ok(_) => {}
            Err(e) if e.kind() == io::ErrorKind::TimedOut => {}
            // No controller has the other side open (EIO on a pseudo-terminal): wait for one.
            Err(_) => std::thread::sleep(TICK),
        }
        // The line has been silent for a frame gap: what came is one frame.
        let now = s.start.elapsed();
        if overlong {
            s.overlong.fetch_add(1, Ordering::Relaxed);
            overlong = false;
            have = 0;
        } else if have > 0 {
            // Every drive on the line receives the frame (and counts it if garbled for it).
            let mut reply = None;
            for d in s.drives().iter_mut() {
                let r = rtu::answer_on_line(d, &frame[..have], now, line);
                reply = reply.or(r);
            }
            have = 0;
            if let Some(r) = reply {
                let _ = port.write_all(&r).and_then(|()| port.flush());
            }
        }
        if ticked.elapsed() >= TICK {
            ticked = Instant::now();
            for d in s.drives().iter_mut() {
                d.tick(now);
            }
        }
    }
}
