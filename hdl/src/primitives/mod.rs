//! Leaf blocks whose Verilog is written by hand, like rust-hdl's own `DFF`:
//! the registered and the pipelined multipliers (rust-hdl only multiplies
//! table ROM, the output filter's digit RAM and micro-program ROM (with
//! power-up values, unlike `SyncROM`), the reference delay line in RAM and
//! the CIC's comb delay RAM. Each is a few lines of Verilog beside its Rust `update()`; the

pub mod convert;
mod digit_ram;
mod fine_sine_rom;
mod microcode_rom;
pub mod pipelined_multiplier;
mod quarter_sine_rom;
mod registered_multiplier;
mod single_port_ram;
mod tapped_delay_line;
mod word_ram;

pub use digit_ram::DigitRam;
pub use fine_sine_rom::FineSineRom;
pub use microcode_rom::MicrocodeRom;
pub use pipelined_multiplier::PipelinedMultiplier;
pub use quarter_sine_rom::QuarterSineRom;
pub use registered_multiplier::RegisteredMultiplier;
pub use single_port_ram::SinglePortRam;
pub use tapped_delay_line::TappedDelayLine;
pub use word_ram::WordRam;
