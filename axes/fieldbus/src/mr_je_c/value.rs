//! A value of an MR-JE-C object, typed by the dictionary, and its forms on the wire: SLMP
//! bytes (little-endian, strings in character order) and Modbus registers (MR-JE-C manual
//! §3.6.2, §7.1: one register per 8/16-bit value with a 00h high byte for 8-bit ones, two per
//! 32-bit value low word first by default, two characters per register).

use crate::modbus::{value_of, words_of, WordOrder};

use super::types::DataType;

/// An object's value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Value {
    /// I8.
    I8(i8),
    /// U8.
    U8(u8),
    /// I16.
    I16(i16),
    /// U16.
    U16(u16),
    /// I32.
    I32(i32),
    /// U32.
    U32(u32),
    /// A visible string, space padded to its size.
    Text(Vec<u8>),
}

impl Value {
    /// `v` as a value of `ty`; `None` when the type cannot hold it (or is a string, or a type
    /// the MR-JE-C dictionary does not use: BOOLEAN, unstated).
    pub fn from_i64(ty: DataType, v: i64) -> Option<Value> {
        Some(match ty {
            DataType::I8 => Value::I8(i8::try_from(v).ok()?),
            DataType::U8 => Value::U8(u8::try_from(v).ok()?),
            DataType::I16 => Value::I16(i16::try_from(v).ok()?),
            DataType::U16 => Value::U16(u16::try_from(v).ok()?),
            DataType::I32 => Value::I32(i32::try_from(v).ok()?),
            DataType::U32 => Value::U32(u32::try_from(v).ok()?),
            // Not in the MR-JE-C dictionary (§7.3 types are the integers and strings).
            DataType::VisibleString { .. } | DataType::Bool | DataType::Unstated => return None,
        })
    }

    /// The number (strings: `None`).
    pub fn as_i64(&self) -> Option<i64> {
        Some(match *self {
            Value::I8(v) => v.into(),
            Value::U8(v) => v.into(),
            Value::I16(v) => v.into(),
            Value::U16(v) => v.into(),
            Value::I32(v) => v.into(),
            Value::U32(v) => v.into(),
            Value::Text(_) => return None,
        })
    }

    /// The text of `ty` (`size` bytes), space padded; `None` when `s` is longer.
    pub fn text(ty: DataType, s: &str) -> Option<Value> {
        let mut bytes = s.as_bytes().to_vec();
        if bytes.len() > ty.bytes() {
            return None;
        }
        bytes.resize(ty.bytes(), b' ');
        Some(Value::Text(bytes))
    }

    /// Whether the value is of type `ty`.
    pub fn is(&self, ty: DataType) -> bool {
        match self {
            Value::Text(b) => matches!(ty, DataType::VisibleString { .. }) && b.len() == ty.bytes(),
            _ => Value::from_i64(ty, self.as_i64().unwrap_or(i64::MAX)).as_ref() == Some(self),
        }
    }

    /// The SLMP bytes (little-endian; strings in character order).
    pub fn to_le(&self) -> Vec<u8> {
        match self {
            Value::I8(v) => v.to_le_bytes().to_vec(),
            Value::U8(v) => vec![*v],
            Value::I16(v) => v.to_le_bytes().to_vec(),
            Value::U16(v) => v.to_le_bytes().to_vec(),
            Value::I32(v) => v.to_le_bytes().to_vec(),
            Value::U32(v) => v.to_le_bytes().to_vec(),
            Value::Text(b) => b.clone(),
        }
    }

    /// The value of `ty` in SLMP bytes; `None` unless exactly its size.
    pub fn from_le(ty: DataType, bytes: &[u8]) -> Option<Value> {
        if bytes.len() != ty.bytes() {
            return None;
        }
        let mut b = [0u8; 4];
        b[..bytes.len().min(4)].copy_from_slice(&bytes[..bytes.len().min(4)]);
        Some(match ty {
            DataType::I8 => Value::I8(b[0] as i8),
            DataType::U8 => Value::U8(b[0]),
            DataType::I16 => Value::I16(i16::from_le_bytes([b[0], b[1]])),
            DataType::U16 => Value::U16(u16::from_le_bytes([b[0], b[1]])),
            DataType::I32 => Value::I32(i32::from_le_bytes(b)),
            DataType::U32 => Value::U32(u32::from_le_bytes(b)),
            DataType::VisibleString { .. } => Value::Text(bytes.to_vec()),
            DataType::Bool | DataType::Unstated => return None,
        })
    }

    /// Appends the Modbus registers (8-bit values with a 00h high byte; strings two
    /// characters a register, the first in the high byte).
    pub fn push_words(&self, order: WordOrder, out: &mut Vec<u16>) {
        match self {
            Value::Text(b) => out.extend(
                b.chunks(2)
                    .map(|c| u16::from_be_bytes([c[0], c.get(1).copied().unwrap_or(b' ')])),
            ),
            Value::I32(_) | Value::U32(_) => {
                out.extend(words_of(self.as_i64().unwrap_or(0) as u32, 2, order))
            }
            Value::I8(v) => out.push(u16::from(*v as u8)),
            other => out.push(other.as_i64().unwrap_or(0) as u16),
        }
    }

    /// The value of `ty` in `words` (exactly its registers); an 8-bit value takes the low
    /// byte (sign-extended for I8, manual §3.6.2 note).
    pub fn from_words(ty: DataType, words: &[u16], order: WordOrder) -> Option<Value> {
        if words.len() != ty.registers() {
            return None;
        }
        Some(match ty {
            DataType::VisibleString { .. } => {
                Value::Text(words.iter().flat_map(|w| w.to_be_bytes()).collect())
            }
            DataType::I8 => Value::I8(words[0] as u8 as i8),
            DataType::U8 => Value::U8(words[0] as u8),
            DataType::I16 => Value::I16(words[0] as i16),
            DataType::U16 => Value::U16(words[0]),
            DataType::I32 => Value::I32(value_of(words, order) as i32),
            DataType::U32 => Value::U32(value_of(words, order)),
            DataType::Bool | DataType::Unstated => return None,
        })
    }
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Text(b) => write!(f, "{:?}", String::from_utf8_lossy(b).trim_end()),
            Value::U16(v) => write!(f, "{v} ({v:04X}h)"),
            Value::U32(v) => write!(f, "{v} ({v:08X}h)"),
            other => write!(f, "{}", other.as_i64().unwrap_or(0)),
        }
    }
}
