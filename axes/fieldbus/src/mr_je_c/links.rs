//! Objects linked to servo parameters: the "Parameter" column of the MR-JE-C manual's object
//! dictionary list (§7.3). A linked object and its parameter are one setting: the drive keeps
//! it once, so whichever of the pair is written, both read the new value (the value stored in
//! the EEPROM, §7.2, is the parameter's). One table, read by the emulator's store and by the
//! checks of a parameter write.

use super::objects::{entry, ObjectId};
use super::parameters::{Group, Parameter};
use super::types::SoftwareVersion;
use Group::{PA, PC, PT};

/// How a linked object's value is held in its parameter(s).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Linkage {
    /// The parameter holds the object's value in the object's unit (signed objects as their
    /// 32-bit two's complement in the U32 parameter object). The network manual gives the
    /// units of the PC parameters, and they equal their objects' (ms; [Pr. PC35] "1000.0 %"
    /// is 10000 in 2D6Bh's 0.1 %). The PA and PT parameters are described in the companion
    /// manuals we do not have: their unit is taken as the object's `[INFER]`, which the
    /// objects' defaults fit (6099h:1 10000 = 100.00 r/min, 6098h 37).
    Same(Parameter),
    /// The object's 32 bits in two parameters: `low` bits 0–15, `high` bits 16–31. 6065h's
    /// default 12582912 (00C00000h) is [Pr. PC75] 0000h and [Pr. PC76] 00C0h, the initial
    /// values §5.1 prints. 607Dh's pairs ([Pr. PT15]/[Pr. PT16], [Pr. PT17]/[Pr. PT18], lower
    /// and upper as for PC75/PC76) follow the same split `[INFER]`: their manual is a
    /// companion we do not have.
    Words {
        /// Bits 0–15.
        low: Parameter,
        /// Bits 16–31.
        high: Parameter,
    },
    /// Linked by the manual, but the parameter's layout (digits or bits) is in a companion
    /// manual we do not have: the pair is listed and not kept in step.
    Undescribed(&'static [Parameter]),
}

/// One row of the "Parameter" column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Link {
    /// The object.
    pub object: ObjectId,
    /// Its parameter(s).
    pub linkage: Linkage,
}

const fn p(group: Group, number: u8) -> Parameter {
    Parameter { group, number }
}

const fn same(index: u16, sub: u8, parameter: Parameter) -> Link {
    Link {
        object: ObjectId::new(index, sub),
        linkage: Linkage::Same(parameter),
    }
}

const fn words(index: u16, sub: u8, low: Parameter, high: Parameter) -> Link {
    Link {
        object: ObjectId::new(index, sub),
        linkage: Linkage::Words { low, high },
    }
}

const fn undescribed(index: u16, sub: u8, parameters: &'static [Parameter]) -> Link {
    Link {
        object: ObjectId::new(index, sub),
        linkage: Linkage::Undescribed(parameters),
    }
}

/// Every object the manual's §7.3 list links to a parameter, ascending by object.
///
/// Not kept in step (`Undescribed`): 605Ah/605Dh ↔ [Pr. PT69] (both objects hold one fixed
/// value, so the parameter must encode them in digits), 607Eh ↔ [Pr. PA14], [Pr. PC29] (bits
/// 5–7 against a rotation-direction setting and the "POL reflection at torque mode" digit,
/// §7.6.6), 6092h:2 ↔ [Pr. PT01] (set from PT01's unit digits) and 60F2h ↔ [Pr. PT03]. 60E0h
/// and 60E1h are linked to [Pr. PA11] and [Pr. PA12]; the list's "PA11/PA12" and
/// "PA12/(PA11)" suggest the pair swaps with the rotation direction [Pr. PA14], which the
/// manual does not explain: not emulated.
pub const LINKS: &[Link] = &[
    same(0x2D20, 0, p(PT, 52)),
    same(0x2D6B, 0, p(PC, 35)),
    undescribed(0x605A, 0, &[p(PT, 69)]),
    undescribed(0x605D, 0, &[p(PT, 69)]),
    words(0x6065, 0, p(PC, 75), p(PC, 76)),
    same(0x6066, 0, p(PC, 77)),
    same(0x6067, 0, p(PT, 65)),
    same(0x6068, 0, p(PT, 66)),
    same(0x606D, 0, p(PT, 67)),
    same(0x606E, 0, p(PT, 68)),
    same(0x606F, 0, p(PT, 63)),
    same(0x6070, 0, p(PT, 64)),
    words(0x607D, 1, p(PT, 17), p(PT, 18)),
    words(0x607D, 2, p(PT, 15), p(PT, 16)),
    undescribed(0x607E, 0, &[p(PA, 14), p(PC, 29)]),
    same(0x607F, 0, p(PT, 51)),
    same(0x6081, 0, p(PT, 50)),
    same(0x6083, 0, p(PC, 1)),
    same(0x6084, 0, p(PC, 2)),
    same(0x6085, 0, p(PC, 51)),
    same(0x6087, 0, p(PT, 49)),
    same(0x6091, 1, p(PA, 6)),
    same(0x6091, 2, p(PA, 7)),
    undescribed(0x6092, 2, &[p(PT, 1)]),
    same(0x6098, 0, p(PT, 45)),
    same(0x6099, 1, p(PT, 5)),
    same(0x6099, 2, p(PT, 6)),
    same(0x609A, 0, p(PT, 61)),
    same(0x60E0, 0, p(PA, 11)),
    same(0x60E1, 0, p(PA, 12)),
    undescribed(0x60F2, 0, &[p(PT, 3)]),
];

/// The link of object `id`, if the manual gives one.
pub fn of_object(id: ObjectId) -> Option<&'static Link> {
    LINKS.iter().find(|l| l.object == id)
}

/// The links that keep an object in parameter object `index` (undescribed ones left out).
pub fn of_parameter(index: u16) -> impl Iterator<Item = &'static Link> {
    LINKS
        .iter()
        .filter(move |l| l.held().iter().flatten().any(|p| p.index() == index))
}

impl Link {
    /// The parameters that hold the object's value (none for an undescribed link).
    pub fn held(&self) -> [Option<Parameter>; 2] {
        match self.linkage {
            Linkage::Same(p) => [Some(p), None],
            Linkage::Words { low, high } => [Some(low), Some(high)],
            Linkage::Undescribed(_) => [None, None],
        }
    }

    /// The parameter values that hold object value `v`.
    pub fn parameter_values(&self, v: i64) -> [Option<(Parameter, u32)>; 2] {
        let bits = v as u32;
        match self.linkage {
            Linkage::Same(p) => [Some((p, bits)), None],
            Linkage::Words { low, high } => [Some((low, bits & 0xFFFF)), Some((high, bits >> 16))],
            Linkage::Undescribed(_) => [None, None],
        }
    }

    /// The object value its parameters give, `param` reading a parameter's value; `None` for
    /// an undescribed link or an object absent on software `sw`.
    pub fn object_value(
        &self,
        sw: SoftwareVersion,
        param: impl Fn(Parameter) -> u32,
    ) -> Option<i64> {
        let bits = match self.linkage {
            Linkage::Same(p) => param(p),
            Linkage::Words { low, high } => (param(high) & 0xFFFF) << 16 | (param(low) & 0xFFFF),
            Linkage::Undescribed(_) => return None,
        };
        let signed = entry(self.object, sw)?.1.ty.value_range()?.0 < 0;
        Some(if signed {
            i64::from(bits as i32)
        } else {
            i64::from(bits)
        })
    }

    /// Whether a parameter value fits its share of the object: a word of a `Words` link
    /// holds 0000h–FFFFh.
    pub fn parameter_fits(&self, value: u32) -> bool {
        !matches!(self.linkage, Linkage::Words { .. }) || value <= 0xFFFF
    }
}
