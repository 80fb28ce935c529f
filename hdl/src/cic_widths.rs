//! The CIC decimator's widths and schedule lengths, which its blocks
//! (`crate::cic_decimator`, `crate::cic_integrators`,
//! `crate::cic_integrator_stage`, `crate::cic_comb`,
//! `crate::cic_output_stage`) and its model (`crate::model::cic_decimator`)
//! import from here, downward. `crate::cic_decimator`'s header derives
//! them.

/// Number of integrator and comb stages.
pub use gyrocal_regs::datapath::CIC_STAGES as STAGES;
/// Width of the input word.
pub const INPUT_BITS: usize = 32;
pub use gyrocal_regs::datapath::{MAX_DECIMATION, MAX_DECIMATION_LOG2, OUTPUT_FRACTION_BITS};
/// Hogenauer register width: B_in + N log2(R_max) = 32 + 4 * 12 = 80.
pub const REGISTER_BITS: usize = INPUT_BITS + (STAGES * MAX_DECIMATION_LOG2) as usize;
/// Width of the output word.
pub const OUTPUT_BITS: usize = 40;
/// Width of the decimation word: R up to 2^12 needs 13 bits.
pub const DECIMATION_BITS: usize = gyrocal_regs::datapath::DECIMATION_BITS as usize;
/// Width of the output shift word: shifts 0..=40 need 6 bits.
pub const SHIFT_BITS: usize = gyrocal_regs::datapath::SHIFT_BITS as usize;
/// Low bits of the shift applied by the last (fine) output step: 0..=7.
pub const FINE_SHIFT_BITS: usize = 3;
/// The shift bits of the fine step: `shift & 0b000111`.
pub const FINE_SHIFT_MASK: u64 = (1 << FINE_SHIFT_BITS) - 1;
/// The shift bits of the coarse step (multiples of 8): `shift & 0b111000`.
pub const COARSE_SHIFT_MASK: u64 = ((1 << SHIFT_BITS) - 1) & !FINE_SHIFT_MASK;
/// Width of floor(2b / 2^shift) as the output stage keeps it: the output
/// and the one bit below it that decides the rounding.
pub const HALF_BITS: usize = OUTPUT_BITS + 1;
/// Width of the doubled, sign-extended comb word 2b: the largest shift the
/// setting holds (63) plus `HALF_BITS` bits, so every read bit exists.
pub const DOUBLED_BITS: usize = HALF_BITS + (1 << SHIFT_BITS) - 1;
/// Width kept after the coarse step: the fine step shifts by at most
/// 2^3 - 1 = 7 and keeps `HALF_BITS`, so bits 0..41 + 7 suffice.
pub const COARSE_BITS: usize = HALF_BITS + (1 << FINE_SHIFT_BITS) - 1;
/// Clocks from a comb output in the accumulator to its rounded value:
/// coarse, fine, round.
pub const OUTPUT_STAGES: usize = 3;
/// Channels sharing the back-end.
pub const CHANNELS: usize = 2;
/// Address bits of the comb delay RAM: `CHANNELS * STAGES` = 8 words.
pub const DELAY_ADDRESS_BITS: usize = 3;
/// Width of a register half: the combs' 80-bit subtraction runs as two
/// 40-bit ones on consecutive clocks (26 MHz on an iCE40 UP5K with one
/// 80-bit carry chain behind the RAM), and each integrator adds in two
/// halves, the high one a clock late (`crate::cic_integrator_stage`).
pub const REGISTER_HALF_BITS: usize = REGISTER_BITS / 2;
/// A comb half with its borrow (low half) or its borrow-in (high half).
pub(crate) const COMB_CARRY_BITS: usize = REGISTER_HALF_BITS + 1;
/// Clocks per comb step: the low half, then the high half.
pub const COMB_CLOCKS: usize = 2;
/// Clocks from leaving `Idle` to being back in it: per channel one load
/// and `STAGES` comb steps, then the second channel's output steps. The
/// least decimation at which no strobe is dropped.
pub const SCHEDULE_CLOCKS: usize = CHANNELS * (1 + COMB_CLOCKS * STAGES as usize) + OUTPUT_STAGES;
/// Clocks from the strobe cycle to `y1`, `y2` and `valid`.
pub const SAMPLE_TO_OUTPUT: usize = SCHEDULE_CLOCKS;

const _: () = assert!(CHANNELS * STAGES as usize == 1 << DELAY_ADDRESS_BITS);
const _: () = assert!(2 * REGISTER_HALF_BITS == REGISTER_BITS);
// `get_bits` offsets inside `update` are literals (rust-hdl prints a named
// constant there verbatim into the Verilog): 40 is `REGISTER_HALF_BITS`,
// in `cic_comb`, `cic_integrators` and `cic_integrator_stage`.
const _: () = assert!(REGISTER_HALF_BITS == 40);
const _: () = assert!(DOUBLED_BITS > REGISTER_BITS);
const _: () = assert!(SCHEDULE_CLOCKS as u32 <= crate::filter_design::MIN_DECIMATION);
/// Width of the schedule's comb stage counter: `STAGES` = 4 steps a
/// channel, counted modulo 4.
pub const STAGE_BITS: usize = 2;
const _: () = assert!(1 << STAGE_BITS == STAGES as usize);
