//! Single-port RAM with a registered read: one address, a write or a read
//! at each edge, no initial contents.
//!
//! ```text
//!  write_enable, address, write_data ──► words[2^A] of W bits
//!                              address ──► words[address] ──► [q]   (when not writing)
//! ```
//!
//! At a rising edge with `write_enable` high, `write_data` goes into the
//! word at `address` and `q` keeps its value; with `write_enable` low, `q`
//! takes the word at `address`. Latency: 1 clock from an address to `q`.
//! This is the port of the iCE40 UltraPlus `SB_SPRAM256KA` (16K x 16, read
//! and write on one address, the output unchanged while writing), so Yosys
//! `synth_ice40 -spram` maps an 8192 x 16 instance to one SPRAM (half of
//! it used); ECP5 maps it to eight `DP16KD` in no-change write mode.
//!
//! The words have no power-up value: an SPRAM cannot be initialized by the
//! bitstream, so the Verilog has no `initial` block and an unwritten word
//! reads as X in Icarus. The caller writes every word before it uses what
//! it reads (`crate::carrier_table_fill`). The Rust model starts every word
//! and `q` at 0; whatever is read before the words are written must not
//! reach an output, and the top-level replay in Icarus (where it would be
//! X) checks that.
//!
//! Leaf block with hand-written Verilog (not single-source): the top-level
//! golden-vector replay in Icarus and Verilator covers it.

use super::convert::i128_to_signed;
use rust_hdl::prelude::*;

/// `2^A` words of `W` bits, one write or one registered read per clock.
#[derive(Clone, Debug, LogicBlock)]
pub struct SinglePortRam<const W: usize, const A: usize> {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Write `write_data` at `address` at this edge (no read).
    pub write_enable: Signal<In, Bit>,
    /// The word written or read.
    pub address: Signal<In, Bits<A>>,
    /// The word written.
    pub write_data: Signal<In, Signed<W>>,
    /// The word at `address` at the last edge without a write.
    pub q: Signal<Out, Signed<W>>,
    _words: Vec<Signed<W>>,
}

impl<const W: usize, const A: usize> SinglePortRam<W, A> {
    /// A RAM of `2^A` words of `W` bits; `A` must be between 1 and 14 (the
    /// depth of one SPRAM) and `W` between 1 and 16 (its width).
    pub fn new() -> Self {
        assert!(
            (1..=14).contains(&A),
            "SinglePortRam depth must be 2..16384 words"
        );
        assert!(
            (1..=16).contains(&W),
            "SinglePortRam width must be 1..16 bits"
        );
        Self {
            clock: Default::default(),
            write_enable: Default::default(),
            address: Default::default(),
            write_data: Default::default(),
            q: Signal::new_with_default(i128_to_signed(0)),
            _words: vec![i128_to_signed(0); 1 << A],
        }
    }
}

impl<const W: usize, const A: usize> Default for SinglePortRam<W, A> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const W: usize, const A: usize> Logic for SinglePortRam<W, A> {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let address = self.address.val().index();
            if self.write_enable.val() {
                self._words[address] = self.write_data.val();
            } else {
                self.q.next = self._words[address];
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

always @(posedge clock) begin
   if (write_enable)
      words[address] <= write_data;
   else
      q <= words[address];
end",
            msb = W - 1,
            last = (1usize << A) - 1
        ))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "single_port_ram".into(),
            clock: "clock".into(),
            inputs: vec!["write_enable".into(), "address".into(), "write_data".into()],
            outputs: vec!["q".into()],
        }]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};

    crate::impl_clocked!(SinglePortRam<8, 4>);

    /// The port's contract, which the hand-written Verilog and the SPRAM
    /// share: a write leaves `q` as it was (no write-through), a read
    /// gives the word one clock later, and each address keeps its own word.
    #[test]
    fn writes_leave_q_alone_and_reads_return_the_words() {
        let mut ram = SinglePortRam::<8, 4>::new();
        prepare(&mut ram);
        let word = |a: u64| a as i128 * 13 - 100;
        let set = |ram: &mut SinglePortRam<8, 4>, write: bool, a: u64, d: i128| {
            ram.write_enable.next = write;
            ram.address.next = a.into();
            ram.write_data.next = i128_to_signed(d);
        };
        // A read of address 3 before any write: the model's 0.
        set(&mut ram, false, 3, 0);
        tick(&mut ram);
        let q = |ram: &SinglePortRam<8, 4>| super::super::convert::signed_to_i128(ram.q.val());
        assert_eq!(q(&ram), 0);
        for a in 0..16 {
            set(&mut ram, true, a, word(a));
            tick(&mut ram);
            assert_eq!(q(&ram), 0, "a write at {a} changed q");
        }
        for a in (0..16).rev() {
            set(&mut ram, false, a, -1);
            tick(&mut ram);
            assert_eq!(q(&ram), word(a), "read {a}");
            // A write elsewhere leaves the word read on q.
            set(&mut ram, true, (a + 5) % 16, word((a + 5) % 16));
            tick(&mut ram);
            assert_eq!(q(&ram), word(a), "write after read {a}");
        }
    }

    /// The hand-written Verilog against this model, clock by clock, on
    /// random writes and reads (every address written first: an unwritten
    /// word is X in Icarus, as in an SPRAM), reads right after writes
    /// included, which the design never does.
    #[test]
    fn the_verilog_matches_the_model() {
        let mut ram = SinglePortRam::<8, 4>::new();
        prepare(&mut ram);
        let mut rng = crate::test_util::Rng::new(5);
        let mut ops: Vec<(bool, u64, i128)> = (0..16).map(|a| (true, a, a as i128 - 8)).collect();
        ops.push((false, 0, 0));
        ops.extend((0..400).map(|_| {
            let r = rng.next_u64();
            (
                r.is_multiple_of(3),
                (r >> 8) % 16,
                ((r >> 16) % 256) as i128 - 128,
            )
        }));
        let mut expected = vec![];
        let mut steps = vec![];
        for &(write, a, d) in &ops {
            ram.write_enable.next = write;
            ram.address.next = a.into();
            ram.write_data.next = i128_to_signed(d);
            tick(&mut ram);
            expected.push(super::super::convert::signed_to_i128(ram.q.val()).to_string());
            steps.push(format!(
                "write_enable = {}; address = {a}; write_data = {d};",
                u8::from(write)
            ));
        }
        let got = crate::test_util::icarus_clocked(
            &generate_verilog(&ram),
            &[
                ("write_enable", 1, false),
                ("address", 4, false),
                ("write_data", 8, true),
            ],
            ("q", 8),
            &steps,
        );
        // The first 16 edges write: q is the (never read) X of an SPRAM there.
        assert_eq!(got.len(), expected.len());
        for (n, (g, e)) in got.iter().zip(&expected).enumerate().skip(16) {
            assert_eq!(g, e, "edge {n}: Verilog q {g}, model {e}");
        }
    }
}
