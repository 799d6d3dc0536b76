//! Who may talk to the drive and who may command it (MR-JE-C manual §5.2.3): the IP address
//! filter [Pr. PN24]–[Pr. PN30] and the operation specification IP address [Pr. PN31]–[Pr.
//! PN36]. Both are `*` parameters: the drive takes them at power-on. All-zero base octets
//! switch a rule off. A range end of 256 ("disables the function") is read as "no range: the
//! octet must equal the base", and octets without a range parameter (the 1st of the filter,
//! the 1st and 2nd of the operation list) must equal theirs, as the extract infers.

use std::net::Ipv4Addr;

use super::store::Store;
use cellrt_fieldbus::mr_je_c::objects::ObjectId;

/// The two rules, latched at power-on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AddressRules {
    /// PN24–PN27 base octets, PN28–PN30 range ends of octets 2–4.
    filter: ([i64; 4], [i64; 3]),
    /// PN31–PN34 base octets, PN35–PN36 range ends of octets 3–4.
    operation: ([i64; 4], [i64; 2]),
}

fn params<const N: usize>(store: &Store, first: u16) -> [i64; N] {
    std::array::from_fn(|k| store.int(ObjectId::new(first + k as u16, 0)))
}

/// Whether `octets` pass `base` with range ends `ends` for the last `ends.len()` octets.
fn matches(octets: [u8; 4], base: [i64; 4], ends: &[i64]) -> bool {
    if base == [0; 4] {
        return true;
    }
    let ranged = 4 - ends.len();
    octets.iter().enumerate().all(|(k, &o)| {
        let (o, lo) = (i64::from(o), base[k]);
        let hi = match k.checked_sub(ranged).map(|r| ends[r]) {
            Some(end) if end != 256 => end,
            _ => lo,
        };
        lo <= o && o <= hi
    })
}

impl AddressRules {
    /// The rules of the parameters in `store`.
    pub(super) fn latch(store: &Store) -> AddressRules {
        AddressRules {
            filter: (params(store, 0x2598), params(store, 0x259C)),
            operation: (params(store, 0x259F), params(store, 0x25A3)),
        }
    }

    /// The IP filter: whether the drive talks to `ip` at all.
    pub fn admits(&self, ip: Ipv4Addr) -> bool {
        matches(ip.octets(), self.filter.0, &self.filter.1)
    }

    /// The operation specification: whether `ip` may write (SLMP 4020h/0002h and /0006h,
    /// Modbus 10h, CC-Link IE Field Basic RWw); reads stay open to everyone the filter admits.
    pub fn may_operate(&self, ip: Ipv4Addr) -> bool {
        matches(ip.octets(), self.operation.0, &self.operation.1)
    }
}
