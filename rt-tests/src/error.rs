//! Errors of the benchmarks: bad input (exit code 2) or a failed run (exit code 1).

/// Why a benchmark did not run or did not finish.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum BenchError {
    /// Bad arguments: the message names the option and the allowed range.
    #[error("{0}")]
    BadInput(String),
    /// The run itself failed (a tool missing, a process that died, I/O).
    #[error("{0}")]
    Failed(String),
}

impl BenchError {
    /// Bad input.
    pub fn bad(msg: impl Into<String>) -> BenchError {
        BenchError::BadInput(msg.into())
    }

    /// A failed run.
    pub fn failed(msg: impl Into<String>) -> BenchError {
        BenchError::Failed(msg.into())
    }
}
