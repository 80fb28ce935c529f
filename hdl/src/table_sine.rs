//! Carrier sine: a quarter-wave table of 8192 words in a single-port RAM,
//! filled at power-up, read through `crate::quarter_wave`. No multiplier.
//!
//! ```text
//!  phase, advance ──► QuarterWave ──► sin
//!  ready ──(live)──►      │ index ▲ word
//!                         ▼       │
//!  fill: write, address ─► RAM 8192 x 16 (the write takes the port)
//!  fill: word ───────────►
//! ```
//!
//! The table holds the sine at the centre of each of the 8192 intervals of
//! the first quadrant (`crate::carrier_table_fill` writes it); the output
//! is the sine of the phase rounded to the nearest of 2^15 interval
//! centres per turn. The RAM is written, not initialized (an SPRAM has no
//! bitstream contents): while `fill_write` is high the fill takes the
//! port, and a lookup reaches `sin` only if `ready` was high when it
//! started, so the output is 0 until the table is complete. The filler
//! must never write once `ready` is high.
//!
//! Widths and pipeline: those of `QuarterWave` (16-bit output, peak 32767,
//! 5 clocks). Error against `32767 sin(2 pi phase / 2^32)`: at most
//! 32767 pi / 2^15 = 3.14 LSB from the phase rounding plus the table
//! words' own error (`crate::carrier_table_fill`: 1 LSB). Spurs: the phase
//! rounding is a phase error periodic in the phase, whose largest spur is
//! near -6.02 x 15 + 3.9 = -86 dBc (Nicholas and Samueli's bound for 15
//! phase bits); measured by FFT in `crate::carrier_nco`. Resources: one
//! 8192 x 16 single-port RAM (an iCE40 UltraPlus SPRAM, or eight ECP5
//! `DP16KD`).

use crate::primitives::SinglePortRam;
use crate::quarter_wave::{QuarterWave, TABLE_BITS};
use rust_hdl::prelude::*;

/// Clock cycles from `phase` to `sin`.
pub const LATENCY: usize = crate::quarter_wave::LATENCY;

/// Sine of a 32-bit phase plus whole quarter turns from a RAM table.
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
    lookup: QuarterWave,
    ram: SinglePortRam<16, TABLE_BITS>,
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
            lookup: QuarterWave::new(),
            ram: SinglePortRam::new(),
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
        self.lookup.clock.next = self.clock.val();
        self.ram.clock.next = self.clock.val();
        self.lookup.phase.next = self.phase.val();
        self.lookup.advance.next = self.advance.val();
        self.lookup.live.next = self.ready.val();
        // The fill takes the port while it writes.
        self.ram.write_enable.next = self.fill_write.val();
        self.ram.address.next = self.lookup.index.val();
        if self.fill_write.val() {
            self.ram.address.next = self.fill_address.val();
        }
        self.ram.write_data.next = self.fill_word.val();
        self.lookup.word.next = self.ram.q.val();
        self.sin.next = self.lookup.sin.val();
    }
}

crate::impl_clocked!(TableSine);
