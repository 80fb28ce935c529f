//! gyrocal-hdl: the synthesizable datapath of the gyrocal interface.

pub mod drive;
pub mod primitives;
pub mod sincos;
pub mod sine_table;
pub mod model;
pub mod am_mixer;
pub mod carrier_nco;
pub mod cic_decimator;
pub mod demod_mux;
pub mod iir_lowpass;
pub mod modulation_nco;
pub mod q15_multiplier;
pub mod reference_alignment;
pub mod gyro_interface;
pub mod rtl;
pub mod export;
pub mod filter_design;
pub mod settings;
