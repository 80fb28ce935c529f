//! gyrocal-sim: gyroscope model, theory, co-simulation engines and experiments.
//!
//! Read in order: `gyro` (the two-mode resonator, discretized exactly),
//! `theory` (exact steady state and the paper's equations), `frontend`
//! (DACs and ADCs), `engine` (the three simulators of the datapath),
//! `cosim` (the closed loop), `experiment` (readout sweep and calibration
//! staircase), `fit` (scale factors).

pub mod allan;
pub mod average;
pub mod bench;
pub mod budget;
pub mod config;
pub mod cosim;
pub mod drift;
pub mod engine;
pub mod experiment;
pub mod field;
pub mod fit;
pub mod frontend;
pub mod gyro;
pub mod images;
pub mod noise;
pub mod rate_noise;
pub mod report;
pub mod ripple;
pub mod settling;
pub mod theory;
#[cfg(feature = "verilator")]
pub mod verilator;
pub mod waveform;
