//! gyrocal-sim: gyroscope model, theory, co-simulation engines and experiments.
//!
//! Read in order: `gyro` (the two-mode resonator, discretized exactly),
//! `theory` (exact steady state and the paper's equations), `frontend`
//! (DACs and ADCs), `error` (those leaf models' typed errors), `engine`
//! (the three simulators of the datapath),
//! `cosim` (the closed loop), `experiment` (readout sweep and calibration
//! staircase), `fit` (scale factors); `field` (the simulated board and the drifting
//! device) and `serve` (that board on the wire, over Etherbone).

pub mod allan;
pub mod analog;
/// Exact window means (`gyrocal_host::average`).
pub use gyrocal_host::average;
pub mod bench;
pub mod budget;
pub mod config;
pub mod cosim;
pub mod coverage;
pub mod datasheet;
pub mod drift;
pub mod edf;
pub mod engine;
pub mod error;
pub mod experiment;
pub mod field;
pub mod fit;
pub mod frontend;
pub mod gyro;
pub mod images;
pub mod noise;
pub mod noise_terms;
pub mod rate_drift;
pub mod rate_noise;
pub mod report;
pub mod ripple;
pub mod serve;
pub mod settling;
pub mod sweep;
/// The exact theory (`gyrocal_host::theory`), shared with the host's prediction.
pub use gyrocal_host::theory;
#[cfg(feature = "verilator")]
pub mod verilator;
pub mod waveform;
