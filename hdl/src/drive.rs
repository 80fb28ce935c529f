//! Driving a rust-hdl block directly, one clock edge at a time.
//!
//! rust-hdl's `Simulation` runs test benches in threads and pays a thread
//! hand-off per clock. Here the caller owns the block: it sets input
//! `.next` values, then `tick()` lowers and raises the clock and lets the
//! design settle after each edge. Inputs set before a tick are captured by
//! that tick's rising edge; outputs read after it are the registers' new
//! values.

use rust_hdl::prelude::*;

/// Settling passes allowed per clock edge before the design is declared
/// oscillating (a combinational loop).
const MAX_SETTLE_PASSES: usize = 1000;

/// A block with a clock input that can be driven directly.
pub trait Clocked: Block {
    /// The block's clock input.
    fn clock_input(&mut self) -> &mut Signal<In, Clock>;
}

/// Prepare a block for direct drive: check it and connect its signals.
pub fn prepare<B: Clocked>(uut: &mut B) {
    uut.connect_all();
    check_all(uut).expect("design failed rust-hdl's connection checks");
    settle(uut);
}

/// One full clock cycle: falling edge, then rising edge.
pub fn tick<B: Clocked>(uut: &mut B) {
    uut.clock_input().next = Clock { clk: false };
    settle(uut);
    uut.clock_input().next = Clock { clk: true };
    settle(uut);
}

/// Settle the combinational logic for inputs just set, without a clock edge.
pub fn settle<B: Block>(uut: &mut B) {
    assert!(
        simulate(uut, MAX_SETTLE_PASSES),
        "design did not settle within {MAX_SETTLE_PASSES} passes"
    );
}

/// Implements [`Clocked`] for blocks whose clock input is the field `clock`.
#[macro_export]
macro_rules! impl_clocked {
    ($($block:ty),+ $(,)?) => {
        $(impl $crate::drive::Clocked for $block {
            fn clock_input(&mut self) -> &mut rust_hdl::prelude::Signal<rust_hdl::prelude::In, rust_hdl::prelude::Clock> {
                &mut self.clock
            }
        })+
    };
}
