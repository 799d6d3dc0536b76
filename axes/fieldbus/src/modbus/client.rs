//! A Modbus/TCP client for one MR-JE-C (MR-JE-C manual §3): one query in flight (the drive
//! serves one at a time), replies to an earlier transaction dropped, a reply deadline, buffers
//! allocated once per connection. [`Registers`] is what Modbus/TCP and Modbus RTU
//! ([`super::serial`]) both offer the layers above.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use super::tcp::{self, MAX_ADU};
use super::{ExceptionCode, ModbusError, Query, Reply, MAX_REGISTERS};

/// Why a client request failed.
#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    /// The connection failed or broke.
    #[error("Modbus {0}")]
    Io(#[from] std::io::Error),
    /// A frame was refused.
    #[error("Modbus: {0}")]
    Frame(#[from] ModbusError),
    /// The drive answered with an exception.
    #[error("Modbus: the drive answered exception {code} to function {function:#04x}")]
    Exception {
        /// Function code.
        function: u8,
        /// Exception code.
        code: ExceptionCode,
    },
    /// No reply before the deadline.
    #[error("Modbus: no reply within {0:?}")]
    Timeout(Duration),
    /// More registers than one query carries, or an output slice of the wrong length.
    #[error("Modbus: {0}")]
    Request(&'static str),
}

/// Register access to one drive: 03h, 10h and the 08h echo (§3.6.1, §4.8.1), over Modbus/TCP
/// or one station of a Modbus RTU line.
pub trait Registers {
    /// 03h: `out.len()` registers from the object at `address`.
    fn read_registers(&mut self, address: u16, out: &mut [u16]) -> Result<(), ClientError>;
    /// 10h: `words` to the objects from `address` on.
    fn write_registers(&mut self, address: u16, words: &[u16]) -> Result<(), ClientError>;
    /// 08h: the drive echoes `value`.
    fn echo(&mut self, value: u16) -> Result<(), ClientError>;
}

impl Registers for TcpClient {
    fn read_registers(&mut self, address: u16, out: &mut [u16]) -> Result<(), ClientError> {
        TcpClient::read_registers(self, address, out)
    }

    fn write_registers(&mut self, address: u16, words: &[u16]) -> Result<(), ClientError> {
        TcpClient::write_registers(self, address, words)
    }

    fn echo(&mut self, value: u16) -> Result<(), ClientError> {
        TcpClient::echo(self, value)
    }
}

/// A connection to one drive's Modbus/TCP server.
pub struct TcpClient {
    stream: TcpStream,
    transaction: u16,
    timeout: Duration,
    out: [u8; MAX_ADU],
    inbox: Vec<u8>,
}

impl TcpClient {
    /// Connects to `addr` (port 502 on a drive); each request waits at most `timeout`.
    pub fn connect(addr: SocketAddr, timeout: Duration) -> Result<TcpClient, ClientError> {
        let stream = TcpStream::connect_timeout(&addr, timeout)?;
        stream.set_nodelay(true)?;
        Ok(TcpClient {
            stream,
            transaction: 0,
            timeout,
            out: [0; MAX_ADU],
            inbox: Vec::with_capacity(4 * MAX_ADU),
        })
    }

    /// 03h: `out.len()` registers from the object at `address`.
    pub fn read_registers(&mut self, address: u16, out: &mut [u16]) -> Result<(), ClientError> {
        if out.is_empty() || out.len() > MAX_REGISTERS {
            return Err(ClientError::Request("1–122 registers per read"));
        }
        let query = Query::Read {
            address,
            registers: out.len() as u16,
        };
        let (start, len) = self.exchange(&query)?;
        let data = &self.inbox[start..start + len];
        // A read reply is the function, the byte count, then the words.
        for (w, pair) in out.iter_mut().zip(data[2..].chunks_exact(2)) {
            *w = u16::from_be_bytes([pair[0], pair[1]]);
        }
        self.inbox.drain(..start + len);
        Ok(())
    }

    /// 10h: `words` to the objects from `address` on.
    pub fn write_registers(&mut self, address: u16, words: &[u16]) -> Result<(), ClientError> {
        if words.is_empty() || words.len() > MAX_REGISTERS {
            return Err(ClientError::Request("1–122 registers per write"));
        }
        let mut data = [0u8; 2 * MAX_REGISTERS];
        for (pair, w) in data.chunks_exact_mut(2).zip(words) {
            pair.copy_from_slice(&w.to_be_bytes());
        }
        let query = Query::Write {
            address,
            data: &data[..2 * words.len()],
        };
        let (start, len) = self.exchange(&query)?;
        self.inbox.drain(..start + len);
        Ok(())
    }

    /// 08h: the drive echoes `value`.
    pub fn echo(&mut self, value: u16) -> Result<(), ClientError> {
        let (start, len) = self.exchange(&Query::Echo(value))?;
        self.inbox.drain(..start + len);
        Ok(())
    }

    /// Sends `query` and waits for its reply; the reply PDU's place in the inbox.
    fn exchange(&mut self, query: &Query<'_>) -> Result<(usize, usize), ClientError> {
        self.transaction = self.transaction.wrapping_add(1);
        let t = self.transaction;
        let n = tcp::encode_query(t, query, &mut self.out)?;
        self.stream.write_all(&self.out[..n])?;
        let deadline = Instant::now() + self.timeout;
        loop {
            if let Some((adu, used)) = tcp::split(&self.inbox)? {
                if adu.transaction != t {
                    // A late reply to an earlier query: dropped.
                    self.inbox.drain(..used);
                    continue;
                }
                let pdu_start = used - adu.pdu.len();
                match tcp::decode_reply(t, query, &adu)? {
                    Reply::Exception { function, code } => {
                        self.inbox.drain(..used);
                        return Err(ClientError::Exception { function, code });
                    }
                    _ => return Ok((pdu_start, adu.pdu.len())),
                }
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(ClientError::Timeout(self.timeout));
            }
            self.stream.set_read_timeout(Some(left))?;
            let mut chunk = [0u8; MAX_ADU];
            match crate::reply_read::sort(self.stream.read(&mut chunk), true)? {
                crate::reply_read::Read::Bytes(k) => self.inbox.extend_from_slice(&chunk[..k]),
                crate::reply_read::Read::TimedOut => {
                    return Err(ClientError::Timeout(self.timeout))
                }
            }
        }
    }
}
