//! The link a MainDevice sends frames over: one frame out, its return in. The in-process link
//! passes frames through an emulated [`Segment`] on a virtual clock; the raw-socket link (on a
//! network interface) is in `raw_socket`.

use crate::ethercat::emulator::Segment;

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

    /// The emulated segment behind the link, where there is one (tests and fault injection).
    fn segment_mut(&mut self) -> Option<&mut Segment> {
        None
    }
}

/// Frame loss injected on an in-process link: the next `n` frames do not return.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DropFrames(pub u32);

/// An emulated segment in this process: no network, no root; deterministic for a given
/// configuration because the ESC clocks run on the virtual time the cyclic exchange advances.
#[derive(Debug)]
pub struct InProcessLink {
    segment: Segment,
    now_ns: u64,
    drop: DropFrames,
}

/// The virtual clock's start: 1 s after the EtherCAT epoch, so DC times are non-zero.
const VIRTUAL_EPOCH_NS: u64 = 1_000_000_000;

impl InProcessLink {
    /// A link to `segment`.
    pub fn new(segment: Segment) -> Self {
        InProcessLink {
            segment,
            now_ns: VIRTUAL_EPOCH_NS,
            drop: DropFrames::default(),
        }
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
        // A malformed frame is dropped by the segment, as on a wire.
        match self.segment.process(&mut buf[..len], self.now_ns) {
            Ok(()) => Ok(len),
            Err(_) => Err(LinkError::Timeout(0)),
        }
    }

    fn advance(&mut self, elapsed_ns: u64) {
        self.now_ns += elapsed_ns;
    }

    fn drop_frames(&mut self, n: u32) -> bool {
        self.drop = DropFrames(n);
        true
    }

    fn stall_subdevice(&mut self, n: usize, frames: u32) -> bool {
        self.segment.stall(n, frames)
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
