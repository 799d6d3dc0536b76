//! Why a Modbus frame was refused, at either end.

/// A frame (or a reply) that cannot be taken, named by what is wrong with it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ModbusError {
    /// Fewer bytes than the frame's own fields announce.
    #[error("truncated frame: {got} bytes, {need} needed")]
    Truncated {
        /// Bytes present.
        got: usize,
        /// Bytes the header asks for.
        need: usize,
    },
    /// More bytes than the frame's fields account for, or beyond the largest frame.
    #[error("oversized frame: {got} bytes, at most {max}")]
    Oversized {
        /// Bytes present.
        got: usize,
        /// The largest frame.
        max: usize,
    },
    /// The MBAP protocol identifier is not 0 (the drive discards the query, §3.5).
    #[error("MBAP protocol identifier {0:#06x}, not 0")]
    ProtocolId(u16),
    /// The MBAP unit identifier is not FFh (the drive discards the query, §3.5).
    #[error("MBAP unit identifier {0:#04x}, not 0xFF")]
    UnitId(u8),
    /// The RTU CRC-16 does not match (the drive does not answer, §4.8.5).
    #[error("CRC {got:#06x}, expected {expected:#06x}")]
    Crc {
        /// CRC in the frame.
        got: u16,
        /// CRC of the frame's bytes.
        expected: u16,
    },
    /// A reply from another slave or to another transaction than the query's.
    #[error("reply to {what} {got}, the query was {expected}")]
    Mismatch {
        /// "transaction" or "slave".
        what: &'static str,
        /// In the reply.
        got: u16,
        /// In the query.
        expected: u16,
    },
    /// A function code the MR-JE-C does not implement (only 03h, 08h, 10h).
    #[error("function code {0:#04x} not supported (03h, 08h, 10h only)")]
    Function(u8),
    /// A field that contradicts another (byte count vs. registers, a register count of 0 or
    /// beyond the maximum, a diagnostics sub-function other than 0000h).
    #[error("malformed {function:#04x} frame: {why}")]
    Malformed {
        /// Function code.
        function: u8,
        /// What is wrong.
        why: &'static str,
    },
    /// The drive answered with an exception.
    #[error("exception {code} to function {function:#04x}")]
    Exception {
        /// The query's function code.
        function: u8,
        /// The exception code.
        code: super::ExceptionCode,
    },
    /// The output buffer is too small for the frame.
    #[error("buffer of {0} bytes too small for the frame")]
    Buffer(usize),
}
