//! The link a MainDevice sends frames over: one frame out, its return in. The raw-socket link
//! (on a network interface) is here; the in-process link to an emulated segment on a virtual
//! clock is the emulator's (`cellrt_emulator::ethercat::InProcessLink`).

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

/// A link that sends a frame again when its return does not come in time, up to `retries`
/// more times: for the acyclic tools (`bus scan`, SII reads), whose datagrams are reads or
/// requests that may be repeated; never for the cyclic exchange, whose lost frames count.
pub struct Retrying<'a> {
    link: &'a mut dyn Link,
    retries: usize,
    request: Vec<u8>,
}

impl<'a> Retrying<'a> {
    /// `link`, each frame sent up to `retries` more times.
    pub fn new(link: &'a mut dyn Link, retries: usize) -> Retrying<'a> {
        Retrying {
            link,
            retries,
            request: Vec::new(),
        }
    }
}

impl Link for Retrying<'_> {
    fn round_trip(&mut self, buf: &mut [u8], len: usize) -> Result<usize, LinkError> {
        // The buffer takes the return (or stale frames while waiting): keep the request.
        self.request.clear();
        self.request.extend_from_slice(&buf[..len]);
        let mut sent = 0;
        loop {
            match self.link.round_trip(buf, len) {
                Err(LinkError::Timeout(_)) if sent < self.retries => {
                    sent += 1;
                    buf[..len].copy_from_slice(&self.request);
                }
                result => return result,
            }
        }
    }
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
    /// in-process segment that excuses host stalls (`InProcessLink::excusing_host_stalls` of the emulator)
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
    /// frames (CRC errors on an emulated segment). False where the link cannot inject.
    fn corrupt_frames(&mut self, n: usize, frames: u32) -> bool {
        let _ = (n, frames);
        false
    }

    /// Fault injection: the logical datagrams of the next `frames` frames are removed . False where the link cannot inject.
    fn drop_datagrams(&mut self, frames: u32) -> bool {
        let _ = frames;
        false
    }

    /// Fault injection: the link in front of SubDevice `n` is down for the next `frames`
    /// frames . False where the link cannot inject.
    fn lose_link(&mut self, n: usize, frames: u32) -> bool {
        let _ = (n, frames);
        false
    }

    /// Fault injection: the emulated drive in `slot` of SubDevice `station` raises alarm
    /// `code`. False where the link cannot inject (a real drive).
    fn inject_alarm(&mut self, station: usize, slot: usize, code: u16) -> bool {
        let _ = (station, slot, code);
        false
    }

    /// The link as [`Any`](std::any::Any), where its owner may look behind it (an emulated
    /// segment's tests); `None` for a real network.
    fn as_any_mut(&mut self) -> Option<&mut dyn std::any::Any> {
        None
    }
}

/// The frame timeout of an in-process link made with [`InProcessLink::new`] (the
/// `[ethercat] frame_timeout_us` default).
pub const DEFAULT_FRAME_TIMEOUT: std::time::Duration = std::time::Duration::from_micros(500);

/// A segment on a network interface, reached through a raw socket.
#[derive(Debug)]
pub struct RawSocketLink {
    socket: crate::raw_socket::RawSocket,
    timeout: std::time::Duration,
}

impl RawSocketLink {
    /// Opens `interface`; a frame not back within `timeout` is lost.
    pub fn open(interface: &str, timeout: std::time::Duration) -> std::io::Result<Self> {
        Ok(RawSocketLink {
            socket: crate::raw_socket::RawSocket::open(interface)?,
            timeout,
        })
    }
}

/// Byte of the first datagram's index in a frame: replies are matched to requests by it.
const FIRST_INDEX_BYTE: usize =
    crate::frame::ETHERNET_HEADER_LEN + crate::frame::ECAT_HEADER_LEN + 1;

impl Link for RawSocketLink {
    fn round_trip(&mut self, buf: &mut [u8], len: usize) -> Result<usize, LinkError> {
        let index = buf.get(FIRST_INDEX_BYTE).copied();
        self.socket.send(&buf[..len])?;
        let deadline = std::time::Instant::now() + self.timeout;
        loop {
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            match self.socket.recv(buf, left)? {
                None => return Err(LinkError::Timeout(self.timeout.as_micros() as u64)),
                // A runt or a stale reply: keep waiting (the socket skips our own frames on
                // the way out, whatever MAC address the SubDevices leave in the reply).
                Some(n) if n <= FIRST_INDEX_BYTE => {}
                Some(_) if Some(buf[FIRST_INDEX_BYTE]) != index => {}
                Some(n) => return Ok(n),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Times out `late` times (scribbling on the buffer as stale frames would), then echoes
    /// the request; records what was sent each time.
    struct Late {
        late: usize,
        sent: Vec<Vec<u8>>,
    }

    impl Link for Late {
        fn round_trip(&mut self, buf: &mut [u8], len: usize) -> Result<usize, LinkError> {
            self.sent.push(buf[..len].to_vec());
            if self.late > 0 {
                self.late -= 1;
                buf[..len].fill(0xEE);
                return Err(LinkError::Timeout(100));
            }
            Ok(len)
        }
    }

    #[test]
    fn a_late_frame_is_sent_again_whole_up_to_the_retries() {
        let mut link = Late {
            late: 2,
            sent: Vec::new(),
        };
        let mut buf = [1u8, 2, 3, 4];
        assert!(matches!(
            Retrying::new(&mut link, 3).round_trip(&mut buf, 3),
            Ok(3)
        ));
        assert_eq!(link.sent, vec![vec![1, 2, 3]; 3]);
        let mut link = Late {
            late: 5,
            sent: Vec::new(),
        };
        let mut buf = [1u8, 2, 3];
        assert!(matches!(
            Retrying::new(&mut link, 3).round_trip(&mut buf, 3),
            Err(LinkError::Timeout(100))
        ));
        assert_eq!(link.sent.len(), 4, "once and three more times");
    }
}
