//! A line of emulated SubDevices that processes EtherCAT frames as a real segment does: each
//! datagram passes every station in order, with auto-increment addresses counted up, working
//! counters added, and the frame returned with the SubDevice bit set in the source MAC.
//!
//! Fault injection on the wire (each for a number of frames): a stalled SubDevice, a bit error
//! on a link segment (CRC error: the stations behind it do not process the frame and count it
//! in their RX error counters, the master's NIC discards it), a dropped logical datagram, and
//! a lost link (DL status, the port before it loops back).

use super::station::{Station, UnitError};
use crate::sim::drive::SimDrive;
use cellrt_ethercat::frame::{self, Command, FrameError, REPLY_SOURCE_MAC_BIT};

/// What became of a frame on the segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[must_use]
pub enum Delivery {
    /// It came back to the master.
    Returned,
    /// It did not (a CRC error the master's NIC discards, or the master's own link down).
    Lost,
}

/// An emulated EtherCAT segment of drives in line topology.
#[derive(Debug)]
pub struct Segment {
    stations: Vec<Station>,
    /// Per station: frames left during which it does not answer (fault injection).
    stalled: Vec<u32>,
    /// Per station: frames left during which the link segment in front of it (from the master
    /// or the previous station) corrupts every frame (fault injection).
    corrupt: Vec<u32>,
    /// Per station: frames left during which the link in front of it is down.
    link_down: Vec<u32>,
    /// Frames left whose logical datagrams are removed (fault injection).
    datagram_drop: u32,
    frames: u64,
}

impl Segment {
    /// A segment of `drives` in this order (position 0 next to the master); identical plants
    /// share one cycle map, as on a [`crate::sim_bus::SimBus`].
    pub fn new(mut drives: Vec<SimDrive>) -> Self {
        let mut maps = crate::sim::plant::CycleMapPool::default();
        drives.iter_mut().for_each(|d| d.share_cycle_map(&mut maps));
        let n = drives.len() as u16;
        let stations = drives
            .into_iter()
            .enumerate()
            .map(|(i, d)| Station::new(d, i as u16, n))
            .collect();
        Self::of_stations(stations)
    }

    /// A segment of stations in this order, each presenting the drives of one unit (one drive
    /// for a 1-axis drive; every axis, in slot order, of a multi-axis unit: [`Station::unit`]).
    pub fn of_units(mut units: Vec<Vec<SimDrive>>) -> Result<Self, UnitError> {
        let mut maps = crate::sim::plant::CycleMapPool::default();
        units
            .iter_mut()
            .flatten()
            .for_each(|d| d.share_cycle_map(&mut maps));
        let n = units.len() as u16;
        let stations = units
            .into_iter()
            .enumerate()
            .map(|(i, drives)| Station::unit(drives, i as u16, n))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self::of_stations(stations))
    }

    fn of_stations(stations: Vec<Station>) -> Self {
        let n = stations.len();
        Segment {
            stalled: vec![0; n],
            corrupt: vec![0; n],
            link_down: vec![0; n],
            datagram_drop: 0,
            stations,
            frames: 0,
        }
    }

    /// The stations in line order.
    pub fn stations(&self) -> &[Station] {
        &self.stations
    }

    /// The master's host stalled for `cycles` cycles before its next frame: on an in-process
    /// segment the drives run on the master's clock, so (like `transport = "sim"`) that time
    /// passes for them without counting lost frames. Frames lost on the wire still count.
    pub fn excuse_host_stall(&mut self, cycles: u64) {
        for st in &mut self.stations {
            st.excuse_host_stall(cycles);
        }
    }

    /// Station `n` presents ESI `device`'s object dictionary and access rights
    /// ([`Station::describe_by`]); false if there is no such station.
    pub fn describe_station(
        &mut self,
        n: usize,
        device: std::sync::Arc<cellrt_ethercat::esi::EsiDevice>,
    ) -> bool {
        self.stations
            .get_mut(n)
            .map(|st| st.describe_by(device))
            .is_some()
    }

    /// Station `n`, mutably (fault injection).
    pub fn station_mut(&mut self, n: usize) -> Option<&mut Station> {
        self.stations.get_mut(n)
    }

    /// Fault injection: station `n` does not answer the next `frames` frames (it forwards
    /// them untouched: no data, no working counter, its drive sees no SYNC0 data). False if
    /// there is no such station.
    pub fn stall(&mut self, n: usize, frames: u32) -> bool {
        match self.stalled.get_mut(n) {
            Some(s) => {
                *s = frames;
                true
            }
            None => false,
        }
    }

    /// Fault injection: the link segment in front of station `n` (from the master for 0)
    /// corrupts the next `frames` frames (a bit error: the frame's CRC is wrong). The stations
    /// before it process the frame; station `n` and those after it do not, and count it in
    /// their RX error counters ([`Station::rx_error`]); the master's NIC discards it. False if
    /// there is no such station.
    pub fn corrupt(&mut self, n: usize, frames: u32) -> bool {
        match self.corrupt.get_mut(n) {
            Some(c) => {
                *c = frames;
                true
            }
            None => false,
        }
    }

    /// Fault injection: the link in front of station `n` (from the master for 0) is down for
    /// the next `frames` frames: DL status shows it on both ends, the station before it closes
    /// its port 1 and returns frames from there (without the working counter of the stations
    /// behind the link); with `n` = 0 no frame returns. The link comes back after them. False
    /// if there is no such station.
    pub fn lose_link(&mut self, n: usize, frames: u32) -> bool {
        if n >= self.link_down.len() {
            return false;
        }
        self.link_down[n] = frames;
        self.set_link(n, frames == 0);
        true
    }

    /// Fault injection: the logical datagrams (the cyclic LRW) of the next `frames` frames are
    /// removed: no station processes them, their working counter returns unchanged; the
    /// frames themselves return.
    pub fn drop_datagrams(&mut self, frames: u32) {
        self.datagram_drop = frames;
    }

    /// Frames left whose logical datagrams are removed ([`Segment::drop_datagrams`]).
    pub fn dropping_datagrams(&self) -> u32 {
        self.datagram_drop
    }

    /// The link in front of station `n` goes up or down at both of its ends.
    fn set_link(&mut self, n: usize, up: bool) {
        if let Some(st) = self.stations.get_mut(n) {
            st.set_link(0, up);
        }
        if let Some(prev) = n.checked_sub(1).and_then(|p| self.stations.get_mut(p)) {
            prev.set_link(1, up);
        }
    }

    /// Frames processed.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Processes `frame` in place at local time `now_ns` (all ESC clocks share it) and says
    /// whether it returns to the master. A malformed frame is returned as an error and left
    /// as it is (a real segment would drop it: the master sees a timeout).
    pub fn process(&mut self, frame: &mut [u8], now_ns: u64) -> Result<Delivery, FrameError> {
        let mut spans = [None; 64];
        let mut count = 0;
        for span in frame::datagrams(frame) {
            let span = span?;
            if count == spans.len() {
                break;
            }
            spans[count] = Some(span);
            count += 1;
        }
        let n = self.stations.len();
        // How far the frame gets: up to the first link that is down, and the first link
        // segment that corrupts it (the stations behind see a CRC error, not a frame to
        // process).
        let cut = self.link_down.iter().position(|&f| f > 0).unwrap_or(n);
        let bad = self.corrupt[..cut].iter().position(|&f| f > 0);
        let reach = bad.unwrap_or(cut);
        let drop_logical = self.datagram_drop > 0;
        for span in spans.iter().take(count).flatten() {
            let h = span.header;
            if drop_logical && matches!(h.command, Command::Lrd | Command::Lwr | Command::Lrw) {
                continue;
            }
            let mut adp = h.adp();
            let mut wkc = frame::wkc(frame, span);
            let (data, _) = frame[span.data_offset..].split_at_mut(usize::from(h.len));
            let mut rmw_read = false;
            for (st, stalled) in self.stations.iter_mut().zip(&self.stalled).take(reach) {
                if *stalled > 0 {
                    // Forwarded unprocessed; an auto-increment address still counts it, as
                    // the port logic of a stuck ESC forwards and increments.
                    if increments_position(h.command) {
                        adp = adp.wrapping_add(1);
                    }
                    continue;
                }
                let inc = datagram_at_station(st, &h, &mut adp, data, now_ns, &mut rmw_read);
                wkc = wkc.wrapping_add(inc);
            }
            let a = span.header_offset + 2;
            frame[a..a + 2].copy_from_slice(&adp.to_le_bytes());
            frame[span.wkc_offset..span.wkc_offset + 2].copy_from_slice(&wkc.to_le_bytes());
        }
        if let Some(k) = bad {
            self.count_crc_errors(k, cut);
        }
        frame[6] |= REPLY_SOURCE_MAC_BIT;
        self.age_wire_faults();
        self.frames += 1;
        Ok(if bad.is_some() || cut == 0 {
            Delivery::Lost
        } else {
            Delivery::Returned
        })
    }

    /// A frame corrupted in front of station `k` runs on to the end of the reachable line
    /// (`cut`) and back: the station behind the bad link detects the CRC error and marks the
    /// frame, the others count the marked frame on the port it arrives at (port 0 on the way
    /// out, port 1 on the way back for every station with a station behind it).
    fn count_crc_errors(&mut self, k: usize, cut: usize) {
        for (i, st) in self.stations.iter_mut().enumerate().take(cut) {
            if i >= k {
                st.rx_error(0, i == k);
            }
            if i + 1 < cut {
                st.rx_error(1, false);
            }
        }
    }

    /// One frame has passed: every injected wire fault has one frame less to go; a link
    /// whose loss has run out comes back.
    fn age_wire_faults(&mut self) {
        for s in self.stalled.iter_mut().chain(&mut self.corrupt) {
            *s = s.saturating_sub(1);
        }
        self.datagram_drop = self.datagram_drop.saturating_sub(1);
        for i in 0..self.stations.len() {
            if self.link_down[i] > 0 {
                self.link_down[i] -= 1;
                if self.link_down[i] == 0 {
                    self.set_link(i, true);
                }
            }
        }
    }
}

/// True for the commands whose position address every station increments as the frame passes
/// (auto-increment and broadcast; ETG.1000.4 §5.4.1).
fn increments_position(command: Command) -> bool {
    matches!(
        command,
        Command::Aprd
            | Command::Apwr
            | Command::Aprw
            | Command::Armw
            | Command::Brd
            | Command::Bwr
            | Command::Brw
    )
}

/// Datagram `h` (its `data`) at station `st`: the working-counter increment. `adp` moves on
/// by the addressing rule; `rmw_read` marks that the read side of an xRMW has happened.
fn datagram_at_station(
    st: &mut Station,
    h: &frame::DatagramHeader,
    adp: &mut u16,
    data: &mut [u8],
    now_ns: u64,
    rmw_read: &mut bool,
) -> u16 {
    match h.command {
        Command::Nop => 0,
        Command::Aprd | Command::Apwr | Command::Aprw => {
            let hit = *adp == 0;
            *adp = adp.wrapping_add(1);
            if hit {
                st.physical(h.command, h.ado(), data, now_ns).wkc
            } else {
                0
            }
        }
        Command::Fprd | Command::Fpwr | Command::Fprw => {
            if st.station_address() == *adp {
                st.physical(h.command, h.ado(), data, now_ns).wkc
            } else {
                0
            }
        }
        Command::Brd | Command::Bwr | Command::Brw => {
            *adp = adp.wrapping_add(1);
            st.physical(h.command, h.ado(), data, now_ns).wkc
        }
        Command::Lrd | Command::Lwr | Command::Lrw => {
            st.logical(h.command, h.address, data, now_ns).wkc
        }
        Command::Armw | Command::Frmw => {
            let hit = if h.command == Command::Armw {
                let hit = *adp == 0;
                *adp = adp.wrapping_add(1);
                hit
            } else {
                st.station_address() == *adp
            };
            if hit && !*rmw_read {
                *rmw_read = true;
                st.physical(h.command, h.ado(), data, now_ns).wkc
            } else {
                st.rmw_write(h.ado(), data, now_ns).wkc
            }
        }
    }
}
