//! The output filter's digit RAM: 2^A words of 16-bit two's complement,
//! one registered read port and one write port.
//!
//! ```text
//!  read_address ──► RAM ──► [q]          (q = word as of the edge that read it)
//!  write_address, write_data, write_enable ──► RAM at the rising edge
//! ```
//!
//! A read and a write of the same word at one edge read the old word (the
//! schedule of `crate::iir_program` never does it: its test checks every
//! read comes after its write). Every word and `q` power up at 0 (Verilog
//! `initial`), so the filter starts from zero state like the flip-flops it
//! replaces. The read goes straight into a register, so Yosys maps the
//! words to one block RAM (iCE40 `SB_RAM40_4K`, ECP5 `DP16KD` or LUT RAM).
//!
//! Latency: 1 clock. Leaf block with hand-written Verilog (not
//! single-source): the top-level golden-vector replay covers it.

use super::convert::i128_to_signed;
use rust_hdl::prelude::*;

/// Width of a word.
pub const DIGIT_WORD_BITS: usize = 16;

/// `2^A` words of 16 bits, registered read, synchronous write.
#[derive(Clone, Debug, LogicBlock)]
pub struct DigitRam<const A: usize> {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Word to read at the next rising edge.
    pub read_address: Signal<In, Bits<A>>,
    /// The word read at the previous rising edge.
    pub q: Signal<Out, Signed<DIGIT_WORD_BITS>>,
    /// Word to write.
    pub write_address: Signal<In, Bits<A>>,
    /// Value to write.
    pub write_data: Signal<In, Signed<DIGIT_WORD_BITS>>,
    /// Write at the next rising edge.
    pub write_enable: Signal<In, Bit>,
    _words: Vec<Signed<DIGIT_WORD_BITS>>,
}

impl<const A: usize> DigitRam<A> {
    /// A RAM of `2^A` zero words; `A` must be 1..=10.
    pub fn new() -> Self {
        assert!((1..=10).contains(&A), "DigitRam holds 2..1024 words");
        Self {
            clock: Default::default(),
            read_address: Default::default(),
            q: Signal::new_with_default(i128_to_signed(0)),
            write_address: Default::default(),
            write_data: Default::default(),
            write_enable: Default::default(),
            _words: vec![i128_to_signed(0); 1 << A],
        }
    }
}

impl<const A: usize> Default for DigitRam<A> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const A: usize> Logic for DigitRam<A> {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            self.q.next = self._words[self.read_address.val().to_u64() as usize];
            if self.write_enable.val() {
                self._words[self.write_address.val().to_u64() as usize] = self.write_data.val();
            }
        }
    }

    fn connect(&mut self) {
        self.q.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(format!(
            "\
reg signed [{msb}:0] words [0:{last}];
integer init_index;

initial begin
   for (init_index = 0; init_index < {depth}; init_index = init_index + 1)
      words[init_index] = 0;
   q = 0;
end

always @(posedge clock) begin
   q <= words[read_address];
   if (write_enable)
      words[write_address] <= write_data;
end",
            msb = DIGIT_WORD_BITS - 1,
            depth = 1usize << A,
            last = (1usize << A) - 1
        ))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "digit_ram".into(),
            clock: "clock".into(),
            inputs: vec![
                "read_address".into(),
                "write_address".into(),
                "write_data".into(),
                "write_enable".into(),
            ],
            outputs: vec!["q".into()],
        }]
    }
}
