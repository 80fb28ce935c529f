//! Bit-true, cycle-true model of `crate::cic_decimator::CicDecimator`.
//!
//! Cycle-true on the ports, not register for register: the hardware's
//! back-end spends `SCHEDULE_CLOCKS` clocks on the combs and the rounding
//! of both channels, but nothing else reads or writes the comb delays in
//! that time, and the shift is held from the strobe. So the model does the
//! whole arithmetic at the strobe and publishes the result
//! `SAMPLE_TO_OUTPUT` clocks later, dropping strobes while it is busy, as
//! the hardware's schedule does.
//!
//! The hardware's 80-bit wrap-around is modelled by wrapping i128
//! arithmetic: reduction modulo 2^80 commutes with addition and
//! subtraction, so the low 80 bits of every model value equal the hardware
//! register; the output stage starts from the wrapped 80-bit comb word,
//! where the upper bits would start to matter.

use crate::cic_widths::{
    CHANNELS, DECIMATION_BITS, OUTPUT_BITS, REGISTER_BITS, SAMPLE_TO_OUTPUT, STAGES,
};

/// Wrap to an 80-bit two's complement value.
#[inline(always)]
fn wrap(x: i128) -> i128 {
    const SHIFT: u32 = 128 - REGISTER_BITS as u32;
    (x << SHIFT) >> SHIFT
}

/// `round(x / 2^shift)` (half up) of the 80-bit value `wrap(x)`, wrapped
/// to 40 bits, computed as the hardware does it:
/// floor((floor(2x / 2^shift) + 1) / 2) (`crate::cic_decimator`'s header).
#[inline(always)]
pub fn scale_output(x: i128, shift: u32) -> i64 {
    let half = (wrap(x) << 1) >> shift;
    let rounded = (half + 1) >> 1;
    const OUT_SHIFT: u32 = 128 - OUTPUT_BITS as u32;
    ((rounded << OUT_SHIFT) >> OUT_SHIFT) as i64
}

/// Cycle-true model of the two-channel CIC.
///
/// The integrators are brought up to date lazily: inputs wait in `pending`
/// and are integrated in one tight loop when the counter samples the fourth
/// integrators, the only place their values are read. The result is the
/// same register values the hardware has at that cycle.
#[derive(Clone, Debug, Default)]
pub struct CicDecimator {
    integrator: [[i128; STAGES as usize]; CHANNELS],
    pending: Vec<(i32, i32)>,
    count: u32,
    comb_delay: [[i128; STAGES as usize]; CHANNELS],
    /// Clocks of the schedule still to run after the current one (0: idle).
    busy: usize,
    /// The outputs the running schedule will publish.
    result: (i64, i64),
    y: (i64, i64),
    valid: bool,
}

impl CicDecimator {
    /// `((y1, y2), valid)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> ((i64, i64), bool) {
        (self.y, self.valid)
    }

    /// Edges from now until the one after which the output is next valid:
    /// the running schedule's last edge, or the counter's run to 0 and the
    /// schedule that sample starts. Exact with the decimation held.
    #[inline(always)]
    pub fn edges_to_valid(&self) -> u64 {
        if self.busy > 0 {
            self.busy as u64
        } else {
            u64::from(self.count) + SAMPLE_TO_OUTPUT as u64
        }
    }

    /// One clock with inputs `x = (x1, x2)`, decimation R (13-bit word) and
    /// output shift.
    #[inline(always)]
    pub fn step(&mut self, x: (i32, i32), decimation: u32, shift: u32) -> ((i64, i64), bool) {
        self.block::<false>(&[x], decimation, shift, |_, _| {});
        self.output()
    }

    /// `x.len()` clocks with `x[i]` the inputs during cycle i: `output`
    /// and `step` clock by clock, the outputs told as events,
    /// `on_valid(i, y)` for each cycle i of the block during which the
    /// output is valid (it holds otherwise). The inputs join `pending` a
    /// slice at a time, when the counter samples the integrators and at
    /// the block's end, instead of one push a clock.
    ///
    /// A clock does one of three things: a busy schedule counts down (its
    /// last clock publishes), or the idle back-end samples at the counter's
    /// 0, or nothing but the counter moves. So the block goes from event
    /// to event, the clocks between them moving only the counter
    /// (`counter_after`).
    ///
    /// `WEIGHTED`: the inputs integrated as weighted sums
    /// (`integrate_pending`), for a build with vector multiplies.
    #[inline(always)]
    pub fn block<const WEIGHTED: bool>(
        &mut self,
        x: &[(i32, i32)],
        decimation: u32,
        shift: u32,
        mut on_valid: impl FnMut(usize, (i64, i64)),
    ) {
        let n = x.len();
        let period = (decimation.wrapping_sub(1) & ((1 << DECIMATION_BITS) - 1)) + 1;
        let mut joined = 0;
        let mut t = 0;
        while t < n {
            if self.valid {
                on_valid(t, self.y);
                self.valid = false;
            }
            if self.busy > 0 {
                // The schedule's clocks (or the block's rest); the last
                // one publishes.
                let d = self.busy.min(n - t);
                self.busy -= d;
                if self.busy == 0 {
                    self.y = self.result;
                    self.valid = true;
                }
                self.count = counter_after(self.count, d, period);
                t += d;
            } else if self.count == 0 {
                // The inputs before this edge, as `step` would hold them.
                self.pending.extend_from_slice(&x[joined..t]);
                joined = t;
                self.integrate_pending::<WEIGHTED>();
                self.result = (self.comb_and_round(0, shift), self.comb_and_round(1, shift));
                self.busy = SAMPLE_TO_OUTPUT - 1;
                self.count = period - 1;
                t += 1;
            } else {
                // Idle until the counter's 0 (or the block's end).
                let d = (self.count as usize).min(n - t);
                self.count -= d as u32;
                t += d;
            }
        }
        // Integrators: the inputs enter at these edges (`integrate_pending`).
        self.pending.extend_from_slice(&x[joined..]);
    }

    /// The four combs of one channel on its sampled fourth integrator, then
    /// the output rounding.
    #[inline(always)]
    fn comb_and_round(&mut self, channel: usize, shift: u32) -> i64 {
        let mut value = self.integrator[channel][STAGES as usize - 1];
        for delay in &mut self.comb_delay[channel] {
            let previous = std::mem::replace(delay, value);
            value = value.wrapping_sub(previous);
        }
        scale_output(wrap(value), shift)
    }

    /// Play the integrators' edges for the inputs still pending but the
    /// last: the hardware's `integral` is the unsplit cascade's value of
    /// one clock earlier (`crate::cic_integrators`), so the newest input is
    /// not in it yet and stays pending.
    ///
    /// In chunks of at most `CHUNK` inputs: the cascade's values after the
    /// chunk from zero in i64, then added to the held values moved on by
    /// the chunk's edges, `integrator_power`. Every step is exact modulo
    /// 2^128, as the wrapping i128 cascade clock by clock is.
    #[inline(always)]
    fn integrate_pending<const WEIGHTED: bool>(&mut self) {
        let newest = self.pending.pop();
        for chunk in self.pending.chunks(CHUNK) {
            let [a, b] = if WEIGHTED {
                weighted_sums(chunk)
            } else {
                cascade(chunk)
            };
            let m = chunk.len() as i128;
            integrator_power(&mut self.integrator[0], m, a);
            integrator_power(&mut self.integrator[1], m, b);
        }
        self.pending.clear();
        self.pending.extend(newest);
    }
}

/// Both channels' cascades from zero after `chunk`'s inputs, clock by
/// clock: every stage takes its predecessor's value before the edge. Exact
/// in i64 for any i32 input and a chunk of at most `CHUNK`: the fourth
/// stage stays within C(512, 4) 2^31 < 2^62.4. Out of line, as the
/// whole integration was before the weighted sums (the portable build
/// ran 1.5% slower with it inlined).
#[inline(never)]
fn cascade(chunk: &[(i32, i32)]) -> [[i64; STAGES as usize]; CHANNELS] {
    let [mut a1, mut a2, mut a3, mut a4] = [0i64; STAGES as usize];
    let [mut b1, mut b2, mut b3, mut b4] = [0i64; STAGES as usize];
    for &(x1, x2) in chunk {
        a4 += a3;
        a3 += a2;
        a2 += a1;
        a1 += i64::from(x1);
        b4 += b3;
        b3 += b2;
        b2 += b1;
        b1 += i64::from(x2);
    }
    [[a1, a2, a3, a4], [b1, b2, b3, b4]]
}

/// `cascade` as sums: after m inputs from zero, stage k holds
/// `sum_j C(m - 1 - j, k - 1) x_j` (input j reaches stage k through
/// k - 1 of the m - 1 - j edges after it), so every input's products are
/// independent and a build with vector multiplies does several at once
/// (32 x 32-bit signed products: each weight is below C(511, 3) < 2^31).
/// The same values as the cascade, in the same i64 bound.
#[inline(always)]
fn weighted_sums(chunk: &[(i32, i32)]) -> [[i64; STAGES as usize]; CHANNELS] {
    let tail = CHUNK - chunk.len();
    let [w1, w2, w3] = WEIGHTS.each_ref().map(|w| &w[tail..]);
    let [mut a1, mut a2, mut a3, mut a4] = [0i64; STAGES as usize];
    let [mut b1, mut b2, mut b3, mut b4] = [0i64; STAGES as usize];
    for (((&(x1, x2), &c1), &c2), &c3) in chunk.iter().zip(w1).zip(w2).zip(w3) {
        let (x1, x2) = (i64::from(x1), i64::from(x2));
        let (c1, c2, c3) = (i64::from(c1), i64::from(c2), i64::from(c3));
        a1 += x1;
        a2 += c1 * x1;
        a3 += c2 * x1;
        a4 += c3 * x1;
        b1 += x2;
        b2 += c1 * x2;
        b3 += c2 * x2;
        b4 += c3 * x2;
    }
    [[a1, a2, a3, a4], [b1, b2, b3, b4]]
}

/// `WEIGHTS[k - 1][t]` = C(CHUNK - 1 - t, k), input t's weight in stage
/// k + 1 of a chunk of `CHUNK` inputs (`weighted_sums`; a shorter chunk
/// takes the table's tail).
static WEIGHTS: [[i32; CHUNK]; 3] = {
    let mut w = [[0; CHUNK]; 3];
    let mut t = 0;
    while t < CHUNK {
        let r = (CHUNK - 1 - t) as i64;
        w[0][t] = r as i32;
        w[1][t] = (r * (r - 1) / 2) as i32;
        w[2][t] = (r * (r - 1) * (r - 2) / 6) as i32;
        t += 1;
    }
    w
};

/// Inputs per chunk of `CicDecimator::integrate_pending`.
const CHUNK: usize = 512;

/// The decimation counter after `clocks` edges from `count`: each edge
/// counts down, and reloads `period - 1` at 0 (`period` the decimation R,
/// 2^13 for R = 0, as a 13-bit word's R - 1 wraps).
#[inline(always)]
fn counter_after(count: u32, clocks: usize, period: u32) -> u32 {
    let count_down = count as usize;
    if clocks <= count_down {
        (count_down - clocks) as u32
    } else {
        let since_reload = (clocks - count_down - 1) % period as usize;
        period - 1 - since_reload as u32
    }
}

/// One channel's integrators after `m` edges: an edge adds each stage's
/// old value to the next (`I + N`, N the shift down the cascade), so `m`
/// of them give `sum_j C(m, j) N^j` on the held values, plus `zero`, the
/// cascade's values after the same inputs from zero.
#[inline(always)]
fn integrator_power(held: &mut [i128; STAGES as usize], m: i128, zero: [i64; STAGES as usize]) {
    let [s1, s2, s3, s4] = *held;
    let c2 = m * (m - 1) / 2;
    let c3 = c2 * (m - 2) / 3;
    let z = zero.map(i128::from);
    *held = [
        s1.wrapping_add(z[0]),
        s2.wrapping_add(s1.wrapping_mul(m)).wrapping_add(z[1]),
        s3.wrapping_add(s2.wrapping_mul(m))
            .wrapping_add(s1.wrapping_mul(c2))
            .wrapping_add(z[2]),
        s4.wrapping_add(s3.wrapping_mul(m))
            .wrapping_add(s2.wrapping_mul(c2))
            .wrapping_add(s1.wrapping_mul(c3))
            .wrapping_add(z[3]),
    ];
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// round(x / 2^shift) half up, exact in i128 (no 80-bit wrap), low 40 bits.
    fn round_half_up(x: i128, shift: u32) -> i64 {
        let rounded = (x + ((1i128 << shift) >> 1)) >> shift;
        let out_shift = 128 - OUTPUT_BITS as u32;
        ((rounded << out_shift) >> out_shift) as i64
    }

    const FULL_SCALE: i128 = 1 << (REGISTER_BITS - 1);

    #[test]
    fn ties_round_up_at_every_shift() {
        for shift in 1..=40u32 {
            let half = 1i128 << (shift - 1);
            for k in [-3i128, -1, 0, 1, 5] {
                let x = (k << shift) + half;
                assert_eq!(
                    scale_output(x, shift),
                    (k + 1) as i64,
                    "tie {k}.5, shift {shift}"
                );
                assert_eq!(scale_output(x - 1, shift), k as i64, "below tie {k}.5");
            }
        }
        assert_eq!(scale_output(-7, 0), -7);
    }

    #[test]
    fn full_scale_words_match_the_exact_rounding() {
        for shift in 0..=40u32 {
            for x in [
                FULL_SCALE - 1,
                -FULL_SCALE,
                FULL_SCALE - (1 << 20),
                -FULL_SCALE + 1,
            ] {
                assert_eq!(
                    scale_output(x, shift),
                    round_half_up(x, shift),
                    "x {x}, shift {shift}"
                );
            }
        }
    }

    /// The chunked integration, as a cascade and as weighted sums, against
    /// the cascade clock by clock in wrapping i128, from held values
    /// anywhere in 128 bits, for runs
    /// around the chunk's length and the longest decimation, with the
    /// largest inputs (the i64 chunk's bound) and random ones.
    #[test]
    fn chunked_integration_is_the_cascade_clock_by_clock() {
        let mut rng = crate::test_util::Rng::new(23);
        for len in [0usize, 1, 2, 511, 512, 513, 1025, 8191] {
            for fill in 0..4 {
                let x = |i: usize, rng: &mut crate::test_util::Rng| match fill {
                    0 => (i32::MIN, i32::MIN),
                    1 => (i32::MAX, i32::MIN),
                    _ => (
                        rng.next_u64() as i32,
                        (rng.next_u64() >> 7) as i32 ^ i as i32,
                    ),
                };
                let inputs: Vec<(i32, i32)> = (0..len).map(|i| x(i, &mut rng)).collect();
                let held: [[i128; 4]; 2] = std::array::from_fn(|_| {
                    std::array::from_fn(|_| (rng.next_u64() as i128) << 64 | rng.next_u64() as i128)
                });
                let cic = |weighted: bool| {
                    let mut cic = CicDecimator {
                        integrator: held,
                        pending: inputs.clone(),
                        ..Default::default()
                    };
                    cic.pending.push((7, 7));
                    if weighted {
                        cic.integrate_pending::<true>();
                    } else {
                        cic.integrate_pending::<false>();
                    }
                    cic
                };
                let mut want = held;
                for &(x1, x2) in &inputs {
                    for (s, x) in want.iter_mut().zip([x1, x2]) {
                        s[3] = s[3].wrapping_add(s[2]);
                        s[2] = s[2].wrapping_add(s[1]);
                        s[1] = s[1].wrapping_add(s[0]);
                        s[0] = s[0].wrapping_add(i128::from(x));
                    }
                }
                for weighted in [false, true] {
                    let cic = cic(weighted);
                    let at = format!("{len} inputs, fill {fill}, weighted {weighted}");
                    assert_eq!(cic.integrator, want, "{at}");
                    assert_eq!(
                        cic.pending,
                        vec![(7, 7)],
                        "{at}: the newest input stays pending"
                    );
                }
            }
        }
    }

    /// The counter after a jump is the counter after as many edges one
    /// by one, for every period's edge cases (R = 1, a 13-bit word's 0
    /// standing for 2^13) and jumps across several reloads.
    #[test]
    fn the_counter_jumps_as_it_counts() {
        for period in [1u32, 2, 3, 7, 1000, 1 << DECIMATION_BITS] {
            for start in [0, 1, period / 2, period - 1] {
                let mut count = start;
                for clocks in 0..3 * period as usize + 5 {
                    assert_eq!(
                        counter_after(start, clocks, period),
                        count,
                        "period {period}, from {start}, {clocks} clocks"
                    );
                    count = if count == 0 { period - 1 } else { count - 1 };
                }
            }
        }
    }

    /// A block jumping from event to event is the clocks one by one
    /// (`step`, a block of one): the same valid cycles and words, and the
    /// same state after, over blocks of every length with decimations
    /// longer and shorter than the schedule (strobes dropped), 1 and the
    /// 13-bit word's 0, changed between blocks; the blocks integrate by
    /// weighted sums and as a cascade in turn.
    #[test]
    fn a_block_is_its_clocks_one_by_one() {
        let mut rng = crate::test_util::Rng::new(31);
        let (mut blocked, mut stepped) = (CicDecimator::default(), CicDecimator::default());
        let (mut events, mut steps) = (0, 0);
        for run in 0..300 {
            let decimation = match run % 6 {
                0 => 0,
                1 => 1,
                2 => SAMPLE_TO_OUTPUT as u32 - 1,
                3 => SAMPLE_TO_OUTPUT as u32 + 1,
                _ => 2 + (rng.next_u64() % 200) as u32,
            };
            let shift = (rng.next_u64() % 41) as u32;
            let n = (rng.next_u64() % 700) as usize;
            let x: Vec<(i32, i32)> = (0..n)
                .map(|_| (rng.next_u64() as i32 >> 8, rng.next_u64() as i32 >> 3))
                .collect();
            let mut told = vec![];
            // Both integrations, in turn.
            let on_valid = |t, y| told.push((t, y));
            if run % 2 == 0 {
                blocked.block::<true>(&x, decimation, shift, on_valid);
            } else {
                blocked.block::<false>(&x, decimation, shift, on_valid);
            }
            let mut seen = vec![];
            for (t, &xt) in x.iter().enumerate() {
                if stepped.output().1 {
                    seen.push((t, stepped.output().0));
                }
                stepped.step(xt, decimation, shift);
            }
            assert_eq!(told, seen, "run {run}: R {decimation}, {n} clocks");
            assert_eq!(blocked.output(), stepped.output(), "run {run}");
            assert_eq!(
                blocked.edges_to_valid(),
                stepped.edges_to_valid(),
                "run {run}"
            );
            events += told.len();
            steps += n;
        }
        assert!(
            events > 200 && steps > 50_000,
            "{events} events, {steps} clocks"
        );
    }

    proptest! {
        /// For every shift the datapath uses (0..=40) the adder-free form
        /// equals round half up of the 80-bit comb word.
        #[test]
        fn doubled_word_form_is_round_half_up(x in -FULL_SCALE..FULL_SCALE, shift in 0u32..=40) {
            prop_assert_eq!(scale_output(x, shift), round_half_up(x, shift));
        }
    }
}
