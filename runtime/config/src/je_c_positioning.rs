//! What a `move` and a `jog` mean on each kind of MR-JE-C axis in a cell (SW A4+, MR-JE-C
//! manual §7.6.3): `mode = "point_table"` with its `[[axes.je_c.point_table]]` (2801h–28FFh,
//! written at start-up), `mode = "indexer"` with `je_c.stations` ([Pr. PT28]; the position unit
//! is the station) and `mode = "jog"`. Their keys are checked with the axis (`je_c_axis`).

use cellrt_fieldbus::mr_je_c::cell::AxisCommand;

use super::je_c_axis::{JecAxisConfig, JecCommandError, JecMode};

/// Where a `move` takes an MR-JE-C axis, by its mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JecMoveTarget {
    /// pp (and pv, tq axes, which move in pp): a position, units.
    Position(f64),
    /// pt: point table `table`, whose position is `position` units.
    PointTable {
        /// 1–255.
        table: u8,
        /// The table's position, units.
        position: f64,
    },
    /// idx: a station (0 … [Pr. PT28] − 1), which is also its position in stations.
    Station(u8),
}

impl JecMoveTarget {
    /// The position the axis ends at, units.
    pub fn end_position(self) -> f64 {
        match self {
            JecMoveTarget::Position(p) => p,
            JecMoveTarget::PointTable { position, .. } => position,
            JecMoveTarget::Station(s) => f64::from(s),
        }
    }
}

impl JecAxisConfig {
    /// What a move to `value` means on this axis, checked: a position within its range (pp,
    /// pv, tq), the number of one of its point tables (pt) or one of its stations (idx); a jog
    /// axis does not move to targets.
    pub fn move_target(&self, value: f64) -> Result<JecMoveTarget, JecCommandError> {
        let axis = || self.name.clone();
        if !value.is_finite() {
            return Err(JecCommandError::TargetNotFinite {
                axis: axis(),
                target: value,
            });
        }
        // One of the numbers `first`…`last` (a table or a station), named `what`.
        let number = |first: u8, last: u8, what: &'static str| {
            if value.fract() == 0.0 && (f64::from(first)..=f64::from(last)).contains(&value) {
                Ok(value as u8)
            } else {
                Err(JecCommandError::NotOneOf {
                    axis: axis(),
                    target: value,
                    what,
                    first,
                    last,
                })
            }
        };
        match self.mode {
            JecMode::Pp | JecMode::Pv | JecMode::Tq => {
                let [lo, hi] = self.position;
                if (lo..=hi).contains(&value) {
                    Ok(JecMoveTarget::Position(value))
                } else {
                    Err(JecCommandError::TargetOutsideRange {
                        axis: axis(),
                        target: value,
                        unit: self.unit.clone(),
                        lo,
                        hi,
                    })
                }
            }
            JecMode::PointTable => {
                // At most MAX_POINT_TABLES (255), checked at load.
                let n = self.point_tables.len() as u8;
                let table = number(1, n, "point tables")?;
                Ok(JecMoveTarget::PointTable {
                    table,
                    position: self.point_tables[usize::from(table) - 1].position,
                })
            }
            JecMode::Indexer { stations } => {
                number(0, stations.saturating_sub(1), "stations").map(JecMoveTarget::Station)
            }
            JecMode::Jog => Err(JecCommandError::JogAxisHasNoTargets { axis: axis() }),
        }
    }

    /// The command of a move to `target` at `velocity` unit/s and `acceleration` unit/s² (a
    /// point table runs at its own).
    pub fn move_command(
        &self,
        target: JecMoveTarget,
        velocity: f64,
        acceleration: f64,
    ) -> AxisCommand {
        let ramp = self.ramp_ms(acceleration);
        let speed = self
            .drive_speed(velocity)
            .unsigned_abs()
            .min(u64::from(u32::MAX)) as u32;
        match target {
            JecMoveTarget::Position(p) => AxisCommand::Move {
                target: self.counts(p),
                velocity: speed,
                acceleration_ms: ramp,
                deceleration_ms: ramp,
            },
            JecMoveTarget::PointTable { table, .. } => AxisCommand::PointTable {
                table: i16::from(table),
            },
            JecMoveTarget::Station(station) => AxisCommand::Station {
                station: i16::from(station),
                velocity: speed,
                acceleration_ms: ramp,
                deceleration_ms: ramp,
            },
        }
    }

    /// The speed (unit/s) and the lower of the accelerations (unit/s²) a move to `target`
    /// runs at: a point table's own, else `velocity` and `acceleration`.
    pub fn profile_of(
        &self,
        target: JecMoveTarget,
        velocity: f64,
        acceleration: f64,
    ) -> (f64, f64) {
        match target {
            JecMoveTarget::PointTable { table, .. } => {
                let t = &self.point_tables[usize::from(table) - 1];
                (t.velocity, t.acceleration.min(t.deceleration))
            }
            _ => (velocity, acceleration),
        }
    }

    /// What MC_Stop sends the axis: Halt on the drive's ramp, or a quick stop on an indexer
    /// axis, whose Halt bit is disabled (MR-JE-C manual §7.6.3).
    pub fn stop_command(&self) -> AxisCommand {
        match self.mode {
            JecMode::Indexer { .. } => AxisCommand::QuickStop,
            _ => AxisCommand::Halt,
        }
    }

    /// Whether a move's own velocity and acceleration apply (not to point tables, which run
    /// at their own).
    pub fn takes_move_limits(&self) -> bool {
        self.mode != JecMode::PointTable
    }

    /// The command of a jog at `velocity` unit/s with `acceleration` unit/s²: jg on a jog or
    /// point-table axis (Table 2.3 has no 60FFh), pv otherwise; an indexer axis does not jog.
    pub fn jog_command(
        &self,
        velocity: f64,
        acceleration: f64,
    ) -> Result<AxisCommand, JecCommandError> {
        let ramp = self.ramp_ms(acceleration);
        let speed = self.drive_speed(velocity);
        match self.mode {
            JecMode::Jog | JecMode::PointTable => Ok(AxisCommand::Jog {
                velocity: speed.unsigned_abs().min(u64::from(u32::MAX)) as u32,
                reverse: speed < 0,
                acceleration_ms: ramp,
                deceleration_ms: ramp,
            }),
            JecMode::Indexer { .. } => Err(JecCommandError::IndexerDoesNotJog {
                axis: self.name.clone(),
            }),
            JecMode::Pp | JecMode::Pv | JecMode::Tq => Ok(AxisCommand::Velocity {
                velocity: speed.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32,
                acceleration_ms: ramp,
                deceleration_ms: ramp,
            }),
        }
    }

    /// The point tables (2801h + n − 1, subs 1–4 and 7) and [Pr. PT28] the drive gets at
    /// start-up.
    pub fn positioning_parameters(
        &self,
    ) -> Vec<(
        cellrt_fieldbus::mr_je_c::ObjectId,
        cellrt_fieldbus::mr_je_c::Value,
    )> {
        use cellrt_fieldbus::mr_je_c::{ObjectId, Value};
        let mut out = Vec::new();
        for (k, t) in self.point_tables.iter().enumerate() {
            let index = 0x2801 + k as u16;
            let speed = self.drive_speed(t.velocity).clamp(0, i64::from(i32::MAX)) as i32;
            for (sub, v) in [
                (1, self.counts(t.position)),
                (2, speed),
                (3, self.ramp_ms(t.acceleration) as i32),
                (4, self.ramp_ms(t.deceleration) as i32),
                (7, i32::from(t.m_code)),
            ] {
                out.push((ObjectId::new(index, sub), Value::I32(v)));
            }
        }
        if let JecMode::Indexer { stations } = self.mode {
            let pt28 = cellrt_fieldbus::mr_je_c::parameters::PT28.index();
            out.push((ObjectId::new(pt28, 0), Value::U32(u32::from(stations))));
        }
        out
    }
}
