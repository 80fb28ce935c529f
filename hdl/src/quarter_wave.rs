//! Quarter-wave lookup pipeline: the table index, the quadrant's sign and
//! the output register around one registered table read, shared by the
//! ROM sine (`crate::sine`) and the carriers' RAM sine (`crate::table_sine`).
//!
//! ```text
//!  clock:      1 index                2 table read        3 word        4 sign             5 output
//!  phase[31:30] + advance = q ─► [q] ───────────────────► [q] ─────────► [q] ─┐
//!  phase[29:17] i ─► q odd ? ~i : i ─► [index] ─► table ─► word ─► [value] ─► ±v (q >= 2: -) ─► [live ? ±v : 0]
//!  live ─────────────► [live] ────────────────────────► [live] ─────────► [live] ────────────┘
//! ```
//!
//! The phase is a binary fraction of a turn (2^32 = 360 degrees); `advance`
//! adds whole quarter turns (1: the output is the cosine). Bits 29:17 pick
//! one of the 8192 intervals of the quadrant (`TABLE_BITS`); the table
//! holds the first-quadrant sine of each interval, sampled at its centre.
//! An odd quadrant runs the quadrant backwards and reads the mirrored
//! entry ~i, whose centre is the same distance from the quadrant's end;
//! quadrants 2 and 3 negate. Phase bits 16:0 are ignored.
//!
//! The table is outside: `index` (a register, so a LUT-built table sees
//! no logic in front of its address) goes to a table with a registered
//! read, whose output comes back as `word` one clock later. A lookup
//! reaches `sin` when `live` was high during its first stage, and gives
//! 0 otherwise (a RAM table that is still being filled).
//!
//! Widths: the table words must lie in [0, 32767] (first-quadrant sines),
//! so the negation cannot overflow and the output is 16-bit two's
//! complement, peak 32767, never -32768. Pipeline: 5 registers (index,
//! the table's read, word, signed word, output): `sin` during cycle n
//! belongs to the `phase`, `advance` and `live` of cycle n - 5.
//! Resources: 13 + 2 x 16 + 8 flip-flops, a 13-bit mirror, a 16-bit negation.

use rust_hdl::prelude::*;

/// Index bits of a quarter-wave table: 2^13 intervals per quadrant.
pub const TABLE_BITS: usize = 13;
/// Intervals per quadrant.
pub const TABLE_ENTRIES: usize = 1 << TABLE_BITS;
/// Phase bits below the table index (32 - 2 quadrant bits - 13).
pub const PHASE_BELOW_INDEX: usize = 32 - 2 - TABLE_BITS;
/// Clock cycles from `phase` to `sin`.
pub const LATENCY: usize = 5;

/// Index, sign and output stages of a quarter-wave table sine.
#[derive(LogicBlock)]
pub struct QuarterWave {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Phase as a fraction of a turn: 2^32 is 360 degrees.
    pub phase: Signal<In, Bits<32>>,
    /// Quarter turns added to `phase` (0: sine, 1: cosine, 2: -sine, 3: -cosine).
    pub advance: Signal<In, Bits<2>>,
    /// The lookup started now reaches `sin` (else `sin` gives 0 for it).
    pub live: Signal<In, Bit>,
    /// Table address (registered): the entry for the phase of the previous cycle.
    pub index: Signal<Out, Bits<TABLE_BITS>>,
    /// The table's registered read of `index`, one clock after it.
    pub word: Signal<In, Signed<16>>,
    /// 32767 sin(phase + advance quarter turns), `LATENCY` clocks after `phase`.
    pub sin: Signal<Out, Signed<16>>,
    index_1: DFF<Bits<TABLE_BITS>>,
    quadrant_1: DFF<Bits<2>>,
    live_1: DFF<Bit>,
    quadrant_2: DFF<Bits<2>>,
    live_2: DFF<Bit>,
    quadrant_3: DFF<Bits<2>>,
    live_3: DFF<Bit>,
    value_3: DFF<Signed<16>>,
    live_4: DFF<Bit>,
    signed_4: DFF<Signed<16>>,
    sin_out: DFF<Signed<16>>,
    quadrant: Signal<Local, Bits<2>>,
    zero: Constant<Signed<16>>,
}

impl QuarterWave {
    /// The pipeline at power-up: every register 0.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            phase: Default::default(),
            advance: Default::default(),
            live: Default::default(),
            index: Default::default(),
            word: Default::default(),
            sin: Default::default(),
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

impl Default for QuarterWave {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for QuarterWave {
    #[hdl_gen]
    fn update(&mut self) {
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
        self.live_1.d.next = self.live.val();
        // Stage 2: the table reads `index`.
        self.index.next = self.index_1.q.val();
        self.quadrant_2.d.next = self.quadrant_1.q.val();
        self.live_2.d.next = self.live_1.q.val();
        // Stage 3: the word registered (a block RAM's clock-to-out plus a
        // negation does not fit one clock at 125 MHz on an ECP5).
        self.quadrant_3.d.next = self.quadrant_2.q.val();
        self.live_3.d.next = self.live_2.q.val();
        self.value_3.d.next = self.word.val();
        // Stage 4: the sign.
        self.live_4.d.next = self.live_3.q.val();
        self.signed_4.d.next = self.value_3.q.val();
        if self.quadrant_3.q.val().get_bit(1) {
            self.signed_4.d.next = -self.value_3.q.val();
        }
        // Stage 5: output, 0 for a lookup that was not live.
        self.sin_out.d.next = self.zero.val();
        if self.live_4.q.val() {
            self.sin_out.d.next = self.signed_4.q.val();
        }
        self.sin.next = self.sin_out.q.val();
    }
}
