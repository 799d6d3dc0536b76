//! A line of emulated SubDevices that processes EtherCAT frames as a real segment does: each
//! datagram passes every station in order, with auto-increment addresses counted up, working
//! counters added, and the frame returned with the SubDevice bit set in the source MAC.

use super::station::Station;
use crate::ethercat::frame::{self, Command, FrameError, REPLY_SOURCE_MAC_BIT};
use crate::sim::drive::SimDrive;

/// An emulated EtherCAT segment of drives in line topology.
#[derive(Debug)]
pub struct Segment {
    stations: Vec<Station>,
    /// Per station: frames left during which it does not answer (fault injection).
    stalled: Vec<u32>,
    frames: u64,
}

impl Segment {
    /// A segment of `drives` in this order (position 0 next to the master).
    pub fn new(drives: Vec<SimDrive>) -> Self {
        let n = drives.len() as u16;
        let stations = drives
            .into_iter()
            .enumerate()
            .map(|(i, d)| Station::new(d, i as u16, n))
            .collect();
        Segment {
            stalled: vec![0; n as usize],
            stations,
            frames: 0,
        }
    }

    /// The stations in line order.
    pub fn stations(&self) -> &[Station] {
        &self.stations
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

    /// Frames processed.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Processes `frame` in place at local time `now_ns` (all ESC clocks share it). A
    /// malformed frame is returned as an error and left as it is (a real segment would drop
    /// it: the master sees a timeout).
    pub fn process(&mut self, frame: &mut [u8], now_ns: u64) -> Result<(), FrameError> {
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
        for span in spans.iter().take(count).flatten() {
            let h = span.header;
            let mut adp = h.adp();
            let mut wkc = frame::wkc(frame, span);
            let (data, _) = frame[span.data_offset..].split_at_mut(usize::from(h.len));
            let mut rmw_read = false;
            for (st, stalled) in self.stations.iter_mut().zip(&self.stalled) {
                if *stalled > 0 {
                    // Forwarded unprocessed; an auto-increment address still counts it, as
                    // the port logic of a stuck ESC forwards and increments.
                    if matches!(
                        h.command,
                        Command::Aprd
                            | Command::Apwr
                            | Command::Aprw
                            | Command::Armw
                            | Command::Brd
                            | Command::Bwr
                            | Command::Brw
                    ) {
                        adp = adp.wrapping_add(1);
                    }
                    continue;
                }
                let inc = match h.command {
                    Command::Nop => 0,
                    Command::Aprd | Command::Apwr | Command::Aprw => {
                        let hit = adp == 0;
                        adp = adp.wrapping_add(1);
                        if hit {
                            st.physical(h.command, h.ado(), data, now_ns).wkc
                        } else {
                            0
                        }
                    }
                    Command::Fprd | Command::Fpwr | Command::Fprw => {
                        if st.station_address() == adp {
                            st.physical(h.command, h.ado(), data, now_ns).wkc
                        } else {
                            0
                        }
                    }
                    Command::Brd | Command::Bwr | Command::Brw => {
                        adp = adp.wrapping_add(1);
                        st.physical(h.command, h.ado(), data, now_ns).wkc
                    }
                    Command::Lrd | Command::Lwr | Command::Lrw => {
                        st.logical(h.command, h.address, data, now_ns).wkc
                    }
                    Command::Armw | Command::Frmw => {
                        let hit = if h.command == Command::Armw {
                            let hit = adp == 0;
                            adp = adp.wrapping_add(1);
                            hit
                        } else {
                            st.station_address() == adp
                        };
                        if hit && !rmw_read {
                            rmw_read = true;
                            st.physical(h.command, h.ado(), data, now_ns).wkc
                        } else {
                            st.rmw_write(h.ado(), data, now_ns).wkc
                        }
                    }
                };
                wkc = wkc.wrapping_add(inc);
            }
            let a = span.header_offset + 2;
            frame[a..a + 2].copy_from_slice(&adp.to_le_bytes());
            frame[span.wkc_offset..span.wkc_offset + 2].copy_from_slice(&wkc.to_le_bytes());
        }
        frame[6] |= REPLY_SOURCE_MAC_BIT;
        for s in &mut self.stalled {
            *s = s.saturating_sub(1);
        }
        self.frames += 1;
        Ok(())
    }
}
