//! ETG.2000 number notations: `HexDecValue` ("#x1A00" or "6656") and hex binary data
//! (`DefaultData`, little-endian bytes as hex digits).

/// A `HexDecValue`: `#x` followed by hex digits, or a decimal integer (optionally signed).
pub fn hex_dec(text: &str) -> Option<i64> {
    let t = text.trim();
    if let Some(hex) = t.strip_prefix("#x").or_else(|| t.strip_prefix("#X")) {
        if hex.is_empty() || hex.len() > 16 {
            return None;
        }
        return u64::from_str_radix(hex, 16).ok().map(|v| v as i64);
    }
    t.parse::<i64>().ok()
}

/// `DefaultData`: the object's bytes in transfer (little-endian) order as hex digit pairs, as
/// an integer; `None` for odd digit counts, non-hex text or more than 8 bytes.
pub fn le_hex_bytes(text: &str) -> Option<i64> {
    let t = text.trim();
    if t.is_empty() || !t.len().is_multiple_of(2) || t.len() > 16 {
        return None;
    }
    let mut v: u64 = 0;
    for (i, pair) in t.as_bytes().chunks(2).enumerate() {
        let byte = u8::from_str_radix(std::str::from_utf8(pair).ok()?, 16).ok()?;
        v |= u64::from(byte) << (8 * i);
    }
    Some(v as i64)
}

/// An ETG.2000 boolean attribute: "1"/"true" or "0"/"false".
pub fn boolean(text: &str) -> Option<bool> {
    match text.trim() {
        "1" | "true" => Some(true),
        "0" | "false" => Some(false),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_and_decimal_values() {
        assert_eq!(hex_dec("#x1A00"), Some(0x1A00));
        assert_eq!(hex_dec(" #x00000A1E "), Some(0xA1E));
        assert_eq!(hex_dec("6656"), Some(6656));
        assert_eq!(hex_dec("-3"), Some(-3));
        assert_eq!(hex_dec("#xFFFFFFFF"), Some(0xFFFF_FFFF));
        for bad in ["", "#x", "0x10", "#xG1", "ten", "#x11112222333344445"] {
            assert_eq!(hex_dec(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn default_data_is_little_endian() {
        assert_eq!(le_hex_bytes("10270000"), Some(10_000));
        assert_eq!(le_hex_bytes("a003"), Some(0x3A0));
        assert_eq!(le_hex_bytes("a0 3"), None);
        assert_eq!(le_hex_bytes("abc"), None);
        assert_eq!(le_hex_bytes("000102030405060708"), None);
    }

    #[test]
    fn booleans() {
        assert_eq!(boolean("1"), Some(true));
        assert_eq!(boolean("false"), Some(false));
        assert_eq!(boolean("yes"), None);
    }
}
