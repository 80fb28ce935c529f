//! Leaf blocks whose Verilog is written by hand, like rust-hdl's own `DFF`:
//! the registered multiplier (rust-hdl only multiplies 16 x 16), the sine
//! table ROM (with power-up values, unlike `SyncROM`) and the reference delay
//! memory. Each is a few lines of Verilog beside its Rust `update()`; the
//! golden-vector replay of the whole design in Icarus and Verilator proves
//! the two agree.

pub mod convert;
mod quarter_sine_rom;
mod registered_multiplier;
mod tapped_delay_line;

pub use quarter_sine_rom::QuarterSineRom;
pub use registered_multiplier::RegisteredMultiplier;
pub use tapped_delay_line::TappedDelayLine;
