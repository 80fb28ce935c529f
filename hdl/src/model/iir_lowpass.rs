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

/// Sign-extend the low `bits` bits of `x`.
#[inline(always)]
fn wrap(x: i64, bits: usize) -> i64 {
    (x << (64 - bits)) >> (64 - bits)
}

/// Low digit mask.
const DIGIT_MASK: i64 = (1 << DIGIT_BITS) - 1;

/// Cycle-true model of the two-channel filter.
#[derive(Clone, Debug)]
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
    /// Digit RAM.
    ram: Vec<i16>,
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
}

impl Default for IirLowpass {
    fn default() -> Self {
        Self {
            pc: 0,
            rom_q: 0,
            word: 0,
            base: 0,
            x: [0; 2],
            ram: vec![0; 1 << crate::iir_program::RAM_ADDRESS_BITS],
            ram_q: 0,
            a: 0,
            b: 0,
            p: 0,
            acc: 0,
            stage: [0; 6],
            z: [0; 2],
            z_valid: false,
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

    /// One clock with inputs `x` and strobe `x_valid`; returns
    /// `(z1, z2, z_valid)` after the edge.
    #[inline(always)]
    pub fn step(&mut self, x: (i64, i64), x_valid: bool, k: &Coefficients) -> (i64, i64, bool) {
        if self.pc == 0 && self.rom_q == 0 && self.word == 0 && !x_valid {
            // Idle: word 0 does nothing that a schedule reads back.
            self.z_valid = false;
            return self.output();
        }
        let w: MicroWord = PROGRAM.words[self.word];
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
            // Digits 0..2 are z1 (45 bits), 3..5 z2; each keeps 40 bits.
            for (c, z) in self.z.iter_mut().enumerate() {
                let d = &self.stage[3 * c..3 * c + 3];
                let value = d[0] | d[1] << DIGIT_BITS | d[2] << (2 * DIGIT_BITS);
                *z = wrap(value, crate::iir_lowpass::SAMPLE_BITS);
            }
        }
        self.z_valid = w.publish;
        self.word = self.rom_q;
        self.rom_q = self.pc;
        self.pc = if accept || (self.pc != 0 && self.pc + 1 < PROGRAM.words.len()) {
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
/// a time, every register wrapping at its recorded width.
#[cfg(test)]
pub mod reference {
    use crate::iir_lowpass::{
        ACCUMULATOR_BITS, COEFFICIENT_FRACTION_BITS, GUARD_BITS, OPERAND_BITS, SAMPLE_BITS,
        STATE_BITS,
    };

    fn wrap(x: i128, bits: usize) -> i128 {
        (x << (128 - bits)) >> (128 - bits)
    }

    /// One channel's registers.
    #[derive(Clone, Copy, Debug, Default)]
    pub struct Channel {
        x0: i64,
        x1: i64,
        y1: i128,
        y2: i128,
        u: i128,
    }

    impl Channel {
        /// Filter one sample; returns z.
        pub fn sample(&mut self, x: i64, k: &super::Coefficients) -> i64 {
            let f = COEFFICIENT_FRACTION_BITS;
            let half = 1i128 << (f - 1);
            let v = wrap(
                (x as i128 + 2 * self.x0 as i128 + self.x1 as i128) << GUARD_BITS,
                OPERAND_BITS,
            );
            let feedback = wrap(2 * self.y1 - self.y2, OPERAND_BITS);
            let products = k.k1 as i128 * self.y1 + k.k2 as i128 * self.y2 + k.k0 as i128 * v;
            let acc_y = wrap((feedback << f | half) + products, ACCUMULATOR_BITS);
            let acc_d = wrap(
                (wrap(feedback - self.u, OPERAND_BITS) << f | half) + products,
                ACCUMULATOR_BITS,
            );
            let y = wrap(acc_y >> f, STATE_BITS);
            let difference = wrap(acc_d >> f, OPERAND_BITS);
            let t = wrap(
                (self.u << f | half) + k.alpha as i128 * difference,
                ACCUMULATOR_BITS,
            );
            self.u = wrap(t >> f, STATE_BITS);
            (self.x1, self.x0, self.y2, self.y1) = (self.x0, x, self.y1, y);
            let rounded = wrap(self.u + (1 << (GUARD_BITS - 1)), STATE_BITS);
            wrap(rounded >> GUARD_BITS, SAMPLE_BITS) as i64
        }
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
}
