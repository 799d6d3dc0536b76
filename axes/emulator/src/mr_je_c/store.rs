//! The simulated drive's object values and the checks a write passes (MR-JE-C manual §7.3:
//! access, size, range; §5.2 parameter ranges).

use std::collections::BTreeMap;

use super::refusal::Refusal;
use super::MrJeCParams;
use cellrt_fieldbus::mr_je_c::links::{self, LINKS};
use cellrt_fieldbus::mr_je_c::objects::{entry, object, ObjectId, Sub, DICTIONARY};
use cellrt_fieldbus::mr_je_c::parameters::definition;
use cellrt_fieldbus::mr_je_c::types::{DataType, Range, SoftwareVersion};
use cellrt_fieldbus::mr_je_c::value::Value;

/// Every object's value (the RAM; the EEPROM is `eeprom`). An object linked to a parameter
/// (§7.3 "Parameter" column, [`links`]) is kept in step with it on every [`Store::set`].
#[derive(Debug, Clone)]
pub struct Store {
    values: BTreeMap<ObjectId, Value>,
    software: SoftwareVersion,
}

impl Store {
    /// The values after power-on: the dictionary's defaults, the manual's parameter initial
    /// values, and the unit's own facts from `params`.
    pub fn new(params: &MrJeCParams) -> Store {
        let sw = params.software;
        let mut values = BTreeMap::new();
        for o in DICTIONARY.iter().filter(|o| o.since <= sw) {
            for index in o.first..=o.last {
                for (sub, row) in o.each_sub(sw) {
                    let id = ObjectId::new(index, sub);
                    let initial = definition(index)
                        .map(|d| i64::from(d.initial))
                        .or(row.initial.value(sw))
                        .unwrap_or(0);
                    let v = match row.ty {
                        DataType::VisibleString { .. } => {
                            Value::text(row.ty, "").unwrap_or(Value::Text(vec![]))
                        }
                        ty => Value::from_i64(ty, initial).unwrap_or(Value::U8(0)),
                    };
                    values.insert(id, v);
                }
            }
        }
        let mut store = Store {
            values,
            software: sw,
        };
        store.unit_facts(params);
        // A linked pair starts at the object's default; the manual's parameter initial values
        // agree where it gives both (tested).
        for link in LINKS {
            if let Some(v) = store.get(link.object).cloned() {
                store.set(link.object, v);
            }
        }
        store
    }

    fn unit_facts(&mut self, p: &MrJeCParams) {
        let text = |index: u16, s: &str| {
            let ty = entry(ObjectId::new(index, 0), SoftwareVersion::A4).map(|(_, r)| r.ty);
            (index, ty.and_then(|ty| Value::text(ty, s)))
        };
        for (index, v) in [
            text(0x1008, &p.model),
            text(0x2D30, &p.model),
            text(0x1009, &p.hardware_version),
            text(0x2D31, &p.hardware_version),
            text(0x100A, &p.software_text),
            text(0x2D32, &p.software_text),
            text(0x2D33, &p.serial_number),
        ] {
            if let (Some(v), true) = (v, self.values.contains_key(&ObjectId::new(index, 0))) {
                self.values.insert(ObjectId::new(index, 0), v);
            }
        }
        let rpm = p.max_speed_rpm;
        for (id, v) in [
            ((0x608F, 1), Value::U32(p.encoder_resolution)),
            ((0x6092, 1), Value::U32(p.encoder_resolution)),
            ((0x6080, 0), Value::U32(rpm)),
            ((0x2D29, 0), Value::U32(rpm)),
            ((0x2D28, 0), Value::U32(p.rated_speed_rpm)),
            ((0x6072, 0), Value::U16(p.max_torque)),
        ] {
            self.values.insert(ObjectId::new(id.0, id.1), v);
        }
    }

    /// The value of `id`.
    pub fn get(&self, id: ObjectId) -> Option<&Value> {
        self.values.get(&id)
    }

    /// The number at `id` (0 if absent or a string).
    pub fn int(&self, id: ObjectId) -> i64 {
        self.get(id).and_then(Value::as_i64).unwrap_or(0)
    }

    /// Every value.
    pub fn iter(&self) -> impl Iterator<Item = (&ObjectId, &Value)> {
        self.values.iter()
    }

    /// Sets `id`, and the other side of its links: the parameters of a linked object, the
    /// object of a linked parameter.
    pub fn set(&mut self, id: ObjectId, v: Value) {
        let n = v.as_i64();
        self.values.insert(id, v);
        let Some(n) = n else { return };
        if let Some(link) = links::of_object(id) {
            for (p, pv) in link.parameter_values(n).into_iter().flatten() {
                let pid = ObjectId::new(p.index(), 0);
                if self.values.contains_key(&pid) {
                    self.values.insert(pid, Value::U32(pv));
                }
            }
        }
        if id.sub != 0 {
            return;
        }
        for link in links::of_parameter(id.index) {
            let ty = match entry(link.object, self.software) {
                Some((_, row)) if self.values.contains_key(&link.object) => row.ty,
                _ => continue,
            };
            let value = link
                .object_value(self.software, |p| {
                    self.int(ObjectId::new(p.index(), 0)) as u32
                })
                .and_then(|x| Value::from_i64(ty, x));
            if let Some(value) = value {
                self.values.insert(link.object, value);
            }
        }
    }
}

/// The row of `id`, or why it does not exist.
pub fn row(id: ObjectId, sw: SoftwareVersion) -> Result<&'static Sub, Refusal> {
    let o = object(id.index, sw).ok_or(Refusal::NoIndex)?;
    o.sub(id.sub, sw).ok_or(Refusal::NoSubIndex)
}

/// The row of a readable `id`.
pub fn readable(id: ObjectId, sw: SoftwareVersion) -> Result<&'static Sub, Refusal> {
    let r = row(id, sw)?;
    if r.access.readable() {
        Ok(r)
    } else {
        Err(Refusal::WriteOnly)
    }
}

/// The row of a writable `id`.
pub fn writable(id: ObjectId, sw: SoftwareVersion) -> Result<&'static Sub, Refusal> {
    let r = row(id, sw)?;
    if r.access.writable() {
        Ok(r)
    } else {
        Err(Refusal::ReadOnly)
    }
}

/// Checks `v` against the range of `id` (its row `r`); `fixed` is the value a fixed object
/// holds, `permissible` the motor's instantaneous permissible speed (0.01 r/min).
pub fn in_range(
    id: ObjectId,
    r: &Sub,
    v: i64,
    fixed: i64,
    permissible: i64,
) -> Result<(), Refusal> {
    let spans: &[(i64, i64)] = match r.range {
        Range::Type => match definition(id.index).and_then(|d| d.range.bounds()) {
            Some((lo, hi)) => return span(v, lo, hi),
            None => return Ok(()),
        },
        Range::Between(lo, hi) => return span(v, lo, hi),
        Range::Fixed => return span(v, fixed, fixed),
        Range::Only(x) if v == x => return Ok(()),
        Range::Only(_) | Range::Automatic => return Err(Refusal::OutOfRange),
        Range::PermissibleSpeed => return span(v, 0, permissible),
        Range::Spans(s) => s,
    };
    let lo = spans.iter().map(|s| s.0).min().unwrap_or(i64::MIN);
    let hi = spans.iter().map(|s| s.1).max().unwrap_or(i64::MAX);
    span(v, lo, hi)?;
    if spans.iter().any(|&(a, b)| a <= v && v <= b) {
        Ok(())
    } else {
        Err(Refusal::OutOfRange)
    }
}

fn span(v: i64, lo: i64, hi: i64) -> Result<(), Refusal> {
    if v < lo {
        Err(Refusal::BelowRange)
    } else if v > hi {
        Err(Refusal::AboveRange)
    } else {
        Ok(())
    }
}
