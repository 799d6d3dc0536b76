//! Numbers on the command line: parsed by clap with the rule they must meet, so NaN, infinities
//! and out-of-range values are refused with the argument's name before anything is sent (JSON
//! has no NaN: one sent would arrive as "not given" and change the request's meaning).

use cellrt_config::echo::Echo;
use cellrt_trajectory::limits::MAX_MOTION_S;

/// The longest `--reply-timeout`, s: beyond an hour a reply is not coming.
pub const MAX_REPLY_TIMEOUT_S: f64 = 3600.0;

/// Why a number on the command line is refused (`text`: the argument as given).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NumberError {
    /// Not a number at all.
    #[error("'{}' is not a number", Echo(.text))]
    NotANumber {
        /// The argument.
        text: String,
    },
    /// Not an integer (decimal or hex).
    #[error("\"{}\" is not a number", Echo(.text))]
    NotAnInteger {
        /// The argument.
        text: String,
    },
    /// NaN or an infinity.
    #[error("{} is not a finite number", Echo(.text))]
    NotFinite {
        /// The argument.
        text: String,
    },
    /// Zero or below where a number > 0 is needed.
    #[error("{} must be a number > 0", Echo(.text))]
    NotPositive {
        /// The argument.
        text: String,
    },
    /// Neither a number of seconds nor a duration such as "2s", "500ms" or "1h 30m".
    #[error("'{}' is not a duration (seconds, or e.g. 2s, 500ms, 1h30m)", Echo(.text))]
    NotADuration {
        /// The argument.
        text: String,
    },
    /// A duration beyond its bound ([`MAX_REPLY_TIMEOUT_S`], [`MAX_MOTION_S`]).
    #[error("{} s is longer than {max} s", Echo(.text))]
    TooLong {
        /// The argument.
        text: String,
        /// The bound, s.
        max: f64,
    },
}

fn number(s: &str) -> Result<f64, NumberError> {
    let text = || s.to_string();
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| NumberError::NotANumber { text: text() })?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(NumberError::NotFinite { text: text() })
    }
}

/// An integer in decimal or hex (0x1EA5 / 1EA5h), with an optional minus sign (object values).
pub fn integer(s: &str) -> Result<i64, NumberError> {
    let t = s.trim();
    let (neg, body) = t.strip_prefix('-').map_or((false, t), |b| (true, b));
    let n = if let Some(h) = body
        .strip_prefix("0x")
        .or_else(|| body.strip_suffix(['h', 'H']))
    {
        i64::from_str_radix(h, 16)
    } else {
        body.parse::<i64>()
    }
    .map_err(|_| NumberError::NotAnInteger {
        text: s.to_string(),
    })?;
    Ok(if neg { -n } else { n })
}

/// Any finite number (a signed jog velocity, an override percentage the cell range-checks).
pub fn finite(s: &str) -> Result<f64, NumberError> {
    number(s)
}

/// A finite number > 0 (limits, durations).
pub fn positive(s: &str) -> Result<f64, NumberError> {
    let v = number(s)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(NumberError::NotPositive {
            text: s.to_string(),
        })
    }
}

/// Seconds > 0 (a number or a duration, [`duration_seconds`]), at most `max`.
fn seconds_up_to(s: &str, max: f64) -> Result<f64, NumberError> {
    let v = duration_seconds(s)?;
    if v <= max {
        Ok(v)
    } else {
        Err(NumberError::TooLong {
            text: s.to_string(),
            max,
        })
    }
}

/// A duration > 0 in seconds: a plain number of seconds ("2.5") or a `humantime` duration
/// ("2s", "500ms", "1h 30m", "1d").
pub fn duration_seconds(s: &str) -> Result<f64, NumberError> {
    if s.trim().parse::<f64>().is_ok() {
        return positive(s);
    }
    let d = humantime::parse_duration(s.trim()).map_err(|_| NumberError::NotADuration {
        text: s.to_string(),
    })?;
    let v = d.as_secs_f64();
    if v > 0.0 {
        Ok(v)
    } else {
        Err(NumberError::NotPositive {
            text: s.to_string(),
        })
    }
}

/// `--reply-timeout`: seconds > 0, at most [`MAX_REPLY_TIMEOUT_S`].
pub fn reply_timeout(s: &str) -> Result<f64, NumberError> {
    seconds_up_to(s, MAX_REPLY_TIMEOUT_S)
}

/// The seconds a motion lasts (`torque --seconds`): > 0, at most [`MAX_MOTION_S`].
pub fn motion_seconds(s: &str) -> Result<f64, NumberError> {
    seconds_up_to(s, MAX_MOTION_S)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_are_seconds_or_humantime() {
        assert_eq!(duration_seconds("2.5"), Ok(2.5));
        assert_eq!(duration_seconds("2s"), Ok(2.0));
        assert_eq!(duration_seconds("500ms"), Ok(0.5));
        assert_eq!(duration_seconds("1h 30m"), Ok(5400.0));
        assert_eq!(duration_seconds("1d"), Ok(86_400.0));
        for bad in ["0", "-1", "0s", "nan", "2 parsecs", "s", ""] {
            assert!(duration_seconds(bad).is_err(), "{bad}");
        }
        assert_eq!(
            duration_seconds("2 parsecs").unwrap_err().to_string(),
            "'2 parsecs' is not a duration (seconds, or e.g. 2s, 500ms, 1h30m)"
        );
        assert_eq!(reply_timeout("2m"), Ok(120.0));
        assert!(reply_timeout("2h").is_err());
    }

    #[test]
    fn nan_infinity_and_out_of_range_are_refused_by_name() {
        for bad in ["nan", "NaN", "inf", "-inf", "infinity", "1e400", "x", ""] {
            assert!(finite(bad).is_err(), "{bad}");
            assert!(positive(bad).is_err(), "{bad}");
        }
        assert_eq!(finite("-12.5"), Ok(-12.5));
        assert_eq!(
            positive("0"),
            Err(NumberError::NotPositive { text: "0".into() })
        );
        assert_eq!(
            positive("0").unwrap_err().to_string(),
            "0 must be a number > 0"
        );
        assert_eq!(
            integer("1x").unwrap_err().to_string(),
            "\"1x\" is not a number"
        );
        assert_eq!(finite("x").unwrap_err().to_string(), "'x' is not a number");
        assert_eq!(
            finite("inf").unwrap_err().to_string(),
            "inf is not a finite number"
        );
        assert!(positive("-1").is_err());
        assert_eq!(positive("1e-3"), Ok(1e-3));
        assert_eq!(
            reply_timeout("1e300").unwrap_err().to_string(),
            "1e300 s is longer than 3600 s"
        );
        assert_eq!(reply_timeout("5"), Ok(5.0));
        assert_eq!(
            motion_seconds("1e300").unwrap_err().to_string(),
            "1e300 s is longer than 86400 s"
        );
        assert_eq!(motion_seconds("86400"), Ok(86_400.0));
    }
}
