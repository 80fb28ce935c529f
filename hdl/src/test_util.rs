//! Helpers shared by the blocks' tests: a seeded generator and the stimulus
//! shapes every DSP block is tried with.

/// SplitMix64: small, seedable, good enough for test stimulus.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator with the given seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `lo..=hi`.
    pub fn range(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next_u64() % ((hi - lo) as u64 + 1)) as i64
    }

    /// A 16-bit word biased toward the extremes: a quarter of the draws are
    /// -32768, -32767, 32767 or 0, the rest uniform.
    pub fn word16(&mut self) -> i16 {
        match self.next_u64() % 16 {
            0 => i16::MIN,
            1 => -32767,
            2 => i16::MAX,
            3 => 0,
            _ => self.next_u64() as i16,
        }
    }
}
