//! Synchronous ROM holding the modulation NCO's quarter-wave sine table,
//! stored as a coarse and a fine column.
//!
//! ```text
//!   addr[13] ──► i = addr >> 1 ──┬─► [coarse ROM, 256 x 16] ─► [reg] ─┐
//!                                └─► [fine ROM, 4096 x 8]   ─► [reg] ─┴─► + ──► value
//! ```
//!
//! One registered read port of the 4096-entry table of `crate::sine_table`,
//! addressed with the 13-bit index of `crate::quarter_wave` (8192 intervals
//! per quadrant) whose lowest bit it ignores: both halves of a table
//! interval read its word, and the mirrored index ~i of `QuarterWave`
//! reads the mirrored entry, since ~i >> 1 = ~(i >> 1).
//!
//! Storage: `value[i] = coarse[i >> 4] + fine[i]`, where `coarse[k] =
//! value[16 k]` and `fine[i]` is the rise from there. The sine rises by at
//! most 32767 (pi / 2) / 4096 = 12.6 per entry, so within a group of 16
//! `fine` stays in [0, 189] and fits 8 unsigned bits (checked in the tests).
//! 4096 x 8 + 256 x 16 bits is nine iCE40 `SB_RAM40_4K` where the plain
//! 4096 x 15 table took fifteen (the UP5K has 30, and the bus FIFO needs
//! six). The sum is formed after the registered reads, in front of the
//! caller's word register. Drive `addr` from a register: where a tool
//! builds a ROM from LUTs, logic before the address would be folded into
//! it. The Verilog is two plain memories with `initial` images and
//! registered reads, which Yosys maps to block RAM. Unlike rust-hdl's
//! `SyncROM`, the read registers have a power-up value (0), so `value` is
//! 0 until the first read and the design simulates from time zero without X.
//!
//! Latency: 1 clock. Leaf block with hand-written Verilog (not
//! single-source): the top-level golden-vector replay covers it.

use super::convert::i128_to_signed;
use crate::quarter_wave::TABLE_BITS;
use crate::sine_table;
use rust_hdl::prelude::*;

/// Entries per coarse group.
const GROUP_BITS: usize = 4;

/// The table's two columns: `coarse[k] = value[16 k]`, `fine[i] = value[i] -
/// coarse[i >> 4]`.
pub fn columns() -> (Vec<i32>, Vec<i32>) {
    let value = sine_table::table();
    let coarse: Vec<i32> = value.iter().step_by(1 << GROUP_BITS).copied().collect();
    let fine = value
        .iter()
        .enumerate()
        .map(|(i, v)| v - coarse[i >> GROUP_BITS])
        .collect();
    (coarse, fine)
}

/// Quarter-wave sine table, one registered read port.
#[derive(Clone, Debug, LogicBlock)]
pub struct QuarterSineRom {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Quarter-wave index (8192 intervals); bit 0 is ignored.
    pub addr: Signal<In, Bits<TABLE_BITS>>,
    /// `value[addr >> 1]` as of the previous rising edge.
    pub value: Signal<Out, Signed<16>>,
    _coarse: Vec<i32>,
    _fine: Vec<i32>,
    _read: (i32, i32),
}

impl QuarterSineRom {
    /// The ROM with the table of `crate::sine_table`.
    pub fn new() -> Self {
        assert_eq!(sine_table::ENTRIES << 1, 1 << TABLE_BITS);
        let (coarse, fine) = columns();
        Self {
            clock: Default::default(),
            addr: Default::default(),
            value: Signal::new_with_default(Signed::default()),
            _coarse: coarse,
            _fine: fine,
            _read: (0, 0),
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
            let i = self.addr.val().index() >> 1;
            self._read = (self._coarse[i >> GROUP_BITS], self._fine[i]);
        }
        self.value.next = i128_to_signed((self._read.0 + self._read.1) as i128);
    }

    fn connect(&mut self) {
        self.value.connect();
    }

    fn hdl(&self) -> Verilog {
        let (coarse, fine) = columns();
        let mut init = String::new();
        for (k, c) in coarse.iter().enumerate() {
            init.push_str(&format!("   coarse_rom[{k}] = 16'sd{c};\n"));
        }
        for (i, f) in fine.iter().enumerate() {
            init.push_str(&format!("   fine_rom[{i}] = 8'd{f};\n"));
        }
        Verilog::Custom(format!(
            "\
reg signed [15:0] coarse_rom [0:{coarse_last}];
reg [7:0] fine_rom [0:{fine_last}];
reg signed [15:0] coarse_q;
reg [7:0] fine_q;

initial begin
{init}   coarse_q = 0;
   fine_q = 0;
end

always @(posedge clock) begin
   coarse_q <= coarse_rom[addr[{msb}:{coarse_low}]];
   fine_q <= fine_rom[addr[{msb}:1]];
end

always @(*) value = coarse_q + $signed({{8'd0, fine_q}});",
            coarse_last = coarse.len() - 1,
            fine_last = fine.len() - 1,
            msb = TABLE_BITS - 1,
            coarse_low = GROUP_BITS + 1,
        ))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "quarter_sine_rom".into(),
            clock: "clock".into(),
            inputs: vec!["addr".into()],
            outputs: vec!["value".into()],
        }]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_fit_their_widths_and_sum_to_the_table() {
        let (coarse, fine) = columns();
        assert_eq!(coarse.len(), sine_table::ENTRIES >> GROUP_BITS);
        assert!(coarse.iter().all(|&c| (0..=sine_table::PEAK).contains(&c)));
        assert!(
            fine.iter().all(|&f| (0..=255).contains(&f)),
            "fine column exceeds 8 bits"
        );
        assert_eq!(fine.iter().max(), Some(&189));
        for (i, v) in sine_table::table().into_iter().enumerate() {
            assert_eq!(coarse[i >> GROUP_BITS] + fine[i], v, "entry {i}");
        }
    }
}
