//! Why a cyclic exchange failed.

use crate::pdo::PdoError;

/// A failed exchange, naming the axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum BusError {
    /// An axis's image did not fit its PDO map.
    #[error("axis {axis}: {source}")]
    Pdo {
        /// The axis index.
        axis: usize,
        /// The codec error.
        source: PdoError,
    },
    /// The cyclic frame did not return (EtherCAT).
    #[error("cyclic frame lost")]
    FrameLost,
    /// The cyclic frame returned with a wrong working counter (EtherCAT): a SubDevice did not
    /// exchange its process data.
    #[error("working counter {found}, expected {expected}")]
    WorkingCounter {
        /// The sum every SubDevice exchanging adds.
        expected: u16,
        /// The counter returned.
        found: u16,
    },
    /// The process image does not fit one frame.
    #[error("process image of {bytes} bytes does not fit one frame")]
    FrameTooLarge {
        /// Its size.
        bytes: usize,
    },
}

/// The bus' clean shutdown that did not complete: its implementation's error.
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
pub struct CloseError(pub Box<dyn std::error::Error + Send + Sync>);
