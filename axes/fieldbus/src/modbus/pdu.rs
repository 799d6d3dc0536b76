//! The three functions of the MR-JE-C (MR-JE-C manual §3.6, §4.8) as typed queries and replies,
//! encoded and decoded with `modbus-core`, plus the checks the drive makes that the generic
//! codec does not (byte count against register count, register count limits, the echo's
//! sub-function).

use modbus_core::{Data, Encode, ExceptionResponse, FunctionCode, Request, Response};

use super::ModbusError;

/// 03h Read Holding Registers.
pub const READ: u8 = 0x03;
/// 08h Diagnostics.
pub const DIAGNOSTICS: u8 = 0x08;
/// 10h Preset Multiple Registers.
pub const WRITE: u8 = 0x10;

/// The most registers one query reads or writes: 122 (244 bytes, the largest write the manual
/// times, §4.6); a larger count is refused at both ends.
pub const MAX_REGISTERS: usize = 122;

/// An exception code the drive answers with (§3.6.5, §4.8.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::Display, strum::FromRepr)]
#[repr(u8)]
pub enum ExceptionCode {
    /// 01h: function code not supported.
    #[strum(serialize = "01h illegal function")]
    IllegalFunction = 1,
    /// 02h: no register at that address, or not readable/writable.
    #[strum(serialize = "02h illegal data address")]
    IllegalDataAddress = 2,
    /// 03h: a value the register cannot take, or No. of Registers = 0.
    #[strum(serialize = "03h illegal data value")]
    IllegalDataValue = 3,
}

impl ExceptionCode {
    fn to_core(self) -> modbus_core::Exception {
        match self {
            Self::IllegalFunction => modbus_core::Exception::IllegalFunction,
            Self::IllegalDataAddress => modbus_core::Exception::IllegalDataAddress,
            Self::IllegalDataValue => modbus_core::Exception::IllegalDataValue,
        }
    }
}

/// A query from the controller.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Query<'a> {
    /// 03h: `registers` words from the object at `address`.
    Read {
        /// First object index.
        address: u16,
        /// Words to read.
        registers: u16,
    },
    /// 08h sub-function 0000h: the drive echoes the value.
    Echo(u16),
    /// 10h: the words (big-endian bytes) from the object at `address` on.
    Write {
        /// First object index.
        address: u16,
        /// The words, each high byte first.
        data: &'a [u8],
    },
}

/// The drive's reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reply<'a> {
    /// 03h: the words read, each high byte first.
    Read(&'a [u8]),
    /// 08h: the echoed value.
    Echo(u16),
    /// 10h: where and how many words were written.
    Written {
        /// First object index.
        address: u16,
        /// Words written.
        registers: u16,
    },
    /// Function + 80h with an exception code.
    Exception {
        /// The query's function code.
        function: u8,
        /// Why.
        code: ExceptionCode,
    },
}

impl Query<'_> {
    /// The function code.
    pub fn function(&self) -> u8 {
        match self {
            Query::Read { .. } => READ,
            Query::Echo(_) => DIAGNOSTICS,
            Query::Write { .. } => WRITE,
        }
    }

    /// Encodes the PDU into `buf`; its length.
    pub fn encode(&self, buf: &mut [u8]) -> Result<usize, ModbusError> {
        let echo;
        let request = match *self {
            Query::Read { address, registers } => {
                check_count(READ, usize::from(registers))?;
                Request::ReadHoldingRegisters(address, registers)
            }
            Query::Echo(value) => {
                let [hi, lo] = value.to_be_bytes();
                echo = [0, 0, hi, lo];
                Request::Custom(FunctionCode::Diagnostics, &echo)
            }
            Query::Write { address, data } => {
                let words = words(WRITE, data)?;
                Request::WriteMultipleRegisters(address, words)
            }
        };
        request
            .encode(buf)
            .map_err(|_| ModbusError::Buffer(buf.len()))
    }

    /// Decodes a query PDU as the drive does.
    pub fn decode(pdu: &[u8]) -> Result<Query<'_>, ModbusError> {
        let Some(&function) = pdu.first() else {
            return Err(truncated(pdu, 1));
        };
        if ![READ, DIAGNOSTICS, WRITE].contains(&function) {
            return Err(ModbusError::Function(function));
        }
        if pdu.len() < 5 {
            return Err(truncated(pdu, 5));
        }
        match Request::try_from(pdu).map_err(|_| truncated(pdu, pdu.len() + 1))? {
            Request::ReadHoldingRegisters(address, registers) => {
                exact(pdu, 5)?;
                check_count(READ, usize::from(registers))?;
                Ok(Query::Read { address, registers })
            }
            Request::WriteMultipleRegisters(address, _) => {
                let registers = usize::from(u16::from_be_bytes([pdu[3], pdu[4]]));
                check_count(WRITE, registers)?;
                let byte_count = usize::from(pdu[5]);
                if byte_count != registers * 2 {
                    return Err(malformed(WRITE, "byte count is not 2 × No. of Registers"));
                }
                exact(pdu, 6 + byte_count)?;
                Ok(Query::Write {
                    address,
                    data: &pdu[6..],
                })
            }
            _ => {
                exact(pdu, 5)?;
                if pdu[1..3] != [0, 0] {
                    return Err(malformed(DIAGNOSTICS, "sub-function is not 0000h"));
                }
                Ok(Query::Echo(u16::from_be_bytes([pdu[3], pdu[4]])))
            }
        }
    }
}

impl Reply<'_> {
    /// Encodes the PDU into `buf`; its length.
    pub fn encode(&self, buf: &mut [u8]) -> Result<usize, ModbusError> {
        let echo;
        let response = match *self {
            Reply::Read(data) => Response::ReadHoldingRegisters(words(READ, data)?),
            Reply::Echo(value) => {
                let [hi, lo] = value.to_be_bytes();
                echo = [0, 0, hi, lo];
                Response::Custom(FunctionCode::Diagnostics, &echo)
            }
            Reply::Written { address, registers } => {
                Response::WriteMultipleRegisters(address, registers)
            }
            Reply::Exception { function, code } => {
                let ex = ExceptionResponse {
                    function: FunctionCode::new(function & 0x7F),
                    exception: code.to_core(),
                };
                return ex.encode(buf).map_err(|_| ModbusError::Buffer(buf.len()));
            }
        };
        response
            .encode(buf)
            .map_err(|_| ModbusError::Buffer(buf.len()))
    }

    /// Decodes the reply PDU to `query`; an exception is a [`Reply::Exception`].
    pub fn decode<'p>(query: &Query<'_>, pdu: &'p [u8]) -> Result<Reply<'p>, ModbusError> {
        let function = query.function();
        let Some(&code) = pdu.first() else {
            return Err(truncated(pdu, 1));
        };
        if code == function | 0x80 {
            exact(pdu, 2)?;
            let code = ExceptionCode::from_repr(pdu[1])
                .ok_or(malformed(function, "unknown exception code"))?;
            return Ok(Reply::Exception { function, code });
        }
        if code != function {
            return Err(ModbusError::Mismatch {
                what: "function",
                got: u16::from(code),
                expected: u16::from(function),
            });
        }
        match *query {
            Query::Read { registers, .. } => {
                let byte_count = usize::from(*pdu.get(1).ok_or(truncated(pdu, 2))?);
                if byte_count != usize::from(registers) * 2 {
                    return Err(malformed(READ, "byte count is not 2 × the registers asked"));
                }
                exact(pdu, 2 + byte_count)?;
                Ok(Reply::Read(&pdu[2..]))
            }
            Query::Echo(value) => {
                exact(pdu, 5)?;
                let echoed = u16::from_be_bytes([pdu[3], pdu[4]]);
                if pdu[1..3] != [0, 0] || echoed != value {
                    return Err(malformed(DIAGNOSTICS, "the echo differs from the query"));
                }
                Ok(Reply::Echo(echoed))
            }
            Query::Write { address, data } => {
                exact(pdu, 5)?;
                let (a, n) = (
                    u16::from_be_bytes([pdu[1], pdu[2]]),
                    u16::from_be_bytes([pdu[3], pdu[4]]),
                );
                if a != address || usize::from(n) * 2 != data.len() {
                    return Err(malformed(WRITE, "the reply names other registers"));
                }
                Ok(Reply::Written {
                    address: a,
                    registers: n,
                })
            }
        }
    }
}

impl ModbusError {
    /// The exception the drive answers a refused query with (none: it stays silent).
    pub fn exception(&self, function: u8) -> Option<Reply<'static>> {
        let code = match self {
            ModbusError::Function(_) => ExceptionCode::IllegalFunction,
            // A diagnostics sub-function other than 0000h "is a communication error" (§4.7):
            // 01h by Modbus convention (the manual names no code).
            ModbusError::Malformed { function: f, .. } if *f == DIAGNOSTICS => {
                ExceptionCode::IllegalFunction
            }
            ModbusError::Malformed { .. } => ExceptionCode::IllegalDataValue,
            _ => return None,
        };
        Some(Reply::Exception { function, code })
    }
}

fn words(function: u8, data: &[u8]) -> Result<Data<'_>, ModbusError> {
    if !data.len().is_multiple_of(2) {
        return Err(malformed(function, "odd number of data bytes"));
    }
    check_count(function, data.len() / 2)?;
    Data::try_from(data).map_err(|_| malformed(function, "no data"))
}

fn check_count(function: u8, registers: usize) -> Result<(), ModbusError> {
    match registers {
        0 => Err(malformed(function, "No. of Registers is 0")),
        n if n > MAX_REGISTERS => Err(malformed(function, "more than 122 registers")),
        _ => Ok(()),
    }
}

fn exact(pdu: &[u8], len: usize) -> Result<(), ModbusError> {
    match pdu.len() {
        n if n < len => Err(truncated(pdu, len)),
        n if n > len => Err(ModbusError::Oversized { got: n, max: len }),
        _ => Ok(()),
    }
}

fn truncated(pdu: &[u8], need: usize) -> ModbusError {
    ModbusError::Truncated {
        got: pdu.len(),
        need,
    }
}

fn malformed(function: u8, why: &'static str) -> ModbusError {
    ModbusError::Malformed { function, why }
}
