//! gyrocal-hdl: the synthesizable datapath of the gyrocal interface.

pub mod am_mixer;
pub mod carrier_multiplier;
pub mod carrier_nco;
pub mod carrier_table_fill;
pub mod cic_comb;
pub mod cic_decimator;
pub mod cic_integrator_stage;
pub mod cic_integrators;
pub mod cic_output_stage;
pub mod cic_widths;
pub mod demod_mux;
pub mod drive;
pub mod export;
pub mod fine_carrier_nco;
pub mod fine_sine_table;
pub mod fine_slope;
/// The output filter's design, from the leaf crate `gyrocal-regs`.
pub use gyrocal_regs::filter_design;
pub mod gyro_interface;
pub mod host;
pub mod iir_coefficient_digit;
pub mod iir_digits;
pub mod iir_lowpass;
pub mod iir_program;
pub mod iir_sequencer;
pub mod iir_widths;
pub mod model;
pub mod modulation_nco;
pub mod notch_coefficient;
pub mod primitives;
pub mod q15_multiplier;
pub mod quarter_wave;
pub mod reference_alignment;
pub mod rtl;
/// The frequency plan (Hz to register values), from the leaf crate `gyrocal-regs`.
pub use gyrocal_regs::plan as settings;
pub mod sine;
pub mod sine_pair;
pub mod sine_table;
pub mod small_multiplier;
pub mod table_sine;
#[cfg(test)]
pub(crate) mod test_util;
