//! The gyroscope in the field: the simulated board, and the scenario that
//! drifts the device over temperature while host code (`gyrocal-host`)
//! identifies and self-calibrates it through the register map alone.
//!
//! - [`board`]: [`board::SimBoard`], the model engine closing the loop over
//!   the gyroscope at a temperature, drifted converter gains and an
//!   unmodelled front-end phase, behind `gyrocal_host::Board`.
//! - [`profile`]: the `[profile]` section (a rate against time at every
//!   step), applied through the board's rate table while the host reads the
//!   calibrated rate output.
//! - [`probe`]: the `[drive_probe]` section: the turn during which the host
//!   measures the drive-gain ratio.
//! - [`scenario`]: the simulation around it: the device drifting over the
//!   `[drift]` steps, the rate table that gives the true scale factor, the
//!   factory-calibrated baseline.
//!
//! The host code itself (identification, staircase, prediction, drive-gain
//! ratio, rate output) is `gyrocal_host`; it never imports this crate.

pub mod board;
pub mod lanes;
pub mod probe;
pub mod profile;
pub mod scenario;
