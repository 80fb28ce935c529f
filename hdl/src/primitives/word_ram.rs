//! Simple dual-port RAM with a registered read: one write port, one read
//! port, one clock.
//!
//! ```text
//!  write_enable, write_address, write_data ──► words[2^A] of W bits
//!  read_address ──► words[read_address] ──► [q]        (read every clock)
//! ```
//!
//! At every rising edge `q` takes the word at `read_address` as it was
//! before the edge, and, when `write_enable` is high, `write_data` goes
//! into the word at `write_address`. Latency: 1 clock from a read address
//! to `q`. Every word powers up at 0; `q` has no power-up value in the
//! Verilog (an initial value on the read register would keep Yosys from
//! using the block RAM's own output register) and is 0 in the Rust model:
//! a user must read an address before using `q`.
//!
//! The caller must never read and write one address at the same edge: the
//! memory carries Yosys's `no_rw_check` attribute, so Yosys adds no bypass
//! logic for that case, and what a block RAM then returns is the part's
//! business. `new()` cannot check this; the Rust model panics on it, so
//! every simulation of a caller checks its schedule.
//!
//! Mapping (Yosys 0.23, measured on an 8 x 80-bit instance): iCE40 five
//! `SB_RAM40_4K` (16 bits wide each) and one LUT; ECP5 twenty
//! `TRELLIS_DPR16X4` (LUT RAM) and the 80 read flip-flops.
//!
//! Leaf block with hand-written Verilog (not single-source): the top-level
//! golden-vector replay in Icarus and Verilator covers it.

use super::convert::i128_to_signed;
use rust_hdl::prelude::*;

/// `2^A` words of `W` bits, one write and one registered read per clock.
#[derive(Clone, Debug, LogicBlock)]
pub struct WordRam<const W: usize, const A: usize> {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Write `write_data` at `write_address` at this edge.
    pub write_enable: Signal<In, Bit>,
    /// Address of the word written.
    pub write_address: Signal<In, Bits<A>>,
    /// The word written.
    pub write_data: Signal<In, Signed<W>>,
    /// Address of the word read; it must differ from `write_address`
    /// whenever `write_enable` is high.
    pub read_address: Signal<In, Bits<A>>,
    /// The word at `read_address` before the previous rising edge.
    pub q: Signal<Out, Signed<W>>,
    _words: Vec<Signed<W>>,
}

impl<const W: usize, const A: usize> WordRam<W, A> {
    /// A RAM of `2^A` words, all zero; `A` must be between 1 and 8.
    pub fn new() -> Self {
        assert!((1..=8).contains(&A), "WordRam depth must be 2..256 words");
        Self {
            clock: Default::default(),
            write_enable: Default::default(),
            write_address: Default::default(),
            write_data: Default::default(),
            read_address: Default::default(),
            q: Signal::new_with_default(i128_to_signed(0)),
            _words: vec![i128_to_signed(0); 1 << A],
        }
    }
}

impl<const W: usize, const A: usize> Default for WordRam<W, A> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const W: usize, const A: usize> Logic for WordRam<W, A> {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let read = self.read_address.val().index();
            self.q.next = self._words[read];
            if self.write_enable.val() {
                let write = self.write_address.val().index();
                assert_ne!(read, write, "WordRam read and write one address");
                self._words[write] = self.write_data.val();
            }
        }
    }

    fn connect(&mut self) {
        self.q.connect();
    }

    fn hdl(&self) -> Verilog {
        let msb = W - 1;
        Verilog::Custom(format!(
            "\
(* no_rw_check *)
reg signed [{msb}:0] words [0:{last}];
integer init_index;

initial begin
   for (init_index = 0; init_index < {depth}; init_index = init_index + 1)
      words[init_index] = 0;
end

always @(posedge clock) begin
   if (write_enable)
      words[write_address] <= write_data;
   q <= words[read_address];
end",
            depth = 1usize << A,
            last = (1usize << A) - 1
        ))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "word_ram".into(),
            clock: "clock".into(),
            inputs: vec![
                "write_enable".into(),
                "write_address".into(),
                "write_data".into(),
                "read_address".into(),
            ],
            outputs: vec!["q".into()],
        }]
    }
}

#[cfg(test)]
mod verilog_tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::primitives::convert::signed_to_i128;

    crate::impl_clocked!(WordRam<8, 3>);

    /// The hand-written Verilog against this model, clock by clock: every
    /// word read before any write (the power-up zeros the design's delay
    /// lines rely on, which its own traffic never reads unwritten), then
    /// random writes and reads at other addresses.
    #[test]
    fn the_verilog_matches_the_model_from_power_up() {
        let mut ram = WordRam::<8, 3>::new();
        prepare(&mut ram);
        let mut rng = crate::test_util::Rng::new(9);
        let mut ops: Vec<(bool, u64, i128, u64)> = (0..8).map(|a| (false, 0, 0, a)).collect();
        ops.extend((0..300).map(|_| {
            let r = rng.next_u64();
            let (w, rd) = ((r >> 8) % 8, (r >> 12) % 8);
            let write = r.is_multiple_of(2) && w != rd;
            (write, w, ((r >> 16) % 256) as i128 - 128, rd)
        }));
        let mut expected = vec![];
        let mut steps = vec![];
        for &(write, w, d, rd) in &ops {
            ram.write_enable.next = write;
            ram.write_address.next = w.into();
            ram.write_data.next = i128_to_signed(d);
            ram.read_address.next = rd.into();
            tick(&mut ram);
            expected.push(signed_to_i128(ram.q.val()).to_string());
            steps.push(format!(
                "write_enable = {}; write_address = {w}; write_data = {d}; read_address = {rd};",
                u8::from(write)
            ));
        }
        let got = crate::test_util::icarus_clocked(
            &generate_verilog(&ram),
            &[
                ("write_enable", 1, false),
                ("write_address", 3, false),
                ("write_data", 8, true),
                ("read_address", 3, false),
            ],
            ("q", 8),
            &steps,
        );
        assert_eq!(got, expected);
    }
}
