//! `cellrt bench ipc`: one-way delivery time of a setpoint block from the planner's publisher to
//! the RT thread's reader (cellrt's setpoint service and `SetpointStream`), beside a raw
//! iceoryx2 publish-subscribe of the same payload size with default settings, measured the same
//! way in alternating rounds (A B A B…) in one run.
//!
//! Method: the sender stamps the block with the time it starts the loan and sends; a receiver
//! thread busy-polls and takes the time when the block is readable. One block in flight at a
//! time (the sender waits for the receiver's acknowledgement through an atomic).

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use cellrt_runtime::rt::setpoint_stream::SetpointStream;
use cellrt_runtime::services;
use cellrt_runtime::setpoints::{AxisSetpoint, SetpointHeader, BLOCK_CYCLES};
use iceoryx2::prelude::*;
use serde::Serialize;

use crate::BenchError;

/// Percentiles of one side, µs.
#[derive(Debug, Clone, Serialize)]
pub struct Side {
    /// Samples.
    pub count: usize,
    /// Median.
    pub p50_us: f64,
    /// 99th percentile.
    pub p99_us: f64,
    /// Largest.
    pub max_us: f64,
}

/// The comparison.
#[derive(Debug, Clone, Serialize)]
pub struct IpcReport {
    /// Axes per block (payload = 16 cycles × axes × 24 bytes).
    pub axes: usize,
    /// Payload bytes.
    pub payload_bytes: usize,
    /// cellrt's setpoint path.
    pub cellrt: Side,
    /// Raw iceoryx2 of the same size.
    pub raw: Side,
}

/// Which path a round measures.
#[derive(Clone, Copy)]
enum Path {
    Cellrt,
    Raw,
}

/// Runs `rounds` alternating rounds of `per_round` blocks each of `axes` axes.
pub fn run(axes: usize, rounds: u32, per_round: u32) -> Result<IpcReport, BenchError> {
    if !(1..=cellrt_runtime::setpoints::MAX_AXES).contains(&axes) {
        return Err(BenchError::bad(format!(
            "--axes: must be 1..={} (got {axes})",
            cellrt_runtime::setpoints::MAX_AXES
        )));
    }
    if rounds == 0 || per_round == 0 {
        return Err(BenchError::bad("--rounds and --count must be > 0"));
    }
    let mut cellrt = Vec::new();
    let mut raw = Vec::new();
    for r in 0..rounds * 2 {
        let path = if r % 2 == 0 { Path::Cellrt } else { Path::Raw };
        let samples = round(path, axes, per_round, r)?;
        match path {
            Path::Cellrt => cellrt.extend(samples),
            Path::Raw => raw.extend(samples),
        }
    }
    Ok(IpcReport {
        axes,
        payload_bytes: BLOCK_CYCLES * axes * std::mem::size_of::<AxisSetpoint>(),
        cellrt: side(cellrt),
        raw: side(raw),
    })
}

fn side(mut us: Vec<f64>) -> Side {
    us.sort_by(f64::total_cmp);
    let q = |p: f64| us[((us.len() - 1) as f64 * p).round() as usize];
    Side {
        count: us.len(),
        p50_us: q(0.5),
        p99_us: q(0.99),
        max_us: us[us.len() - 1],
    }
}

/// One round: a receiver thread and this thread as the sender; returns one-way times, µs.
fn round(path: Path, axes: usize, count: u32, r: u32) -> Result<Vec<f64>, BenchError> {
    let cell = format!("bench-ipc-{}-{r}", std::process::id());
    let origin = Instant::now();
    let ready = Arc::new(AtomicBool::new(false));
    let received = Arc::new(AtomicU64::new(0));
    let (ready2, received2, cell2) = (ready.clone(), received.clone(), cell.clone());
    let n = BLOCK_CYCLES * axes;
    let receiver = std::thread::spawn(move || -> Result<Vec<f64>, BenchError> {
        let node = services::node(&cell2, "rx").map_err(|e| BenchError::failed(e.to_string()))?;
        let mut out = Vec::with_capacity(count as usize);
        let deadline = Instant::now() + Duration::from_secs(60);
        match path {
            Path::Cellrt => {
                let sub = services::setpoint_subscriber(&node, &cell2)
                    .map_err(|e| BenchError::failed(e.to_string()))?;
                let mut stream = SetpointStream::new(sub);
                ready2.store(true, Ordering::Release);
                while out.len() < count as usize && Instant::now() < deadline {
                    if let Ok(Some(b)) = stream.front() {
                        let now = origin.elapsed().as_nanos() as f64;
                        out.push((now - b.setpoints[0].position) / 1e3);
                        stream.pop();
                        received2.fetch_add(1, Ordering::Release);
                    }
                }
            }
            Path::Raw => {
                let service = raw_service(&node, &cell2)?;
                let sub = service
                    .subscriber_builder()
                    .create()
                    .map_err(|e| BenchError::failed(format!("{e:?}")))?;
                ready2.store(true, Ordering::Release);
                while out.len() < count as usize && Instant::now() < deadline {
                    if let Ok(Some(s)) = sub.receive() {
                        let now = origin.elapsed().as_nanos() as f64;
                        out.push((now - s.payload()[0].position) / 1e3);
                        drop(s);
                        received2.fetch_add(1, Ordering::Release);
                    }
                }
            }
        }
        Ok(out)
    });
    while !ready.load(Ordering::Acquire) && !receiver.is_finished() {
        std::thread::sleep(Duration::from_millis(1));
    }
    let node = services::node(&cell, "tx").map_err(|e| BenchError::failed(e.to_string()))?;
    let rows = vec![AxisSetpoint::default(); n];
    let send_all = |send: &mut dyn FnMut(f64) -> Result<(), BenchError>| -> Result<(), BenchError> {
        // Let the connection settle (the first send after a peer joins allocates).
        std::thread::sleep(Duration::from_millis(20));
        for i in 0..count {
            send(origin.elapsed().as_nanos() as f64)?;
            let until = Instant::now() + Duration::from_secs(2);
            while received.load(Ordering::Acquire) <= u64::from(i) {
                if Instant::now() > until {
                    return Err(BenchError::failed("the receiver stopped answering"));
                }
                std::hint::spin_loop();
            }
        }
        Ok(())
    };
    let sent = match path {
        Path::Cellrt => {
            let publisher = services::setpoint_publisher(&node, &cell, axes)
                .map_err(|e| BenchError::failed(e.to_string()))?;
            let mut rows = rows;
            send_all(&mut |t| {
                rows[0].position = t;
                let mut loaned = publisher
                    .loan_slice_uninit(n)
                    .map_err(|e| BenchError::failed(format!("{e:?}")))?;
                *loaned.user_header_mut() = SetpointHeader {
                    motion_id: 1,
                    flags: 0,
                    start_cycle: 0,
                    cycles: BLOCK_CYCLES as u32,
                    axis_count: axes as u32,
                };
                loaned
                    .write_from_slice(&rows)
                    .send()
                    .map(|_| ())
                    .map_err(|e| BenchError::failed(format!("{e:?}")))
            })
        }
        Path::Raw => {
            let service = raw_service(&node, &cell)?;
            let publisher = service
                .publisher_builder()
                .initial_max_slice_len(n)
                .create()
                .map_err(|e| BenchError::failed(format!("{e:?}")))?;
            let mut rows = rows;
            send_all(&mut |t| {
                rows[0].position = t;
                publisher
                    .loan_slice_uninit(n)
                    .map_err(|e| BenchError::failed(format!("{e:?}")))?
                    .write_from_slice(&rows)
                    .send()
                    .map(|_| ())
                    .map_err(|e| BenchError::failed(format!("{e:?}")))
            })
        }
    };
    let samples = receiver
        .join()
        .map_err(|_| BenchError::failed("the receiver panicked"))??;
    sent?;
    Ok(samples)
}

fn raw_service(
    node: &Node<ipc::Service>,
    cell: &str,
) -> Result<
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<
        ipc::Service,
        [AxisSetpoint],
        (),
    >,
    BenchError,
> {
    let name = ServiceName::new(&format!("cellrt/{cell}/raw-bench"))
        .map_err(|e| BenchError::failed(format!("{e:?}")))?;
    node.service_builder(&name)
        .publish_subscribe::<[AxisSetpoint]>()
        .open_or_create()
        .map_err(|e| BenchError::failed(format!("{e:?}")))
}

/// The table.
pub fn render(r: &IpcReport) -> String {
    format!(
        "setpoint block delivery, one way ({} axes, {} bytes), alternating rounds\n\
         {:<32} {:>8} {:>10} {:>10} {:>10}\n\
         {:<32} {:>8} {:>10.2} {:>10.2} {:>10.2}\n\
         {:<32} {:>8} {:>10.2} {:>10.2} {:>10.2}\n\
         cellrt − raw at p50: {:+.2} µs\n",
        r.axes,
        r.payload_bytes,
        "path",
        "samples",
        "p50 µs",
        "p99 µs",
        "max µs",
        "cellrt setpoint service + stream",
        r.cellrt.count,
        r.cellrt.p50_us,
        r.cellrt.p99_us,
        r.cellrt.max_us,
        "raw iceoryx2 publish-subscribe",
        r.raw.count,
        r.raw.p50_us,
        r.raw.p99_us,
        r.raw.max_us,
        r.cellrt.p50_us - r.raw.p50_us
    )
}
