//! `bus_diag`: the EtherCAT segment's diagnostics on a running cell (per SubDevice its links,
//! ESC error counters, AL status and DC time difference; the master's frame counters), read
//! by the mailbox worker off the RT thread. The service thread never waits for it: the request
//! starts a reading, a later pass answers the client.

use std::time::{Duration, Instant};

use cellrt_ethercat::master::SegmentDiag;
use serde::{Deserialize, Serialize};

use crate::host::link::CellLink;
use cellrt_config::CellConfig;

/// How long a reading may take (the worker's frames ride one per cycle after the cyclic one).
pub const READING_TIMEOUT: Duration = Duration::from_secs(3);

/// The answer to `bus_diag`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct BusDiagReply {
    /// Per SubDevice (line order): the drive model and the axes it carries.
    pub stations: Vec<StationName>,
    /// The reading.
    pub segment: SegmentDiag,
}

/// What a SubDevice is in the cell's config.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct StationName {
    /// Drive model.
    pub model: String,
    /// Its axes, slot order.
    pub axes: Vec<String>,
}

/// Why a `bus_diag` request gets no reading.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BusDiagError {
    /// The cell runs no EtherCAT segment.
    #[error("bus_diag: this cell has no EtherCAT segment (its axes are simulated drives)")]
    NoSegment,
    /// Another client's reading is being taken.
    #[error("bus_diag: a reading is in progress; try again")]
    InProgress,
    /// The mailbox worker did not answer in time.
    #[error("bus_diag: the mailbox worker took no reading within {} s", .timeout.as_secs())]
    NoReading {
        /// How long the service waited.
        timeout: Duration,
    },
}

/// The reading in progress.
#[derive(Debug, Default)]
pub struct DiagInFlight {
    started: Option<Instant>,
}

impl DiagInFlight {
    /// Asks the mailbox worker for a reading.
    pub fn start(&mut self, link: &dyn CellLink) -> Result<(), BusDiagError> {
        let Some(d) = link.bus_diagnostics() else {
            return Err(BusDiagError::NoSegment);
        };
        if self.started.is_some() {
            return Err(BusDiagError::InProgress);
        }
        d.request();
        self.started = Some(Instant::now());
        Ok(())
    }

    /// The reading once taken, or the timeout; `None` while it is being taken (or none is).
    pub fn poll(
        &mut self,
        link: &dyn CellLink,
        cell: &CellConfig,
    ) -> Option<Result<BusDiagReply, BusDiagError>> {
        let started = self.started?;
        if let Some(segment) = link.bus_diagnostics().and_then(|d| d.take()) {
            self.started = None;
            return Some(Ok(BusDiagReply {
                stations: stations(cell),
                segment,
            }));
        }
        if started.elapsed() < READING_TIMEOUT {
            return None;
        }
        self.started = None;
        Some(Err(BusDiagError::NoReading {
            timeout: READING_TIMEOUT,
        }))
    }
}

/// The SubDevices the cell's axes make, as the segment was planned.
fn stations(cell: &CellConfig) -> Vec<StationName> {
    let config = crate::host::cell_bus::segment_config(cell);
    config
        .stations()
        .unwrap_or_default()
        .iter()
        .map(|s| StationName {
            model: config.drives[s.first_axis()]
                .profile
                .model
                .as_str()
                .to_string(),
            axes: s
                .slots
                .iter()
                .flatten()
                .map(|&a| config.drives[a].axis.clone())
                .collect(),
        })
        .collect()
}
