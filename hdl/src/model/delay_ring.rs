//! A pipeline of fixed latency as the models keep it: the values in
//! flight in a ring, the current output at its head. The ROM sine
//! (`super::sine`) and the carrier NCO (`super::carrier_nco`) compute a
//! word from the phase at an edge and publish it `L` edges later; the
//! stages between change nothing the ports show, so the model keeps the
//! `L` words in flight instead of the stages' registers.

/// `L` values in flight; `pipe[head]` is the output during the current
/// cycle, the one that entered `L` edges ago.
#[derive(Clone, Copy, Debug)]
pub struct DelayRing<T, const L: usize> {
    pipe: [T; L],
    head: usize,
}

impl<T: Copy + Default, const L: usize> Default for DelayRing<T, L> {
    fn default() -> Self {
        Self {
            pipe: [T::default(); L],
            head: 0,
        }
    }
}

impl<T: Copy, const L: usize> DelayRing<T, L> {
    /// The output during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> T {
        self.pipe[self.head]
    }

    /// One edge at which `value` enters; returns the output after it.
    #[inline(always)]
    pub fn step(&mut self, value: T) -> T {
        self.pipe[self.head] = value;
        self.head = if self.head + 1 == L { 0 } else { self.head + 1 };
        self.output()
    }

    /// The outputs during the next `out.len()` cycles, then as many edges
    /// with `entering(k)` entering at edge `k`: the same as `output` and
    /// `step(entering(k))` for k = 0, 1, ... The outputs from cycle `L` on
    /// are `entering(i - L)`, so a caller whose `entering` is arithmetic on
    /// `k` gets a loop without a carried dependence.
    #[inline(always)]
    pub fn block(&mut self, out: &mut [T], entering: impl Fn(usize) -> T) {
        let n = out.len();
        let old = *self;
        let in_flight = |i: usize| old.pipe[(old.head + i) % L];
        for (i, o) in out.iter_mut().enumerate().take(L) {
            *o = in_flight(i);
        }
        for (i, o) in out.iter_mut().enumerate().skip(L) {
            *o = entering(i - L);
        }
        self.skip(n, entering);
    }

    /// `n` edges with `entering(k)` entering at edge k, as `block` plays
    /// them, without the outputs: only the last `L` values entering are
    /// computed.
    #[inline(always)]
    pub fn skip(&mut self, n: usize, entering: impl Fn(usize) -> T) {
        let old = *self;
        let in_flight = |i: usize| old.pipe[(old.head + i) % L];
        // After n edges the ring holds the outputs during cycles n..n + L.
        for (j, p) in self.pipe.iter_mut().enumerate() {
            let i = n + j;
            *p = if i < L { in_flight(i) } else { entering(i - L) };
        }
        self.head = 0;
    }
}

/// A word leaving a pipeline of `latency` edges that two channels share
/// on alternate edges (channel 1 entering on turn false, as the envelope
/// multiplier and the modulation sine are used), into its channel's half
/// of `pair`, at an edge of `turn`.
#[inline(always)]
pub fn latch_alternate(pair: &mut (i16, i16), turn: bool, latency: usize, word: i16) {
    if latches_first(turn, latency) {
        pair.0 = word;
    } else {
        pair.1 = word;
    }
}

/// Whether a word leaving a pipeline of `latency` edges at an edge of
/// `turn` goes into the pair's first half (channel 1's).
#[inline(always)]
fn latches_first(turn: bool, latency: usize) -> bool {
    turn == (latency % 2 == 1)
}

/// `latch_alternate` over a run of edges whose turn alternates from
/// `turn` at edge 0: `out[k]` is `pair` during cycle k, before edge k
/// latches `words[k]`. Two edges at a time, whose halves the run's first
/// turn fixes, so that no edge tests its turn.
#[inline(always)]
pub fn latch_alternate_block(
    pair: &mut (i16, i16),
    turn: bool,
    latency: usize,
    words: &[i16],
    out: &mut [(i16, i16)],
) {
    debug_assert_eq!(words.len(), out.len());
    let first_low = latches_first(turn, latency);
    let mut held = *pair;
    for (o, w) in out.chunks_exact_mut(2).zip(words.chunks_exact(2)) {
        o[0] = held;
        if first_low {
            held.0 = w[0];
        } else {
            held.1 = w[0];
        }
        o[1] = held;
        if first_low {
            held.1 = w[1];
        } else {
            held.0 = w[1];
        }
    }
    let m = out.len();
    if m % 2 == 1 {
        // The last edge is even: its turn is the first's.
        out[m - 1] = held;
        latch_alternate(&mut held, turn, latency, words[m - 1]);
    }
    *pair = held;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::Rng;

    /// `latch_alternate_block` over runs of 0 to 9 edges, either first
    /// turn and latency parity: `latch_alternate` edge by edge.
    #[test]
    fn a_latch_block_is_its_edges() {
        let mut rng = Rng::new(11);
        for n in 0..10 {
            for turn in [false, true] {
                for latency in [2, 3] {
                    let words: Vec<i16> = (0..n).map(|_| rng.next_u64() as i16).collect();
                    let start = (rng.next_u64() as i16, rng.next_u64() as i16);
                    let (mut pair, mut out) = (start, vec![(0, 0); n]);
                    latch_alternate_block(&mut pair, turn, latency, &words, &mut out);
                    let mut stepped = start;
                    for (k, &w) in words.iter().enumerate() {
                        assert_eq!(out[k], stepped, "n {n} turn {turn} latency {latency} k {k}");
                        latch_alternate(&mut stepped, turn ^ (k % 2 == 1), latency, w);
                    }
                    assert_eq!(pair, stepped);
                }
            }
        }
    }

    /// `block` over runs of 0 to 12 cycles, the ring's head anywhere,
    /// against `output` and `step` cycle by cycle.
    #[test]
    fn a_block_is_its_steps() {
        let mut rng = Rng::new(5);
        let (mut ring, mut stepped) = (
            DelayRing::<u32, 5>::default(),
            DelayRing::<u32, 5>::default(),
        );
        let mut k0 = 0u32;
        for _ in 0..200 {
            let n = rng.range(0, 12) as usize;
            let salt = rng.range(0, 1000) as u32;
            let entering = |k: usize| (k as u32 + k0).wrapping_mul(2654435761) ^ salt;
            let mut out = vec![0; n];
            ring.block(&mut out, entering);
            for (k, &o) in out.iter().enumerate() {
                assert_eq!(o, stepped.output(), "cycle {k} of {n}");
                stepped.step(entering(k));
            }
            assert_eq!(ring.output(), stepped.output());
            k0 += n as u32;
        }
    }
}
