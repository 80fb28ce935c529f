//! Sine of a 32-bit phase by table lookup: a quarter-wave table of 8192
//! words in a single-port RAM, no multiplier.
//!
//! ```text
//!  clock:      1 index               2 RAM read        3 word        4 sign            5 output
//!  phase[31:30] + advance = q ─► [q] ────────────────► [q] ─────────► [q] ─┐
//!  phase[29:17] i ─► q odd ? ~i : i ─► [index] ─► RAM ─► [value] ─────► ±v (q >= 2: -) ─► [live ? ±v : 0]
//!  ready ───────────► [live] ────────► [live] ────────► [live] ────────► [live] ─────────┘
//!  fill: write, address, word ─────────────────────► RAM (the write takes the port)
//! ```
//!
//! The phase is a binary fraction of a turn (2^32 = 360 degrees); `advance`
//! adds whole quarter turns (1: the output is the cosine). Bits 29:17 pick
//! one of the 8192 intervals of the quadrant; the table holds the sine at
//! each interval's centre (`crate::carrier_table_fill`). An odd quadrant
//! runs the quadrant backwards and reads the mirrored entry ~i, whose
//! centre is the same distance from the quadrant's end; quadrants 2 and 3
//! negate. Phase bits 16:0 are ignored: the output is the sine of the
//! phase rounded to the nearest of 2^15 interval centres per turn.
//!
//! Widths: output 16-bit two's complement, peak 32767, never -32768 (the
//! table words are sine generator outputs, within [0, 32767] in the first
//! quadrant, so the negation cannot overflow). Error against
//! `32767 sin(2 pi phase / 2^32)`: at most 32767 pi / 2^15 = 3.14 LSB from
//! the phase rounding plus the table words' own 1.2 LSB (`crate::sine`).
//! Spurs: the phase rounding is a phase error periodic in the phase, whose
//! largest spur is near -6.02 x 15 + 3.9 = -86 dBc (Nicholas and Samueli's
//! bound for 15 phase bits); measured by FFT in `crate::carrier_nco`.
//!
//! The RAM is written, not initialized (an SPRAM has no bitstream
//! contents): while `write` is high the fill takes the port, and until
//! `ready` the output is 0. A lookup is live when `ready` was high during
//! its first stage, and the `live` bit travels with it, so the output is
//! the sine of the phase of cycle n - 5 when `ready` was high during cycle
//! n - 5, and 0 otherwise. The filler must never write once `ready` is
//! high (`CarrierTableFill` stops writing 11 clocks before).
//!
//! Pipeline: 5 registers (index, RAM read, word, signed word, output), as
//! `crate::sine::Sine`. Resources: one 8192 x 16 single-port RAM (an iCE40
//! UltraPlus SPRAM, or eight ECP5 `DP16KD`), no multiplier.

use crate::carrier_table_fill::TABLE_BITS;
use crate::primitives::SinglePortRam;
use rust_hdl::prelude::*;

/// Clock cycles from `phase` to `sin`.
pub const LATENCY: usize = 5;

/// Sine of a 32-bit phase plus whole quarter turns from a RAM table,
/// 16-bit output, 5-clock pipeline.
#[derive(LogicBlock)]
pub struct TableSine {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Phase as a fraction of a turn: 2^32 is 360 degrees.
    pub phase: Signal<In, Bits<32>>,
    /// Quarter turns added to `phase` (0: sine, 1: cosine, 2: -sine, 3: -cosine).
    pub advance: Signal<In, Bits<2>>,
    /// Fill: write `fill_word` at `fill_address` at this edge (no lookup read).
    pub fill_write: Signal<In, Bit>,
    /// Fill: the table entry written.
    pub fill_address: Signal<In, Bits<TABLE_BITS>>,
    /// Fill: the word written.
    pub fill_word: Signal<In, Signed<16>>,
    /// The table is complete: lookups started now reach `sin`.
    pub ready: Signal<In, Bit>,
    /// 32767 sin(phase + advance quarter turns), 16-bit two's complement,
    /// `LATENCY` clocks after `phase`; 0 for a phase presented before `ready`.
    pub sin: Signal<Out, Signed<16>>,
    ram: SinglePortRam<16, TABLE_BITS>,
    // Stage 1: the table index, mirrored in odd quadrants.
    index_1: DFF<Bits<TABLE_BITS>>,
    quadrant_1: DFF<Bits<2>>,
    live_1: DFF<Bit>,
    // Stage 2 (beside the RAM read).
    quadrant_2: DFF<Bits<2>>,
    live_2: DFF<Bit>,
    // Stage 3: the word registered (RAM clock-to-out plus a negation does
    // not fit one clock at 125 MHz on an ECP5).
    quadrant_3: DFF<Bits<2>>,
    live_3: DFF<Bit>,
    value_3: DFF<Signed<16>>,
    // Stage 4: negated in the negative half of the turn.
    live_4: DFF<Bit>,
    signed_4: DFF<Signed<16>>,
    // Stage 5: output register, 0 until a live lookup arrives.
    sin_out: DFF<Signed<16>>,
    quadrant: Signal<Local, Bits<2>>,
    zero: Constant<Signed<16>>,
}

impl TableSine {
    /// A table sine whose RAM is still to be filled.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            phase: Default::default(),
            advance: Default::default(),
            fill_write: Default::default(),
            fill_address: Default::default(),
            fill_word: Default::default(),
            ready: Default::default(),
            sin: Default::default(),
            ram: SinglePortRam::new(),
            index_1: Default::default(),
            quadrant_1: Default::default(),
            live_1: Default::default(),
            quadrant_2: Default::default(),
            live_2: Default::default(),
            quadrant_3: Default::default(),
            live_3: Default::default(),
            value_3: Default::default(),
            live_4: Default::default(),
            signed_4: Default::default(),
            sin_out: Default::default(),
            quadrant: Default::default(),
            zero: Constant::new(0.into()),
        }
    }
}

impl Default for TableSine {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for TableSine {
    #[hdl_gen]
    fn update(&mut self) {
        self.ram.clock.next = self.clock.val();
        dff_setup!(
            self, clock, index_1, quadrant_1, live_1, quadrant_2, live_2, quadrant_3, live_3,
            value_3, live_4, signed_4, sin_out
        );
        // Stage 1: table index (the mirrored entry in odd quadrants).
        self.quadrant.next = self.phase.val().get_bits::<2>(30) + self.advance.val();
        self.index_1.d.next = self.phase.val().get_bits::<TABLE_BITS>(17);
        if self.quadrant.val().get_bit(0) {
            self.index_1.d.next = !(self.phase.val().get_bits::<TABLE_BITS>(17));
        }
        self.quadrant_1.d.next = self.quadrant.val();
        self.live_1.d.next = self.ready.val();
        // Stage 2: the RAM reads the index, or the fill writes.
        self.ram.write_enable.next = self.fill_write.val();
        self.ram.address.next = self.index_1.q.val();
        if self.fill_write.val() {
            self.ram.address.next = self.fill_address.val();
        }
        self.ram.write_data.next = self.fill_word.val();
        self.quadrant_2.d.next = self.quadrant_1.q.val();
        self.live_2.d.next = self.live_1.q.val();
        // Stage 3: the word registered.
        self.quadrant_3.d.next = self.quadrant_2.q.val();
        self.live_3.d.next = self.live_2.q.val();
        self.value_3.d.next = self.ram.q.val();
        // Stage 4: the sign.
        self.live_4.d.next = self.live_3.q.val();
        self.signed_4.d.next = self.value_3.q.val();
        if self.quadrant_3.q.val().get_bit(1) {
            self.signed_4.d.next = -self.value_3.q.val();
        }
        // Stage 5: output, 0 until the table is ready.
        self.sin_out.d.next = self.zero.val();
        if self.live_4.q.val() {
            self.sin_out.d.next = self.signed_4.q.val();
        }
        self.sin.next = self.sin_out.q.val();
    }
}

crate::impl_clocked!(TableSine);
