//! The mailbox worker's frames carried by the RT thread: one link, one thread doing its I/O.
//! The worker hands a frame over and waits; the RT thread sends it after the cyclic frame
//! (at most [`FRAMES_PER_CYCLE`] per cycle) and hands the return back. Frame buffers move
//! between the two through lock-free queues: the RT side neither allocates nor blocks.

use std::sync::Arc;
use std::time::{Duration, Instant};

use crossbeam::queue::ArrayQueue;

use super::link::{Link, LinkError};

/// Bytes of a carried frame buffer (an Ethernet frame without FCS, rounded up).
const FRAME_BUF: usize = 1536;
/// Frames the RT thread carries per cycle at most: a mailbox transfer takes a few cycles,
/// the cycle itself one round trip more at most.
pub(super) const FRAMES_PER_CYCLE: usize = 1;
/// Frame buffers in circulation (one in flight, one returning late after a timeout).
const POOL: usize = 2;
/// How long the worker waits for its frame to come back: a few cycles at the slowest cycle
/// time (8 ms), and longer than the link's frame timeout.
const CARRY_TIMEOUT: Duration = Duration::from_millis(200);
/// The worker's poll interval while its frame is out.
const POLL: Duration = Duration::from_micros(50);

/// A frame on its way: the bytes, their length, and what the link made of it.
struct CarriedFrame {
    seq: u64,
    buf: Box<[u8; FRAME_BUF]>,
    len: usize,
    /// Length of the returned frame; `None`: lost.
    returned: Option<usize>,
}

/// The two queues between the worker and the RT thread.
struct Queues {
    to_rt: ArrayQueue<CarriedFrame>,
    to_worker: ArrayQueue<CarriedFrame>,
}

/// The RT thread's end: carries the worker's frames over the cyclic link.
pub(super) struct CarrierRt {
    queues: Arc<Queues>,
}

impl CarrierRt {
    /// Sends up to [`FRAMES_PER_CYCLE`] waiting frames over `link` and hands their returns
    /// back. No allocation, no lock: the buffers only change hands.
    pub(super) fn carry(&self, link: &mut dyn Link) -> usize {
        let mut carried = 0;
        while carried < FRAMES_PER_CYCLE {
            let Some(mut f) = self.queues.to_rt.pop() else {
                break;
            };
            let len = f.len;
            f.returned = link.round_trip(&mut f.buf[..], len).ok();
            // The pool is no larger than the queue: the push cannot fail.
            let _ = self.queues.to_worker.push(f);
            carried += 1;
        }
        carried
    }
}

/// The worker's end: a [`Link`] whose round trips ride the RT thread's cycle.
pub(super) struct CarriedLink {
    queues: Arc<Queues>,
    free: Vec<CarriedFrame>,
    seq: u64,
    /// Carried frames that did not return (a reply given up on included).
    lost: u64,
}

/// A carrier's two ends.
pub(super) fn carrier() -> (CarrierRt, CarriedLink) {
    let queues = Arc::new(Queues {
        to_rt: ArrayQueue::new(POOL),
        to_worker: ArrayQueue::new(POOL),
    });
    let free = (0..POOL)
        .map(|_| CarriedFrame {
            seq: 0,
            buf: Box::new([0; FRAME_BUF]),
            len: 0,
            returned: None,
        })
        .collect();
    (
        CarrierRt {
            queues: queues.clone(),
        },
        CarriedLink {
            queues,
            free,
            seq: 0,
            lost: 0,
        },
    )
}

impl CarriedLink {
    /// Takes back the frames that have returned; the one numbered `seq` is written into `buf`.
    fn collect(&mut self, seq: u64, buf: &mut [u8]) -> Option<Result<usize, LinkError>> {
        let mut answer = None;
        while let Some(f) = self.queues.to_worker.pop() {
            self.lost += u64::from(f.returned.is_none());
            if f.seq == seq {
                answer = Some(match f.returned {
                    Some(n) => {
                        let n = n.min(buf.len());
                        buf[..n].copy_from_slice(&f.buf[..n]);
                        Ok(n)
                    }
                    None => Err(LinkError::Timeout(0)),
                });
            }
            self.free.push(f);
        }
        answer
    }
}

impl CarriedLink {
    /// The worker's frames the RT thread carried that did not return.
    pub(super) fn frames_lost(&self) -> u64 {
        self.lost
    }

    /// Takes back the frames that have returned without a reply waiting for them.
    fn reclaim(&mut self) {
        while let Some(f) = self.queues.to_worker.pop() {
            self.lost += u64::from(f.returned.is_none());
            self.free.push(f);
        }
    }
}

impl Link for CarriedLink {
    fn round_trip(&mut self, buf: &mut [u8], len: usize) -> Result<usize, LinkError> {
        self.seq += 1;
        let seq = self.seq;
        // A frame given up on earlier may still be out: wait for a free buffer as for a reply.
        let start = Instant::now();
        let mut frame = loop {
            self.reclaim();
            if let Some(f) = self.free.pop() {
                break f;
            }
            if start.elapsed() > CARRY_TIMEOUT {
                return Err(LinkError::Timeout(CARRY_TIMEOUT.as_micros() as u64));
            }
            std::thread::sleep(POLL);
        };
        let len = len.min(FRAME_BUF).min(buf.len());
        frame.buf[..len].copy_from_slice(&buf[..len]);
        frame.len = len;
        frame.seq = seq;
        frame.returned = None;
        if let Err(f) = self.queues.to_rt.push(frame) {
            self.free.push(f);
            return Err(LinkError::Timeout(0));
        }
        loop {
            if let Some(r) = self.collect(seq, buf) {
                return r;
            }
            if start.elapsed() > CARRY_TIMEOUT {
                return Err(LinkError::Timeout(CARRY_TIMEOUT.as_micros() as u64));
            }
            std::thread::sleep(POLL);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A link that answers each frame with its bytes reversed.
    struct Mirror;

    impl Link for Mirror {
        fn round_trip(&mut self, buf: &mut [u8], len: usize) -> Result<usize, LinkError> {
            buf[..len].reverse();
            Ok(len)
        }
    }

    #[test]
    fn the_workers_frame_rides_the_rt_threads_link_and_comes_back() {
        let (rt, mut worker) = carrier();
        let carrier = std::thread::spawn(move || {
            let mut link = Mirror;
            let mut carried = 0;
            while carried < 3 {
                carried += rt.carry(&mut link);
                std::thread::sleep(Duration::from_micros(100));
            }
        });
        for i in 0..3u8 {
            let mut buf = [i, 2, 3, 0];
            assert_eq!(worker.round_trip(&mut buf, 3).unwrap(), 3);
            assert_eq!(buf, [3, 2, i, 0]);
        }
        carrier.join().unwrap();
    }

    #[test]
    fn nobody_carrying_is_a_timeout_and_a_late_return_is_not_taken_for_the_next() {
        let (rt, mut worker) = carrier();
        let mut buf = [1u8, 2];
        assert!(matches!(
            worker.round_trip(&mut buf, 2),
            Err(LinkError::Timeout(_))
        ));
        // The first frame is carried only now, with the second: the second gets its own reply.
        let carrier = std::thread::spawn(move || {
            let mut link = Mirror;
            let mut carried = 0;
            while carried < 2 {
                carried += rt.carry(&mut link);
                std::thread::sleep(Duration::from_micros(100));
            }
        });
        let mut buf = [7u8, 8, 9];
        assert_eq!(worker.round_trip(&mut buf, 3).unwrap(), 3);
        assert_eq!(buf, [9, 8, 7]);
        carrier.join().unwrap();
    }
}
