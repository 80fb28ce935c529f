//! Dual-read synchronous ROM holding the quarter-wave sine table.
//!
//! ```text
//!   addr_a[8] ──► [value, slope ROM] ──► [reg] ──► value_a, slope_a  (16-bit signed)
//!   addr_b[8] ──► [value, slope ROM] ──► [reg] ──► value_b, slope_b
//! ```
//!
//! Two registered read ports of the 256 x (16 + 16)-bit table of
//! `crate::sine_table`. Port a reads the sine sample of an interval and port
//! b the mirrored entry, which is its cosine. The Verilog is a plain memory
//! with an `initial` image and registered reads, which Yosys and vendor tools
//! map to block RAM (two copies on iCE40, whose EBRs have a single read port).
//! Unlike rust-hdl's `SyncROM`, the output registers have a power-up value
//! (0), so the design simulates from time zero without X.
//!
//! Latency: 1 clock. Leaf block with hand-written Verilog (not
//! single-source): the top-level golden-vector replay covers it.

use super::convert::i128_to_signed;
use crate::sine_table;
use rust_hdl::prelude::*;

/// Quarter-wave sine and slope table, two registered read ports.
#[derive(Clone, Debug, LogicBlock)]
pub struct QuarterSineRom {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Address of read port a.
    pub addr_a: Signal<In, Bits<8>>,
    /// Address of read port b.
    pub addr_b: Signal<In, Bits<8>>,
    /// `value[addr_a]` as of the previous rising edge.
    pub value_a: Signal<Out, Signed<16>>,
    /// `slope[addr_a]` as of the previous rising edge.
    pub slope_a: Signal<Out, Signed<16>>,
    /// `value[addr_b]` as of the previous rising edge.
    pub value_b: Signal<Out, Signed<16>>,
    /// `slope[addr_b]` as of the previous rising edge.
    pub slope_b: Signal<Out, Signed<16>>,
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
            addr_a: Default::default(),
            addr_b: Default::default(),
            value_a: Signal::new_with_default(Signed::default()),
            slope_a: Signal::new_with_default(Signed::default()),
            value_b: Signal::new_with_default(Signed::default()),
            slope_b: Signal::new_with_default(Signed::default()),
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
            let a = self.addr_a.val().to_u64() as usize;
            let b = self.addr_b.val().to_u64() as usize;
            self.value_a.next = self._value[a];
            self.slope_a.next = self._slope[a];
            self.value_b.next = self._value[b];
            self.slope_b.next = self._slope[b];
        }
    }

    fn connect(&mut self) {
        self.value_a.connect();
        self.slope_a.connect();
        self.value_b.connect();
        self.slope_b.connect();
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
{init}   value_a = 0;
   slope_a = 0;
   value_b = 0;
   slope_b = 0;
end

always @(posedge clock) begin
   value_a <= value_rom[addr_a];
   slope_a <= slope_rom[addr_a];
   value_b <= value_rom[addr_b];
   slope_b <= slope_rom[addr_b];
end"
        ))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "quarter_sine_rom".into(),
            clock: "clock".into(),
            inputs: vec!["addr_a".into(), "addr_b".into()],
            outputs: vec![
                "value_a".into(),
                "slope_a".into(),
                "value_b".into(),
                "slope_b".into(),
            ],
        }]
    }
}
