//! Bit-true model of `crate::modulation_nco::ModulationNco`.

use super::delay_ring::{latch_alternate, latch_alternate_block};
use super::sine::Sine;
use crate::quarter_wave::PHASE_BELOW_INDEX;
use crate::sine::LATENCY;
use crate::sine_table::PEAK;

const PHASE_MASK: u64 = (1 << 48) - 1;

/// Cycle-true model of the modulation NCO.
#[derive(Clone, Debug, Default)]
pub struct ModulationNco {
    phase: u64,
    /// false: the sine generator is asked for the cosine (A1); true: the sine (A2).
    turn: bool,
    sine: Sine,
    am: (i16, i16),
}

impl ModulationNco {
    /// `(am1, am2)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i16, i16) {
        self.am
    }

    /// The sine generator's output during the current cycle (the carrier
    /// tables' word during the fill).
    #[inline(always)]
    pub fn fill_word(&self) -> i16 {
        self.sine.output()
    }

    /// One clock; `fill` is the carrier table fill's request for the sine
    /// generator (`CarrierNco::fill_request`). Returns `(am1, am2)` after
    /// the edge.
    #[inline(always)]
    pub fn step(&mut self, step: u64, select: bool, fill: Option<u32>) -> (i16, i16) {
        if !select {
            self.am = (PEAK as i16, PEAK as i16);
        } else {
            latch(&mut self.am, self.turn, self.sine.output());
        }
        match fill {
            Some(phase) => self.sine.step(phase, 0),
            None => self
                .sine
                .step((self.phase >> 16) as u32, if self.turn { 0 } else { 1 }),
        };
        self.turn = !self.turn;
        self.phase = (self.phase + step) & PHASE_MASK;
        self.am
    }

    /// `(am1, am2)` during the next `out.len()` cycles, then as many edges
    /// with `step` and `select` held and no fill request: the same as
    /// `output` and `step(step, select, None)` clock by clock. The sine
    /// generator's phases and advances at edge k are arithmetic on k
    /// (`Sine::block`); then one pass latches the words as `step` does.
    /// In readout nothing latches them, and only the words left in the
    /// sine's pipeline are looked up (`Sine::skip`).
    #[inline(always)]
    pub fn block(&mut self, step: u64, select: bool, out: &mut [(i16, i16)]) {
        const CHUNK: usize = 64;
        let mut sines = [0i16; CHUNK];
        let (phase0, turn0) = (self.phase, self.turn);
        let input = |k: usize| {
            let phase = phase0.wrapping_add(step.wrapping_mul(k as u64)) & PHASE_MASK;
            let turn = turn0 ^ (k % 2 == 1);
            ((phase >> 16) as u32, if turn { 0 } else { 1 })
        };
        let n = out.len();
        if !select {
            if let Some((first, rest)) = out.split_first_mut() {
                *first = self.am;
                self.am = (PEAK as i16, PEAK as i16);
                rest.fill(self.am);
            }
            self.sine.skip(n, input);
        } else {
            for (c, chunk) in out.chunks_mut(CHUNK).enumerate() {
                let (base, m) = (c * CHUNK, chunk.len());
                let sines = &mut sines[..m];
                match steady_words(phase0, step, base, m) {
                    Some(words) => self.sine.block_words(sines, |k| {
                        let (_, advance) = input(base + k);
                        words[usize::from(advance)]
                    }),
                    None => self.sine.block(sines, |k| input(base + k)),
                }
                let turn = turn0 ^ (base % 2 == 1);
                latch_alternate_block(&mut self.am, turn, LATENCY, sines, chunk);
            }
        }
        self.turn = turn0 ^ (n % 2 == 1);
        self.phase = phase0.wrapping_add(step.wrapping_mul(n as u64)) & PHASE_MASK;
    }
}

/// The sine generator's word into the factor it belongs to, at an edge of
/// `turn`: the cosine asked for on turn false into A1, the sine into A2
/// (`latch_alternate`).
#[inline(always)]
fn latch(am: &mut (i16, i16), turn: bool, word: i16) {
    latch_alternate(am, turn, LATENCY, word);
}

/// The ROM words at advances 0 and 1 for every edge base..base + m of a
/// run from `phase0` with `step`, when one pair serves them all: the
/// phase does not wrap over those edges and stays within one ROM
/// interval (a word depends on the phase's bits from
/// `PHASE_BELOW_INDEX + 1` up, the ROM holding one word per pair of
/// intervals). At a calibration frequency the phase crosses an interval
/// every few hundred clocks.
#[inline(always)]
fn steady_words(phase0: u64, step: u64, base: usize, m: usize) -> Option<[i16; 2]> {
    const KEPT: usize = 16 + PHASE_BELOW_INDEX + 1;
    let step = step & PHASE_MASK;
    let first = phase0 + step * base as u64;
    let last = first + step * (m as u64 - 1);
    (first >> 48 == last >> 48 && (first & PHASE_MASK) >> KEPT == (last & PHASE_MASK) >> KEPT).then(
        || {
            let phase = ((first & PHASE_MASK) >> 16) as u32;
            [super::sine::sine(phase, 0), super::sine::sine(phase, 1)]
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `block` against `output` and `step` clock by clock: 400 runs of 1
    /// to 300 clocks, readout and calibration, steps of every width (the
    /// phase crossing a ROM interval every clock, every few hundred
    /// clocks or never in a run) and the 48-bit phase wrapping.
    #[test]
    fn a_block_is_its_steps() {
        let mut rng = crate::test_util::Rng::new(11);
        let (mut a, mut b) = (ModulationNco::default(), ModulationNco::default());
        for run in 0..400 {
            let width = rng.range(1, 48);
            let step = rng.next_u64() & ((1u64 << width) - 1);
            let select = rng.range(0, 3) > 0;
            let mut out = vec![(0, 0); rng.range(1, 300) as usize];
            a.block(step, select, &mut out);
            for (k, &o) in out.iter().enumerate() {
                assert_eq!(o, b.output(), "run {run} (step {step:#x}), clock {k}");
                b.step(step, select, None);
            }
            assert_eq!(
                (a.output(), a.fill_word()),
                (b.output(), b.fill_word()),
                "run {run}"
            );
            assert_eq!((a.phase, a.turn), (b.phase, b.turn), "run {run}");
        }
    }
    use gyrocal_regs::datapath::{CarrierProfile, calibration_word, q15_product};
    use std::f64::consts::TAU;

    /// The host predicts the calibration signal from
    /// `gyrocal_regs::datapath::calibration_word`: the envelope words'
    /// fundamental, computed from the ROM's words without the gateware.
    /// Here the envelopes F x A1 and F x A2 come from this model over one
    /// whole period (2^20 clocks, every interval visited 32 times) and are
    /// projected on the accumulator's phase. The two agree to the samples'
    /// spread over each word's interval, which the host's sum takes at the
    /// interval's centre: measured within 2e-7, asserted within 1e-6. The
    /// envelope's amplitude alone (amp PEAK / 2^15, what the host took
    /// before) is 3.7e-5 off at amp 260, and the test fails it.
    #[test]
    fn the_envelopes_fundamental_is_the_hosts_calibration_word() {
        let step = 1u64 << 28;
        let period = 1usize << 20;
        for amp in [1i16, 7, 259, 260, 1000, 29490, -260, i16::MAX] {
            let mut nco = ModulationNco::default();
            let mut phase = 0u64;
            let mut sums = [[0.0f64; 2]; 2];
            for n in 0..2 * period {
                let (a1, a2) = nco.step(step, true, None);
                phase = (phase + step) & PHASE_MASK;
                if n < period {
                    continue;
                }
                let theta = TAU * phase as f64 / 2f64.powi(48);
                for (k, a) in [a1, a2].into_iter().enumerate() {
                    let e = f64::from(q15_product(amp, a));
                    sums[k][0] += e * theta.cos();
                    sums[k][1] += e * theta.sin();
                }
            }
            let expected = calibration_word(CarrierProfile::Fine, amp).abs();
            for (k, [c, s]) in sums.into_iter().enumerate() {
                let fundamental = 2.0 * c.hypot(s) / period as f64 * f64::from(PEAK) / 32768.0;
                let error = fundamental / expected - 1.0;
                assert!(
                    error.abs() < 1e-6,
                    "amp {amp}, envelope {}: {fundamental} against {expected} ({error:+.2e})",
                    k + 1
                );
            }
        }
    }
}
