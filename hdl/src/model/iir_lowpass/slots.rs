//! A running schedule's clocks without a sample (`IirLowpass::run_without_input`)
//! from a table of what each ROM word does at each sample counter: its RAM
//! addresses resolved, its accumulator operation as a shift and two masks,
//! its emission as a value select and a write address (a scratch word when
//! it writes no RAM). The registers are `IirLowpass::clock`'s with
//! `x_valid` low, clock for clock; the table only takes the decoding and
//! its branches out of the clock (a busy clock took 6.4 ns decoded word by
//! word, docs/speed-and-resources.md).

use super::{DIGIT_MASK, FACTOR_SELECTS, Factors, IirLowpass, RAM_WORDS, wrap};
use crate::iir_program::{
    ACCUMULATOR_BITS, AccumulatorOp, DIGIT_BITS, Emit, MicroWord, PROGRAM, ROTATING_SLOTS,
    STATE_TOP_BITS, physical_address,
};
use std::sync::LazyLock;

/// The local RAM of a run: the digit RAM, then words no address field
/// reaches, so that any `u8` indexes it and a word that writes no RAM
/// writes `SCRATCH`.
type LocalRam = [i16; 256];

/// The word of the local RAM that a word writing no RAM writes.
const SCRATCH: u8 = u8::MAX;

/// What the emission writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Value {
    /// The accumulator's low digit (also the staged one).
    Digit,
    /// The accumulator's low digit, sign-extended from bit 14.
    TopDigit,
    /// An input digit.
    Input,
}

/// One ROM word at one sample counter.
#[derive(Clone, Copy, Debug)]
struct Slot {
    /// Physical RAM read address.
    read: u8,
    /// Physical RAM write address, or `SCRATCH`.
    write: u8,
    /// What a RAM write writes.
    value: Value,
    /// Input digit (channel * 3 + digit) of `Value::Input`.
    x_select: u8,
    /// Shift the low digit into the staging register.
    stage: bool,
    /// Copy the staging register to z and pulse z_valid.
    publish: bool,
    /// The operand's sign extension: `64 - STATE_TOP_BITS` when the word
    /// wraps it, else 0.
    wrap_shift: u32,
    /// Factor select.
    factor: u8,
    /// acc = ((acc >> acc_shift) & acc_keep) + (p & p_keep) + round: the
    /// four operations (`AccumulatorOp`), wrapped to the accumulator after.
    acc_shift: u32,
    acc_keep: i64,
    p_keep: i64,
    round: i64,
}

impl Slot {
    fn new(w: &MicroWord, base: u8) -> Self {
        let (write, value) = match w.emit {
            Emit::None | Emit::Stage => (SCRATCH, Value::Digit),
            Emit::Digit => (physical_address(w.write, base) as u8, Value::Digit),
            Emit::TopDigit => (physical_address(w.write, base) as u8, Value::TopDigit),
            Emit::Input => (physical_address(w.write, base) as u8, Value::Input),
        };
        let (acc_shift, acc_keep, p_keep) = match w.op {
            AccumulatorOp::Hold => (0, -1, 0),
            AccumulatorOp::Start => (0, 0, -1),
            AccumulatorOp::Add => (0, -1, -1),
            AccumulatorOp::Shift => (DIGIT_BITS as u32, -1, -1),
        };
        let round = if w.op == AccumulatorOp::Start && w.round {
            1 << 29
        } else {
            0
        };
        Self {
            read: physical_address(w.read, base) as u8,
            write,
            value,
            x_select: w.x_select,
            stage: w.emit == Emit::Stage,
            publish: w.publish,
            wrap_shift: if w.wrap {
                64 - STATE_TOP_BITS as u32
            } else {
                0
            },
            factor: w.factor,
            acc_shift,
            acc_keep,
            p_keep,
            round,
        }
    }
}

/// `PROGRAM`'s words as slots, at each sample counter.
static SLOTS: LazyLock<[Vec<Slot>; ROTATING_SLOTS as usize]> = LazyLock::new(|| {
    std::array::from_fn(|base| {
        PROGRAM
            .words
            .iter()
            .map(|w| Slot::new(w, base as u8))
            .collect()
    })
});

impl IirLowpass {
    /// `IirLowpass::run_without_input`'s clocks: the registers in locals,
    /// each clock's word from `SLOTS`.
    #[inline(always)]
    pub(super) fn run_slots(
        &mut self,
        clocks: usize,
        factors: &Factors,
        mut on_z: impl FnMut(usize, (i64, i64)),
    ) -> usize {
        let slots = &SLOTS[usize::from(self.base)][..];
        debug_assert_eq!(slots.len(), self.words.len());
        let inputs: [i64; 8] =
            std::array::from_fn(|s| if s < 6 { self.input_digit(s as u8) } else { 0 });
        let mut ram: LocalRam = [0; 256];
        ram[..RAM_WORDS].copy_from_slice(&self.ram);
        let (mut pc, mut rom_q, mut word) = (self.pc, self.rom_q, self.word);
        let (mut ram_q, mut a, mut b, mut p, mut acc) =
            (self.ram_q, self.a, self.b, self.p, self.acc);
        let (mut stage, mut z, mut z_valid) = (self.stage, self.z, self.z_valid);
        let mut i = 0;
        while i < clocks && (pc | rom_q | word) != 0 {
            let s = slots[word];
            // Values at the rising edge, all from the current registers.
            let q = ram[usize::from(s.read)];
            let digit = acc & DIGIT_MASK;
            let value = match s.value {
                Value::Digit => digit,
                Value::TopDigit => wrap(acc, DIGIT_BITS),
                Value::Input => inputs[usize::from(s.x_select & 7)],
            };
            ram[usize::from(s.write)] = value as i16;
            if s.stage {
                stage.rotate_left(1);
                stage[5] = digit;
            }
            acc = wrap(
                ((acc >> s.acc_shift) & s.acc_keep) + (p & s.p_keep) + s.round,
                ACCUMULATOR_BITS,
            );
            p = a * b;
            a = (i64::from(ram_q) << s.wrap_shift) >> s.wrap_shift;
            b = factors.0[usize::from(s.factor) % FACTOR_SELECTS];
            ram_q = q;
            if s.publish {
                z = IirLowpass::staged(&stage);
                on_z(i, (z[0], z[1]));
            }
            z_valid = s.publish;
            word = rom_q;
            rom_q = pc;
            pc = if pc != 0 && pc + 1 < slots.len() {
                pc + 1
            } else {
                0
            };
            i += 1;
        }
        self.ram.copy_from_slice(&ram[..RAM_WORDS]);
        (self.pc, self.rom_q, self.word) = (pc, rom_q, word);
        (self.ram_q, self.a, self.b, self.p, self.acc) = (ram_q, a, b, p, acc);
        (self.stage, self.z, self.z_valid) = (stage, z, z_valid);
        i
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Coefficients, Factors, IirLowpass};
    use crate::iir_lowpass::SCHEDULE_CLOCKS;
    use crate::test_util::Rng;

    /// A busy run from the slots is `step` without a sample clock by
    /// clock: the same clocks played, z at the same clocks, and the whole
    /// filter equal after it (RAM, operands, product, accumulator, staging
    /// register, program counters). Random coefficients over their whole
    /// range and random 40-bit inputs; runs of every length around a
    /// schedule's, started at each sample counter and anywhere in a
    /// schedule (single steps with and without a sample between them).
    #[test]
    fn a_busy_run_is_the_clocks_stepped_without_a_sample() {
        let mut rng = Rng::new(53);
        let word = |rng: &mut Rng| rng.next_u64() as i32;
        let lengths = [
            1,
            2,
            3,
            5,
            SCHEDULE_CLOCKS - 1,
            SCHEDULE_CLOCKS,
            SCHEDULE_CLOCKS + 7,
            400,
        ];
        for case in 0..40 {
            let k = Coefficients {
                k0: word(&mut rng),
                k1: word(&mut rng),
                k2: word(&mut rng),
                alpha: word(&mut rng),
            };
            let (mut run, mut stepped) = (IirLowpass::default(), IirLowpass::default());
            for event in 0..300 {
                if rng.range(0, 2) == 0 {
                    let x = (
                        rng.range(-(1 << 39), (1 << 39) - 1),
                        rng.range(-(1 << 39), (1 << 39) - 1),
                    );
                    let valid = rng.range(0, 1) == 0;
                    assert_eq!(run.step(x, valid, &k), stepped.step(x, valid, &k));
                    continue;
                }
                let clocks = lengths[rng.range(0, lengths.len() as i64 - 1) as usize];
                let mut z_run = vec![];
                let factors = Factors::new(&k);
                let played = run.run_without_input(clocks, &factors, |i, z| z_run.push((i, z)));
                let mut z_stepped = vec![];
                let mut i = 0;
                while i < clocks && !stepped.idle() {
                    let (z1, z2, valid) = stepped.step((0, 0), false, &k);
                    if valid {
                        z_stepped.push((i, (z1, z2)));
                    }
                    i += 1;
                }
                let at = format!("case {case}, event {event}, {clocks} clocks");
                assert_eq!(played, i, "{at}: clocks played");
                assert_eq!(z_run, z_stepped, "{at}: z");
                assert_eq!(run, stepped, "{at}: the filter after the run");
            }
        }
    }
}
