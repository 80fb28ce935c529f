//! The output filter's digit RAM: 2^A words of 16-bit two's complement,
//! one registered read port and one write port.
//!
//! ```text
//!  read_address ──► RAM ──► [q]          (q = word as of the edge that read it)
//!  write_address, write_data, write_enable ──► RAM at the rising edge
//! ```
//!
//! The caller must never read and write one word at the same edge (the
//! schedule of `crate::iir_program` never does: its test checks every read
//! comes after its write). The memories carry Yosys's `no_rw_check`
//! attribute, so Yosys adds no bypass logic for that case (41 flip-flops
//! and 5 LUTs on iCE40 for a 128-word RAM); the Rust model panics on it,
//! so every simulation of the filter checks the schedule. Every word and `q` power up at 0 (Verilog
//! `initial`), so the filter starts from zero state like the flip-flops it
//! replaces.
//!
//! The Verilog keeps the words in two memories of 2^(A-1), split by the top
//! address bit, each read straight into its own register, with a 2-to-1
//! multiplexer after them (the same words, the same `q`). Each half maps to
//! one block RAM on iCE40 (`SB_RAM40_4K`), and, being at most 1 kbit, to
//! LUT RAM on ECP5: a 128 x 16 memory went into a `DP16KD`, whose
//! clock-to-output (6.6 ns with the operand's multiplexer) made the read
//! into the operand register the design's critical path at 100 MHz.
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
    /// A RAM of `2^A` zero words; `A` must be 2..=10.
    pub fn new() -> Self {
        assert!((2..=10).contains(&A), "DigitRam holds 4..1024 words");
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
            let read = self.read_address.val().to_u64() as usize;
            self.q.next = self._words[read];
            if self.write_enable.val() {
                let write = self.write_address.val().to_u64() as usize;
                assert_ne!(read, write, "DigitRam read and write one address");
                self._words[write] = self.write_data.val();
            }
        }
    }

    fn connect(&mut self) {
        self.q.connect();
    }

    fn hdl(&self) -> Verilog {
        Verilog::Custom(format!(
            "\
(* no_rw_check *) reg signed [{msb}:0] words_low [0:{last}];
(* no_rw_check *) reg signed [{msb}:0] words_high [0:{last}];
reg signed [{msb}:0] q_low;
reg signed [{msb}:0] q_high;
reg high_read;
integer init_index;

initial begin
   for (init_index = 0; init_index < {half}; init_index = init_index + 1) begin
      words_low[init_index] = 0;
      words_high[init_index] = 0;
   end
   q_low = 0;
   q_high = 0;
   high_read = 0;
end

always @(posedge clock) begin
   q_low <= words_low[read_address[{top_minus_1}:0]];
   q_high <= words_high[read_address[{top_minus_1}:0]];
   high_read <= read_address[{top}];
   if (write_enable && !write_address[{top}])
      words_low[write_address[{top_minus_1}:0]] <= write_data;
   if (write_enable && write_address[{top}])
      words_high[write_address[{top_minus_1}:0]] <= write_data;
end

always @(*)
   q = high_read ? q_high : q_low;",
            msb = DIGIT_WORD_BITS - 1,
            half = 1usize << (A - 1),
            last = (1usize << (A - 1)) - 1,
            top = A - 1,
            top_minus_1 = A - 2
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
