//! Shift register with a run-time tap: q = d delayed by `delay` + 1 clocks.
//!
//! ```text
//!  d ──► [0] ──► [1] ──► ... ──► [2^A - 1]
//!         └───────┴──── mux(delay) ────────► q   (combinational read)
//! ```
//!
//! `taps[0]` takes `d` at every rising edge and each tap takes the one
//! before it, so during cycle n, `q = d(n - 1 - delay)`. All taps power up
//! at 0. The Verilog is a register array with a dynamic read index, which
//! Xilinx tools map to SRL32 shift registers with a dynamic address and
//! other tools to flip-flops and a multiplexer.
//!
//! Leaf block with hand-written Verilog (not single-source): the top-level
//! golden-vector replay in Icarus and Verilator covers it.

use super::convert::i128_to_signed;
use rust_hdl::prelude::*;

/// A `2^A`-tap shift register of `W`-bit words with a run-time read tap.
#[derive(Clone, Debug, LogicBlock)]
pub struct TappedDelayLine<const W: usize, const A: usize> {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Input word, shifted in at every rising edge.
    pub d: Signal<In, Signed<W>>,
    /// Tap to read: `q` is `d` delayed by `delay + 1` clocks.
    pub delay: Signal<In, Bits<A>>,
    /// The selected tap (combinational from `delay` and the taps).
    pub q: Signal<Out, Signed<W>>,
    _taps: Vec<Signed<W>>,
}

impl<const W: usize, const A: usize> TappedDelayLine<W, A> {
    /// A delay line of `2^A` taps, all zero; `A` must be between 1 and 10.
    pub fn new() -> Self {
        assert!(
            (1..=10).contains(&A),
            "TappedDelayLine depth must be 2..1024 taps"
        );
        Self {
            clock: Default::default(),
            d: Default::default(),
            delay: Default::default(),
            q: Default::default(),
            _taps: vec![i128_to_signed(0); 1 << A],
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
            self._taps.rotate_right(1);
            self._taps[0] = self.d.val();
        }
        self.q.next = self._taps[self.delay.val().to_u64() as usize];
    }

    fn connect(&mut self) {
        self.q.connect();
    }

    fn hdl(&self) -> Verilog {
        let depth = 1usize << A;
        let msb = W - 1;
        Verilog::Custom(format!(
            "\
reg signed [{msb}:0] taps [0:{last}];
integer init_index;
integer shift_index;

initial begin
   for (init_index = 0; init_index < {depth}; init_index = init_index + 1)
      taps[init_index] = 0;
end

always @(posedge clock) begin
   taps[0] <= d;
   for (shift_index = 1; shift_index < {depth}; shift_index = shift_index + 1)
      taps[shift_index] <= taps[shift_index - 1];
end

always @(*) q = taps[delay];",
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
