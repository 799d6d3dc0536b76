//! EtherCAT frames and datagrams on the wire (ETG.1000.4 §5.3–5.4): the Ethernet header with
//! EtherType 88A4h, the 2-byte EtherCAT header and the chain of datagrams, each with its
//! command, address, length, interrupt field, data and working counter. One codec, used by the
//! SubDevice emulator and by the master's own cyclic exchange.

/// EtherType of EtherCAT frames.
pub const ETHERTYPE: u16 = 0x88A4;
/// Bytes of the Ethernet header (destination, source, EtherType; no VLAN tag).
pub const ETHERNET_HEADER_LEN: usize = 14;
/// Bytes of the EtherCAT frame header.
pub const ECAT_HEADER_LEN: usize = 2;
/// Bytes of a datagram header (command, index, address, length/flags, IRQ).
pub const DATAGRAM_HEADER_LEN: usize = 10;
/// Bytes of the working counter after a datagram's data.
pub const WKC_LEN: usize = 2;
/// EtherCAT header type of datagram frames.
const TYPE_DATAGRAMS: u16 = 1;
/// Datagram length field: the low 11 bits.
const LEN_MASK: u16 = 0x07FF;
/// Datagram flag: the frame has circulated once (ETG.1000.4 Table 14).
pub const FLAG_CIRCULATING: u16 = 1 << 14;
/// Datagram flag: another datagram follows.
pub const FLAG_MORE_FOLLOWS: u16 = 1 << 15;
/// The bit a SubDevice sets in the source MAC of the frames it returns (byte 6 = first byte of
/// the source address, "locally administered"; ethercrab drops replies without it).
pub const REPLY_SOURCE_MAC_BIT: u8 = 0x02;

/// The EtherCAT commands (ETG.1000.4 Table 12).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Command {
    /// No operation.
    Nop = 0,
    /// Auto-increment physical read.
    Aprd = 1,
    /// Auto-increment physical write.
    Apwr = 2,
    /// Auto-increment physical read/write.
    Aprw = 3,
    /// Configured-address physical read.
    Fprd = 4,
    /// Configured-address physical write.
    Fpwr = 5,
    /// Configured-address physical read/write.
    Fprw = 6,
    /// Broadcast read.
    Brd = 7,
    /// Broadcast write.
    Bwr = 8,
    /// Broadcast read/write.
    Brw = 9,
    /// Logical memory read.
    Lrd = 10,
    /// Logical memory write.
    Lwr = 11,
    /// Logical memory read/write.
    Lrw = 12,
    /// Auto-increment read, multiple write.
    Armw = 13,
    /// Configured-address read, multiple write.
    Frmw = 14,
}

impl Command {
    /// The command of wire code `code`, `None` for reserved codes.
    pub const fn from_code(code: u8) -> Option<Command> {
        use Command::*;
        Some(match code {
            0 => Nop,
            1 => Aprd,
            2 => Apwr,
            3 => Aprw,
            4 => Fprd,
            5 => Fpwr,
            6 => Fprw,
            7 => Brd,
            8 => Bwr,
            9 => Brw,
            10 => Lrd,
            11 => Lwr,
            12 => Lrw,
            13 => Armw,
            14 => Frmw,
            _ => return None,
        })
    }

    /// True if the command reads SubDevice memory into the datagram.
    pub const fn reads(self) -> bool {
        use Command::*;
        matches!(
            self,
            Aprd | Aprw | Fprd | Fprw | Brd | Brw | Lrd | Lrw | Armw | Frmw
        )
    }

    /// True if the command writes the datagram into SubDevice memory.
    pub const fn writes(self) -> bool {
        use Command::*;
        matches!(
            self,
            Apwr | Aprw | Fpwr | Fprw | Bwr | Brw | Lwr | Lrw | Armw | Frmw
        )
    }
}

/// A frame that cannot be parsed, naming what is wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    /// Shorter than the Ethernet and EtherCAT headers.
    #[error("frame of {0} bytes is shorter than the Ethernet and EtherCAT headers")]
    TooShort(usize),
    /// Not EtherType 88A4h.
    #[error("EtherType {0:#06x} is not EtherCAT (0x88a4)")]
    NotEthercat(u16),
    /// The EtherCAT header type is not 1 (datagrams).
    #[error("EtherCAT header type {0} is not 1 (datagrams)")]
    NotDatagrams(u16),
    /// A datagram runs past the end of the frame.
    #[error("datagram {index} at byte {offset} runs past the end of the frame")]
    Truncated {
        /// Position of the datagram in the frame (0-based).
        index: usize,
        /// Its byte offset in the frame.
        offset: usize,
    },
    /// A reserved command code.
    #[error("datagram {index}: reserved command code {code}")]
    UnknownCommand {
        /// Position of the datagram in the frame.
        index: usize,
        /// The code.
        code: u8,
    },
}

/// One datagram's header fields, read from or written to a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DatagramHeader {
    /// The command.
    pub command: Command,
    /// The index the MainDevice uses to match replies.
    pub index: u8,
    /// Address: ADP (position or station address) in the low half, ADO (register) in the high
    /// half; a logical address for Lxx.
    pub address: u32,
    /// Data bytes.
    pub len: u16,
    /// The circulating flag.
    pub circulating: bool,
    /// True if another datagram follows.
    pub more_follows: bool,
}

impl DatagramHeader {
    /// ADP: auto-increment position or configured station address.
    pub const fn adp(&self) -> u16 {
        self.address as u16
    }

    /// ADO: the register (physical memory) offset.
    pub const fn ado(&self) -> u16 {
        (self.address >> 16) as u16
    }

    fn read(buf: &[u8], index: usize) -> Result<DatagramHeader, FrameError> {
        let code = buf[0];
        let command = Command::from_code(code).ok_or(FrameError::UnknownCommand { index, code })?;
        let flags = u16::from_le_bytes([buf[6], buf[7]]);
        Ok(DatagramHeader {
            command,
            index: buf[1],
            address: u32::from_le_bytes([buf[2], buf[3], buf[4], buf[5]]),
            len: flags & LEN_MASK,
            circulating: flags & FLAG_CIRCULATING != 0,
            more_follows: flags & FLAG_MORE_FOLLOWS != 0,
        })
    }

    fn write(&self, buf: &mut [u8]) {
        buf[0] = self.command as u8;
        buf[1] = self.index;
        buf[2..6].copy_from_slice(&self.address.to_le_bytes());
        let mut flags = self.len & LEN_MASK;
        if self.circulating {
            flags |= FLAG_CIRCULATING;
        }
        if self.more_follows {
            flags |= FLAG_MORE_FOLLOWS;
        }
        buf[6..8].copy_from_slice(&flags.to_le_bytes());
        buf[8..10].fill(0);
    }
}

/// Where one datagram sits in a frame: the header, and the byte offsets of its data and WKC.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DatagramSpan {
    /// The parsed header.
    pub header: DatagramHeader,
    /// Offset of the header in the frame.
    pub header_offset: usize,
    /// Offset of the data in the frame.
    pub data_offset: usize,
    /// Offset of the working counter in the frame.
    pub wkc_offset: usize,
}

/// Checks the Ethernet and EtherCAT headers of `frame` and returns the end of the datagrams.
pub fn check_frame(frame: &[u8]) -> Result<usize, FrameError> {
    if frame.len() < ETHERNET_HEADER_LEN + ECAT_HEADER_LEN {
        return Err(FrameError::TooShort(frame.len()));
    }
    let ethertype = u16::from_be_bytes([frame[12], frame[13]]);
    if ethertype != ETHERTYPE {
        return Err(FrameError::NotEthercat(ethertype));
    }
    let h = u16::from_le_bytes([frame[14], frame[15]]);
    if h >> 12 != TYPE_DATAGRAMS {
        return Err(FrameError::NotDatagrams(h >> 12));
    }
    let end = ETHERNET_HEADER_LEN + ECAT_HEADER_LEN + usize::from(h & LEN_MASK);
    Ok(end.min(frame.len()))
}

/// The datagrams of a checked frame, in order; stops at the first malformed one.
pub fn datagrams(frame: &[u8]) -> impl Iterator<Item = Result<DatagramSpan, FrameError>> + '_ {
    let end = check_frame(frame);
    let mut offset = ETHERNET_HEADER_LEN + ECAT_HEADER_LEN;
    let mut index = 0;
    let mut done = false;
    std::iter::from_fn(move || {
        if done {
            return None;
        }
        let end = match end {
            Ok(e) => e,
            Err(e) => {
                done = true;
                return Some(Err(e));
            }
        };
        if offset + DATAGRAM_HEADER_LEN > end {
            done = true;
            return (index == 0).then_some(Err(FrameError::Truncated { index, offset }));
        }
        let header = match DatagramHeader::read(&frame[offset..], index) {
            Ok(h) => h,
            Err(e) => {
                done = true;
                return Some(Err(e));
            }
        };
        let data_offset = offset + DATAGRAM_HEADER_LEN;
        let wkc_offset = data_offset + usize::from(header.len);
        if wkc_offset + WKC_LEN > end {
            done = true;
            return Some(Err(FrameError::Truncated { index, offset }));
        }
        let span = DatagramSpan {
            header,
            header_offset: offset,
            data_offset,
            wkc_offset,
        };
        offset = wkc_offset + WKC_LEN;
        index += 1;
        done = !header.more_follows;
        Some(Ok(span))
    })
}

/// The working counter of a datagram.
pub fn wkc(frame: &[u8], span: &DatagramSpan) -> u16 {
    u16::from_le_bytes([frame[span.wkc_offset], frame[span.wkc_offset + 1]])
}

/// Writes a frame of datagrams into `buf` without allocating: the MainDevice side of the
/// cyclic exchange.
#[derive(Debug)]
pub struct FrameBuilder<'a> {
    buf: &'a mut [u8],
    len: usize,
    last_header: Option<usize>,
}

/// The minimum Ethernet frame without FCS; shorter frames are padded.
pub const MIN_FRAME_LEN: usize = 60;

impl<'a> FrameBuilder<'a> {
    /// Starts a frame from `source` MAC to broadcast in `buf`.
    pub fn new(buf: &'a mut [u8], source: [u8; 6]) -> Self {
        buf[0..6].fill(0xFF);
        buf[6..12].copy_from_slice(&source);
        buf[12..14].copy_from_slice(&ETHERTYPE.to_be_bytes());
        FrameBuilder {
            buf,
            len: ETHERNET_HEADER_LEN + ECAT_HEADER_LEN,
            last_header: None,
        }
    }

    /// Appends a datagram with `data`; returns its span or `None` if the buffer is full.
    pub fn push(
        &mut self,
        command: Command,
        index: u8,
        address: u32,
        data: &[u8],
    ) -> Option<DatagramSpan> {
        let header_offset = self.len;
        let data_offset = header_offset + DATAGRAM_HEADER_LEN;
        let wkc_offset = data_offset + data.len();
        if wkc_offset + WKC_LEN > self.buf.len() || data.len() > usize::from(LEN_MASK) {
            return None;
        }
        if let Some(prev) = self.last_header {
            self.buf[prev + 7] |= (FLAG_MORE_FOLLOWS >> 8) as u8;
        }
        let header = DatagramHeader {
            command,
            index,
            address,
            len: data.len() as u16,
            circulating: false,
            more_follows: false,
        };
        header.write(&mut self.buf[header_offset..]);
        self.buf[data_offset..wkc_offset].copy_from_slice(data);
        self.buf[wkc_offset..wkc_offset + WKC_LEN].fill(0);
        self.len = wkc_offset + WKC_LEN;
        self.last_header = Some(header_offset);
        Some(DatagramSpan {
            header,
            header_offset,
            data_offset,
            wkc_offset,
        })
    }

    /// Writes the EtherCAT header, pads to the minimum frame and returns the frame length.
    pub fn finish(self) -> usize {
        let pdu_len = (self.len - ETHERNET_HEADER_LEN - ECAT_HEADER_LEN) as u16;
        let h = (TYPE_DATAGRAMS << 12) | (pdu_len & LEN_MASK);
        self.buf[14..16].copy_from_slice(&h.to_le_bytes());
        let len = self.len.max(MIN_FRAME_LEN).min(self.buf.len());
        self.buf[self.len..len].fill(0);
        len
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_built_frame_parses_back_with_the_flags_and_offsets() {
        let mut buf = [0u8; 128];
        let mut b = FrameBuilder::new(&mut buf, [0x10; 6]);
        let a = b.push(Command::Fprd, 7, 0x0130_1001, &[0; 2]).unwrap();
        let c = b.push(Command::Lrw, 8, 0, &[1, 2, 3]).unwrap();
        let len = b.finish();
        assert_eq!(len, MIN_FRAME_LEN);
        let spans: Vec<_> = datagrams(&buf[..len]).collect::<Result<_, _>>().unwrap();
        assert_eq!(spans.len(), 2);
        assert!(spans[0].header.more_follows && !spans[1].header.more_follows);
        assert_eq!(spans[0].header.adp(), 0x1001);
        assert_eq!(spans[0].header.ado(), 0x0130);
        assert_eq!(spans[0].data_offset, a.data_offset);
        assert_eq!(spans[1].header.command, Command::Lrw);
        assert_eq!(&buf[c.data_offset..c.data_offset + 3], &[1, 2, 3]);
    }

    #[test]
    fn malformed_frames_name_what_is_wrong() {
        assert_eq!(check_frame(&[0; 10]), Err(FrameError::TooShort(10)));
        let mut buf = [0u8; 64];
        buf[12] = 0x08;
        assert_eq!(check_frame(&buf), Err(FrameError::NotEthercat(0x0800)));
        let mut b = FrameBuilder::new(&mut buf, [0; 6]);
        b.push(Command::Brd, 0, 0, &[0; 4]).unwrap();
        b.finish();
        buf[16] = 0x55;
        let e = datagrams(&buf).next().unwrap().unwrap_err();
        assert_eq!(
            e,
            FrameError::UnknownCommand {
                index: 0,
                code: 0x55
            }
        );
        // A length running past the frame.
        buf[16] = Command::Brd as u8;
        buf[22] = 0xFF;
        buf[23] = 0x07;
        assert!(matches!(
            datagrams(&buf).next().unwrap(),
            Err(FrameError::Truncated { index: 0, .. })
        ));
    }
}
