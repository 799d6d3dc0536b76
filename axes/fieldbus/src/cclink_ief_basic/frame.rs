//! The byte layout of the cyclic request and response (multi-byte fields little-endian, the
//! subheader big-endian; IP addresses as the little-endian u32 of the address).

/// Stations one request carries at most.
pub const MAX_STATIONS: usize = 16;
/// RWw / RWr bytes per station (32 words).
pub const LINK_WORDS_BYTES: usize = 64;
/// RY / RX bytes per station (64 bits).
pub const LINK_BITS_BYTES: usize = 8;

const REQUEST_HEADER: usize = 67;
const RESPONSE_HEADER: usize = 59;
const COMMAND: u16 = 0x0E70;
const REQUEST_CYCLIC_OFFSET: u16 = 36;
const RESPONSE_CYCLIC_OFFSET: u16 = 40;
/// Slave ID of a station that continues a multi-station slave.
const CONTINUATION: u32 = 0xFFFF_FFFF;

/// A response end code (0000h normal).
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::FromRepr)]
#[repr(u16)]
pub enum EndCode {
    /// Normal.
    Normal = 0x0000,
    /// Another master is already connected (master duplication).
    MasterDuplication = 0xCFE0,
    /// The slave-ID list implies another number of occupied stations.
    WrongStationCount = 0xCFE1,
    /// Slave error.
    SlaveError = 0xCFF0,
    /// The slave asks to be disconnected.
    DisconnectRequest = 0xCFFF,
}

/// One station's link devices in a request (RWw, RY) or a response (RWr, RX).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StationData {
    /// The station's IP (slave ID), little-endian u32 of the address.
    pub slave_id: u32,
    /// RWw or RWr, 32 words little-endian.
    pub words: [u8; LINK_WORDS_BYTES],
    /// RY or RX, 64 bits.
    pub bits: [u8; LINK_BITS_BYTES],
}

impl Default for StationData {
    fn default() -> Self {
        StationData {
            slave_id: 0,
            words: [0; LINK_WORDS_BYTES],
            bits: [0; LINK_BITS_BYTES],
        }
    }
}

/// The master's cyclic request (one group).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CyclicRequest {
    /// Protocol version, 1 or 2.
    pub protocol_version: u16,
    /// Master local unit info: bit 0 running.
    pub unit_info: u16,
    /// Clock, Unix time in ms (0: none).
    pub clock_ms: u64,
    /// The master's IP.
    pub master_id: u32,
    /// Group No., 1–64.
    pub group: u8,
    /// Frame sequence No., echoed by the slaves.
    pub sequence: u16,
    /// Timeout value, ms (0: 500 ms).
    pub timeout_ms: u16,
    /// Parallel-off timeout count (0: 3).
    pub parallel_off_count: u16,
    /// Parameter No. (configuration revision).
    pub parameter_no: u16,
    /// Cyclic transmission state: bit k−1 for station k.
    pub transmission: u16,
    /// Occupied stations in the group.
    pub stations: usize,
    /// Each station's slave ID, RWw and RY (first `stations` valid).
    pub station: [StationData; MAX_STATIONS],
}

/// A slave's cyclic response (one station: M = 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CyclicResponse {
    /// Protocol version (not documented for the MR-JE-C: not asserted by clients).
    pub protocol_version: u16,
    /// End code.
    pub end_code: EndCode,
    /// Vendor code.
    pub vendor_code: u16,
    /// Model code.
    pub model_code: u32,
    /// Equipment version.
    pub equipment_version: u16,
    /// Slave local unit info: bit 0 operating.
    pub unit_info: u16,
    /// Slave error code (vendor-defined).
    pub error_code: u16,
    /// Local management info (vendor-defined).
    pub local_info: u32,
    /// Group No., echoed.
    pub group: u8,
    /// Frame sequence No., echoed.
    pub sequence: u16,
    /// The station's slave ID, RWr and RX.
    pub station: StationData,
}

/// A frame a slave drops (silently) or a master refuses.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CyclicError {
    /// Not the size its header and station count give.
    #[error("cyclic frame of {got} bytes, {expected} expected")]
    Size {
        /// Bytes present.
        got: usize,
        /// Bytes expected.
        expected: usize,
    },
    /// A header field out of its range or not the constant the layout fixes.
    #[error("cyclic frame field {field}: {value:#x}")]
    Field {
        /// The field's name.
        field: &'static str,
        /// Its value.
        value: u64,
    },
    /// The master ID is not the frame's source address.
    #[error("master ID {master:#010x} is not the source address {from:#010x}")]
    Source {
        /// Master ID in the frame.
        master: u32,
        /// UDP source address.
        from: u32,
    },
    /// The output buffer is too small.
    #[error("buffer of {0} bytes too small")]
    Buffer(usize),
}

fn le16(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}

fn le32(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn put(buf: &mut [u8], at: usize, bytes: &[u8]) {
    buf[at..at + bytes.len()].copy_from_slice(bytes);
}

/// The common 9-byte header (subheader, network FFh station, unit I/O 03FFh, multidrop, dl).
fn header(buf: &mut [u8], subheader: [u8; 2], len: usize) {
    put(buf, 0, &subheader);
    put(buf, 2, &[0x00, 0xFF, 0xFF, 0x03, 0x00]);
    put(buf, 7, &((len - 9) as u16).to_le_bytes());
}

fn field(field: &'static str, value: impl Into<u64>) -> CyclicError {
    CyclicError::Field {
        field,
        value: value.into(),
    }
}

impl CyclicRequest {
    /// The request's size for its station count.
    pub fn size(&self) -> usize {
        REQUEST_HEADER + 76 * self.stations
    }

    /// Master: the UDP payload; its length.
    pub fn encode(&self, buf: &mut [u8]) -> Result<usize, CyclicError> {
        let n = self.stations;
        if n == 0 || n > MAX_STATIONS {
            return Err(field("slave total occupied station count", n as u64));
        }
        let len = self.size();
        if buf.len() < len {
            return Err(CyclicError::Buffer(buf.len()));
        }
        buf[..len].fill(0);
        header(buf, [0x50, 0x00], len);
        put(buf, 11, &COMMAND.to_le_bytes());
        put(buf, 15, &self.protocol_version.to_le_bytes());
        put(buf, 19, &REQUEST_CYCLIC_OFFSET.to_le_bytes());
        put(buf, 35, &self.unit_info.to_le_bytes());
        put(buf, 39, &self.clock_ms.to_le_bytes());
        put(buf, 47, &self.master_id.to_le_bytes());
        buf[51] = self.group;
        put(buf, 53, &self.sequence.to_le_bytes());
        put(buf, 55, &self.timeout_ms.to_le_bytes());
        put(buf, 57, &self.parallel_off_count.to_le_bytes());
        put(buf, 59, &self.parameter_no.to_le_bytes());
        put(buf, 61, &(n as u16).to_le_bytes());
        put(buf, 63, &self.transmission.to_le_bytes());
        for (k, s) in self.station[..n].iter().enumerate() {
            put(buf, REQUEST_HEADER + 4 * k, &s.slave_id.to_le_bytes());
            put(buf, REQUEST_HEADER + 4 * n + 64 * k, &s.words);
            put(buf, REQUEST_HEADER + 68 * n + 8 * k, &s.bits);
        }
        Ok(len)
    }

    /// Slave: the request in `frame` received from `source` (its IP), validated as a
    /// conformant slave does; an error means the frame is dropped without an answer.
    pub fn decode(frame: &[u8], source: u32) -> Result<CyclicRequest, CyclicError> {
        if frame.len() < REQUEST_HEADER {
            return Err(CyclicError::Size {
                got: frame.len(),
                expected: REQUEST_HEADER,
            });
        }
        if frame[..7] != [0x50, 0x00, 0x00, 0xFF, 0xFF, 0x03, 0x00] {
            return Err(field("header", u64::from(le16(frame, 0))));
        }
        let n = usize::from(le16(frame, 61));
        if n == 0 || n > MAX_STATIONS {
            return Err(field("slave total occupied station count", n as u64));
        }
        let expected = REQUEST_HEADER + 76 * n;
        if frame.len() != expected || usize::from(le16(frame, 7)) != expected - 9 {
            return Err(CyclicError::Size {
                got: frame.len(),
                expected,
            });
        }
        if (le16(frame, 11), le16(frame, 13)) != (COMMAND, 0) {
            return Err(field("command", le32(frame, 11)));
        }
        let version = le16(frame, 15);
        if !(1..=2).contains(&version) {
            return Err(field("protocol version", version));
        }
        if le16(frame, 19) != REQUEST_CYCLIC_OFFSET {
            return Err(field("cyclic info offset", le16(frame, 19)));
        }
        let unit_info = le16(frame, 35);
        let allowed = if version == 1 { 0x0001 } else { 0x0003 };
        if unit_info & !allowed != 0 {
            return Err(field("master local unit info", unit_info));
        }
        let master_id = le32(frame, 47);
        if master_id == 0 || master_id != source {
            return Err(CyclicError::Source {
                master: master_id,
                from: source,
            });
        }
        let group = frame[51];
        if !(1..=64).contains(&group) {
            return Err(field("group No.", group));
        }
        let mut station = [StationData::default(); MAX_STATIONS];
        for (k, s) in station[..n].iter_mut().enumerate() {
            s.slave_id = le32(frame, REQUEST_HEADER + 4 * k);
            let w = REQUEST_HEADER + 4 * n + 64 * k;
            s.words.copy_from_slice(&frame[w..w + LINK_WORDS_BYTES]);
            let b = REQUEST_HEADER + 68 * n + 8 * k;
            s.bits.copy_from_slice(&frame[b..b + LINK_BITS_BYTES]);
        }
        Ok(CyclicRequest {
            protocol_version: version,
            unit_info,
            clock_ms: u64::from(le32(frame, 39)) | u64::from(le32(frame, 43)) << 32,
            master_id,
            group,
            sequence: le16(frame, 53),
            timeout_ms: le16(frame, 55),
            parallel_off_count: le16(frame, 57),
            parameter_no: le16(frame, 59),
            transmission: le16(frame, 63),
            stations: n,
            station,
        })
    }

    /// The station number (1-based) of the slave with IP `own`, if the request carries it.
    pub fn station_of(&self, own: u32) -> Option<usize> {
        self.station[..self.stations]
            .iter()
            .position(|s| s.slave_id == own && own != CONTINUATION)
            .map(|k| k + 1)
    }

    /// Whether station `k` (1-based) is in cyclic transmission.
    pub fn transmitting(&self, k: usize) -> bool {
        (1..=MAX_STATIONS).contains(&k) && self.transmission & (1 << (k - 1)) != 0
    }

    /// The supervision time after which a slave considers the master lost:
    /// timeout × parallel-off count, with the defaults for 0 (500 ms, 3).
    pub fn master_lost_after_ms(&self) -> u32 {
        let timeout = if self.timeout_ms == 0 {
            500
        } else {
            self.timeout_ms
        };
        let count = if self.parallel_off_count == 0 {
            3
        } else {
            self.parallel_off_count
        };
        u32::from(timeout) * u32::from(count)
    }
}

/// The response's size (one occupied station).
pub const RESPONSE_SIZE: usize = RESPONSE_HEADER + 72;

impl CyclicResponse {
    /// Slave: the UDP payload; its length.
    pub fn encode(&self, buf: &mut [u8]) -> Result<usize, CyclicError> {
        let len = RESPONSE_SIZE;
        if buf.len() < len {
            return Err(CyclicError::Buffer(buf.len()));
        }
        buf[..len].fill(0);
        header(buf, [0xD0, 0x00], len);
        put(buf, 11, &self.protocol_version.to_le_bytes());
        put(buf, 13, &(self.end_code as u16).to_le_bytes());
        put(buf, 15, &RESPONSE_CYCLIC_OFFSET.to_le_bytes());
        put(buf, 31, &self.vendor_code.to_le_bytes());
        put(buf, 35, &self.model_code.to_le_bytes());
        put(buf, 39, &self.equipment_version.to_le_bytes());
        put(buf, 43, &self.unit_info.to_le_bytes());
        put(buf, 45, &self.error_code.to_le_bytes());
        put(buf, 47, &self.local_info.to_le_bytes());
        put(buf, 51, &self.station.slave_id.to_le_bytes());
        buf[55] = self.group;
        put(buf, 57, &self.sequence.to_le_bytes());
        put(buf, RESPONSE_HEADER, &self.station.words);
        put(buf, RESPONSE_HEADER + 64, &self.station.bits);
        Ok(len)
    }

    /// Master: the response in `frame` (one occupied station).
    pub fn decode(frame: &[u8]) -> Result<CyclicResponse, CyclicError> {
        if frame.len() != RESPONSE_SIZE || usize::from(le16(frame, 7)) != RESPONSE_SIZE - 9 {
            return Err(CyclicError::Size {
                got: frame.len(),
                expected: RESPONSE_SIZE,
            });
        }
        if frame[..7] != [0xD0, 0x00, 0x00, 0xFF, 0xFF, 0x03, 0x00] {
            return Err(field("header", u64::from(le16(frame, 0))));
        }
        let end = le16(frame, 13);
        let end_code = EndCode::from_repr(end).ok_or(field("end code", end))?;
        let mut station = StationData {
            slave_id: le32(frame, 51),
            ..StationData::default()
        };
        station
            .words
            .copy_from_slice(&frame[RESPONSE_HEADER..RESPONSE_HEADER + 64]);
        station
            .bits
            .copy_from_slice(&frame[RESPONSE_HEADER + 64..RESPONSE_SIZE]);
        Ok(CyclicResponse {
            protocol_version: le16(frame, 11),
            end_code,
            vendor_code: le16(frame, 31),
            model_code: le32(frame, 35),
            equipment_version: le16(frame, 39),
            unit_info: le16(frame, 43),
            error_code: le16(frame, 45),
            local_info: le32(frame, 47),
            group: frame[55],
            sequence: le16(frame, 57),
            station,
        })
    }
}
