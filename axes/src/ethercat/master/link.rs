//! The link a MainDevice sends frames over: one frame out, its return in. The in-process link
//! passes frames through an emulated [`Segment`] on a virtual clock; the raw-socket link (on a
//! network interface) is in `raw_socket`.

use crate::ethercat::emulator::{Delivery, Segment};

/// A frame round trip that did not complete.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// The frame did not come back in time (lost, or no segment on the wire).
    #[error("no frame returned within {0} µs")]
    Timeout(u64),
    /// The socket failed.
    #[error("link I/O: {0}")]
    Io(#[from] std::io::Error),
}

/// Sends a frame and receives its return.
pub trait Link: Send {
    /// Sends `buf[..len]` and writes the returned frame into `buf`; returns its length.
    fn round_trip(&mut self, buf: &mut [u8], len: usize) -> Result<usize, LinkError>;

    /// The cyclic exchange moved on by `elapsed_ns` (a virtual clock advances; a real one
    /// ignores it).
    fn advance(&mut self, elapsed_ns: u64) {
        let _ = elapsed_ns;
    }

    /// The master's RT loop overran: its next frame comes `cycles` cycles late. A link to an
    /// in-process segment that excuses host stalls ([`InProcessLink::excusing_host_stalls`])
    /// lets the drives run on; elsewhere the drives see missed SYNC0s, as real ones do.
    fn host_stall(&mut self, cycles: u64) {
        let _ = cycles;
    }

    /// Fault injection: the next `n` frames are lost on the wire. False where the link cannot
    /// inject (a real network).
    fn drop_frames(&mut self, n: u32) -> bool {
        let _ = n;
        false
    }

    /// Fault injection: SubDevice `n` does not answer the next `frames` frames. False where
    /// the link cannot inject.
    fn stall_subdevice(&mut self, n: usize, frames: u32) -> bool {
        let _ = (n, frames);
        false
    }

    /// Fault injection: the next `frames` frames reach the segment and return `delay_ns` late
    /// (on the link's clock); one delayed to the frame timeout or beyond is lost at the master.
    /// False where the link cannot inject.
    fn delay_frames(&mut self, delay_ns: u64, frames: u32) -> bool {
        let _ = (delay_ns, frames);
        false
    }

    /// Fault injection: the link segment in front of SubDevice `n` corrupts the next `frames`
    /// frames (CRC errors; see [`Segment::corrupt`]). False where the link cannot inject.
    fn corrupt_frames(&mut self, n: usize, frames: u32) -> bool {
        let _ = (n, frames);
        false
    }

    /// Fault injection: the logical datagrams of the next `frames` frames are removed (see
    /// [`Segment::drop_datagrams`]). False where the link cannot inject.
    fn drop_datagrams(&mut self, frames: u32) -> bool {
        let _ = frames;
        false
    }

    /// Fault injection: the link in front of SubDevice `n` is down for the next `frames`
    /// frames (see [`Segment::lose_link`]). False where the link cannot inject.
    fn lose_link(&mut self, n: usize, frames: u32) -> bool {
        let _ = (n, frames);
        false
    }

    /// The emulated segment behind the link, where there is one (tests and fault injection).
    fn segment_mut(&mut self) -> Option<&mut Segment> {
        None
    }
}

/// Frame loss injected on an in-process link: the next `n` frames do not return.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DropFrames(pub u32);

/// Frame delay injected on an in-process link: the next `frames` frames are `ns` late.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DelayFrames {
    /// The delay, ns.
    pub ns: u64,
    /// Frames left.
    pub frames: u32,
}

/// The frame timeout of an in-process link made with [`InProcessLink::new`] (the
/// `[ethercat] frame_timeout_us` default).
pub const DEFAULT_FRAME_TIMEOUT: std::time::Duration = std::time::Duration::from_micros(500);

/// An emulated segment in this process: no network, no root; deterministic for a given
/// configuration because the ESC clocks run on the virtual time the cyclic exchange advances.
#[derive(Debug)]
pub struct InProcessLink {
    segment: Segment,
    now_ns: u64,
    drop: DropFrames,
    delay: DelayFrames,
    timeout_ns: u64,
    excuse_stalls: bool,
}

/// The virtual clock's start: 1 s after the EtherCAT epoch, so DC times are non-zero.
const VIRTUAL_EPOCH_NS: u64 = 1_000_000_000;

impl InProcessLink {
    /// A link to `segment` with the [`DEFAULT_FRAME_TIMEOUT`].
    pub fn new(segment: Segment) -> Self {
        Self::with_frame_timeout(segment, DEFAULT_FRAME_TIMEOUT)
    }

    /// A link to `segment` on which a frame not back within `timeout` (virtual time) is lost.
    pub fn with_frame_timeout(segment: Segment, timeout: std::time::Duration) -> Self {
        InProcessLink {
            segment,
            now_ns: VIRTUAL_EPOCH_NS,
            drop: DropFrames::default(),
            delay: DelayFrames::default(),
            timeout_ns: u64::try_from(timeout.as_nanos()).unwrap_or(u64::MAX),
            excuse_stalls: false,
        }
    }

    /// This link, telling the segment when the master's host stalled so the drives run on
    /// instead of counting missed SYNC0s (what `cellrt run` uses for `interface =
    /// "in-process"`: the emulated drives live on the master's clock, like `transport =
    /// "sim"`, so a loaded machine does not fault them; frames lost on the wire still count).
    pub fn excusing_host_stalls(mut self) -> Self {
        self.excuse_stalls = true;
        self
    }

    /// The segment.
    pub fn segment(&self) -> &Segment {
        &self.segment
    }
}

impl Link for InProcessLink {
    fn round_trip(&mut self, buf: &mut [u8], len: usize) -> Result<usize, LinkError> {
        if self.drop.0 > 0 {
            self.drop.0 -= 1;
            return Err(LinkError::Timeout(0));
        }
        let mut delay = 0;
        if self.delay.frames > 0 {
            self.delay.frames -= 1;
            delay = self.delay.ns;
        }
        // A malformed frame is dropped by the segment, as on a wire. A delayed frame reaches
        // the stations late (after their SYNC0 if it pushes it past: applied a cycle late);
        // at or beyond the timeout the master has given up on it.
        match self.segment.process(&mut buf[..len], self.now_ns + delay) {
            Ok(Delivery::Returned) if delay < self.timeout_ns => Ok(len),
            Ok(_) | Err(_) => Err(LinkError::Timeout(self.timeout_ns / 1000)),
        }
    }

    fn advance(&mut self, elapsed_ns: u64) {
        self.now_ns += elapsed_ns;
    }

    fn host_stall(&mut self, cycles: u64) {
        if self.excuse_stalls {
            self.segment.excuse_host_stall(cycles);
        }
    }

    fn drop_frames(&mut self, n: u32) -> bool {
        self.drop = DropFrames(n);
        true
    }

    fn stall_subdevice(&mut self, n: usize, frames: u32) -> bool {
        self.segment.stall(n, frames)
    }

    fn delay_frames(&mut self, delay_ns: u64, frames: u32) -> bool {
        self.delay = DelayFrames {
            ns: delay_ns,
            frames,
        };
        true
    }

    fn corrupt_frames(&mut self, n: usize, frames: u32) -> bool {
        self.segment.corrupt(n, frames)
    }

    fn drop_datagrams(&mut self, frames: u32) -> bool {
        self.segment.drop_datagrams(frames);
        true
    }

    fn lose_link(&mut self, n: usize, frames: u32) -> bool {
        self.segment.lose_link(n, frames)
    }

    fn segment_mut(&mut self) -> Option<&mut Segment> {
        Some(&mut self.segment)
    }
}

/// A segment on a network interface, reached through a raw socket.
#[derive(Debug)]
pub struct RawSocketLink {
    socket: crate::ethercat::raw_socket::RawSocket,
    timeout: std::time::Duration,
}

impl RawSocketLink {
    /// Opens `interface`; a frame not back within `timeout` is lost.
    pub fn open(interface: &str, timeout: std::time::Duration) -> std::io::Result<Self> {
        Ok(RawSocketLink {
            socket: crate::ethercat::raw_socket::RawSocket::open(interface)?,
            timeout,
        })
    }
}

/// Byte of the first datagram's index in a frame: replies are matched to requests by it.
const FIRST_INDEX_BYTE: usize =
    crate::ethercat::frame::ETHERNET_HEADER_LEN + crate::ethercat::frame::ECAT_HEADER_LEN + 1;

impl Link for RawSocketLink {
    fn round_trip(&mut self, buf: &mut [u8], len: usize) -> Result<usize, LinkError> {
        let index = buf.get(FIRST_INDEX_BYTE).copied();
        self.socket.send(&buf[..len])?;
        let deadline = std::time::Instant::now() + self.timeout;
        loop {
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            match self.socket.recv(buf, left)? {
                None => return Err(LinkError::Timeout(self.timeout.as_micros() as u64)),
                // Our own frame seen on the way out, or a stale reply: keep waiting.
                Some(n)
                    if n <= FIRST_INDEX_BYTE
                        || buf[6] & crate::ethercat::frame::REPLY_SOURCE_MAC_BIT == 0 => {}
                Some(_) if Some(buf[FIRST_INDEX_BYTE]) != index => {}
                Some(n) => return Ok(n),
            }
        }
    }
}
