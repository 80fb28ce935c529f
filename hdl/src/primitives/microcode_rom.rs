//! Synchronous ROM of `2^A` words of `W` bits with a power-up image: the
//! output filter's micro-program (`crate::iir_program`).
//!
//! ```text
//!  address[A] ──► ROM ──► [q]   (q = word as of the edge that read it)
//! ```
//!
//! Words past the image read 0. `q` powers up at 0 (Verilog `initial`),
//! unlike rust-hdl's `SyncROM`, so the design simulates from time zero
//! without X. The read goes straight into a register, so Yosys maps it to
//! block RAM.
//!
//! Latency: 1 clock. Leaf block with hand-written Verilog (not
//! single-source): the top-level golden-vector replay covers it.

use super::convert::u128_to_bits;
use rust_hdl::prelude::*;

/// `2^A` words of `W` bits, registered read.
#[derive(Clone, Debug, LogicBlock)]
pub struct MicrocodeRom<const W: usize, const A: usize> {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Word to read at the next rising edge.
    pub address: Signal<In, Bits<A>>,
    /// The word read at the previous rising edge.
    pub q: Signal<Out, Bits<W>>,
    _image: Vec<u64>,
}

impl<const W: usize, const A: usize> MicrocodeRom<W, A> {
    /// A ROM holding `image`; panics unless it fits `2^A` words of `W <= 64` bits.
    pub fn new(image: Vec<u64>) -> Self {
        assert!(W <= 64 && (1..=12).contains(&A), "MicrocodeRom shape");
        assert!(image.len() <= 1 << A, "MicrocodeRom image too long");
        assert!(
            image.iter().all(|&w| W == 64 || w < 1 << W),
            "MicrocodeRom word too wide"
        );
        Self {
            clock: Default::default(),
            address: Default::default(),
            q: Signal::new_with_default(Bits::default()),
            _image: image,
        }
    }
}

impl<const W: usize, const A: usize> Logic for MicrocodeRom<W, A> {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let a = self.address.val().to_u64() as usize;
            let word = self._image.get(a).copied().unwrap_or(0);
            self.q.next = u128_to_bits(word as u128);
        }
    }

    fn connect(&mut self) {
        self.q.connect();
    }

    fn hdl(&self) -> Verilog {
        let mut init = String::new();
        for a in 0..1usize << A {
            let word = self._image.get(a).copied().unwrap_or(0);
            init.push_str(&format!("   program_words[{a}] = {W}'h{word:x};\n"));
        }
        Verilog::Custom(format!(
            "\
reg [{msb}:0] program_words [0:{last}];

initial begin
{init}   q = 0;
end

always @(posedge clock) begin
   q <= program_words[address];
end",
            msb = W - 1,
            last = (1usize << A) - 1
        ))
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "microcode_rom".into(),
            clock: "clock".into(),
            inputs: vec!["address".into()],
            outputs: vec!["q".into()],
        }]
    }
}
