//! What one read from a drive's socket gave a request/response client (Modbus/TCP, SLMP):
//! bytes, the drive's end of the connection, or the deadline.

use std::io;

/// The outcome of one read.
pub(crate) enum Read {
    /// This many bytes.
    Bytes(usize),
    /// The read timed out.
    TimedOut,
}

/// Sorts `result` of a read; on a stream, 0 bytes is the drive closing the connection.
pub(crate) fn sort(result: io::Result<usize>, stream: bool) -> io::Result<Read> {
    match result {
        Ok(0) if stream => Err(io::Error::new(
            io::ErrorKind::UnexpectedEof,
            "the drive closed the connection",
        )),
        Ok(k) => Ok(Read::Bytes(k)),
        Err(e)
            if matches!(
                e.kind(),
                io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
            ) =>
        {
            Ok(Read::TimedOut)
        }
        Err(e) => Err(e),
    }
}
