//! MR-JE-C object values on the wire (MR-JE-C manual §3.6.2, §7.1; vectors MT-9, MT-10, OV-14
//! of docs/test-vectors.md): Modbus registers and SLMP bytes of each data type.

use cellrt_fieldbus::modbus::WordOrder;
use cellrt_fieldbus::mr_je_c::{DataType, Value};

fn words(v: &Value, order: WordOrder) -> Vec<u16> {
    let mut out = Vec::new();
    v.push_words(order, &mut out);
    out
}

#[test]
fn registers_of_each_type() {
    // MT-10: 6064h = 100000 = 000186A0h, low word first.
    let v = Value::I32(100_000);
    assert_eq!(words(&v, WordOrder::LowFirst), [0x86A0, 0x0001]);
    assert_eq!(words(&v, WordOrder::HighFirst), [0x0001, 0x86A0]);
    assert_eq!(
        Value::from_words(DataType::I32, &[0x86A0, 0x0001], WordOrder::LowFirst),
        Some(v)
    );
    // MT-9: 6061h = −101 reads as 009Bh; the client sign-extends.
    assert_eq!(words(&Value::I8(-101), WordOrder::LowFirst), [0x009B]);
    assert_eq!(
        Value::from_words(DataType::I8, &[0x009B], WordOrder::LowFirst),
        Some(Value::I8(-101))
    );
    assert_eq!(
        Value::from_words(DataType::U16, &[0x0437], WordOrder::LowFirst),
        Some(Value::U16(0x0437))
    );
    // A word count that is not the type's is refused.
    assert_eq!(
        Value::from_words(DataType::U32, &[1], WordOrder::LowFirst),
        None
    );
}

#[test]
fn strings_carry_two_characters_a_register() {
    // OV-14: 1008h of an MR-JE-20C, 16 registers, space padded.
    let ty = DataType::VisibleString { octets: 32 };
    let v = Value::text(ty, "MR-JE-20C").unwrap();
    let w = words(&v, WordOrder::LowFirst);
    assert_eq!(w.len(), 16);
    assert_eq!(&w[..5], &[0x4D52, 0x2D4A, 0x452D, 0x3230, 0x4320]);
    assert!(w[5..].iter().all(|&x| x == 0x2020));
    assert_eq!(
        Value::from_words(ty, &w, WordOrder::LowFirst),
        Some(v.clone())
    );
    assert_eq!(v.to_le()[..9], *b"MR-JE-20C");
    assert_eq!(v.to_string(), "\"MR-JE-20C\"");
    assert!(Value::text(DataType::VisibleString { octets: 2 }, "ABC").is_none());
}

#[test]
fn slmp_bytes_are_little_endian_in_the_types_size() {
    assert_eq!(Value::U16(0x000F).to_le(), [0x0F, 0x00]);
    assert_eq!(Value::U32(0x6576_6173).to_le(), *b"save");
    assert_eq!(
        Value::from_le(DataType::I32, &[0xA0, 0x86, 0x01, 0x00]),
        Some(Value::I32(100_000))
    );
    assert_eq!(Value::from_le(DataType::U16, &[1, 2, 3]), None);
    assert!(Value::I16(-1).is(DataType::I16));
    assert!(!Value::I16(-1).is(DataType::U16));
    assert_eq!(Value::from_i64(DataType::U8, 256), None);
    assert_eq!(Value::from_i64(DataType::I8, -128), Some(Value::I8(-128)));
}
