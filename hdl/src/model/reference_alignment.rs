//! Bit-true model of `crate::reference_alignment::ReferenceAlignment`.

const TAPS: usize = 1 << crate::reference_alignment::DELAY_BITS;

/// Cycle-true model of the two 64-word delay lines.
#[derive(Clone, Debug)]
pub struct ReferenceAlignment {
    /// Ring buffer of (ref1, ref2); `words[newest]` entered at the last edge.
    words: [(i16, i16); TAPS],
    newest: usize,
    /// The registered output.
    aligned: (i16, i16),
}

impl Default for ReferenceAlignment {
    fn default() -> Self {
        Self {
            words: [(0, 0); TAPS],
            newest: 0,
            aligned: (0, 0),
        }
    }
}

impl ReferenceAlignment {
    /// `(aligned1, aligned2)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i16, i16) {
        self.aligned
    }

    /// One clock: read the word `delay` edges old (or the input itself for
    /// a delay of 0), then write the references.
    #[inline(always)]
    pub fn step(&mut self, ref1: i16, ref2: i16, delay: u8) {
        let delay = delay as usize & (TAPS - 1);
        self.aligned = if delay == 0 {
            (ref1, ref2)
        } else {
            self.words[(self.newest + TAPS + 1 - delay) % TAPS]
        };
        self.newest = (self.newest + 1) % TAPS;
        self.words[self.newest] = (ref1, ref2);
    }

    /// `(aligned1, aligned2)` during the next `out.len()` cycles, then as
    /// many edges with `refs(i)` the references during cycle i: `output`
    /// and `step` clock by clock. The output after the edge of cycle t is
    /// the reference of cycle t - delay (a delay of 0 included), from the
    /// ring while that lies before the block.
    #[inline(always)]
    pub fn block(&mut self, refs: impl Fn(usize) -> (i16, i16), delay: u8, out: &mut [(i16, i16)]) {
        let n = out.len();
        if n == 0 {
            return;
        }
        let d = delay as usize & (TAPS - 1);
        // The reference of cycle i - TAPS <= j < 0 is in the ring.
        let before = |j: usize| self.words[(self.newest + 1 + j) % TAPS];
        let reference = |t: usize| {
            if t >= d {
                refs(t - d)
            } else {
                before(TAPS + t - d)
            }
        };
        out[0] = self.aligned;
        // Cycles before the delay reach back into the ring; the rest copy
        // the block's own references, a loop without a test.
        let early = d.min(n - 1);
        for (t, o) in out[1..=early].iter_mut().enumerate() {
            *o = before(TAPS + t - d);
        }
        for (t, o) in out[1 + early..].iter_mut().enumerate() {
            *o = refs(t);
        }
        self.aligned = reference(n - 1);
        let words: [(i16, i16); TAPS] = std::array::from_fn(|k| {
            // Ring slot k after n edges holds the reference of cycle
            // n - TAPS + ((k - newest') mod TAPS), newest' = newest + n.
            let age = (k + 2 * TAPS - 1 - (self.newest + n) % TAPS) % TAPS;
            let j = n + age;
            if j >= TAPS { refs(j - TAPS) } else { before(j) }
        });
        self.words = words;
        self.newest = (self.newest + n) % TAPS;
    }
}
