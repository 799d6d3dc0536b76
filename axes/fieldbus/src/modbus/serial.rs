//! Modbus RTU on an RS-485 line (MR-JE-C manual §4.1–§4.9): the line's settings, its frame
//! silence, and a master that talks to one station at a time on it. A frame is delimited by a
//! silent interval of at least 3.5 character times (§4.5, §4.7); the master sends the next query
//! only after the reply (or its deadline), drops anything left on the line before a query (a
//! reply that came too late), and waits the drive's processing time after a broadcast (§4.6).
//! Buffers are allocated once per line.

use std::io;
use std::time::{Duration, Instant};

use serialport::{ClearBuffer, DataBits, Parity, SerialPort, StopBits};

use super::client::{ClientError, Registers};
use super::pdu::READ;
use super::rtu::{self, BROADCAST, MAX_FRAME};
use super::{Query, Reply, MAX_REGISTERS};

/// Parity and stop bits of the line, [Pr. PF45] digit `___x` (MR-JE-C manual §5.2.1 PF45).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, strum::Display, strum::EnumString)]
pub enum Framing {
    /// Even parity, 1 stop bit (PF45 = 0, the initial setting).
    #[default]
    #[strum(serialize = "even")]
    Even1,
    /// Odd parity, 1 stop bit (PF45 = 1).
    #[strum(serialize = "odd")]
    Odd1,
    /// No parity, 2 stop bits (PF45 = 2).
    #[strum(serialize = "none")]
    None2,
}

/// The bit rates the drive offers, [Pr. PC71] digit `__x_` (§4.4, §5.2.1 PC71).
pub const BAUD_RATES: [u32; 6] = [4800, 9600, 19_200, 38_400, 57_600, 115_200];

impl Framing {
    /// The framing [Pr. PF45] digit `___x` selects (0 even/1, 1 odd/1, 2 none/2); `None` for
    /// a value the manual does not define.
    pub fn from_pf45(digit: i64) -> Option<Framing> {
        match digit {
            0 => Some(Framing::Even1),
            1 => Some(Framing::Odd1),
            2 => Some(Framing::None2),
            _ => None,
        }
    }

    /// The [Pr. PF45] digit `___x` that selects it.
    pub fn pf45_digit(self) -> i64 {
        match self {
            Framing::Even1 => 0,
            Framing::Odd1 => 1,
            Framing::None2 => 2,
        }
    }
}

/// [Pr. PC71] digit `__x_` → bit rate (MR-JE-C manual §5.2.3 PC71; 5 raises AL. 37.1).
const PC71_BAUD: [(i64, u32); 6] = [
    (0, 9600),
    (1, 19_200),
    (2, 38_400),
    (3, 57_600),
    (4, 115_200),
    (6, 4800),
];

/// The bit rate [Pr. PC71] digit `__x_` selects; `None` for a value the manual gives none.
pub fn baud_from_pc71(digit: i64) -> Option<u32> {
    PC71_BAUD.iter().find(|(d, _)| *d == digit).map(|(_, b)| *b)
}

/// The [Pr. PC71] digit `__x_` that selects `baud`.
pub fn pc71_digit(baud: u32) -> Option<i64> {
    PC71_BAUD.iter().find(|(_, b)| *b == baud).map(|(d, _)| *d)
}

/// The settings of an RS-485 line: 8 data bits always (§4.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LineSettings {
    /// Bit rate, one of [`BAUD_RATES`] (115200 initial, §4.9.1).
    pub baud: u32,
    /// Parity and stop bits.
    pub framing: Framing,
}

impl Default for LineSettings {
    fn default() -> Self {
        LineSettings {
            baud: 115_200,
            framing: Framing::Even1,
        }
    }
}

/// The shortest frame silence cellrt uses. The manual asks for 3.5 character times (§4.5),
/// which at 115200 bit/s is 0.33 ms; the Modbus serial-line specification fixes 1.75 ms above
/// 19200 bit/s, and a pseudo-terminal or USB adapter delivers bytes in bursts, so cellrt never
/// waits less than this.
pub const MIN_SILENCE: Duration = Duration::from_micros(1750);

/// A bit rate the drive does not offer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("bit rate {0}: the MR-JE-C offers {BAUD_RATES:?} bit/s ([Pr. PC71])")]
pub struct BaudRateError(pub u32);

impl LineSettings {
    /// Settings checked against what the drive offers.
    pub fn new(baud: u32, framing: Framing) -> Result<LineSettings, BaudRateError> {
        if !BAUD_RATES.contains(&baud) {
            return Err(BaudRateError(baud));
        }
        Ok(LineSettings { baud, framing })
    }

    /// One character on the wire: start, 8 data, parity or second stop, stop = 11 bits.
    pub fn char_time(&self) -> Duration {
        Duration::from_nanos(11 * 1_000_000_000 / u64::from(self.baud))
    }

    /// The silence that ends a frame: 3.5 character times, at least [`MIN_SILENCE`].
    pub fn silence(&self) -> Duration {
        (self.char_time() * 7 / 2).max(MIN_SILENCE)
    }

    /// Opens the serial device at `path` (a `/dev/ttyS…`, a USB adapter or a pseudo-terminal).
    pub fn open(&self, path: &str) -> Result<Box<dyn SerialPort>, ClientError> {
        let (parity, stop) = match self.framing {
            Framing::Even1 => (Parity::Even, StopBits::One),
            Framing::Odd1 => (Parity::Odd, StopBits::One),
            Framing::None2 => (Parity::None, StopBits::Two),
        };
        serialport::new(path, self.baud)
            .data_bits(DataBits::Eight)
            .parity(parity)
            .stop_bits(stop)
            .timeout(self.silence())
            .open()
            .map_err(|e| {
                ClientError::Io(io::Error::new(
                    io::ErrorKind::NotFound,
                    format!("serial port {path}: {e}"),
                ))
            })
    }
}

/// How long the master waits after a broadcast before its next query (§4.6): the manual gives
/// 24 ms for 2 registers and 300 ms for 122; between them cellrt interpolates linearly.
pub fn broadcast_wait(registers: u16) -> Duration {
    let n = u64::from(registers.clamp(2, MAX_REGISTERS as u16));
    Duration::from_micros(24_000 + (n - 2) * (300_000 - 24_000) / 120)
}

/// A Modbus RTU master on one line, talking to one station at a time.
pub struct RtuClient {
    port: Box<dyn SerialPort>,
    station: u8,
    timeout: Duration,
    silence: Duration,
    /// When the line last carried a byte, for the silence before the next query.
    quiet_since: Instant,
    out: [u8; MAX_FRAME],
    inbox: [u8; MAX_FRAME],
}

impl RtuClient {
    /// A master on `port` (opened with `line`), talking to `station` (1–247); each request
    /// waits at most `timeout` for its reply.
    pub fn new(
        port: Box<dyn SerialPort>,
        line: LineSettings,
        station: u8,
        timeout: Duration,
    ) -> Result<RtuClient, ClientError> {
        check_station(station)?;
        Ok(RtuClient {
            port,
            station,
            timeout,
            silence: line.silence(),
            quiet_since: Instant::now(),
            out: [0; MAX_FRAME],
            inbox: [0; MAX_FRAME],
        })
    }

    /// Talks to `station` (1–247) from now on.
    pub fn set_station(&mut self, station: u8) -> Result<(), ClientError> {
        check_station(station)?;
        self.station = station;
        Ok(())
    }

    /// 10h to every station at once (address 0): no reply; waits the drives' processing time.
    pub fn broadcast_write(&mut self, address: u16, words: &[u16]) -> Result<(), ClientError> {
        let mut data = [0u8; 2 * MAX_REGISTERS];
        let n = fill_words(words, &mut data)?;
        let query = Query::Write {
            address,
            data: &data[..n],
        };
        self.send(BROADCAST, &query)?;
        std::thread::sleep(broadcast_wait(words.len() as u16));
        self.quiet_since = Instant::now();
        Ok(())
    }

    /// Sends `query` to `slave` after the line has been silent for a frame gap, dropping any
    /// late bytes first.
    fn send(&mut self, slave: u8, query: &Query<'_>) -> Result<(), ClientError> {
        let n = rtu::encode_query(slave, query, &mut self.out)?;
        let quiet = self.quiet_since.elapsed();
        if quiet < self.silence {
            std::thread::sleep(self.silence - quiet);
        }
        self.port
            .clear(ClearBuffer::Input)
            .map_err(|e| ClientError::Io(e.into()))?;
        self.port.write_all(&self.out[..n])?;
        self.port.flush()?;
        Ok(())
    }

    /// Sends `query` and reads its reply frame; the frame's length in the inbox.
    fn exchange(&mut self, query: &Query<'_>) -> Result<usize, ClientError> {
        self.send(self.station, query)?;
        let deadline = Instant::now() + self.timeout;
        let mut have = 0;
        loop {
            if let Some(len) = reply_len(query, &self.inbox[..have]) {
                if have >= len {
                    self.quiet_since = Instant::now();
                    return Ok(len);
                }
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                self.quiet_since = Instant::now();
                return Err(ClientError::Timeout(self.timeout));
            }
            self.port
                .set_timeout(left)
                .map_err(|e| ClientError::Io(e.into()))?;
            match crate::reply_read::sort(self.port.read(&mut self.inbox[have..]), false)? {
                crate::reply_read::Read::Bytes(k) => have += k,
                crate::reply_read::Read::TimedOut => {}
            }
            if have == MAX_FRAME && reply_len(query, &self.inbox).is_none_or(|l| l > MAX_FRAME) {
                return Err(ClientError::Request("a reply longer than an RTU frame"));
            }
        }
    }

    /// The reply of `query` after [`Self::exchange`]: exceptions become errors.
    fn reply<'a>(&'a self, query: &Query<'_>, len: usize) -> Result<Reply<'a>, ClientError> {
        match rtu::decode_reply(self.station, query, &self.inbox[..len])? {
            Reply::Exception { function, code } => Err(ClientError::Exception { function, code }),
            r => Ok(r),
        }
    }
}

impl Registers for RtuClient {
    fn read_registers(&mut self, address: u16, out: &mut [u16]) -> Result<(), ClientError> {
        if out.is_empty() || out.len() > MAX_REGISTERS {
            return Err(ClientError::Request("1–122 registers per read"));
        }
        let query = Query::Read {
            address,
            registers: out.len() as u16,
        };
        let len = self.exchange(&query)?;
        if let Reply::Read(data) = self.reply(&query, len)? {
            for (w, pair) in out.iter_mut().zip(data.chunks_exact(2)) {
                *w = u16::from_be_bytes([pair[0], pair[1]]);
            }
        }
        Ok(())
    }

    fn write_registers(&mut self, address: u16, words: &[u16]) -> Result<(), ClientError> {
        let mut data = [0u8; 2 * MAX_REGISTERS];
        let n = fill_words(words, &mut data)?;
        let query = Query::Write {
            address,
            data: &data[..n],
        };
        let len = self.exchange(&query)?;
        self.reply(&query, len).map(|_| ())
    }

    fn echo(&mut self, value: u16) -> Result<(), ClientError> {
        let query = Query::Echo(value);
        let len = self.exchange(&query)?;
        self.reply(&query, len).map(|_| ())
    }
}

fn check_station(station: u8) -> Result<(), ClientError> {
    if station == BROADCAST || station > 247 {
        return Err(ClientError::Request(
            "an RTU station number is 1–247 (0 is the broadcast address)",
        ));
    }
    Ok(())
}

/// `words` high byte first into `data`; the bytes used.
fn fill_words(words: &[u16], data: &mut [u8; 2 * MAX_REGISTERS]) -> Result<usize, ClientError> {
    if words.is_empty() || words.len() > MAX_REGISTERS {
        return Err(ClientError::Request("1–122 registers per write"));
    }
    for (pair, w) in data.chunks_exact_mut(2).zip(words) {
        pair.copy_from_slice(&w.to_be_bytes());
    }
    Ok(2 * words.len())
}

/// The length of the reply frame to `query` whose first bytes are `head`, once they tell it:
/// an exception is 5 bytes, a read reply 5 + its byte count, an echo or a write reply 8.
fn reply_len(query: &Query<'_>, head: &[u8]) -> Option<usize> {
    let function = *head.get(1)?;
    if function & 0x80 != 0 {
        return Some(5);
    }
    match query.function() {
        READ => head.get(2).map(|&count| 5 + usize::from(count)),
        _ => Some(8),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// §4.6: 24 ms after a 2-register broadcast, 300 ms after 122.
    #[test]
    fn broadcast_waits_follow_the_manual() {
        assert_eq!(broadcast_wait(2), Duration::from_millis(24));
        assert_eq!(broadcast_wait(122), Duration::from_millis(300));
        assert_eq!(broadcast_wait(1), Duration::from_millis(24));
    }

    /// 3.5 characters of 11 bits: 8.02 ms at 4800 bit/s; above 19200 bit/s the floor.
    #[test]
    fn the_frame_silence_is_three_and_a_half_characters() {
        let slow = LineSettings::new(4800, Framing::Even1).unwrap();
        assert_eq!(slow.silence(), Duration::from_nanos(2_291_666 * 7 / 2));
        let fast = LineSettings::default();
        assert_eq!(fast.silence(), MIN_SILENCE);
        assert!(LineSettings::new(14_400, Framing::Even1)
            .unwrap_err()
            .to_string()
            .contains("14400"));
    }

    #[test]
    fn reply_lengths_come_from_the_head() {
        let read = Query::Read {
            address: 0x6041,
            registers: 1,
        };
        assert_eq!(reply_len(&read, &[1]), None);
        assert_eq!(reply_len(&read, &[1, 3]), None);
        assert_eq!(reply_len(&read, &[1, 3, 2]), Some(7));
        assert_eq!(reply_len(&read, &[1, 0x83]), Some(5));
        assert_eq!(reply_len(&Query::Echo(5), &[1, 8]), Some(8));
    }
}
