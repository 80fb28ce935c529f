//! Delay line in block RAM with a run-time tap: q = d delayed by `delay` + 1
//! clocks.
//!
//! ```text
//!  d ──► RAM[wp] (2^A words, wp = cycle count mod 2^A)
//!        RAM[wp - delay] ──► [ram_q] ──┐
//!  d ─────────────────────► [bypass] ──┴── mux(delay was 0) ──► q
//! ```
//!
//! At every rising edge the RAM writes `d` at the write pointer, which then
//! advances, and reads, synchronously, the word written `delay` edges
//! earlier; a delay of 0 asks for the word being written, which comes from
//! a bypass register instead. So during cycle n + 1, `q = d(n - delay(n))`:
//! for a constant delay, `q = d(m - 1 - delay)` during cycle m, as a shift
//! register with a combinational tap would give, and a new delay acts one
//! clock later than with such a tap. Read and write addresses meet only at
//! delay 0, whose RAM word the bypass replaces, so the RAM's
//! read-during-write mode does not matter: the memory carries Yosys's
//! `no_rw_check` attribute, and Yosys adds no collision logic. Every word
//! powers up at 0.
//!
//! The RAM read goes straight into a register, so Yosys maps the words to
//! one block RAM per line (iCE40 `SB_RAM40_4K`, ECP5 `DP16KD` or LUT RAM)
//! instead of the 2^A x W flip-flops and the multiplexer of a shift
//! register.
//!
//! Leaf block with hand-written Verilog (not single-source): the top-level
//! golden-vector replay in Icarus and Verilator covers it.

use super::convert::i128_to_signed;
use rust_hdl::prelude::*;

/// A `2^A`-word delay line of `W`-bit words in RAM with a run-time tap.
#[derive(Clone, Debug, LogicBlock)]
pub struct TappedDelayLine<const W: usize, const A: usize> {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Input word, written at every rising edge.
    pub d: Signal<In, Signed<W>>,
    /// Tap to read: `q` is `d` delayed by `delay + 1` clocks (`delay`
    /// sampled at the edge that reads).
    pub delay: Signal<In, Bits<A>>,
    /// The selected word (registered).
    pub q: Signal<Out, Signed<W>>,
    /// `_words[i]` is `d` from i + 1 edges ago.
    _words: Vec<Signed<W>>,
}

impl<const W: usize, const A: usize> TappedDelayLine<W, A> {
    /// A delay line of `2^A` words, all zero; `A` must be between 1 and 10.
    pub fn new() -> Self {
        assert!(
            (1..=10).contains(&A),
            "TappedDelayLine depth must be 2..1024 words"
        );
        Self {
            clock: Default::default(),
            d: Default::default(),
            delay: Default::default(),
            q: Signal::new_with_default(i128_to_signed(0)),
            _words: vec![i128_to_signed(0); 1 << A],
        }
    }
}

impl<const W: usize, const A: usize> Default for TappedDelayLine<W, A> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const W: usize, const A: usize> Logic for TappedDelayLine<W, A> {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let delay = self.delay.val().to_u64() as usize;
            self.q.next = if delay == 0 {
                self.d.val()
            } else {
                self._words[delay - 1]
            };
            self._words.rotate_right(1);
            self._words[0] = self.d.val();
        }
    }

    fn connect(&mut self) {
        self.q.connect();
    }

    fn hdl(&self) -> Verilog {
        let depth = 1usize << A;
        let msb = W - 1;
        let amsb = A - 1;
        Verilog::Custom(format!(
            "\
(* no_rw_check *) reg signed [{msb}:0] words [0:{last}];
reg [{amsb}:0] write_address;
// An A-bit wire, so the address wraps modulo 2^A in every simulator.
wire [{amsb}:0] read_address = write_address - delay;
reg signed [{msb}:0] ram_q;
reg signed [{msb}:0] bypass_q;
reg use_bypass;
integer init_index;

initial begin
   for (init_index = 0; init_index < {depth}; init_index = init_index + 1)
      words[init_index] = 0;
   write_address = 0;
   ram_q = 0;
   bypass_q = 0;
   use_bypass = 0;
end

always @(posedge clock) begin
   words[write_address] <= d;
   write_address <= write_address + 1'b1;
   ram_q <= words[read_address];
   bypass_q <= d;
   use_bypass <= (delay == 0);
end

always @(*) q = use_bypass ? bypass_q : ram_q;",
            last = depth - 1
        ))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "tapped_delay_line".into(),
            clock: "clock".into(),
            inputs: vec!["d".into()],
            outputs: vec!["q".into()],
        }]
    }
}
