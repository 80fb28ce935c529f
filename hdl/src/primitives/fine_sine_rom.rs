//! Synchronous ROM of the fine carrier table (`crate::fine_sine_table`),
//! two registered read ports.
//!
//! ```text
//!   addr_a ──► [ROM 8192 x 17, initialized] ──► [reg] ──► word_a
//!   addr_b ──►            (second port)      ──► [reg] ──► word_b
//! ```
//!
//! `crate::sine_pair` reads an interval's sine (`addr_a = i`) and its
//! cosine (`addr_b = ~i`) at once. The Verilog is one memory with an
//! `initial` image and two registered reads, which Yosys maps to block RAM
//! used as a true dual-port ROM: 8192 x 17 bits is eight ECP5 `DP16KD`
//! of 1K x 18, as placed (`verilog-out/RESOURCES.md`). An iCE40 UltraPlus cannot hold it (its SPRAMs have no
//! initial contents, and 139 kbit is more than its 30 `SB_RAM40_4K`):
//! this ROM belongs to the ECP5 carrier profile only. The read registers
//! power up at 0, so the block simulates from time zero without X.
//! Drive the addresses from registers (a LUT-built ROM folds logic in
//! front of its address into itself).
//!
//! Latency: 1 clock. Leaf block with hand-written Verilog (not
//! single-source): `crate::sine_pair`'s tests replay it in Icarus.

use super::convert::i128_to_signed;
use crate::fine_sine_table::{TABLE_BITS, WORD_BITS, words};
use rust_hdl::prelude::*;

/// The fine table, two registered read ports.
#[derive(Clone, Debug, LogicBlock)]
pub struct FineSineRom {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// First port's table index.
    pub addr_a: Signal<In, Bits<TABLE_BITS>>,
    /// Second port's table index.
    pub addr_b: Signal<In, Bits<TABLE_BITS>>,
    /// `word[addr_a]` as of the previous rising edge (never negative).
    pub word_a: Signal<Out, Signed<18>>,
    /// `word[addr_b]` as of the previous rising edge (never negative).
    pub word_b: Signal<Out, Signed<18>>,
    _words: Vec<u32>,
    _read: (u32, u32),
}

impl FineSineRom {
    /// The ROM with the table of `crate::fine_sine_table`.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            addr_a: Default::default(),
            addr_b: Default::default(),
            word_a: Signal::new_with_default(Signed::default()),
            word_b: Signal::new_with_default(Signed::default()),
            _words: words(),
            _read: (0, 0),
        }
    }
}

impl Default for FineSineRom {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for FineSineRom {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            self._read = (
                self._words[self.addr_a.val().index()],
                self._words[self.addr_b.val().index()],
            );
        }
        self.word_a.next = i128_to_signed(self._read.0 as i128);
        self.word_b.next = i128_to_signed(self._read.1 as i128);
    }

    fn connect(&mut self) {
        self.word_a.connect();
        self.word_b.connect();
    }

    fn hdl(&self) -> Verilog {
        let mut init = String::new();
        for (i, w) in words().iter().enumerate() {
            init.push_str(&format!("   words[{i}] = {WORD_BITS}'d{w};\n"));
        }
        Verilog::Custom(format!(
            "\
reg [{msb}:0] words [0:{last}];
reg [{msb}:0] a_q;
reg [{msb}:0] b_q;

initial begin
{init}   a_q = 0;
   b_q = 0;
end

always @(posedge clock) begin
   a_q <= words[addr_a];
   b_q <= words[addr_b];
end

always @(*) begin
   word_a = $signed({{1'b0, a_q}});
   word_b = $signed({{1'b0, b_q}});
end",
            msb = WORD_BITS - 1,
            last = (1usize << TABLE_BITS) - 1,
        ))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "fine_sine_rom".into(),
            clock: "clock".into(),
            inputs: vec!["addr_a".into(), "addr_b".into()],
            outputs: vec!["word_a".into(), "word_b".into()],
        }]
    }
}
