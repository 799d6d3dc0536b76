//! CC-Link IE Field Network Basic cyclic frames as the MR-JE-C exchanges them (MR-JE-C manual
//! §2.2.1–§2.5): the master's request (UDP 61450, directed broadcast, up to 16 stations' RY and
//! RWw) and the slave's unicast response (its RX and RWr). The manual gives no byte layout; it
//! follows the CLPA layout as an independent open implementation (rt-labs c-link) has it, as
//! the spec extract records. One station (64 RY/RX bits, 32 RWw/RWr words) per MR-JE-C.

mod frame;
pub mod io_thread;
pub mod master;

pub use frame::{
    CyclicError, CyclicRequest, CyclicResponse, EndCode, StationData, LINK_BITS_BYTES,
    LINK_WORDS_BYTES, MAX_STATIONS, RESPONSE_SIZE,
};

/// UDP port of the cyclic exchange.
pub const CYCLIC_PORT: u16 = 61450;
/// UDP port of NodeSearch and IPAddressSet.
pub const SEARCH_PORT: u16 = 61451;

/// RY(n+3)F / RX(n+3)F: CSR (cyclic communication ready command) from the master, SSR (cyclic
/// communication ready) from the drive (manual §2.3.2 Table 2.1): bit 63, byte 7, mask 80h.
pub const READY_BIT: usize = 63;

/// Whether bit `bit` of an RY/RX block is on.
pub fn bit(block: &[u8; LINK_BITS_BYTES], bit: usize) -> bool {
    block[bit / 8] & (1 << (bit % 8)) != 0
}

/// Sets bit `bit` of an RY/RX block.
pub fn set_bit(block: &mut [u8; LINK_BITS_BYTES], bit: usize, on: bool) {
    if on {
        block[bit / 8] |= 1 << (bit % 8);
    } else {
        block[bit / 8] &= !(1 << (bit % 8));
    }
}
