//! Process exit codes, one meaning each.

/// How `cellrt` exits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exit {
    /// Success (also a clean shutdown on SIGINT/SIGTERM).
    Ok,
    /// The run failed (program error, fault, I/O).
    Failed,
    /// Bad input: configuration, program or command line.
    BadInput,
    /// The cell rejected the command (nothing changed).
    Rejected,
    /// No running cell, or it did not answer.
    Unreachable,
}

impl Exit {
    /// The numeric exit code.
    pub fn code(self) -> i32 {
        match self {
            Exit::Ok => 0,
            Exit::Failed => 1,
            Exit::BadInput => 2,
            Exit::Rejected => 3,
            Exit::Unreachable => 4,
        }
    }

    /// The exit of a device or file that could not be opened: bad input when what was named
    /// does not exist or is no valid name, a failure otherwise (permissions, the system).
    pub fn of_open_error(e: &std::io::Error) -> Exit {
        match e.kind() {
            std::io::ErrorKind::NotFound | std::io::ErrorKind::InvalidInput => Exit::BadInput,
            _ => Exit::Failed,
        }
    }
}
