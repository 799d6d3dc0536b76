//! Triggered capture (`[recording] mode = "triggered"`): instead of one continuous recording the
//! recorder keeps the last `pre_s` seconds of records in memory and writes one complete MCAP file
//! around each trigger — an event of a named kind, or an axis quantity crossing a threshold —
//! with `post_s` seconds after it. For long-running cells where a continuous recording is too
//! large; `cellrt capture` writes the ring on demand.

use std::path::Path;
use std::str::FromStr;

use super::{AxisConfig, ConfigError};
use crate::events::EventKind;

/// Longest pre-trigger window, s (the ring lives in memory: 16 axes at 1 kHz take about
/// 1.5 MiB per second).
pub const MAX_PRE_S: f64 = 60.0;
/// Longest post-trigger window, s.
pub const MAX_POST_S: f64 = 600.0;

/// What makes the recorder write a capture.
#[derive(Debug, Clone, PartialEq)]
pub enum Trigger {
    /// An event of this kind.
    Event(EventKind),
    /// An axis quantity compared with a value, in the axis' units.
    Threshold {
        /// Axis index.
        axis: usize,
        /// The quantity.
        quantity: Quantity,
        /// The comparison.
        comparison: Comparison,
        /// The value.
        value: f64,
    },
}

/// An axis quantity a threshold watches, as the recording's `/axis/NAME` topic names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, strum::EnumString, strum::IntoStaticStr)]
#[strum(serialize_all = "snake_case")]
pub enum Quantity {
    /// Following error, unit.
    FollowingError,
    /// Actual position, unit.
    ActualPosition,
    /// Actual velocity, unit/s.
    ActualVelocity,
    /// Setpoint position, unit.
    SetpointPosition,
    /// Setpoint velocity, unit/s.
    SetpointVelocity,
}

/// How a quantity is compared; `|…|` around the quantity compares its magnitude.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Comparison {
    /// Above.
    Above,
    /// Below.
    Below,
    /// Magnitude above.
    AbsAbove,
}

impl Comparison {
    /// Whether `x` meets the comparison with `value`.
    pub fn holds(self, x: f64, value: f64) -> bool {
        match self {
            Comparison::Above => x > value,
            Comparison::Below => x < value,
            Comparison::AbsAbove => x.abs() > value,
        }
    }
}

/// The triggered mode's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureConfig {
    /// Seconds kept before a trigger.
    pub pre_s: f64,
    /// Seconds written after it.
    pub post_s: f64,
    /// The triggers.
    pub triggers: Vec<Trigger>,
}

/// `recording.mode`, `pre_s`, `post_s` and `triggers`, checked against the axes.
pub fn capture_config(
    file: &Path,
    mode: &str,
    pre_s: f64,
    post_s: f64,
    triggers: &[String],
    axes: &[AxisConfig],
) -> Result<Option<CaptureConfig>, ConfigError> {
    let err = |key: &str, msg: String| ConfigError::new(file, format!("recording.{key}"), msg);
    match mode {
        "continuous" => {
            if !triggers.is_empty() {
                return Err(err("triggers", "triggers need mode = \"triggered\"".into()));
            }
            return Ok(None);
        }
        "triggered" => {}
        other => {
            return Err(err(
                "mode",
                format!("unknown mode '{other}' (allowed: continuous, triggered)"),
            ))
        }
    }
    if !(pre_s.is_finite() && (0.0..=MAX_PRE_S).contains(&pre_s)) {
        return Err(err(
            "pre_s",
            format!("must be 0..={MAX_PRE_S} s (got {pre_s})"),
        ));
    }
    if !(post_s.is_finite() && post_s > 0.0 && post_s <= MAX_POST_S) {
        return Err(err(
            "post_s",
            format!("must be above 0 and at most {MAX_POST_S} s (got {post_s})"),
        ));
    }
    let triggers = triggers
        .iter()
        .enumerate()
        .map(|(i, t)| {
            parse_trigger(t, axes).map_err(|e| err(&format!("triggers[{i}]"), e.to_string()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Some(CaptureConfig {
        pre_s,
        post_s,
        triggers,
    }))
}

/// Why a `recording.triggers` entry is refused (`text`: the entry, trimmed).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TriggerError {
    /// No `/` and not an event kind.
    #[error("'{text}' is not an event kind (e.g. drive_fault, overrun, stop_started) nor a threshold like '/axis/x.following_error > 0.5'")]
    NotAnEventKind {
        /// The entry.
        text: String,
    },
    /// A threshold without `>` or `<`.
    #[error("'{text}': a threshold compares with > or <")]
    NoComparison {
        /// The entry.
        text: String,
    },
    /// A magnitude compared with `<`.
    #[error("'{text}': a magnitude is compared with >")]
    MagnitudeBelow {
        /// The entry.
        text: String,
    },
    /// The left side is not `/axis/NAME.QUANTITY`.
    #[error("'{text}': expected /axis/NAME.QUANTITY")]
    NotAnAxisQuantity {
        /// The entry.
        text: String,
    },
    /// No axis of that name.
    #[error("'{text}': no axis named '{axis}'")]
    UnknownAxis {
        /// The entry.
        text: String,
        /// The name.
        axis: String,
    },
    /// A quantity that is not recorded.
    #[error("'{text}': unknown quantity '{quantity}' (allowed: following_error, actual_position, actual_velocity, setpoint_position, setpoint_velocity)")]
    UnknownQuantity {
        /// The entry.
        text: String,
        /// The quantity.
        quantity: String,
    },
    /// The threshold is not a finite number.
    #[error("'{text}': '{value}' is not a finite number")]
    NotFinite {
        /// The entry.
        text: String,
        /// The threshold's text.
        value: String,
    },
}

/// `drive_fault` (an event kind), or `/axis/NAME.QUANTITY > VALUE` (also `<`, and `|…|` around
/// the quantity for its magnitude: `|/axis/x.following_error| > 0.5`).
fn parse_trigger(text: &str, axes: &[AxisConfig]) -> Result<Trigger, TriggerError> {
    let t = text.trim();
    let text = || t.to_string();
    if !t.contains('/') {
        return EventKind::from_str(t)
            .map(Trigger::Event)
            .map_err(|_| TriggerError::NotAnEventKind { text: text() });
    }
    let (lhs, op, rhs) = ['>', '<']
        .iter()
        .find_map(|&op| t.split_once(op).map(|(l, r)| (l.trim(), op, r.trim())))
        .ok_or_else(|| TriggerError::NoComparison { text: text() })?;
    let (inner, magnitude) = match lhs.strip_prefix('|').and_then(|l| l.strip_suffix('|')) {
        Some(inner) => (inner.trim(), true),
        None => (lhs, false),
    };
    let comparison = match (op, magnitude) {
        ('>', false) => Comparison::Above,
        ('<', false) => Comparison::Below,
        ('>', true) => Comparison::AbsAbove,
        _ => return Err(TriggerError::MagnitudeBelow { text: text() }),
    };
    let (name, quantity) = inner
        .strip_prefix("/axis/")
        .and_then(|r| r.rsplit_once('.'))
        .ok_or_else(|| TriggerError::NotAnAxisQuantity { text: text() })?;
    let axis =
        axes.iter()
            .position(|a| a.name == name)
            .ok_or_else(|| TriggerError::UnknownAxis {
                text: text(),
                axis: name.to_string(),
            })?;
    let quantity = Quantity::from_str(quantity).map_err(|_| TriggerError::UnknownQuantity {
        text: text(),
        quantity: quantity.to_string(),
    })?;
    let value: f64 = rhs
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite())
        .ok_or_else(|| TriggerError::NotFinite {
            text: text(),
            value: rhs.to_string(),
        })?;
    Ok(Trigger::Threshold {
        axis,
        quantity,
        comparison,
        value,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CellConfig;

    fn parse(recording: &str) -> Result<CellConfig, ConfigError> {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../configs/demo.toml"
        ))
        .unwrap()
        .replacen("[recording]\n", &format!("[recording]\n{recording}\n"), 1);
        CellConfig::parse(Path::new("cell.toml"), &text)
    }

    fn refused(recording: &str, key: &str, why: &str) {
        let e = parse(recording).expect_err(recording);
        assert_eq!(e.key, key, "{e}");
        assert!(e.message.contains(why), "{recording}: {e}");
    }

    #[test]
    fn triggers_parse_into_event_kinds_and_thresholds() {
        let c = parse(
            "mode = \"triggered\"\npre_s = 2\npost_s = 1\ntriggers = [\"drive_fault\", \"/axis/y.following_error > 0.5\", \"|/axis/c.actual_velocity| > 90\", \"/axis/x.actual_position < -1\"]",
        )
        .unwrap();
        let cap = c.recording.capture.unwrap();
        assert_eq!((cap.pre_s, cap.post_s), (2.0, 1.0));
        assert_eq!(cap.triggers[0], Trigger::Event(EventKind::DriveFault));
        assert_eq!(
            cap.triggers[1],
            Trigger::Threshold {
                axis: 1,
                quantity: Quantity::FollowingError,
                comparison: Comparison::Above,
                value: 0.5
            }
        );
        assert!(matches!(
            cap.triggers[2],
            Trigger::Threshold {
                axis: 3,
                comparison: Comparison::AbsAbove,
                ..
            }
        ));
        assert!(Comparison::Below.holds(-2.0, -1.0) && !Comparison::AbsAbove.holds(-5.0, 5.0));
        assert!(parse("").unwrap().recording.capture.is_none());
    }

    #[test]
    fn bad_capture_settings_are_refused_naming_the_key() {
        refused(
            "mode = \"sometimes\"",
            "recording.mode",
            "unknown mode 'sometimes'",
        );
        refused(
            "triggers = [\"drive_fault\"]",
            "recording.triggers",
            "mode = \"triggered\"",
        );
        let t = |rest: &str| format!("mode = \"triggered\"\n{rest}");
        refused(&t("pre_s = 61"), "recording.pre_s", "0..=60");
        refused(&t("post_s = 0"), "recording.post_s", "above 0");
        refused(&t("post_s = nan"), "recording.post_s", "above 0");
        refused(
            &t("triggers = [\"drive_falt\"]"),
            "recording.triggers[0]",
            "not an event kind",
        );
        refused(
            &t("triggers = [\"overrun\", \"/axis/q.following_error > 1\"]"),
            "recording.triggers[1]",
            "no axis named 'q'",
        );
        refused(
            &t("triggers = [\"/axis/x.torque > 1\"]"),
            "recording.triggers[0]",
            "unknown quantity 'torque'",
        );
        refused(
            &t("triggers = [\"/axis/x.following_error > inf\"]"),
            "recording.triggers[0]",
            "not a finite number",
        );
        refused(
            &t("triggers = [\"/axis/x.following_error = 1\"]"),
            "recording.triggers[0]",
            "> or <",
        );
        refused(
            &t("triggers = [\"|/axis/x.following_error| < 1\"]"),
            "recording.triggers[0]",
            "magnitude",
        );
    }
}
