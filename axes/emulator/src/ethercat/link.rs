//! The in-process link: a MainDevice's frames pass through an emulated [`Segment`] in this
//! process, on a virtual clock (no network, no root).

use cellrt_ethercat::master::{Link, LinkError, DEFAULT_FRAME_TIMEOUT};

use super::{Delivery, Segment};

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

    fn inject_alarm(&mut self, station: usize, slot: usize, code: u16) -> bool {
        match self
            .segment
            .station_mut(station)
            .and_then(|st| st.drive_at_mut(slot))
        {
            Some(d) => {
                d.inject_alarm(code);
                true
            }
            None => false,
        }
    }

    fn as_any_mut(&mut self) -> Option<&mut dyn std::any::Any> {
        Some(self)
    }
}

/// The emulated segment behind `link`, where it is an [`InProcessLink`] (tests look at the
/// stations behind a running master).
pub fn segment_of(link: &mut dyn Link) -> Option<&mut Segment> {
    link.as_any_mut()?
        .downcast_mut::<InProcessLink>()
        .map(|l| &mut l.segment)
}
