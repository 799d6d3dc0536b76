//! Frames held back by an injected frame delay until they are due: a small preallocated
//! queue, so the emulator's receive loop goes on serving other frames meanwhile.

/// The largest frame held (an Ethernet frame without FCS).
pub const MAX_FRAME: usize = 1536;

/// How many frames can wait at once (a delay of several cycles at the cyclic rate).
pub const CAPACITY: usize = 16;

#[derive(Debug, Clone)]
struct Slot {
    frame: [u8; MAX_FRAME],
    len: usize,
    due_ns: u64,
    used: bool,
}

/// Delayed frames, each with the time it is due.
#[derive(Debug, Clone)]
pub struct DelayLine {
    slots: Box<[Slot]>,
}

impl Default for DelayLine {
    fn default() -> Self {
        Self::new()
    }
}

impl DelayLine {
    /// An empty line of [`CAPACITY`] frames.
    pub fn new() -> Self {
        let empty = Slot {
            frame: [0; MAX_FRAME],
            len: 0,
            due_ns: 0,
            used: false,
        };
        DelayLine {
            slots: vec![empty; CAPACITY].into_boxed_slice(),
        }
    }

    /// Holds `frame` until `due_ns`; false (the frame is not held) when the line is full or
    /// the frame is longer than [`MAX_FRAME`].
    pub fn push(&mut self, frame: &[u8], due_ns: u64) -> bool {
        if frame.len() > MAX_FRAME {
            return false;
        }
        match self.slots.iter_mut().find(|s| !s.used) {
            Some(s) => {
                s.frame[..frame.len()].copy_from_slice(frame);
                s.len = frame.len();
                s.due_ns = due_ns;
                s.used = true;
                true
            }
            None => false,
        }
    }

    /// When the earliest held frame is due.
    pub fn next_due(&self) -> Option<u64> {
        self.slots.iter().filter(|s| s.used).map(|s| s.due_ns).min()
    }

    /// Moves the earliest frame due at `now_ns` into `out` and returns its length (`None` if
    /// none is due; a frame longer than `out` is cut to it).
    pub fn pop_due(&mut self, now_ns: u64, out: &mut [u8]) -> Option<usize> {
        let s = self
            .slots
            .iter_mut()
            .filter(|s| s.used && s.due_ns <= now_ns)
            .min_by_key(|s| s.due_ns)?;
        s.used = false;
        let n = s.len.min(out.len());
        out[..n].copy_from_slice(&s.frame[..n]);
        Some(n)
    }

    /// Frames held.
    pub fn len(&self) -> usize {
        self.slots.iter().filter(|s| s.used).count()
    }

    /// True if no frame is held.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_leave_in_order_of_their_due_time_and_not_before() {
        let mut line = DelayLine::new();
        assert!(line.push(&[1; 60], 2_000));
        assert!(line.push(&[2; 64], 1_000));
        assert_eq!(line.next_due(), Some(1_000));
        let mut out = [0u8; MAX_FRAME];
        assert_eq!(line.pop_due(999, &mut out), None);
        assert_eq!(line.pop_due(1_500, &mut out), Some(64));
        assert_eq!(out[0], 2);
        assert_eq!(line.pop_due(1_500, &mut out), None);
        assert_eq!(line.pop_due(2_000, &mut out), Some(60));
        assert_eq!(out[0], 1);
        assert!(line.is_empty());
        assert_eq!(line.next_due(), None);
    }

    #[test]
    fn a_full_line_refuses_the_next_frame() {
        let mut line = DelayLine::new();
        for i in 0..CAPACITY {
            assert!(line.push(&[0; 60], i as u64));
        }
        assert!(!line.push(&[0; 60], 0));
        assert!(!DelayLine::new().push(&[0; MAX_FRAME + 1], 0));
        assert_eq!(line.len(), CAPACITY);
    }
}
