//! The RT thread's end of the setpoint service: zero-copy access to the block in use.
//!
//! Blocks are consumed in order; the RT thread holds at most one borrowed sample, so the
//! subscriber buffer is the lookahead queue and nothing is copied.

use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;

use crate::services::SetpointSubscriber;
use crate::setpoints::{AxisSetpoint, SetpointBlock, SetpointHeader};

/// Receiving from the setpoint service failed (the iceoryx2 error, kept allocation-free).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("setpoint receive failed: {0:?}")]
pub struct StreamError(pub iceoryx2::port::ReceiveError);

/// Zero-copy reader of setpoint blocks, front first.
pub struct SetpointStream {
    subscriber: SetpointSubscriber,
    front: Option<Sample<ipc::Service, [AxisSetpoint], SetpointHeader>>,
}

impl SetpointStream {
    /// Wraps the RT thread's subscriber.
    pub fn new(subscriber: SetpointSubscriber) -> Self {
        SetpointStream {
            subscriber,
            front: None,
        }
    }

    /// The oldest block not yet consumed, receiving one if none is held.
    pub fn front(&mut self) -> Result<Option<SetpointBlock<'_>>, StreamError> {
        if self.front.is_none() {
            self.front = self.subscriber.receive().map_err(StreamError)?;
        }
        Ok(self.front.as_ref().map(|s| SetpointBlock {
            header: s.user_header(),
            setpoints: s.payload(),
        }))
    }

    /// Releases the front block.
    pub fn pop(&mut self) {
        self.front = None;
    }

    /// Releases every block received so far (after a stop: nothing of the old stream runs).
    /// Returns how many blocks were dropped.
    pub fn discard_all(&mut self) -> usize {
        let mut n = usize::from(self.front.take().is_some());
        // Bounded by the subscriber's buffer: the publisher cannot outrun it within one call.
        for _ in 0..crate::services::SETPOINT_BUFFER_BLOCKS + 4 {
            match self.subscriber.receive() {
                Ok(Some(_)) => n += 1,
                _ => break,
            }
        }
        n
    }
}
