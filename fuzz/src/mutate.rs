//! A small deterministic mutator for the corpus replay test: bit flips, byte sets, cuts,
//! duplications and interesting numbers over a seed, so `cargo test` (on the stable
//! toolchain, without libFuzzer) exercises each target beyond its seeds.

/// xorshift64*: deterministic and dependency-free.
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed` (0 is replaced).
    pub fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// A number below `n` (0 for `n` = 0).
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next_u64() % n as u64) as usize
        }
    }
}

/// Values that tend to sit on a decoder's edges.
const INTERESTING: [u64; 8] = [0, 1, 0x7F, 0x80, 0xFF, 0xFFFF, 0xFFFF_FFFF, u64::MAX];

/// `seed` with one to four random mutations.
pub fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut out = seed.to_vec();
    for _ in 0..=rng.below(4) {
        let at = rng.below(out.len());
        match rng.below(6) {
            0 if !out.is_empty() => out[at] ^= 1 << rng.below(8),
            1 if !out.is_empty() => out[at] = rng.next_u64() as u8,
            2 => out.truncate(at),
            3 => {
                let len = rng.below(out.len() - at + 1).min(64);
                let copy = out[at..at + len].to_vec();
                out.splice(at..at, copy);
            }
            4 => {
                let v = INTERESTING[rng.below(INTERESTING.len())].to_le_bytes();
                let width = [1, 2, 4, 8][rng.below(4)];
                let end = (at + width).min(out.len());
                out[at..end].copy_from_slice(&v[..end - at]);
            }
            _ => out.insert(at, rng.next_u64() as u8),
        }
    }
    out
}
