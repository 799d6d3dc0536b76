//! A drive's object dictionary read from SDO Information (ETG.1000.6 §5.6.3) for the host
//! (`cellrt sdo list`). The host asks through a bounded channel the mailbox worker polls beside
//! its other work, never through the RT thread's one-scalar SDO slot: the walk is long and its
//! answer variable-sized. The RT thread takes no part in it beyond carrying the frames.

use crossbeam::channel::{bounded, Receiver, Sender, TrySendError};

use super::refusal::abort_meaning;
use cellrt_cia402::bus::DictionaryEntry;

/// Why no dictionary came from SDO Information.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NoSdoInformation {
    /// The bus has no such axis.
    #[error("the segment has no axis {0}")]
    UnknownAxis(usize),
    /// The SubDevice's SII does not set CoE details bit 1.
    #[error("its SubDevice's SII does not offer SDO Information (CoE details bit 1)")]
    NotOffered,
    /// The SubDevice has no CoE mailbox.
    #[error("its SubDevice has no CoE mailbox")]
    NoMailbox,
    /// The drive answered the OD list request with an SDO Info Error Request.
    #[error("the drive refused SDO Information: abort code 0x{code:08X} ({})", abort_meaning(*code))]
    Refused {
        /// The abort code.
        code: u32,
    },
    /// A transfer failed otherwise (no answer, a malformed response).
    #[error("reading SDO Information failed at {object}: {reason}")]
    Failed {
        /// What was being read ("the OD list", "object 6041h", "entry 6041h:00").
        object: String,
        /// ethercrab's error.
        reason: String,
    },
}

/// The worker's answer to one request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DictionaryReading {
    /// The axis asked for.
    pub axis: usize,
    /// Its SubDevice's dictionary in index order, or why there is none.
    pub entries: Result<Vec<DictionaryEntry>, NoSdoInformation>,
}

/// The worker's ends of the channels.
pub(super) struct DictionaryQueue {
    pub(super) requests: Receiver<usize>,
    pub(super) replies: Sender<DictionaryReading>,
}

/// The host's handle on a running segment's dictionaries: ask for an axis', then collect it.
#[derive(Clone)]
pub struct DictionaryReader {
    requests: Sender<usize>,
    replies: Receiver<DictionaryReading>,
}

impl std::fmt::Debug for DictionaryReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DictionaryReader").finish_non_exhaustive()
    }
}

/// The two ends: one request and one reading in flight at most.
pub(super) fn dictionary_channels() -> (DictionaryReader, DictionaryQueue) {
    let (request_tx, request_rx) = bounded(1);
    let (reply_tx, reply_rx) = bounded(1);
    (
        DictionaryReader {
            requests: request_tx,
            replies: reply_rx,
        },
        DictionaryQueue {
            requests: request_rx,
            replies: reply_tx,
        },
    )
}

impl DictionaryReader {
    /// Asks the worker for `axis`' dictionary (a reading not yet collected is discarded);
    /// false while another request waits to be taken up.
    pub fn request(&self, axis: usize) -> bool {
        while self.replies.try_recv().is_ok() {}
        !matches!(self.requests.try_send(axis), Err(TrySendError::Full(_)))
    }

    /// The reading, once the worker has taken it.
    pub fn take(&self) -> Option<DictionaryReading> {
        self.replies.try_recv().ok()
    }
}

/// A walk through a SubDevice's dictionary in progress on the mailbox worker ([`super::od_walk`]).
pub(super) struct OdWalk {
    pub(super) axis: usize,
    pub(super) station: usize,
    /// The objects not yet described; `None` before the OD list was read.
    pub(super) objects: Option<std::collections::VecDeque<u16>>,
    /// The object being described: its index, name and the sub-indices left.
    pub(super) object: Option<(u16, String, std::ops::RangeInclusive<u8>)>,
    pub(super) entries: Vec<DictionaryEntry>,
}
