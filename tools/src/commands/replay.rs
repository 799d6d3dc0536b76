//! `cellrt replay FILE.mcap`: feeds the recorded RxPDO stream (controlword, target position and
//! torque of every axis, cycle by cycle, with the recorded cycle numbers so skipped cycles are
//! skipped again) to the simulated drives of the recorded configuration (the attached
//! configuration file), with the profile axes' objects (6081h, 6083h, 6084h, 6087h) in the
//! RxPDO or written by SDO in the cycle the recording shows them change, and compares the
//! drives' feedback with the recorded feedback. On simulated drives the two are bit-identical;
//! the first divergence is reported with its cycle. MR-JE-C axes are left out of the check,
//! and replay says so.

use std::path::Path;

use cellrt_cia402::bus::{AcyclicBus, BusError, CyclicBus};
use cellrt_cia402::controlword::Controlword;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::pdo::objects::PROFILE_OBJECTS;
use cellrt_cia402::pdo::{PdoError, TxPdo};
use cellrt_cia402::Cycles;
use cellrt_config::CellConfig;
use cellrt_runtime::host::cell_bus::sim_bus;
use cellrt_runtime::host::record::proto::AxisCycle;
use cellrt_runtime::rt::executive::{AxisChannel, CycleCommand};
use cellrt_runtime::rt::injection::InjectionSchedule;

use crate::cli::ReplayArgs;
use crate::exit::Exit;
use cellrt_recording::RecFile;

/// The first difference between recorded and replayed feedback.
#[derive(Debug)]
pub struct Divergence {
    /// Cycle.
    pub cycle: u64,
    /// Axis name.
    pub axis: String,
    /// Field (TxPDO object).
    pub field: &'static str,
    /// Recorded value.
    pub recorded: i64,
    /// Replayed value.
    pub replayed: i64,
}

/// Runs `cellrt replay`.
pub fn run(args: ReplayArgs) -> Exit {
    let bad = |e: String| {
        eprintln!("error: {e}");
        Exit::BadInput
    };
    let file = match RecFile::open(&args.file) {
        Ok(f) => f,
        Err(e) => return bad(e.to_string()),
    };
    let info = match file.cell() {
        Ok(c) => c,
        Err(e) => return bad(e.to_string()),
    };
    let Some((name, text)) = file
        .attachments()
        .into_iter()
        .find(|(n, _)| n.ends_with(".toml"))
    else {
        return bad(format!(
            "{}: no configuration file attached",
            args.file.display()
        ));
    };
    let text = String::from_utf8_lossy(&text).into_owned();
    let cell = match CellConfig::parse(Path::new(&name), &text) {
        Ok(c) => c,
        Err(e) => {
            return bad(format!(
                "{}: the attached configuration does not load: {e}",
                args.file.display()
            ))
        }
    };
    let recs = match file.decode(&info, true) {
        Ok(r) => r,
        Err(e) => return bad(e.to_string()),
    };
    if info.axes.len() != cell.axes.on_loop().len() {
        return bad(format!(
            "{}: metadata names {} axes, the attached configuration {}",
            args.file.display(),
            info.axes.len(),
            cell.axes.on_loop().len()
        ));
    }
    if let Some(note) = je_c_excluded(&cell) {
        println!("{note}");
    }
    match replay(&cell, &recs.axes) {
        Ok((cycles, None)) => {
            println!(
                "replay of {}: {cycles} cycles × {} axes through simulated drives: feedback \
                 bit-identical to the recording",
                args.file.display(),
                cell.axes.on_loop().len()
            );
            Exit::Ok
        }
        Ok((cycles, Some(d))) => {
            println!(
                "replay of {}: DIVERGED at cycle {} (t = {:.3} s), axis {}: {} recorded {}, \
                 replayed {} ({cycles} cycles identical before it)",
                args.file.display(),
                d.cycle,
                d.cycle as f64 * cell.period(),
                d.axis,
                d.field,
                d.recorded,
                d.replayed
            );
            Exit::Failed
        }
        Err(e) => bad(format!("{}: {e}", args.file.display())),
    }
}

/// What replay leaves out: the MR-JE-C axes run beside the RT loop, on a link of their own with
/// the drive's own profile motion, so their recorded exchanges are not a deterministic function
/// of the RxPDO stream.
fn je_c_excluded(cell: &CellConfig) -> Option<String> {
    if cell.axes.on_link().is_empty() {
        return None;
    }
    let names: Vec<String> = cell
        .axes
        .on_link()
        .iter()
        .map(|a| format!("{} ({})", a.name, a.transport.name()))
        .collect();
    Some(format!(
        "replay: MR-JE-C axes {} are NOT replayed and NOT part of the bit-identical check: they \
         run beside the RT loop on their own link, moved by their drives' own profiles",
        names.join(", ")
    ))
}

/// Why a recording cannot be replayed to its end.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The recording has no axis records.
    #[error("no axis records to replay")]
    NoRecords,
    /// The axes' record counts differ.
    #[error("axes have different record counts (records were dropped): cannot replay")]
    CountsDiffer,
    /// The first record is not of cycle 0.
    #[error(
        "the recording starts at cycle {cycle} (a rotated part?): replay needs it from cycle 0"
    )]
    LateStart {
        /// The first recorded cycle.
        cycle: u64,
    },
    /// The records of one index are of different cycles.
    #[error(
        "record {record}: axis {axis} is at cycle {at}, axis {first} at {cycle} (records dropped)"
    )]
    Misaligned {
        /// The record's index.
        record: usize,
        /// The axis out of step.
        axis: String,
        /// Its record's cycle.
        at: u64,
        /// The first axis.
        first: String,
        /// The first axis' record's cycle.
        cycle: u64,
    },
    /// The simulated bus refused the exchange before cycle 0.
    #[error("bus exchange: {0:?}")]
    FirstExchange(BusError),
    /// The simulated bus refused an exchange.
    #[error("bus exchange at cycle {cycle}: {error:?}")]
    Exchange {
        /// The cycle.
        cycle: u64,
        /// Why.
        error: BusError,
    },
    /// An axis' TxPDO image does not decode.
    #[error("axis {axis}: TxPDO: {error:?}")]
    TxPdo {
        /// The axis.
        axis: String,
        /// Why.
        error: PdoError,
    },
    /// An axis' RxPDO image does not encode.
    #[error("axis {axis}: RxPDO: {error:?}")]
    RxPdo {
        /// The axis.
        axis: String,
        /// Why.
        error: PdoError,
    },
    /// A simulated drive aborted the download of a recorded profile object.
    #[error("axis {axis}: {index:04X}h = {value} at cycle {cycle}: SDO abort {abort:08X}h")]
    SdoAbort {
        /// The axis.
        axis: String,
        /// The object.
        index: u16,
        /// The recorded value.
        value: u32,
        /// The cycle.
        cycle: u64,
        /// The abort code.
        abort: u32,
    },
}

/// Replays `axes` (recorded per axis, in cycle order) through the simulated drives of `cell`.
/// Returns the cycles compared and the first divergence, if any.
pub fn replay(
    cell: &CellConfig,
    axes: &[Vec<AxisCycle>],
) -> Result<(u64, Option<Divergence>), ReplayError> {
    let n = axes.first().map(Vec::len).unwrap_or(0);
    if n == 0 {
        return Err(ReplayError::NoRecords);
    }
    if axes.iter().any(|a| a.len() != n) {
        return Err(ReplayError::CountsDiffer);
    }
    if axes[0][0].cycle != 0 {
        return Err(ReplayError::LateStart {
            cycle: axes[0][0].cycle,
        });
    }
    let channels: Vec<AxisChannel> = cell
        .axes
        .on_loop()
        .iter()
        .map(|a| AxisChannel::new(cell, a))
        .collect();
    let mut bus = sim_bus(cell);
    // The bus faults at the cycles the executive applied them (a stall is the loop's own).
    let mut faults = InjectionSchedule::in_process(cell);
    // As Executive::run: one exchange of all-zero outputs before cycle 0.
    bus.exchange(Cycles(1))
        .map_err(ReplayError::FirstExchange)?;
    let mut prev: Option<u64> = None;
    for k in 0..n {
        let cycle = axes[0][k].cycle;
        if let Some(i) = axes.iter().position(|a| a[k].cycle != cycle) {
            return Err(ReplayError::Misaligned {
                record: k,
                axis: cell.axes.on_loop()[i].name.clone(),
                at: axes[i][k].cycle,
                first: cell.axes.on_loop()[0].name.clone(),
                cycle,
            });
        }
        while faults.next_due(cycle, &mut bus).is_some() {}
        for (i, ch) in channels.iter().enumerate() {
            let rec = &axes[i][k];
            let tx = ch
                .tx_map
                .decode_tx(bus.tx_image(i))
                .map_err(|error| ReplayError::TxPdo {
                    axis: cell.axes.on_loop()[i].name.clone(),
                    error,
                })?;
            if let Some((field, recorded, replayed)) = compare(rec, &tx) {
                return Ok((
                    k as u64,
                    Some(Divergence {
                        cycle,
                        axis: cell.axes.on_loop()[i].name.clone(),
                        field,
                        recorded,
                        replayed,
                    }),
                ));
            }
            let mut rx = ch.rx_pdo(&CycleCommand {
                // Recordings made before field 20 existed were csp only.
                mode: if rec.mode == 0 {
                    ModeOfOperation::CyclicSyncPosition.as_i8()
                } else {
                    rec.mode as i8
                },
                controlword: Controlword(rec.controlword as u16),
                target_position: rec.setpoint_counts,
                target_velocity: rec.setpoint_velocity_counts,
                target_torque: rec.setpoint_torque as i16,
                // Recordings made before field 25 existed sent the configured bits only.
                controlword2: if rec.controlword2 == 0 {
                    ch.static_controlword2()
                } else {
                    rec.controlword2 as u16
                },
                counter: rec.counter_sent as u8,
            });
            let profile = profile_objects(rec);
            (
                rx.profile_velocity,
                rx.profile_acceleration,
                rx.profile_deceleration,
                rx.torque_slope,
            ) = (profile[0], profile[1], profile[2], profile[3]);
            // A csp axis the recording may show switched to pp at run time: its pp plan.
            let objects = cell.axes.on_loop()[i]
                .profile_objects
                .or_else(|| cellrt_config::profile_axis::pp_switch(&cell.axes.on_loop()[i]).ok());
            if let Some(objects) = objects {
                let before = k
                    .checked_sub(1)
                    .map_or([0; 4], |p| profile_objects(&axes[i][p]));
                for (n, index) in PROFILE_OBJECTS.into_iter().enumerate() {
                    if profile[n] != before[n] && !objects.is_cyclic(index) {
                        bus.sdo_download(i, index, 0, &profile[n].to_le_bytes())
                            .map_err(|abort| ReplayError::SdoAbort {
                                axis: cell.axes.on_loop()[i].name.clone(),
                                index,
                                value: profile[n],
                                cycle,
                                abort,
                            })?;
                    }
                }
            }
            ch.rx_map
                .encode_rx(&rx, bus.rx_image_mut(i))
                .map_err(|error| ReplayError::RxPdo {
                    axis: cell.axes.on_loop()[i].name.clone(),
                    error,
                })?;
        }
        let elapsed = prev.map(|p| cycle.saturating_sub(p)).unwrap_or(1).max(1);
        prev = Some(cycle);
        bus.exchange(Cycles(elapsed.min(u64::from(u32::MAX)) as u32))
            .map_err(|error| ReplayError::Exchange { cycle, error })?;
    }
    Ok((n as u64, None))
}

/// The profile objects a record holds, in the order of [`PROFILE_OBJECTS`].
fn profile_objects(rec: &AxisCycle) -> [u32; 4] {
    [
        rec.profile_velocity,
        rec.profile_acceleration,
        rec.profile_deceleration,
        rec.torque_slope,
    ]
}

/// The first field of the recorded feedback that differs from `tx`.
fn compare(rec: &AxisCycle, tx: &TxPdo) -> Option<(&'static str, i64, i64)> {
    let pairs: [(&'static str, i64, i64); 7] = [
        (
            "statusword (6041h)",
            i64::from(rec.statusword),
            i64::from(tx.statusword.0),
        ),
        (
            "position actual (6064h)",
            i64::from(rec.actual_position_counts),
            i64::from(tx.position_actual),
        ),
        (
            "velocity actual (606Ch)",
            i64::from(rec.actual_velocity_counts),
            i64::from(tx.velocity_actual),
        ),
        (
            "following error (60F4h)",
            i64::from(rec.following_error_counts),
            i64::from(tx.following_error),
        ),
        (
            "torque actual (6077h)",
            i64::from(rec.actual_torque),
            i64::from(tx.torque_actual),
        ),
        (
            "mode display (6061h)",
            i64::from(rec.mode_display),
            i64::from(tx.mode_display),
        ),
        (
            "error code (603Fh)",
            i64::from(rec.error_code),
            i64::from(tx.error_code),
        ),
    ];
    pairs.into_iter().find(|p| p.1 != p.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_recording_without_records_or_not_from_cycle_0_is_not_replayed() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/demo.toml");
        let cell = CellConfig::parse(&path, &std::fs::read_to_string(&path).unwrap()).unwrap();
        let e = replay(&cell, &[]).unwrap_err();
        assert!(matches!(e, ReplayError::NoRecords), "{e:?}");
        let late = AxisCycle {
            cycle: 5,
            ..AxisCycle::default()
        };
        let axes = vec![vec![late]; cell.axes.on_loop().len()];
        let e = replay(&cell, &axes).unwrap_err();
        assert!(matches!(e, ReplayError::LateStart { cycle: 5 }), "{e:?}");
        assert_eq!(
            e.to_string(),
            "the recording starts at cycle 5 (a rotated part?): replay needs it from cycle 0"
        );
    }
}
