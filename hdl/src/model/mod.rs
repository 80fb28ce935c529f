//! Bit-true, cycle-true models of the hdl blocks in plain Rust.
//!
//! One file per block, mirroring `crate::*`. Every model keeps the values of
//! the block's registers during the current cycle; `step(inputs)` plays one
//! rising edge and returns the outputs after it, `output()` the outputs
//! before it. Each block's tests drive the rust-hdl block and its model with
//! the same random stimulus and require identical outputs on every cycle;
//! `GyroInterface` composes them into the fast `model` engine.

pub mod am_mixer;
pub mod carrier_nco;
pub mod cic_decimator;
pub mod delay_ring;
pub mod demod_mux;
pub mod gyro_interface;
pub mod iir_lowpass;
pub mod isa;
pub mod lanes;
pub mod modulation_nco;
pub mod notch_coefficient;
pub mod q15_multiplier;
pub mod quarter_wave;
pub mod reference_alignment;
pub mod sine;
pub mod sine_pair;
