//! Numbers on the command line: parsed by clap with the rule they must meet, so NaN, infinities
//! and out-of-range values are refused with the argument's name before anything is sent (JSON
//! has no NaN: one sent would arrive as "not given" and change the request's meaning).

/// The longest `--reply-timeout`, s: beyond an hour a reply is not coming.
pub const MAX_REPLY_TIMEOUT_S: f64 = 3600.0;

fn number(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{s} is not a finite number"))
    }
}

/// An integer in decimal or hex (0x1EA5 / 1EA5h), with an optional minus sign (object values).
pub fn integer(s: &str) -> Result<i64, String> {
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
    .map_err(|_| format!("{s:?} is not a number"))?;
    Ok(if neg { -n } else { n })
}

/// Any finite number (a signed jog velocity, an override percentage the cell range-checks).
pub fn finite(s: &str) -> Result<f64, String> {
    number(s)
}

/// A finite number > 0 (limits, durations).
pub fn positive(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{s} must be a number > 0"))
    }
}

/// `--reply-timeout`: seconds > 0, at most [`MAX_REPLY_TIMEOUT_S`].
pub fn reply_timeout(s: &str) -> Result<f64, String> {
    let v = positive(s)?;
    if v <= MAX_REPLY_TIMEOUT_S {
        Ok(v)
    } else {
        Err(format!("{s} s is longer than {MAX_REPLY_TIMEOUT_S} s"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_infinity_and_out_of_range_are_refused_by_name() {
        for bad in ["nan", "NaN", "inf", "-inf", "infinity", "1e400", "x", ""] {
            assert!(finite(bad).is_err(), "{bad}");
            assert!(positive(bad).is_err(), "{bad}");
        }
        assert_eq!(finite("-12.5"), Ok(-12.5));
        assert!(positive("0").unwrap_err().contains("> 0"));
        assert!(positive("-1").is_err());
        assert_eq!(positive("1e-3"), Ok(1e-3));
        assert!(reply_timeout("1e300").unwrap_err().contains("3600"));
        assert_eq!(reply_timeout("5"), Ok(5.0));
    }
}
