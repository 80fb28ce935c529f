//! Leaf blocks whose Verilog is written by hand, like rust-hdl's own `DFF`:
//! the registered and the pipelined multipliers (rust-hdl only multiplies
//! 16 x 16), the sine table ROM (with power-up values, unlike `SyncROM`),
//! the reference delay line in RAM and the CIC's comb delay RAM. Each is a
//! few lines of Verilog beside its Rust `update()`; the golden-vector replay
//! of the whole design in Icarus and Verilator proves the two agree.

pub mod convert;
pub mod pipelined_multiplier;
mod quarter_sine_rom;
mod registered_multiplier;
mod tapped_delay_line;
mod word_ram;

pub use pipelined_multiplier::PipelinedMultiplier;
pub use quarter_sine_rom::QuarterSineRom;
pub use registered_multiplier::RegisteredMultiplier;
pub use tapped_delay_line::TappedDelayLine;
pub use word_ram::WordRam;
