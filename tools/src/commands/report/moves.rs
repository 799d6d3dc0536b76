//! The report's per-move table: for each motion the planner ran and each axis it moved, the
//! travel, the peak speed and following error, and how long the axis took to settle on its
//! target once the last setpoint was sent.

use cellrt_runtime::host::record::proto::{AxisCycle, Event};

/// One motion of one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct MoveRow {
    /// The motion's id (`motion_started` events).
    pub motion: i64,
    /// The axis' index in the recording.
    pub axis: usize,
    /// The cycle the motion started.
    pub start_cycle: u64,
    /// Cycles from the start to the motion's last setpoint (`motion_finished`).
    pub duration_cycles: u64,
    /// Final setpoint − setpoint at the start, axis units.
    pub travel: f64,
    /// Largest |setpoint velocity|, axis units/s.
    pub peak_velocity: f64,
    /// Largest |following error| from the start until settled (or the next motion), units.
    pub peak_following_error: f64,
    /// Cycles from the last setpoint until |actual − final setpoint| stayed within the band;
    /// `None` where it did not before the next motion or the end of the recording.
    pub settling_cycles: Option<u64>,
}

/// The motions of a recording: (id, start cycle, finish cycle) from its `motion_started` and
/// `motion_finished` events, a motion without its finish ending at the next start or at `end`.
fn motions(events: &[Event], end: u64) -> Vec<(i64, u64, u64)> {
    let mut out: Vec<(i64, u64, u64)> = Vec::new();
    for e in events {
        match e.kind.as_str() {
            "motion_started" => {
                if let Some(open) = out.last_mut().filter(|m| m.2 == u64::MAX) {
                    open.2 = e.cycle;
                }
                out.push((e.value, e.cycle, u64::MAX));
            }
            "motion_finished" => {
                if let Some(open) = out
                    .iter_mut()
                    .rev()
                    .find(|m| m.0 == e.value && m.2 == u64::MAX)
                {
                    open.2 = e.cycle;
                }
            }
            _ => {}
        }
    }
    for m in &mut out {
        m.2 = m.2.min(end);
    }
    out
}

/// The per-move rows of `axes` (each one's samples in cycle order), with `band` the settling
/// band per axis in its units. An axis whose setpoint did not change in a motion has no row.
pub fn move_table(events: &[Event], axes: &[&[AxisCycle]], band: &[f64]) -> Vec<MoveRow> {
    let end = axes
        .iter()
        .filter_map(|s| s.last().map(|a| a.cycle))
        .max()
        .unwrap_or(0);
    let motions = motions(events, end);
    let mut rows = Vec::new();
    for (k, &(id, start, finish)) in motions.iter().enumerate() {
        // The window in which the axis may settle: until the next motion starts.
        let until = motions.get(k + 1).map_or(end, |m| m.1);
        for (axis, s) in axes.iter().enumerate() {
            let span = |from: u64, to: u64| {
                let i = s.partition_point(|a| a.cycle < from);
                let j = s.partition_point(|a| a.cycle <= to);
                &s[i..j.max(i)]
            };
            let moving = span(start, finish);
            let (Some(first), Some(last)) = (moving.first(), moving.last()) else {
                continue;
            };
            let target = last.setpoint_position;
            let travel = target - first.setpoint_position;
            let peak_velocity = moving
                .iter()
                .map(|a| a.setpoint_velocity.abs())
                .fold(0.0, f64::max);
            if travel.abs() < 1e-12 && peak_velocity < 1e-12 {
                continue;
            }
            let band = band.get(axis).copied().unwrap_or(0.0);
            let after = span(finish, until);
            // The first sample from which every later one of the window is within the band.
            let outside = after
                .iter()
                .rposition(|a| (a.actual_position - target).abs() > band);
            let settled_at = match outside {
                None => after.first(),
                Some(i) => after.get(i + 1),
            }
            .map(|a| a.cycle);
            let fe_until = settled_at.unwrap_or(until);
            let peak_following_error = span(start, fe_until)
                .iter()
                .map(|a| a.following_error.abs())
                .fold(0.0, f64::max);
            rows.push(MoveRow {
                motion: id,
                axis,
                start_cycle: start,
                duration_cycles: finish.saturating_sub(start),
                travel,
                peak_velocity,
                peak_following_error,
                settling_cycles: settled_at.map(|c| c.saturating_sub(finish)),
            });
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    fn event(kind: &str, cycle: u64, value: i64) -> Event {
        Event {
            cycle,
            kind: kind.into(),
            value,
            ..Event::default()
        }
    }

    /// An axis ramping 0 → 10 over cycles 10..=20, its actual lagging by `lag` cycles' travel
    /// and reaching the target `lag` cycles after the last setpoint.
    fn ramp(lag: u64) -> Vec<AxisCycle> {
        (0..60u64)
            .map(|c| {
                let sp = |c: u64| (c.clamp(10, 20) - 10) as f64;
                let actual = sp(c.saturating_sub(lag));
                AxisCycle {
                    cycle: c,
                    setpoint_position: sp(c),
                    setpoint_velocity: if (10..20).contains(&c) { 1000.0 } else { 0.0 },
                    actual_position: actual,
                    following_error: sp(c) - actual,
                    ..AxisCycle::default()
                }
            })
            .collect()
    }

    #[test]
    fn a_move_reports_its_travel_peaks_and_the_cycles_it_took_to_settle() {
        let events = [
            event("motion_started", 10, 1),
            event("motion_finished", 20, 1),
        ];
        let x = ramp(3);
        let still = vec![AxisCycle::default(); 60];
        let rows = move_table(&events, &[&x, &still], &[0.5, 0.5]);
        assert_eq!(
            rows.len(),
            1,
            "the axis that did not move has no row: {rows:?}"
        );
        let r = &rows[0];
        assert_eq!((r.motion, r.axis, r.start_cycle), (1, 0, 10));
        assert_eq!(r.duration_cycles, 10);
        assert_eq!(r.travel, 10.0);
        assert_eq!(r.peak_velocity, 1000.0);
        // Three cycles behind on the ramp: 3 units of following error.
        assert_eq!(r.peak_following_error, 3.0);
        // The actual reaches 10 at cycle 23; within 0.5 from there: 3 cycles to settle.
        assert_eq!(r.settling_cycles, Some(3));
    }

    #[test]
    fn events_out_of_order_in_a_damaged_recording_give_rows_not_a_panic() {
        // A finish before its start, and a start after the last sample.
        let events = [
            event("motion_started", 30, 1),
            event("motion_finished", 12, 1),
            event("motion_started", 500, 2),
        ];
        let x = ramp(3);
        let rows = move_table(&events, &[&x], &[0.5]);
        assert!(rows.iter().all(|r| r.duration_cycles == 0), "{rows:?}");
    }

    #[test]
    fn an_axis_that_never_settles_before_the_next_motion_says_so() {
        let events = [
            event("motion_started", 10, 1),
            event("motion_finished", 20, 1),
            event("motion_started", 22, 2),
        ];
        let x = ramp(5);
        let rows = move_table(&events, &[&x], &[0.5]);
        assert_eq!(rows[0].settling_cycles, None, "{rows:?}");
        // A motion without its finish ends at the end of the recording.
        assert_eq!(rows.len(), 1, "motion 2 moves nothing: {rows:?}");
    }
}
