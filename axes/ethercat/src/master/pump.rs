//! Driving ethercrab's futures over a [`Link`]: cellrt polls them itself and passes their frames
//! (bring-up and acyclic transfers; the cyclic exchange builds its own frame).

use std::future::Future;
use std::pin::pin;
use std::task::{Context, Poll, Waker};
use std::time::Duration;

use ethercrab::{PduRx, PduTx};

use super::error::{step, EthercatError};
use super::link::Link;

/// Drives an ethercrab future to completion, passing its frames over `link`.
pub(super) fn pump<F: Future>(
    fut: F,
    tx: &mut PduTx<'static>,
    rx: &mut PduRx<'static>,
    link: &mut dyn Link,
    buf: &mut [u8],
) -> F::Output {
    let mut fut = pin!(fut);
    let mut cx = Context::from_waker(Waker::noop());
    loop {
        if let Poll::Ready(v) = fut.as_mut().poll(&mut cx) {
            return v;
        }
        let mut sent = false;
        while let Some(frame) = tx.next_sendable_frame() {
            sent = true;
            let mut len = 0;
            let ok = frame.send_blocking(|data| {
                len = data.len().min(buf.len());
                buf[..len].copy_from_slice(&data[..len]);
                Ok(data.len())
            });
            if ok.is_ok() {
                if let Ok(n) = link.round_trip(buf, len) {
                    let _ = rx.receive_frame(&buf[..n]);
                }
            }
        }
        if !sent {
            std::thread::sleep(Duration::from_micros(20));
        }
    }
}

/// The bring-up's ends of ethercrab's PDU loop, the link and a frame buffer, borrowed until the
/// bus is built from them.
pub(super) struct Wire<'a> {
    pub(super) tx: &'a mut PduTx<'static>,
    pub(super) rx: &'a mut PduRx<'static>,
    pub(super) link: &'a mut dyn Link,
    pub(super) buf: &'a mut [u8],
}

impl Wire<'_> {
    /// Runs bring-up step `what` to completion.
    pub(super) fn run<T>(
        &mut self,
        what: impl Into<String>,
        fut: impl Future<Output = Result<T, ethercrab::error::Error>>,
    ) -> Result<T, EthercatError> {
        step(what, pump(fut, self.tx, self.rx, self.link, self.buf))
    }
}
