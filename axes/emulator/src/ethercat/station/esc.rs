//! The ESC's address space of an emulated station: datagram access to registers and process
//! RAM with the side effects of SII control, the DC receive-time latch, the SyncManagers and
//! the port links.

use super::{Access, Station, HOP_DELAY_NS, MEMORY_LEN, SII_READ, SII_READ_8, SM_FULL};
use cellrt_ethercat::frame::Command;
use cellrt_ethercat::register as reg;

impl Station {
    /// The byte at register `addr` of the ESC address space (0 outside it).
    pub fn register(&self, addr: u16) -> u8 {
        self.mem.get(usize::from(addr)).copied().unwrap_or(0)
    }

    /// The little-endian word at register `addr` (e.g. [`reg::DL_STATUS`]).
    pub fn register16(&self, addr: u16) -> u16 {
        u16::from_le_bytes([self.register(addr), self.register(addr.wrapping_add(1))])
    }

    /// A frame with a CRC error reached `port` (0 or 1): the first ESC to see the error counts
    /// it in its invalid frame counter (0300h + 2·port) and marks the frame; the following
    /// ones count the marked frame in their forwarded RX error counter (0308h + port). The
    /// frame is not processed. Counters saturate at FFh.
    pub fn rx_error(&mut self, port: u8, first: bool) {
        let at = if first {
            reg::RX_ERROR_COUNTER + 2 * u16::from(port)
        } else {
            reg::FORWARDED_RX_ERROR_COUNTER + u16::from(port)
        };
        let b = &mut self.mem[usize::from(at)];
        *b = b.saturating_add(1);
    }

    /// The physical link on `port` (0 or 1) goes down or comes back: DL status link and
    /// communication bits; port 1 closes (loops back) while its link is down, as in the ESC's
    /// auto loop mode. A link going down counts in the lost link counter (0310h + port).
    pub fn set_link(&mut self, port: u8, up: bool) {
        let (link, comm) = if port == 0 {
            (reg::DL_LINK_PORT0, reg::DL_COMM_PORT0)
        } else {
            (reg::DL_LINK_PORT1, reg::DL_COMM_PORT1)
        };
        let mut dl = self.get16(reg::DL_STATUS);
        if up {
            dl |= link | comm;
            if port == 1 {
                dl &= !reg::DL_LOOP_PORT1;
            }
        } else {
            if dl & link != 0 {
                let b = &mut self.mem[usize::from(reg::LOST_LINK_COUNTER + u16::from(port))];
                *b = b.saturating_add(1);
            }
            dl &= !(link | comm);
            if port == 1 {
                dl |= reg::DL_LOOP_PORT1;
            }
        }
        self.put16(reg::DL_STATUS, dl);
    }

    pub(super) fn get16(&self, at: u16) -> u16 {
        let a = usize::from(at);
        u16::from_le_bytes([self.mem[a], self.mem[a + 1]])
    }

    pub(super) fn put16(&mut self, at: u16, v: u16) {
        let a = usize::from(at);
        self.mem[a..a + 2].copy_from_slice(&v.to_le_bytes());
    }

    pub(super) fn get_u64(&self, at: u16) -> u64 {
        let a = usize::from(at);
        let mut b = [0u8; 8];
        b.copy_from_slice(&self.mem[a..a + 8]);
        u64::from_le_bytes(b)
    }

    pub(super) fn put_u64(&mut self, at: u16, v: u64) {
        let a = usize::from(at);
        self.mem[a..a + 8].copy_from_slice(&v.to_le_bytes());
    }

    /// Handles a physical-address datagram (APxx/FPxx/Bxx, and the addressed side of xRMW)
    /// on `data` at register `ado` at local time `now_ns`.
    pub fn physical(&mut self, command: Command, ado: u16, data: &mut [u8], now_ns: u64) -> Access {
        let start = usize::from(ado);
        let end = start + data.len();
        if end > MEMORY_LEN {
            return Access::default();
        }
        let mut wkc = 0;
        self.tick(now_ns);
        self.check_pd_watchdog(now_ns);
        if command.reads() {
            self.refresh_for_read(start, end, now_ns);
            if command == Command::Brd || command == Command::Brw {
                for (d, m) in data.iter_mut().zip(&self.mem[start..end]) {
                    *d |= *m;
                }
            } else {
                data.copy_from_slice(&self.mem[start..end]);
            }
            self.after_read(start, end);
            wkc += 1;
        }
        if command.writes() && !matches!(command, Command::Armw | Command::Frmw) {
            self.write(start, data, now_ns);
            wkc += if command.reads() { 2 } else { 1 };
        }
        Access { wkc }
    }

    /// The writing side of ARMW/FRMW (every station but the addressed one).
    pub fn rmw_write(&mut self, ado: u16, data: &[u8], now_ns: u64) -> Access {
        let start = usize::from(ado);
        if start + data.len() > MEMORY_LEN {
            return Access::default();
        }
        self.write(start, data, now_ns);
        Access { wkc: 1 }
    }

    /// Registers whose value is computed at read time: the DC system time.
    pub(super) fn refresh_for_read(&mut self, start: usize, end: usize, now_ns: u64) {
        let sys = usize::from(reg::DC_SYSTEM_TIME);
        if start < sys + 8 && end > sys {
            let offset = self.get_u64(reg::DC_SYSTEM_TIME_OFFSET);
            self.put_u64(reg::DC_SYSTEM_TIME, now_ns.wrapping_add(offset));
        }
    }

    /// Reading the last byte of the SubDevice→master mailbox empties it.
    pub(super) fn after_read(&mut self, start: usize, end: usize) {
        let mb = self.layout.mailbox_in;
        let last = usize::from(mb.start + mb.len - 1);
        if self.sm_enabled(1) && start <= last && end > last {
            self.mem[usize::from(reg::sync_manager(1)) + 5] &= !SM_FULL;
            self.fill_mailbox_in();
        }
    }

    pub(super) fn sm_enabled(&self, n: u8) -> bool {
        self.mem[usize::from(reg::sync_manager(n)) + 6] & 1 != 0
    }

    pub(super) fn writable(addr: usize) -> bool {
        let sm_end = usize::from(reg::sync_manager(16));
        match addr {
            0x0010..=0x0013 | 0x0120..=0x0121 | 0x0400..=0x0443 | 0x0500..=0x050F => true,
            0x0600..=0x06FF => true,
            a if (usize::from(reg::SM_BASE)..sm_end).contains(&a) => (a - 0x800) % 8 != 5,
            0x0900..=0x09FF => !(0x0910..0x0918).contains(&addr),
            a => a >= usize::from(reg::PROCESS_RAM) && a < MEMORY_LEN,
        }
    }

    pub(super) fn write(&mut self, start: usize, data: &[u8], now_ns: u64) {
        for (i, &b) in data.iter().enumerate() {
            if Self::writable(start + i) {
                self.mem[start + i] = b;
            }
        }
        let end = start + data.len();
        let touches = |r: u16, n: usize| start < usize::from(r) + n && end > usize::from(r);
        if touches(reg::RX_ERROR_COUNTER, 0x14) {
            // Writing any error counter clears them all (0300h–0313h).
            let a = usize::from(reg::RX_ERROR_COUNTER);
            self.mem[a..a + 0x14].fill(0);
        }
        if touches(reg::AL_CONTROL, 1) {
            self.al_control(self.mem[usize::from(reg::AL_CONTROL)], now_ns);
        }
        if touches(reg::SII_CONTROL, 2) {
            self.sii_command();
        }
        if touches(reg::DC_TIME_PORT0, 1) {
            self.latch_receive_times(now_ns);
        }
        let mb = self.layout.mailbox_out;
        let last = usize::from(mb.start + mb.len - 1);
        if self.sm_enabled(0) && start <= last && end > last {
            self.mailbox_request();
        }
    }

    pub(super) fn sii_command(&mut self) {
        let control = self.get16(reg::SII_CONTROL);
        if control & SII_READ != 0 {
            let word = usize::from(self.get16(reg::SII_ADDRESS));
            let mut data = [0u8; 8];
            for (i, d) in data.iter_mut().enumerate() {
                *d = self.sii.get(2 * word + i).copied().unwrap_or(0xFF);
            }
            let a = usize::from(reg::SII_DATA);
            self.mem[a..a + 8].copy_from_slice(&data);
        }
        // Not busy, no errors, 8-byte reads; write and reload requests are ignored (the image
        // is generated from the profile and read-only).
        self.put16(reg::SII_CONTROL, SII_READ_8);
    }

    pub(super) fn latch_receive_times(&mut self, now_ns: u64) {
        let p = u64::from(self.position);
        let n = u64::from(self.line_len);
        let port0 = now_ns + p * HOP_DELAY_NS;
        let port1 = if p + 1 < n {
            now_ns + (2 * n - 2 - p) * HOP_DELAY_NS
        } else {
            0
        };
        let a = usize::from(reg::DC_TIME_PORT0);
        self.mem[a..a + 4].copy_from_slice(&(port0 as u32).to_le_bytes());
        self.mem[a + 4..a + 8].copy_from_slice(&(port1 as u32).to_le_bytes());
        self.mem[a + 8..a + 16].fill(0);
        self.put_u64(reg::DC_RECEIVE_TIME, port0);
    }

    /// True if SyncManager `n` is enabled with exactly `area`'s start and length.
    pub(super) fn sm_matches(&self, n: u8, start: u16, len: u16) -> bool {
        let r = reg::sync_manager(n);
        self.sm_enabled(n) && self.get16(r) == start && self.get16(r + 2) == len
    }
}
