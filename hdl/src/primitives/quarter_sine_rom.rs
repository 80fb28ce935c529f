//! Synchronous ROM holding the quarter-wave sine table.
//!
//! ```text
//!   addr[8] ──► [value, slope ROM] ──► [reg] ──► value, slope  (16-bit signed)
//! ```
//!
//! One registered read port of the 256 x (16 + 16)-bit table of
//! `crate::sine_table`: the sample at the centre of an interval and the
//! derivative there. Drive `addr` from a register: where a tool builds the
//! ROM from LUTs (Yosys `synth_xilinx`), logic before the address would be
//! folded into the ROM's (an address mirrored by a ninth input doubles it). The Verilog is a plain memory with an `initial` image
//! and a registered read, which Yosys and vendor tools map to block RAM (two
//! iCE40 `SB_RAM40_4K`, 16 bits wide each; one ECP5 `DP16KD`).
//! Unlike rust-hdl's `SyncROM`, the output registers have a power-up value
//! (0), so the design simulates from time zero without X.
//!
//! Latency: 1 clock. Leaf block with hand-written Verilog (not
//! single-source): the top-level golden-vector replay covers it.

use super::convert::i128_to_signed;
use crate::sine_table;
use rust_hdl::prelude::*;

/// Quarter-wave sine and slope table, one registered read port.
#[derive(Clone, Debug, LogicBlock)]
pub struct QuarterSineRom {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Table index: the interval of the quadrant.
    pub addr: Signal<In, Bits<8>>,
    /// `value[addr]` as of the previous rising edge.
    pub value: Signal<Out, Signed<16>>,
    /// `slope[addr]` as of the previous rising edge.
    pub slope: Signal<Out, Signed<16>>,
    _value: Vec<Signed<16>>,
    _slope: Vec<Signed<16>>,
}

impl QuarterSineRom {
    /// The ROM with the table of `crate::sine_table`.
    pub fn new() -> Self {
        let (value, slope) = sine_table::table();
        assert_eq!(value.len(), 1 << 8);
        let to_words = |v: Vec<i32>| v.into_iter().map(|x| i128_to_signed(x as i128)).collect();
        Self {
            clock: Default::default(),
            addr: Default::default(),
            value: Signal::new_with_default(Signed::default()),
            slope: Signal::new_with_default(Signed::default()),
            _value: to_words(value),
            _slope: to_words(slope),
        }
    }
}

impl Default for QuarterSineRom {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for QuarterSineRom {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let a = self.addr.val().to_u64() as usize;
            self.value.next = self._value[a];
            self.slope.next = self._slope[a];
        }
    }

    fn connect(&mut self) {
        self.value.connect();
        self.slope.connect();
    }

    fn hdl(&self) -> Verilog {
        let (value, slope) = sine_table::table();
        let mut init = String::new();
        for (i, (v, s)) in value.iter().zip(&slope).enumerate() {
            init.push_str(&format!(
                "   value_rom[{i}] = 16'sd{v}; slope_rom[{i}] = 16'sd{s};\n"
            ));
        }
        Verilog::Custom(format!(
            "\
reg signed [15:0] value_rom [0:255];
reg signed [15:0] slope_rom [0:255];

initial begin
{init}   value = 0;
   slope = 0;
end

always @(posedge clock) begin
   value <= value_rom[addr];
   slope <= slope_rom[addr];
end"
        ))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "quarter_sine_rom".into(),
            clock: "clock".into(),
            inputs: vec!["addr".into()],
            outputs: vec!["value".into(), "slope".into()],
        }]
    }
}
