//! Bit-true model of `crate::iir_lowpass::IirLowpass` (both channels).
//!
//! It runs the hardware's micro-program (`crate::iir_program::PROGRAM`)
//! word by word with the same registers: program counter, ROM output and
//! the word register after it,
//! digit RAM and its read register, the two operand registers, the product
//! register, the column accumulator and the output staging register. Each
//! `step` is one clock: every register takes the value the hardware's takes
//! at the rising edge, so the model and the hardware agree on every cycle,
//! including the clocks at which each coefficient is read.
//!
//! `reference` (tests) is the arithmetic of record, the header's equations
//! in i128; a property test shows the program computes exactly it.

use crate::iir_program::{
    ACCUMULATOR_BITS, AccumulatorOp, DIGIT_BITS, Emit, MicroWord, PROGRAM, STATE_TOP_BITS,
    factor_value, physical_address,
};

pub use gyrocal_regs::Coefficients;

mod slots;

/// Sign-extend the low `bits` bits of `x`.
#[inline(always)]
fn wrap(x: i64, bits: usize) -> i64 {
    (x << (64 - bits)) >> (64 - bits)
}

/// Low digit mask.
const DIGIT_MASK: i64 = (1 << DIGIT_BITS) - 1;

/// Words of the digit RAM.
const RAM_WORDS: usize = 1 << crate::iir_program::RAM_ADDRESS_BITS;

/// Factor selects: 5 bits (`Factor::encode`).
const FACTOR_SELECTS: usize = 1 << 5;

/// `factor_value` of every factor select for one set of coefficients,
/// looked up by a busy clock (`IirLowpass::run_without_input`): made
/// once for the coefficients a run holds.
#[derive(Clone, Debug)]
pub struct Factors([i64; FACTOR_SELECTS]);

impl Factors {
    /// The operands of the coefficients `k`.
    pub fn new(k: &Coefficients) -> Self {
        Self(std::array::from_fn(|select| factor_value(select as u8, k)))
    }
}

/// Cycle-true model of the two-channel filter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IirLowpass {
    /// ROM address (0 = idle).
    pc: usize,
    /// Index of the word in the ROM's output register.
    rom_q: usize,
    /// Index of the word in the fabric register after it (the one executing).
    word: usize,
    /// Sample counter modulo 3 (slot rotation).
    base: u8,
    /// Captured inputs.
    x: [i64; 2],
    /// Digit RAM (an array, not a `Vec`: a copy of the whole filter in
    /// locals, `run_without_input`, allocates nothing).
    ram: [i16; RAM_WORDS],
    /// RAM read register.
    ram_q: i16,
    /// Operand registers.
    a: i64,
    b: i64,
    /// Product register.
    p: i64,
    /// Column accumulator.
    acc: i64,
    /// Output staging register: six digits, the newest last.
    stage: [i64; 6],
    /// Outputs.
    z: [i64; 2],
    z_valid: bool,
    /// `PROGRAM`'s words, dereferenced once instead of at every clock.
    words: &'static [MicroWord],
}

impl Default for IirLowpass {
    fn default() -> Self {
        Self {
            pc: 0,
            rom_q: 0,
            word: 0,
            base: 0,
            x: [0; 2],
            ram: [0; RAM_WORDS],
            ram_q: 0,
            a: 0,
            b: 0,
            p: 0,
            acc: 0,
            stage: [0; 6],
            z: [0; 2],
            z_valid: false,
            words: &PROGRAM.words,
        }
    }
}

impl IirLowpass {
    /// `(z1, z2, z_valid)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i64, i64, bool) {
        (self.z[0], self.z[1], self.z_valid)
    }

    /// True while a schedule runs (strobes are dropped).
    #[inline(always)]
    pub fn busy(&self) -> bool {
        self.pc != 0
    }

    /// True while no schedule runs and none is about to leave its
    /// pipeline: an edge can publish z only after the filter accepts a
    /// sample.
    #[inline(always)]
    pub fn idle(&self) -> bool {
        self.pc == 0 && self.rom_q == 0 && self.word == 0
    }

    /// Edges from now to the one that publishes z, while a schedule's
    /// publishing word (the program's last) is still to run: the edges
    /// run the words `word`, `rom_q`, then `pc` on to the end, and a
    /// running schedule takes no strobe. `None` when idle.
    #[inline(always)]
    pub fn edges_to_publish(&self) -> Option<u64> {
        let last = self.words.len() - 1;
        if self.word == last {
            Some(1)
        } else if self.rom_q == last {
            Some(2)
        } else if self.pc != 0 {
            Some(3 + (last - self.pc) as u64)
        } else {
            debug_assert!(self.idle(), "a schedule's tail holds its last word");
            None
        }
    }

    /// z1 and z2 from the staging register: digits 0..2 are z1 (45 bits),
    /// 3..5 z2; each keeps 40 bits.
    #[inline(always)]
    fn staged(stage: &[i64; 6]) -> [i64; 2] {
        std::array::from_fn(|c| {
            let d = &stage[3 * c..3 * c + 3];
            wrap(
                d[0] | d[1] << DIGIT_BITS | d[2] << (2 * DIGIT_BITS),
                crate::iir_widths::SAMPLE_BITS,
            )
        })
    }

    /// The input digit `select` (channel * 3 + digit) as stored in RAM.
    #[inline(always)]
    fn input_digit(&self, select: u8) -> i64 {
        let x = self.x[select as usize / 3];
        match select % 3 {
            0 => x & DIGIT_MASK,
            1 => (x >> DIGIT_BITS) & DIGIT_MASK,
            _ => x >> (2 * DIGIT_BITS),
        }
    }

    /// `step` without a sample (`x_valid` low) for at most `clocks` clocks,
    /// stopping at the first clock the filter is idle at (where a step
    /// without a sample would only clear z_valid): returns the clocks
    /// played, calling `on_z(i, z)` when clock i (from 0) publishes z.
    /// `factors` are the coefficients' (`Factors::new`). The registers
    /// live in locals over the run, and each word's addresses and
    /// operations come from a table built once (`slots`), where decoded
    /// at every clock a busy clock took 6.4 ns.
    #[inline(always)]
    pub fn run_without_input(
        &mut self,
        clocks: usize,
        factors: &Factors,
        on_z: impl FnMut(usize, (i64, i64)),
    ) -> usize {
        self.run_slots(clocks, factors, on_z)
    }

    /// One clock with inputs `x` and strobe `x_valid`; returns
    /// `(z1, z2, z_valid)` after the edge.
    #[inline(always)]
    pub fn step(&mut self, x: (i64, i64), x_valid: bool, k: &Coefficients) -> (i64, i64, bool) {
        if self.idle() && !x_valid {
            // Idle: word 0 does nothing that a schedule reads back.
            self.z_valid = false;
            return self.output();
        }
        let w: MicroWord = self.words[self.word];
        let accept = self.pc == 0 && x_valid;
        // Values at the rising edge, all from the current registers.
        let ram_q = self.ram[physical_address(w.read, self.base)];
        let digit = self.acc & DIGIT_MASK;
        let top_digit = wrap(self.acc, DIGIT_BITS);
        match w.emit {
            Emit::None => {}
            Emit::Stage => {
                self.stage.rotate_left(1);
                self.stage[5] = digit;
            }
            e => {
                let value = match e {
                    Emit::Digit => digit,
                    Emit::TopDigit => top_digit,
                    _ => self.input_digit(w.x_select),
                };
                self.ram[physical_address(w.write, self.base)] = value as i16;
            }
        }
        let p = self.p;
        self.acc = wrap(
            match w.op {
                AccumulatorOp::Hold => self.acc,
                AccumulatorOp::Start => p + if w.round { 1 << 29 } else { 0 },
                AccumulatorOp::Add => self.acc + p,
                AccumulatorOp::Shift => (self.acc >> DIGIT_BITS) + p,
            },
            ACCUMULATOR_BITS,
        );
        self.p = self.a * self.b;
        self.a = if w.wrap {
            wrap(self.ram_q as i64, STATE_TOP_BITS)
        } else {
            self.ram_q as i64
        };
        self.b = factor_value(w.factor, k);
        self.ram_q = ram_q;
        if w.publish {
            self.z = IirLowpass::staged(&self.stage);
        }
        self.z_valid = w.publish;
        self.word = self.rom_q;
        self.rom_q = self.pc;
        self.pc = if accept || (self.pc != 0 && self.pc + 1 < self.words.len()) {
            self.pc + 1
        } else {
            0
        };
        if accept {
            self.x = [x.0, x.1];
            self.base = (self.base + 1) % 3;
        }
        self.output()
    }
}

/// The arithmetic of record in i128: the header's equations, one sample at
/// a time, every register wrapping at its recorded width; it also records
/// each register's largest exact magnitude and whether any wrapped (the
/// overflow bounds), and runs the same recursion in f64.
#[cfg(test)]
pub mod reference {
    use crate::iir_lowpass::{
        ACCUMULATOR_BITS, COEFFICIENT_FRACTION_BITS, GUARD_BITS, OPERAND_BITS, SAMPLE_BITS,
        STATE_BITS,
    };

    fn wrap(x: i128, bits: usize) -> i128 {
        (x << (128 - bits)) >> (128 - bits)
    }

    /// The registers of record, in the order a sample computes them.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub enum Register {
        /// (x + 2 x0 + x1) 2^16, the numerator operand.
        V,
        /// 2 y1 - y2, the feedback operand.
        Feedback,
        /// The biquad's accumulator, about y 2^30.
        AccY,
        /// Feedback - u, the RC difference's feedback part.
        FeedbackMinusU,
        /// The difference's accumulator, about (y - u) 2^30.
        AccD,
        /// y, the biquad state.
        Y,
        /// y - u, the RC section's operand.
        Difference,
        /// The RC section's accumulator, about u 2^30.
        AccU,
        /// u, the RC state.
        U,
        /// u + 2^15, before the output rounding's shift.
        Rounded,
        /// z, the output.
        Z,
    }

    impl Register {
        /// Every register.
        pub const ALL: [Register; 11] = [
            Register::V,
            Register::Feedback,
            Register::AccY,
            Register::FeedbackMinusU,
            Register::AccD,
            Register::Y,
            Register::Difference,
            Register::AccU,
            Register::U,
            Register::Rounded,
            Register::Z,
        ];

        /// Its recorded width (two's complement).
        pub fn bits(self) -> usize {
            match self {
                Register::V
                | Register::Feedback
                | Register::FeedbackMinusU
                | Register::Difference => OPERAND_BITS,
                Register::AccY | Register::AccD | Register::AccU => ACCUMULATOR_BITS,
                Register::Y | Register::U | Register::Rounded => STATE_BITS,
                Register::Z => SAMPLE_BITS,
            }
        }
    }

    /// The largest exact magnitude of each register (index: its place in
    /// `Register::ALL`), and whether any value wrapped.
    #[derive(Clone, Copy, Debug, Default)]
    pub struct Peaks {
        /// Largest |value| before wrapping.
        pub max: [u128; 11],
        /// Some value did not fit its register.
        pub wrapped: bool,
    }

    /// One channel's registers.
    #[derive(Clone, Copy, Debug, Default)]
    pub struct Channel {
        x0: i64,
        x1: i64,
        y1: i128,
        y2: i128,
        u: i128,
        /// Peaks since the channel was made.
        pub peaks: Peaks,
    }

    impl Channel {
        /// `x` wrapped to register `r`'s width, recorded in the peaks.
        fn fit(&mut self, x: i128, r: Register) -> i128 {
            let w = wrap(x, r.bits());
            let slot = &mut self.peaks.max[r as usize];
            *slot = (*slot).max(x.unsigned_abs());
            self.peaks.wrapped |= w != x;
            w
        }

        /// Filter one sample; returns z.
        pub fn sample(&mut self, x: i64, k: &super::Coefficients) -> i64 {
            use Register as R;
            let f = COEFFICIENT_FRACTION_BITS;
            let half = 1i128 << (f - 1);
            let v = self.fit(
                (x as i128 + 2 * self.x0 as i128 + self.x1 as i128) << GUARD_BITS,
                R::V,
            );
            let feedback = self.fit(2 * self.y1 - self.y2, R::Feedback);
            let products = k.k1 as i128 * self.y1 + k.k2 as i128 * self.y2 + k.k0 as i128 * v;
            let acc_y = self.fit((feedback << f | half) + products, R::AccY);
            let fed = self.fit(feedback - self.u, R::FeedbackMinusU);
            let acc_d = self.fit((fed << f | half) + products, R::AccD);
            let y = self.fit(acc_y >> f, R::Y);
            let difference = self.fit(acc_d >> f, R::Difference);
            let t = self.fit((self.u << f | half) + k.alpha as i128 * difference, R::AccU);
            self.u = self.fit(t >> f, R::U);
            (self.x1, self.x0, self.y2, self.y1) = (self.x0, x, self.y1, y);
            let rounded = self.fit(self.u + (1 << (GUARD_BITS - 1)), R::Rounded);
            self.fit(rounded >> GUARD_BITS, R::Z) as i64
        }
    }

    /// The linear registers of one sample of the f64 recursion, in input
    /// units (the fixed-point states carry 2^16 more).
    #[derive(Clone, Copy, Debug, Default)]
    pub struct FloatSample {
        /// 2 y1 - y2.
        pub feedback: f64,
        /// Feedback - u (before the sample).
        pub feedback_minus_u: f64,
        /// y.
        pub y: f64,
        /// y - u (u before the sample).
        pub difference: f64,
        /// u, which z rounds.
        pub u: f64,
    }

    /// The same recursion in f64 with the quantized coefficients: the
    /// fixed-point one may differ from it only by its roundings.
    pub fn float_run(k: &super::Coefficients, x: &[i64]) -> Vec<FloatSample> {
        let s = 2f64.powi(COEFFICIENT_FRACTION_BITS as i32);
        let (k0, k1, k2, a) = (
            k.k0 as f64 / s,
            k.k1 as f64 / s,
            k.k2 as f64 / s,
            k.alpha as f64 / s,
        );
        let (mut x1, mut x2, mut y1, mut y2, mut u) = (0.0, 0.0, 0.0, 0.0, 0.0);
        x.iter()
            .map(|&x0| {
                let x0 = x0 as f64;
                let feedback = 2.0 * y1 - y2;
                let y = feedback + k0 * (x0 + 2.0 * x1 + x2) + k1 * y1 + k2 * y2;
                let out = FloatSample {
                    feedback,
                    feedback_minus_u: feedback - u,
                    y,
                    difference: y - u,
                    u: u + a * (y - u),
                };
                (x2, x1, y2, y1, u) = (x1, x0, y1, y, out.u);
                out
            })
            .collect()
    }

    /// The input of `n` samples, each +-`full_scale`, that drives the
    /// linear register whose impulse response is `h` to `full_scale` times
    /// sum |h[0..n]| at the last sample: the signs of h read backwards
    /// (times `sign`).
    pub fn worst_case_input(h: &[f64], n: usize, full_scale: i64, sign: i64) -> Vec<i64> {
        (0..n)
            .map(|i| sign * full_scale * if h[n - 1 - i] < 0.0 { -1 } else { 1 })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::reference::Channel;
    use super::*;
    use crate::filter_design::{self, MAX_CUTOFF_RATIO, MIN_CUTOFF_RATIO, MIN_DECIMATION};
    use crate::iir_lowpass::{LATENCY, SCHEDULE_CLOCKS};
    use proptest::prelude::*;

    /// Largest 40-bit input magnitude.
    const X_LIMIT: i64 = (1 << 39) - 1;

    /// Coefficients a user can get: a design from random cut-offs within
    /// `MIN_CUTOFF_RATIO..=MAX_CUTOFF_RATIO` of f_z and a random decimation.
    fn designed() -> impl Strategy<Value = Coefficients> {
        (MIN_DECIMATION..=4096u32, 0.0..1.0f64, 0.0..1.0f64).prop_filter_map(
            "unstable once quantized",
            |(r, b, c)| {
                let fz = 50e6 / r as f64;
                let ratio =
                    |t: f64| MIN_CUTOFF_RATIO * (MAX_CUTOFF_RATIO / MIN_CUTOFF_RATIO).powf(t);
                filter_design::design(50e6, r, fz * ratio(b), fz * ratio(c))
                    .ok()
                    .map(|d| d.coefficients)
            },
        )
    }

    /// Any 32-bit register values: the program must match the reference
    /// bit for bit even where the recursion overflows and wraps.
    fn arbitrary() -> impl Strategy<Value = Coefficients> {
        (any::<i32>(), any::<i32>(), any::<i32>(), any::<i32>())
            .prop_map(|(k0, k1, k2, alpha)| Coefficients { k0, k1, k2, alpha })
    }

    /// Feed `samples` with the given gaps (strobe, then gap - 1 clocks with
    /// extra strobes where `extra` says, which must be dropped); return the
    /// z pairs seen with z_valid and check when they come.
    fn run_model(k: &Coefficients, samples: &[(i64, i64, usize, bool)]) -> Vec<(i64, i64)> {
        let mut model = IirLowpass::default();
        let mut out = vec![];
        let mut strobes = vec![];
        let mut cycle = 0;
        // The last sample's z comes LATENCY clocks after its strobe.
        let tail = [(0, 0, LATENCY, false)];
        for (i, &(x1, x2, gap, extra)) in samples.iter().chain(&tail).enumerate() {
            for n in 0..gap {
                let strobe = (n == 0 || (extra && n == gap / 2)) && i < samples.len();
                let x = if n == 0 { (x1, x2) } else { (-x2, x1 / 3) };
                if n == 0 && strobe {
                    strobes.push(cycle);
                }
                let (z1, z2, valid) = model.step(x, strobe, k);
                cycle += 1;
                if valid {
                    // During cycle `cycle` (after this edge), LATENCY after its strobe.
                    assert_eq!(cycle - strobes[out.len()], LATENCY, "z_valid timing");
                    out.push((z1, z2));
                }
            }
        }
        out
    }

    fn run_reference(k: &Coefficients, samples: &[(i64, i64, usize, bool)]) -> Vec<(i64, i64)> {
        let (mut c1, mut c2) = (Channel::default(), Channel::default());
        samples
            .iter()
            .map(|&(x1, x2, _, _)| (c1.sample(x1, k), c2.sample(x2, k)))
            .collect()
    }

    fn stimulus() -> impl Strategy<Value = Vec<(i64, i64, usize, bool)>> {
        let gap = prop_oneof![Just(SCHEDULE_CLOCKS), SCHEDULE_CLOCKS..SCHEDULE_CLOCKS + 40];
        prop::collection::vec(
            (
                -X_LIMIT - 1..=X_LIMIT,
                -X_LIMIT - 1..=X_LIMIT,
                gap,
                any::<bool>(),
            ),
            20..60,
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn program_computes_the_arithmetic_of_record_with_designed_coefficients(
            k in designed(),
            samples in stimulus(),
        ) {
            prop_assert_eq!(run_model(&k, &samples), run_reference(&k, &samples));
        }

        #[test]
        fn program_computes_the_arithmetic_of_record_with_any_register_values(
            k in arbitrary(),
            samples in stimulus(),
        ) {
            prop_assert_eq!(run_model(&k, &samples), run_reference(&k, &samples));
        }
    }

    #[test]
    fn extremes_match_the_reference() {
        // The most negative and largest inputs and coefficients, held.
        for k in [
            Coefficients {
                k0: i32::MIN,
                k1: i32::MIN,
                k2: i32::MIN,
                alpha: i32::MIN,
            },
            Coefficients {
                k0: i32::MAX,
                k1: i32::MAX,
                k2: i32::MAX,
                alpha: i32::MAX,
            },
            Coefficients {
                k0: i32::MAX,
                k1: i32::MIN,
                k2: i32::MAX,
                alpha: i32::MIN,
            },
        ] {
            for x in [X_LIMIT, -X_LIMIT - 1] {
                let samples = vec![(x, -x - 1, SCHEDULE_CLOCKS, false); 40];
                assert_eq!(
                    run_model(&k, &samples),
                    run_reference(&k, &samples),
                    "{k:?} {x}"
                );
            }
        }
    }

    /// Designs at the corners of the supported range: the least decimation,
    /// one with a CIC gain near 1/2 (R = 182) and the largest, each with
    /// either cut-off at either end of its range (`filter_design`).
    fn corner_designs() -> Vec<filter_design::FilterDesign> {
        let mut out = Vec::new();
        for r in [MIN_DECIMATION, 182, 4096] {
            let fz = 50e6 / r as f64;
            for b in [MIN_CUTOFF_RATIO, 0.02, MAX_CUTOFF_RATIO] {
                for c in [MIN_CUTOFF_RATIO, MAX_CUTOFF_RATIO] {
                    out.push(filter_design::design(50e6, r, b * fz, c * fz).unwrap());
                }
            }
        }
        out
    }

    /// The impulse response of each linear register (f64, input units) and
    /// the length after which its tail is below 1e-9 of its l1 norm.
    fn impulse_responses(k: &Coefficients) -> (Vec<[f64; 5]>, usize) {
        let mut impulse = vec![0i64; 20_000];
        impulse[0] = 1;
        let h: Vec<[f64; 5]> = reference::float_run(k, &impulse)
            .into_iter()
            .map(|s| [s.feedback, s.feedback_minus_u, s.y, s.difference, s.u])
            .collect();
        // tail[n][j] = sum over m >= n of |h[m][j]|.
        let mut tail = vec![[0f64; 5]; h.len() + 1];
        for n in (0..h.len()).rev() {
            for j in 0..5 {
                tail[n][j] = tail[n + 1][j] + h[n][j].abs();
            }
        }
        let n = (0..h.len())
            .find(|&n| (0..5).all(|j| tail[n][j] < 1e-9 * tail[0][j]))
            .expect("the impulse response decays within 20000 samples");
        (h, n)
    }

    #[test]
    fn worst_case_sequences_fit_every_register() {
        // Header of crate::iir_lowpass, "Overflow bound". x is the CIC
        // output for mixer words of at most 2^30 (a product of two 16-bit
        // words): |x| <= 2^38 G + 1/2 with G the CIC gain. Each linear
        // register (the five of `FloatSample`) is driven by the sign
        // sequence of its own impulse response at that full scale, both
        // signs; it must reach x_max times the l1 norm of its response
        // (the stimulus is the worst case) and no register may wrap. The
        // bit-true model gives the same z on the worst case of u.
        use reference::Register as R;
        let linear = [R::Feedback, R::FeedbackMinusU, R::Y, R::Difference, R::U];
        let mut worst = [0u128; 11];
        let mut largest_l1 = [0f64; 5];
        for d in corner_designs() {
            let k = d.coefficients;
            let full_scale = ((1u64 << 38) as f64 * d.cic_gain).ceil() as i64;
            let (h, n) = impulse_responses(&k);
            for (j, &register) in linear.iter().enumerate() {
                let response: Vec<f64> = h.iter().map(|v| v[j]).collect();
                let l1: f64 = response.iter().map(|v| v.abs()).sum();
                let l1_n: f64 = response[..n].iter().map(|v| v.abs()).sum();
                largest_l1[j] = largest_l1[j].max(l1 * d.cic_gain);
                for sign in [1, -1] {
                    let x = reference::worst_case_input(&response, n, full_scale, sign);
                    let mut channel = Channel::default();
                    let z: Vec<i64> = x.iter().map(|&v| channel.sample(v, &k)).collect();
                    let peaks = channel.peaks;
                    assert!(
                        !peaks.wrapped,
                        "R {} {register:?}: a register wrapped",
                        d.decimation
                    );
                    let scale = (1u64 << crate::iir_widths::GUARD_BITS) as f64;
                    let peak = peaks.max[register as usize] as f64;
                    let (low, high) = (
                        full_scale as f64 * l1_n * scale,
                        full_scale as f64 * l1 * scale,
                    );
                    assert!(
                        peak >= low - scale && peak <= high + scale,
                        "R {} {register:?}: peak {peak:e}, bound {high:e}",
                        d.decimation
                    );
                    for (w, p) in worst.iter_mut().zip(peaks.max) {
                        *w = (*w).max(p);
                    }
                    if register == R::U && sign == 1 {
                        let mut mirror = Channel::default();
                        let want: Vec<(i64, i64)> = x
                            .iter()
                            .zip(&z)
                            .map(|(&v, &z1)| (z1, mirror.sample(-v, &k)))
                            .collect();
                        let samples: Vec<_> =
                            x.iter().map(|&v| (v, -v, SCHEDULE_CLOCKS, false)).collect();
                        assert_eq!(run_model(&k, &samples), want, "R {}: model", d.decimation);
                    }
                }
            }
        }
        for register in R::ALL {
            let peak = worst[register as usize];
            let limit = 1u128 << (register.bits() - 1);
            let margin = (limit as f64 / peak as f64).log2();
            eprintln!(
                "{register:?}: {} bits, peak 2^{:.2}, margin {margin:.2} bits",
                register.bits(),
                (peak as f64).log2()
            );
            assert!(peak < limit, "{register:?}");
        }
        eprintln!("corners: largest l1 x G (feedback, feedback - u, y, y - u, u) {largest_l1:.4?}");
        // l1 x G depends on the cut-off ratios only (up to the rounding of
        // the coefficients): a sweep of 40 x 8 ratios over the range may not
        // exceed the corners' by more than 1%.
        let mut swept = [0f64; 5];
        for i in 0..40 {
            for j in 0..8 {
                let ratio =
                    |t: f64| MIN_CUTOFF_RATIO * (MAX_CUTOFF_RATIO / MIN_CUTOFF_RATIO).powf(t);
                let fz = 50e6 / 1000.0;
                let d = filter_design::design(
                    50e6,
                    1000,
                    fz * ratio(i as f64 / 39.0),
                    fz * ratio(j as f64 / 7.0),
                )
                .unwrap();
                let (h, _) = impulse_responses(&d.coefficients);
                for (k, w) in swept.iter_mut().enumerate() {
                    *w = w.max(h.iter().map(|v| v[k].abs()).sum::<f64>() * d.cic_gain);
                }
            }
        }
        eprintln!("sweep: largest l1 x G {swept:.4?}");
        for (w, c) in swept.iter().zip(largest_l1) {
            assert!(*w <= 1.01 * c, "the sweep found {w}, the corners {c}");
        }
    }
}
