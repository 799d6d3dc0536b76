//! SLMP binary frames (MR-JE-C manual §2.4.2–§2.4.4): the 3E/4E header, command 4020h with its
//! four sub commands and 0101h, normal and abnormal responses. Multi-byte fields are little-
//! endian except the subheader; the 4E serial number is echoed byte for byte.

use super::EndCode;

/// 3E request subheader (`50 00`).
const REQUEST_3E: [u8; 2] = [0x50, 0x00];
/// 4E request subheader (`54 00`, then the serial and `00 00`).
const REQUEST_4E: [u8; 2] = [0x54, 0x00];
/// 3E / 4E response subheaders.
const RESPONSE_3E: [u8; 2] = [0xD0, 0x00];
const RESPONSE_4E: [u8; 2] = [0xD4, 0x00];
/// Request destination module I/O No., fixed 03FFh.
const MODULE_IO: u16 = 0x03FF;
/// CiA 402 object access.
const OBJECT_ACCESS: u16 = 0x4020;
/// Model code read.
const MODEL_READ: u16 = 0x0101;
/// The largest frame the codec handles (a 4E header and 4020h data of an object record).
pub const MAX_FRAME: usize = 2048;

/// The frame type: 3E, or 4E with the client's serial number (echoed verbatim).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Subheader {
    /// 3E frame.
    E3,
    /// 4E frame with its serial number bytes.
    E4 {
        /// The two serial bytes as sent.
        serial: [u8; 2],
    },
}

/// Request destination network and station numbers (echoed by the drive).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Route {
    /// Network No.
    pub network: u8,
    /// Station No.
    pub station: u8,
}

impl Default for Route {
    /// Network 00h, station FFh: the usual "own station" values.
    fn default() -> Self {
        Route {
            network: 0,
            station: 0xFF,
        }
    }
}

/// A request's command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command<'a> {
    /// 4020h/0001h: read one object sub-index.
    Upload {
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
    },
    /// 4020h/0002h: write one object sub-index (`data` little-endian).
    Download {
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
        /// The value's bytes.
        data: &'a [u8],
    },
    /// 4020h/0005h: read the sub-indexes from `sub` on.
    BlockUpload {
        /// Object index.
        index: u16,
        /// First sub-index.
        sub: u8,
    },
    /// 4020h/0006h: write consecutive sub-indexes from `sub` on.
    BlockDownload {
        /// Object index.
        index: u16,
        /// First sub-index.
        sub: u8,
        /// The values' bytes, each in its sub-index's size.
        data: &'a [u8],
    },
    /// 0101h/0000h: the amplifier's model.
    ModelRead,
}

impl Command<'_> {
    /// (command, sub command).
    pub fn codes(&self) -> (u16, u16) {
        match self {
            Command::Upload { .. } => (OBJECT_ACCESS, 0x0001),
            Command::Download { .. } => (OBJECT_ACCESS, 0x0002),
            Command::BlockUpload { .. } => (OBJECT_ACCESS, 0x0005),
            Command::BlockDownload { .. } => (OBJECT_ACCESS, 0x0006),
            Command::ModelRead => (MODEL_READ, 0x0000),
        }
    }
}

/// A request frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Request<'a> {
    /// 3E or 4E.
    pub subheader: Subheader,
    /// Destination.
    pub route: Route,
    /// Monitoring timer, 0.25 s units (0: wait until done).
    pub monitoring_timer: u16,
    /// The command.
    pub command: Command<'a>,
}

/// The drive's answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reply<'a> {
    /// Normal answer to an upload: the value's bytes, little-endian.
    Upload {
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
        /// The value.
        data: &'a [u8],
    },
    /// Normal answer to a download: the "Number of data value" echoed.
    Download {
        /// Object index.
        index: u16,
        /// Sub-index.
        sub: u8,
        /// Bytes written.
        count: u16,
    },
    /// Normal answer to a model read: 16 ASCII characters and the model code.
    Model {
        /// Model name, space padded.
        name: [u8; 16],
        /// Model code.
        code: u16,
    },
    /// Abnormal end with the error information (responding station and the refused command).
    Error {
        /// End code.
        code: EndCode,
        /// Error information: network, station, module I/O (2), multi-drop, command (2), sub
        /// command (2).
        info: [u8; 9],
    },
}

/// A response frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Response<'a> {
    /// 3E or 4E, as the request.
    pub subheader: Subheader,
    /// The request's destination, echoed.
    pub route: Route,
    /// The answer.
    pub reply: Reply<'a>,
}

/// A frame that cannot be taken.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SlmpError {
    /// Fewer bytes than the header and length announce.
    #[error("truncated SLMP frame: {got} bytes, {need} needed")]
    Truncated {
        /// Bytes present.
        got: usize,
        /// Bytes needed.
        need: usize,
    },
    /// Not an SLMP binary subheader (ASCII frames are not supported).
    #[error("subheader {0:02X?} is not a binary 3E/4E frame")]
    Subheader([u8; 2]),
    /// The request is answered with an abnormal end code.
    #[error("{code} (command {command:04X}h/{sub:04X}h)")]
    Refused {
        /// The end code to answer with.
        code: EndCode,
        /// The request's frame type.
        subheader: Subheader,
        /// The request's destination.
        route: Route,
        /// The command as received.
        command: u16,
        /// The sub command as received.
        sub: u16,
    },
    /// An end code this codec does not know (not an MR-JE-C's).
    #[error("unknown end code {0:04X}h")]
    UnknownEndCode(u16),
    /// A response that does not answer the request.
    #[error("response {what} differs from the request's")]
    Mismatch {
        /// "serial", "route", "index" or "length".
        what: &'static str,
    },
    /// The output buffer is too small.
    #[error("buffer of {0} bytes too small for the frame")]
    Buffer(usize),
}

impl SlmpError {
    /// The abnormal response the drive sends for a refused request (none: it stays silent).
    pub fn answer(&self) -> Option<Response<'static>> {
        let SlmpError::Refused {
            code,
            subheader,
            route,
            command,
            sub,
        } = *self
        else {
            return None;
        };
        let [io_lo, io_hi] = MODULE_IO.to_le_bytes();
        let [c_lo, c_hi] = command.to_le_bytes();
        let [s_lo, s_hi] = sub.to_le_bytes();
        Some(Response {
            subheader,
            route,
            reply: Reply::Error {
                code,
                info: [
                    route.network,
                    route.station,
                    io_lo,
                    io_hi,
                    0,
                    c_lo,
                    c_hi,
                    s_lo,
                    s_hi,
                ],
            },
        })
    }
}

/// Writes the subheader and route; the offset of the length field.
pub(super) fn head(subheader: Subheader, route: Route, request: bool, buf: &mut [u8]) -> usize {
    let at = match subheader {
        Subheader::E3 => {
            buf[..2].copy_from_slice(if request { &REQUEST_3E } else { &RESPONSE_3E });
            2
        }
        Subheader::E4 { serial } => {
            buf[..2].copy_from_slice(if request { &REQUEST_4E } else { &RESPONSE_4E });
            buf[2..4].copy_from_slice(&serial);
            buf[4..6].fill(0);
            6
        }
    };
    buf[at] = route.network;
    buf[at + 1] = route.station;
    buf[at + 2..at + 4].copy_from_slice(&MODULE_IO.to_le_bytes());
    buf[at + 4] = 0;
    at + 5
}

/// Reads the subheader and route; the offset of the length field.
pub(super) fn read_head(
    frame: &[u8],
    request: bool,
) -> Result<(Subheader, Route, usize), SlmpError> {
    let truncated = |need| SlmpError::Truncated {
        got: frame.len(),
        need,
    };
    if frame.len() < 2 {
        return Err(truncated(2));
    }
    let sh = [frame[0], frame[1]];
    let (e3, e4) = if request {
        (REQUEST_3E, REQUEST_4E)
    } else {
        (RESPONSE_3E, RESPONSE_4E)
    };
    let (subheader, at) = if sh == e3 {
        (Subheader::E3, 2)
    } else if sh == e4 {
        if frame.len() < 6 {
            return Err(truncated(6));
        }
        (
            Subheader::E4 {
                serial: [frame[2], frame[3]],
            },
            6,
        )
    } else {
        return Err(SlmpError::Subheader(sh));
    };
    if frame.len() < at + 7 {
        return Err(truncated(at + 7));
    }
    let route = Route {
        network: frame[at],
        station: frame[at + 1],
    };
    Ok((subheader, route, at + 5))
}

fn le16(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

/// Client: the frame of `request`; its length.
pub fn encode_request(request: &Request<'_>, buf: &mut [u8]) -> Result<usize, SlmpError> {
    let data: &[u8] = match request.command {
        Command::Download { data, .. } | Command::BlockDownload { data, .. } => data,
        _ => &[],
    };
    let body = 2
        + 4
        + if request.command == Command::ModelRead {
            0
        } else {
            6 + data.len()
        };
    let need = 6 + 5 + 2 + body;
    if buf.len() < need || need > MAX_FRAME {
        return Err(SlmpError::Buffer(buf.len()));
    }
    let len_at = head(request.subheader, request.route, true, buf);
    buf[len_at..len_at + 2].copy_from_slice(&(body as u16).to_le_bytes());
    let mut at = len_at + 2;
    let (command, sub) = request.command.codes();
    for v in [request.monitoring_timer, command, sub] {
        buf[at..at + 2].copy_from_slice(&v.to_le_bytes());
        at += 2;
    }
    match request.command {
        Command::Upload { index, sub } | Command::BlockUpload { index, sub } => {
            at = object_address(buf, at, index, sub, 0);
        }
        Command::Download { index, sub, data } | Command::BlockDownload { index, sub, data } => {
            at = object_address(buf, at, index, sub, data.len() as u16);
            buf[at..at + data.len()].copy_from_slice(data);
            at += data.len();
        }
        Command::ModelRead => {}
    }
    Ok(at)
}

/// Index, sub-index, reserved byte and "Number of data value" at `at`; the offset after them.
fn object_address(buf: &mut [u8], at: usize, index: u16, sub: u8, count: u16) -> usize {
    buf[at..at + 2].copy_from_slice(&index.to_le_bytes());
    buf[at + 2] = sub;
    buf[at + 3] = 0;
    buf[at + 4..at + 6].copy_from_slice(&count.to_le_bytes());
    at + 6
}

/// Drive: the request in `frame`, or why it is refused ([`SlmpError::answer`] gives the
/// abnormal response where the drive sends one).
pub fn decode_request(frame: &[u8]) -> Result<Request<'_>, SlmpError> {
    let (subheader, route, len_at) = read_head(frame, true)?;
    let declared = usize::from(le16(frame, len_at));
    let body = &frame[len_at + 2..];
    let refuse = |code, command, sub| SlmpError::Refused {
        code,
        subheader,
        route,
        command,
        sub,
    };
    if body.len() < 6 {
        return Err(SlmpError::Truncated {
            got: frame.len(),
            need: len_at + 2 + 6,
        });
    }
    let (timer, command, sub_command) = (le16(body, 0), le16(body, 2), le16(body, 4));
    if declared != body.len() {
        return Err(refuse(EndCode::LengthMismatch, command, sub_command));
    }
    let request = |command| Request {
        subheader,
        route,
        monitoring_timer: timer,
        command,
    };
    if (command, sub_command) == (MODEL_READ, 0) {
        return if body.len() == 6 {
            Ok(request(Command::ModelRead))
        } else {
            Err(refuse(EndCode::LengthMismatch, command, sub_command))
        };
    }
    if command != OBJECT_ACCESS || ![1, 2, 5, 6].contains(&sub_command) {
        return Err(refuse(EndCode::CommandUnknown, command, sub_command));
    }
    if body.len() < 12 {
        return Err(refuse(EndCode::RequestIncorrect, command, sub_command));
    }
    let (index, sub, count) = (le16(body, 6), body[8], usize::from(le16(body, 10)));
    let data = &body[12..];
    match sub_command {
        1 | 5 if count != 0 || !data.is_empty() => {
            Err(refuse(EndCode::RequestIncorrect, command, sub_command))
        }
        1 => Ok(request(Command::Upload { index, sub })),
        5 => Ok(request(Command::BlockUpload { index, sub })),
        _ if count != data.len() || data.is_empty() => {
            Err(refuse(EndCode::LengthMismatch, command, sub_command))
        }
        2 => Ok(request(Command::Download { index, sub, data })),
        _ => Ok(request(Command::BlockDownload { index, sub, data })),
    }
}

/// Drive: the frame of `response`; its length.
pub fn encode_response(response: &Response<'_>, buf: &mut [u8]) -> Result<usize, SlmpError> {
    let body = 2 + match response.reply {
        Reply::Upload { data, .. } => 6 + data.len(),
        Reply::Download { .. } => 6,
        Reply::Model { .. } => 18,
        Reply::Error { .. } => 9,
    };
    let need = 6 + 5 + 2 + body;
    if buf.len() < need {
        return Err(SlmpError::Buffer(buf.len()));
    }
    let len_at = head(response.subheader, response.route, false, buf);
    buf[len_at..len_at + 2].copy_from_slice(&(body as u16).to_le_bytes());
    let at = len_at + 4;
    let end = match response.reply {
        Reply::Upload { index, sub, data } => {
            buf[len_at + 2..at].fill(0);
            let at = object_address(buf, at, index, sub, data.len() as u16);
            buf[at..at + data.len()].copy_from_slice(data);
            at + data.len()
        }
        Reply::Download { index, sub, count } => {
            buf[len_at + 2..at].fill(0);
            object_address(buf, at, index, sub, count)
        }
        Reply::Model { name, code } => {
            buf[len_at + 2..at].fill(0);
            buf[at..at + 16].copy_from_slice(&name);
            buf[at + 16..at + 18].copy_from_slice(&code.to_le_bytes());
            at + 18
        }
        Reply::Error { code, info } => {
            buf[len_at + 2..at].copy_from_slice(&(code as u16).to_le_bytes());
            buf[at..at + 9].copy_from_slice(&info);
            at + 9
        }
    };
    Ok(end)
}

/// Client: the drive's response in `frame` to `request`. The data of an upload is taken from
/// the response data length, not from its "Number of data value" (manual §2.4.4 leaves that
/// field's meaning open in responses).
pub fn decode_response<'f>(
    request: &Request<'_>,
    frame: &'f [u8],
) -> Result<Response<'f>, SlmpError> {
    let (subheader, route, len_at) = read_head(frame, false)?;
    if subheader != request.subheader {
        return Err(SlmpError::Mismatch { what: "serial" });
    }
    if route != request.route {
        return Err(SlmpError::Mismatch { what: "route" });
    }
    let declared = usize::from(le16(frame, len_at));
    let body = &frame[len_at + 2..];
    if declared != body.len() || body.len() < 2 {
        return Err(SlmpError::Mismatch { what: "length" });
    }
    let end = le16(body, 0);
    let respond = |reply| Response {
        subheader,
        route,
        reply,
    };
    if end != 0 {
        let code = EndCode::from_repr(end).ok_or(SlmpError::UnknownEndCode(end))?;
        let info: [u8; 9] = body[2..]
            .try_into()
            .map_err(|_| SlmpError::Mismatch { what: "length" })?;
        return Ok(respond(Reply::Error { code, info }));
    }
    let data = &body[2..];
    if request.command == Command::ModelRead {
        let (name, code) = data
            .split_first_chunk::<16>()
            .filter(|(_, rest)| rest.len() == 2)
            .ok_or(SlmpError::Mismatch { what: "length" })?;
        return Ok(respond(Reply::Model {
            name: *name,
            code: le16(code, 0),
        }));
    }
    if data.len() < 6 {
        return Err(SlmpError::Mismatch { what: "length" });
    }
    let (index, sub) = (le16(data, 0), data[2]);
    let (want_index, want_sub) = match request.command {
        Command::Upload { index, sub }
        | Command::BlockUpload { index, sub }
        | Command::Download { index, sub, .. }
        | Command::BlockDownload { index, sub, .. } => (index, sub),
        Command::ModelRead => return Err(SlmpError::Mismatch { what: "index" }),
    };
    if (index, sub) != (want_index, want_sub) {
        return Err(SlmpError::Mismatch { what: "index" });
    }
    Ok(respond(match request.command {
        Command::Upload { .. } | Command::BlockUpload { .. } => Reply::Upload {
            index,
            sub,
            data: &data[6..],
        },
        _ if data.len() == 6 => Reply::Download {
            index,
            sub,
            count: le16(data, 4),
        },
        _ => return Err(SlmpError::Mismatch { what: "length" }),
    }))
}
