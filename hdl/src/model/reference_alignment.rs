//! Bit-true model of `crate::reference_alignment::ReferenceAlignment`.

const TAPS: usize = 1 << crate::reference_alignment::DELAY_BITS;

/// Cycle-true model of the two 64-tap delay lines.
#[derive(Clone, Debug)]
pub struct ReferenceAlignment {
    /// Ring buffer of (ref1, ref2); `taps[newest]` entered at the last edge.
    taps: [(i16, i16); TAPS],
    newest: usize,
}

impl Default for ReferenceAlignment {
    fn default() -> Self {
        Self {
            taps: [(0, 0); TAPS],
            newest: 0,
        }
    }
}

impl ReferenceAlignment {
    /// `(aligned1, aligned2)` during the current cycle for the given delay
    /// (a combinational read of the taps).
    #[inline(always)]
    pub fn output(&self, delay: u8) -> (i16, i16) {
        self.taps[(self.newest + TAPS - (delay as usize & (TAPS - 1))) % TAPS]
    }

    /// One clock: shift the references in.
    #[inline(always)]
    pub fn step(&mut self, ref1: i16, ref2: i16) {
        self.newest = (self.newest + 1) % TAPS;
        self.taps[self.newest] = (ref1, ref2);
    }
}
