//! Object values as Modbus registers (MR-JE-C manual §7.1, §3.6.2): 8- and 16-bit objects take
//! one register, 32-bit objects two, low word first by default; Modbus RTU can put the high
//! word first ([Pr. PC72] = 1, manual §5.2.1). Within a word the high byte comes first.

/// The order of the two words of a 32-bit value ([Pr. PC72], RTU only; Modbus/TCP is always
/// low word first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WordOrder {
    /// Low word first ("standard endian", the initial setting).
    #[default]
    LowFirst,
    /// High word first ("big endian", [Pr. PC72] = 1).
    HighFirst,
}

/// The registers of a value that takes `registers` words (1 or 2).
pub fn words_of(value: u32, registers: usize, order: WordOrder) -> [u16; 2] {
    let (lo, hi) = (value as u16, (value >> 16) as u16);
    match (registers, order) {
        (1, _) => [lo, 0],
        (_, WordOrder::LowFirst) => [lo, hi],
        (_, WordOrder::HighFirst) => [hi, lo],
    }
}

/// The value of one object's registers (1 or 2 words, as [`words_of`] lays them out).
pub fn value_of(words: &[u16], order: WordOrder) -> u32 {
    match (words, order) {
        ([w], _) => u32::from(*w),
        ([lo, hi, ..], WordOrder::LowFirst) => u32::from(*lo) | u32::from(*hi) << 16,
        ([hi, lo, ..], WordOrder::HighFirst) => u32::from(*lo) | u32::from(*hi) << 16,
        _ => 0,
    }
}
