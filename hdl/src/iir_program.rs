//! The output filter's micro-program: every product of both channels'
//! biquad and RC sections as 16 x 16 digit products on one multiplier,
//! summed column by column in a narrow accumulator.
//!
//! ```text
//!  word w of the ROM:  read RAM digit ─► operand: wrap, coefficient digit ─► product ─► accumulate, emit
//!  slot issued at w:   w                w + 1                              w + 2       w + 3
//! ```
//!
//! Numbers are cut into `DIGIT_BITS` = 15-bit digits: a value `a` is
//! `sum a_i 2^(15 i)`, every digit but the top one unsigned (0..2^15 - 1),
//! the top one signed, so each digit is a 16-bit two's complement multiplier
//! operand (one `SB_MAC16`, one `MULT18X18D`). A dot product
//! `sum_t a_t b_t 2^(15 o_t)` is summed by columns: column c adds every
//! `a_ti b_tj` with `i + j + o_t = c`, then its low 15 bits are final (a
//! digit of the result, written to RAM or dropped) and the rest carries
//! into column c + 1 (an arithmetic shift by 15). Every step is exact, so
//! each emitted digit is the result modulo 2^15 at its place, and a result
//! taken from columns c..c+3 is the exact sum's bits 15c..15c+59, wrapped.
//!
//! Passes per channel (`crate::iir_lowpass` gives the equations):
//! - biquad: S = (k1 + 2^31) y1 + (k2 - 2^30) y2 + 2 k0 x 2^15 +
//!   4 k0 x0 2^15 + 2 k0 x1 2^15 + 2^29, which is the recorded sum
//!   (2 y1 - y2) 2^30 + 2^29 + k1 y1 + k2 y2 + k0 (x + 2 x0 + x1) 2^16 as
//!   an integer; y = S / 2^30 is columns 2..5 (60 bits; read back as the
//!   58-bit state by sign-extending the top digit from bit 12, `wrap`);
//! - difference: d = y - u, columns 0..3 of y (+1) and u (-1), wrapped to
//!   60 bits (the recorded `(acc_y - u 2^30) / 2^30`, modulo 2^60);
//! - RC: T = alpha d + u 2^30 + 2^29, u = T / 2^30 (columns 2..5);
//! - output: z = (u 2^14 + 2^29) / 2^30 = (u + 2^15) / 2^16, columns 2..4,
//!   shifted into a staging register; `publish` copies it to z1, z2.
//!
//! State words live in a 128-word RAM of digits (`Location`): x, y and u
//! keep three ages each (new, previous, two back) in slots that rotate with
//! a sample counter `base` modulo 3, so the new sample overwrites the one
//! three back and no word is ever copied. The program is built once by
//! typed Rust (`Program::build`), encoded into `WORD_BITS`-bit ROM words for
//! the hardware and interpreted word by word by the model, so the two run
//! the same schedule by construction. `build` inserts idle words where a
//! read would come before the write it depends on.

use crate::iir_widths::{SAMPLE_BITS, STATE_BITS};
use gyrocal_regs::Coefficients;
use std::sync::LazyLock;

/// Bits of a digit below its sign: 15.
pub const DIGIT_BITS: usize = 15;
/// Width of a multiplier operand: a digit and a sign bit.
pub const OPERAND_BITS: usize = DIGIT_BITS + 1;
/// Width of the exact product of two operands.
pub const PRODUCT_BITS: usize = 2 * OPERAND_BITS;
/// Digits of a state (58 bits) or a 60-bit operand: 4.
pub const STATE_DIGITS: usize = 4;
/// Digits of a sample (40 bits): 3, the top one 10 bits.
pub const SAMPLE_DIGITS: usize = 3;
/// Digits of a coefficient (up to 34 bits once scaled): 3, the top one 4 bits.
pub const COEFFICIENT_DIGITS: usize = 3;
/// Width of the top digit of a state (58 = 3 x 15 + 13).
pub const STATE_TOP_BITS: usize = STATE_BITS - 3 * DIGIT_BITS;
/// Width of the top digit of a sample (40 = 2 x 15 + 10).
pub const SAMPLE_TOP_BITS: usize = SAMPLE_BITS - 2 * DIGIT_BITS;
/// Width of the top digit of a scaled coefficient (34 = 2 x 15 + 4).
pub const COEFFICIENT_TOP_BITS: usize = 4;
/// Width of the scaled coefficients (4 k0 spans 34 bits).
pub const SCALED_COEFFICIENT_BITS: usize = 2 * DIGIT_BITS + COEFFICIENT_TOP_BITS;
/// Width of the column accumulator: at most `MAX_COLUMN_PRODUCTS` = 15
/// products of magnitude <= 2^30 per column, plus 2^29 and a carry below
/// 2^20: |acc| < 16 2^30 = 2^34, so 35 bits and a sign margin, 36.
/// `column_sums_fit_the_accumulator` checks the bound on the program.
pub const ACCUMULATOR_BITS: usize = 36;
/// Most products in one column of any pass (the biquad's column 3).
pub const MAX_COLUMN_PRODUCTS: usize = 15;
/// Address width of the digit RAM: channel, word, slot, digit.
pub const RAM_ADDRESS_BITS: usize = 7;
/// Width of the program counter (ROM address).
pub const PC_BITS: usize = 8;
/// Width of a ROM word (the last field, publish, is bit 29).
pub const WORD_BITS: usize = 30;
/// Clocks from a slot's RAM read to its accumulation.
pub const ACCUMULATE_DELAY: usize = 3;
/// Slots of the rotating words; slot 3 is the fixed one.
pub const ROTATING_SLOTS: u8 = 3;

/// A word of the digit RAM.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Word {
    /// Input samples x (ages: new, x0, x1).
    X = 0,
    /// Biquad output y (ages: new, y1, y2).
    Y = 1,
    /// RC state u (ages: new, previous).
    U = 2,
    /// The difference y - u (one fixed slot).
    D = 3,
}

/// Which sample a rotating word belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Age {
    /// Written during this schedule.
    New = 0,
    /// Written by the previous schedule.
    Previous = 1,
    /// Written two schedules ago.
    TwoBack = 2,
}

/// A digit's place in the RAM.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Location {
    /// Channel 0 or 1.
    pub channel: usize,
    /// The word.
    pub word: Word,
    /// The age (ignored for `Word::D`).
    pub age: Age,
    /// Digit index, 0 = least significant.
    pub digit: usize,
}

impl Location {
    /// The address field: channel, word, slot (rotation r = -age mod 3, or
    /// 3 for the fixed word), digit. The hardware adds `base` to r modulo 3.
    pub fn encode(self) -> u8 {
        let slot = match self.word {
            Word::D => ROTATING_SLOTS,
            _ => (ROTATING_SLOTS - self.age as u8) % ROTATING_SLOTS,
        };
        ((self.channel as u8) << 6) | ((self.word as u8) << 4) | (slot << 2) | self.digit as u8
    }
}

/// The physical RAM address of an address field at sample counter `base`
/// (0..`ROTATING_SLOTS`): a rotating slot r becomes (r + base) mod 3, as
/// one conditional subtraction, since r + base < 6 (the model runs this
/// twice a clock, where a division by 3 was 4% of the datapath's time).
#[inline(always)]
pub const fn physical_address(field: u8, base: u8) -> usize {
    debug_assert!(base < ROTATING_SLOTS);
    let slot = (field >> 2) & 3;
    let slot = if slot == ROTATING_SLOTS {
        slot
    } else {
        let sum = slot + base;
        if sum >= ROTATING_SLOTS {
            sum - ROTATING_SLOTS
        } else {
            sum
        }
    };
    ((field & !0b1100) | (slot << 2)) as usize
}

/// The coefficient words a digit can come from (`Factor::Digit`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scaled {
    /// k1 + 2^31 (folds 2 y1 into the product).
    K1Plus = 1,
    /// k2 - 2^30 (folds -y2).
    K2Minus = 2,
    /// 2 k0 (the 2^16 of v, less one digit).
    K0Twice = 3,
    /// 4 k0 (2 x0).
    K0Quad = 4,
    /// alpha.
    Alpha = 5,
}

/// The second operand of a product.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Factor {
    /// 0 (idle slots).
    Zero,
    /// +1.
    One,
    /// -1.
    MinusOne,
    /// 2^14.
    Pow14,
    /// Digit j of a scaled coefficient.
    Digit(Scaled, usize),
}

impl Factor {
    /// The 5-bit select: source in bits 4:2, digit in 1:0.
    pub fn encode(self) -> u8 {
        match self {
            Factor::Zero => 0,
            Factor::One => 1,
            Factor::MinusOne => 2,
            Factor::Pow14 => 3,
            Factor::Digit(s, j) => ((s as u8) << 2) | j as u8,
        }
    }
}

/// The scaled coefficient `source` (1..=5, `Scaled`) as an integer.
#[inline(always)]
pub fn scaled_value(source: u8, k: &Coefficients) -> i64 {
    match source {
        1 => k.k1 as i64 + (1 << 31),
        2 => k.k2 as i64 - (1 << 30),
        3 => 2 * k.k0 as i64,
        4 => 4 * k.k0 as i64,
        _ => k.alpha as i64,
    }
}

/// The operand a factor select gives for coefficients `k`.
#[inline(always)]
pub fn factor_value(select: u8, k: &Coefficients) -> i64 {
    let (source, digit) = (select >> 2, select & 3);
    if source == 0 {
        return [0, 1, -1, 1 << 14][digit as usize];
    }
    let c = scaled_value(source, k);
    match digit {
        0 => c & 0x7fff,
        1 => (c >> DIGIT_BITS) & 0x7fff,
        _ => c >> (2 * DIGIT_BITS),
    }
}

/// What the accumulator does with the product.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AccumulatorOp {
    /// Hold.
    Hold = 0,
    /// Start a pass: acc = p (+ 2^29 with `round`).
    Start = 1,
    /// acc += p.
    Add = 2,
    /// Next column: acc = (acc >> 15) + p.
    Shift = 3,
}

/// Where the finished column digit `acc mod 2^15` (or an input digit) goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Emit {
    /// Nowhere.
    None = 0,
    /// To RAM, zero-extended (a lower digit).
    Digit = 1,
    /// To RAM, sign-extended from bit 14 (a top digit).
    TopDigit = 2,
    /// Into the output staging register.
    Stage = 3,
    /// Input digit `x_select` to RAM.
    Input = 4,
}

/// One ROM word, decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MicroWord {
    /// RAM read address field (`Location::encode`).
    pub read: u8,
    /// Sign-extend the operand from bit 12 (a state's top digit).
    pub wrap: bool,
    /// Second operand (`Factor::encode`).
    pub factor: u8,
    /// Accumulator operation.
    pub op: AccumulatorOp,
    /// With `Start`: add the rounding constant 2^29.
    pub round: bool,
    /// The emission.
    pub emit: Emit,
    /// RAM write address field.
    pub write: u8,
    /// Input digit for `Emit::Input`: channel * 3 + digit.
    pub x_select: u8,
    /// Copy the staging register to z1, z2 and pulse z_valid.
    pub publish: bool,
}

impl MicroWord {
    /// The idle word (all fields zero).
    pub const IDLE: MicroWord = MicroWord {
        read: 0,
        wrap: false,
        factor: 0,
        op: AccumulatorOp::Hold,
        round: false,
        emit: Emit::None,
        write: 0,
        x_select: 0,
        publish: false,
    };

    /// Bit layout: read 6:0, wrap 7, factor 12:8, op 14:13, round 15, emit
    /// 18:16, write 25:19, x_select 28:26, publish 29.
    pub fn encode(&self) -> u64 {
        self.read as u64
            | (self.wrap as u64) << 7
            | (self.factor as u64) << 8
            | (self.op as u64) << 13
            | (self.round as u64) << 15
            | (self.emit as u64) << 16
            | (self.write as u64) << 19
            | (self.x_select as u64) << 26
            | (self.publish as u64) << 29
    }
}

/// A term of a dot product: digits of a RAM word times a factor's digits.
#[derive(Clone, Copy, Debug)]
struct Term {
    /// The word's first digit; its digits follow.
    word: Location,
    /// Its number of digits.
    digits: usize,
    /// Read the top digit as a 58-bit state's (sign from bit 12).
    wrap_top: bool,
    /// The factor's digits (one for a constant).
    factors: [Factor; COEFFICIENT_DIGITS],
    /// Number of factor digits.
    factor_digits: usize,
    /// Column offset.
    offset: usize,
}

/// Where a pass's column digits go.
#[derive(Clone, Copy, Debug)]
enum Target {
    /// Columns `first..first + digits` to RAM word `to` (top digit last).
    Ram { to: Location, first: usize },
    /// Columns `first..first + 3` into the staging register.
    Stage { first: usize },
}

/// The first digit of `word` of `age` on `channel`.
fn at(channel: usize, word: Word, age: Age) -> Location {
    Location {
        channel,
        word,
        age,
        digit: 0,
    }
}

impl Term {
    /// A state word (`STATE_DIGITS`, its top digit read as the 58-bit
    /// state's when `wrap_top`) times the three digits of coefficient `s`.
    fn state_by(word: Location, wrap_top: bool, s: Scaled) -> Self {
        Term {
            word,
            digits: STATE_DIGITS,
            wrap_top,
            factors: [
                Factor::Digit(s, 0),
                Factor::Digit(s, 1),
                Factor::Digit(s, 2),
            ],
            factor_digits: 3,
            offset: 0,
        }
    }

    /// A sample word (`SAMPLE_DIGITS`) times the three digits of
    /// coefficient `s`, one column up.
    fn sample_by(word: Location, s: Scaled) -> Self {
        Term {
            digits: SAMPLE_DIGITS,
            offset: 1,
            ..Term::state_by(word, false, s)
        }
    }

    /// A state word times the one-digit constant `f`, `offset` columns up.
    fn state_times(word: Location, wrap_top: bool, f: Factor, offset: usize) -> Self {
        Term {
            word,
            digits: STATE_DIGITS,
            wrap_top,
            factors: [f, Factor::Zero, Factor::Zero],
            factor_digits: 1,
            offset,
        }
    }
}

/// The biquad's terms (module header): `(k1 + 2^31) y1 + (k2 - 2^30) y2`
/// and `2 k0 x + 4 k0 x0 + 2 k0 x1`, the samples one column (2^15) up.
fn biquad(channel: usize) -> [Term; 5] {
    [
        Term::state_by(at(channel, Word::Y, Age::Previous), true, Scaled::K1Plus),
        Term::state_by(at(channel, Word::Y, Age::TwoBack), true, Scaled::K2Minus),
        Term::sample_by(at(channel, Word::X, Age::New), Scaled::K0Twice),
        Term::sample_by(at(channel, Word::X, Age::Previous), Scaled::K0Quad),
        Term::sample_by(at(channel, Word::X, Age::TwoBack), Scaled::K0Twice),
    ]
}

/// The difference `d = y - u`, u the previous RC output.
fn difference(channel: usize) -> [Term; 2] {
    [
        Term::state_times(at(channel, Word::Y, Age::New), false, Factor::One, 0),
        Term::state_times(
            at(channel, Word::U, Age::Previous),
            true,
            Factor::MinusOne,
            0,
        ),
    ]
}

/// The RC step's terms `alpha d + u 2^30` (u two columns up).
fn rc(channel: usize) -> [Term; 2] {
    [
        Term::state_by(at(channel, Word::D, Age::New), false, Scaled::Alpha),
        Term::state_times(at(channel, Word::U, Age::Previous), true, Factor::One, 2),
    ]
}

/// The output's term `u 2^14`, into the staging register.
fn output(channel: usize) -> [Term; 1] {
    [Term::state_times(
        at(channel, Word::U, Age::New),
        true,
        Factor::Pow14,
        0,
    )]
}

/// The schedule: ROM words and the figures derived from them.
#[derive(Clone, Debug)]
pub struct Program {
    /// ROM words; word 0 is idle and the last one publishes.
    pub words: Vec<MicroWord>,
    /// Most products summed in one column.
    pub max_column_products: usize,
    /// Largest column sum bound (magnitude) over the program.
    pub max_column_sum: i128,
    /// Word index of the last write to each RAM address field (checks).
    last_write: Vec<Option<usize>>,
    /// Next word at which a slot can be issued.
    cursor: usize,
    /// Word of the next accumulator operation of the current pass.
    last_op: usize,
}

/// The program, built once.
pub static PROGRAM: LazyLock<Program> = LazyLock::new(Program::build);

impl Program {
    fn new() -> Self {
        Program {
            words: vec![MicroWord::IDLE],
            max_column_products: 0,
            max_column_sum: 0,
            last_write: vec![None; 1 << RAM_ADDRESS_BITS],
            cursor: 1,
            last_op: 0,
        }
    }

    fn word(&mut self, w: usize) -> &mut MicroWord {
        if self.words.len() <= w {
            self.words.resize(w + 1, MicroWord::IDLE);
        }
        &mut self.words[w]
    }

    /// Record a write at word `w`.
    fn emit(&mut self, w: usize, emit: Emit, write: u8) {
        let word = self.word(w);
        assert_eq!(word.emit, Emit::None, "two emissions at word {w}");
        word.emit = emit;
        word.write = write;
        if emit != Emit::Stage {
            self.last_write[write as usize] = Some(w);
        }
    }

    /// Issue one slot: an optional read, its factor, and the operation.
    fn slot(&mut self, read: Option<(u8, bool)>, factor: Factor, op: AccumulatorOp, round: bool) {
        let mut w = self
            .cursor
            .max((self.last_op + 1).saturating_sub(ACCUMULATE_DELAY));
        if let Some((address, _)) = read
            && let Some(written) = self.last_write[address as usize]
        {
            w = w.max(written + 1);
        }
        if let Some((address, wrap)) = read {
            self.word(w).read = address;
            self.word(w + 1).wrap = wrap;
        }
        self.word(w + 1).factor = factor.encode();
        let o = self.word(w + ACCUMULATE_DELAY);
        o.op = op;
        o.round = round;
        self.cursor = w + 1;
        self.last_op = w + ACCUMULATE_DELAY;
    }

    /// One dot product, column by column, emitting into `target`.
    fn pass(&mut self, terms: &[Term], round: bool, columns: usize, target: Target) {
        let mut first = true;
        for column in 0..columns {
            if column > 0 {
                // The previous column is final once this one starts.
                self.emit_column(column - 1, target);
            }
            let mut products = 0;
            let mut bound: i128 = if round { 1 << 29 } else { 0 } + (1 << 20);
            for t in terms {
                for i in 0..t.digits {
                    for j in 0..t.factor_digits {
                        if i + j + t.offset != column {
                            continue;
                        }
                        let location = Location { digit: i, ..t.word };
                        let top = i + 1 == t.digits;
                        let op = if first {
                            AccumulatorOp::Start
                        } else if products == 0 {
                            AccumulatorOp::Shift
                        } else {
                            AccumulatorOp::Add
                        };
                        self.slot(
                            Some((location.encode(), top && t.wrap_top)),
                            t.factors[j],
                            op,
                            round && first,
                        );
                        first = false;
                        products += 1;
                        bound += 1 << 30;
                    }
                }
            }
            if products == 0 {
                let op = if first {
                    AccumulatorOp::Start
                } else {
                    AccumulatorOp::Shift
                };
                self.slot(None, Factor::Zero, op, round && first);
                first = false;
            }
            self.max_column_products = self.max_column_products.max(products);
            self.max_column_sum = self.max_column_sum.max(bound);
        }
        self.emit_column(columns - 1, target);
    }

    /// Emit column `column`'s digit at the word after the last operation.
    fn emit_column(&mut self, column: usize, target: Target) {
        let w = self.last_op + 1;
        match target {
            Target::Ram { to, first } => {
                if column >= first && column < first + STATE_DIGITS {
                    let digit = column - first;
                    let location = Location { digit, ..to };
                    let emit = if digit + 1 == STATE_DIGITS {
                        Emit::TopDigit
                    } else {
                        Emit::Digit
                    };
                    self.emit(w, emit, location.encode());
                }
            }
            Target::Stage { first } => {
                if column >= first && column < first + SAMPLE_DIGITS {
                    self.emit(w, Emit::Stage, 0);
                }
            }
        }
    }

    /// The schedule: the input digits, then per channel the biquad, the
    /// difference `y - u`, the RC step and the output, each a pass of
    /// dot products (`biquad` .. `output` below), then the publish word.
    fn build() -> Self {
        let mut p = Program::new();
        p.input_words();
        for channel in 0..2 {
            let to = at(channel, Word::Y, Age::New);
            p.pass(&biquad(channel), true, 6, Target::Ram { to, first: 2 });
        }
        for channel in 0..2 {
            let to = at(channel, Word::D, Age::New);
            p.pass(&difference(channel), false, 4, Target::Ram { to, first: 0 });
        }
        for channel in 0..2 {
            let to = at(channel, Word::U, Age::New);
            p.pass(&rc(channel), true, 6, Target::Ram { to, first: 2 });
        }
        for channel in 0..2 {
            p.pass(&output(channel), true, 5, Target::Stage { first: 2 });
        }
        p.publish_after_the_last_stage();
        p
    }

    /// Input samples into the new x slots, one digit per word.
    fn input_words(&mut self) {
        for channel in 0..2 {
            for digit in 0..SAMPLE_DIGITS {
                let w = 1 + channel * SAMPLE_DIGITS + digit;
                let to = Location {
                    digit,
                    ..at(channel, Word::X, Age::New)
                };
                self.emit(w, Emit::Input, to.encode());
                self.word(w).x_select = (channel * SAMPLE_DIGITS + digit) as u8;
            }
        }
    }

    /// Publish once the last staged digit is in; the schedule ends there.
    fn publish_after_the_last_stage(&mut self) {
        let last_stage = self.words.iter().rposition(|w| w.emit == Emit::Stage);
        let last_stage = last_stage.expect("the output pass stages digits");
        let publish = (last_stage + 1).max(self.words.len() - 1);
        self.word(publish).publish = true;
        self.words.truncate(publish + 1);
    }

    /// Clocks from accepting a strobe to accepting the next one.
    pub fn schedule_clocks(&self) -> usize {
        self.words.len()
    }

    /// Clocks from `x_valid` to `z_valid`: the ROM read and the word
    /// register put word k in force 2 + k clocks after the strobe; z_valid
    /// follows the last word by one clock.
    pub fn latency(&self) -> usize {
        self.words.len() + 2
    }

    /// The ROM image.
    pub fn image(&self) -> Vec<u64> {
        self.words.iter().map(MicroWord::encode).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::iir_lowpass::{LATENCY, SCHEDULE_CLOCKS};

    /// Every field at every base: the rotating slot moves by the base
    /// modulo 3, the fixed slot and the other bits stay.
    #[test]
    fn a_rotating_slot_moves_by_the_base_modulo_3() {
        for base in 0..ROTATING_SLOTS {
            for field in 0..=u8::MAX {
                let slot = (field >> 2) & 3;
                let moved = if slot == ROTATING_SLOTS {
                    slot
                } else {
                    (slot + base) % ROTATING_SLOTS
                };
                let expected = (field & !0b1100) | (moved << 2);
                assert_eq!(physical_address(field, base), usize::from(expected));
            }
        }
    }

    #[test]
    fn constants_match_the_program() {
        let p = &*PROGRAM;
        assert_eq!(SCHEDULE_CLOCKS, p.schedule_clocks());
        assert_eq!(LATENCY, p.latency());
        assert!(p.words.len() <= 1 << PC_BITS);
        assert_eq!(p.words[0], MicroWord::IDLE);
        assert_eq!(MicroWord::IDLE.encode(), 0);
        // The last word runs one clock after the next strobe can be taken
        // (which steps `base` and the captured x): it must only publish.
        let last = p.words.last().unwrap();
        assert_eq!(
            MicroWord {
                publish: false,
                ..*last
            },
            MicroWord::IDLE
        );
        assert!(last.publish);
        assert!(p.image().iter().all(|&w| w < 1 << WORD_BITS));
    }

    #[test]
    fn column_sums_fit_the_accumulator() {
        let p = &*PROGRAM;
        assert_eq!(p.max_column_products, MAX_COLUMN_PRODUCTS);
        assert!(p.max_column_sum < 1 << (ACCUMULATOR_BITS - 2));
    }

    #[test]
    fn every_read_follows_the_write_it_needs() {
        // Emulate the RAM's write times and check that every read of a
        // digit written during the schedule comes after the write.
        let p = &*PROGRAM;
        let mut written: Vec<Option<usize>> = vec![None; 1 << RAM_ADDRESS_BITS];
        for (w, word) in p.words.iter().enumerate() {
            if let Some(at) = written[word.read as usize] {
                assert!(w > at, "word {w} reads {:#x} written at {at}", word.read);
            }
            if !matches!(word.emit, Emit::None | Emit::Stage) {
                written[word.write as usize] = Some(w);
            }
        }
    }
}
