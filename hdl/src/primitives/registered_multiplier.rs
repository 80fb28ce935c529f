//! Registered signed multiplier: `p <= a * b`, full precision.
//!
//! ```text
//!   a[A] ──┐
//!          ×──► [reg] ──► p[A+B]
//!   b[B] ──┘
//! ```
//!
//! rust-hdl 0.46 only multiplies 16 x 16 (through a BigInt, ~260 ns each in
//! simulation), so every product of the datapath goes through this leaf. Its
//! Verilog is a single registered `*` of two signed ports, which every FPGA
//! tool maps onto DSP slices with the output register absorbed (MREG/PREG on
//! Xilinx, the output register of the iCE40 `SB_MAC16`). The product width is
//! exact, P = A + B, so it can never overflow; `new()` checks that.
//!
//! This block is not single-source: its Rust `update()` and its Verilog are
//! written twice. The golden-vector replay of the whole `GyroInterface` in
//! Icarus and Verilator covers every instance of it.
//!
//! Latency: 1 clock. Power-up value of `p`: 0 (Verilog `initial`).

use super::convert::{i128_to_signed, signed_to_i128};
use rust_hdl::prelude::*;

/// `p <= a * b` on every rising clock edge; `P` must equal `A + B` (<= 128).
#[derive(Clone, Debug, LogicBlock)]
pub struct RegisteredMultiplier<const A: usize, const B: usize, const P: usize> {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// First factor, two's complement.
    pub a: Signal<In, Signed<A>>,
    /// Second factor, two's complement.
    pub b: Signal<In, Signed<B>>,
    /// Product of the factors present at the previous rising edge.
    pub p: Signal<Out, Signed<P>>,
}

impl<const A: usize, const B: usize, const P: usize> RegisteredMultiplier<A, B, P> {
    /// A multiplier; panics at construction if `P != A + B` or `P > 128`.
    pub fn new() -> Self {
        assert_eq!(P, A + B, "RegisteredMultiplier needs P = A + B");
        assert!(
            P <= 128,
            "RegisteredMultiplier products are at most 128 bits"
        );
        Self {
            clock: Default::default(),
            a: Default::default(),
            b: Default::default(),
            p: Signal::new_with_default(Signed::default()),
        }
    }
}

impl<const A: usize, const B: usize, const P: usize> Default for RegisteredMultiplier<A, B, P> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const A: usize, const B: usize, const P: usize> Logic for RegisteredMultiplier<A, B, P> {
    fn update(&mut self) {
        if self.clock.pos_edge() {
            let product = signed_to_i128(self.a.val()) * signed_to_i128(self.b.val());
            self.p.next = i128_to_signed::<P>(product);
        }
    }

    fn connect(&mut self) {
        self.p.connect();
    }

    fn hdl(&self) -> Verilog {
        // Both ports are declared `signed`, and the context width is P = A + B,
        // so Verilog sign-extends both factors to P bits: the exact product.
        Verilog::Custom(
            "\
initial p = 0;

always @(posedge clock) begin
   p <= a * b;
end"
            .into(),
        )
    }

    fn timing(&self) -> Vec<TimingInfo> {
        vec![TimingInfo {
            name: "registered_multiplier".into(),
            clock: "clock".into(),
            inputs: vec!["a".into(), "b".into()],
            outputs: vec!["p".into()],
        }]
    }
}
