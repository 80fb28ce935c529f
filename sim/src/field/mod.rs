//! The gyroscope in the field: a board the host reaches only through the
//! register map, identification of the drifting device from that board,
//! and the self-calibration cycle that turns a calibration staircase into
//! a readout scale factor (issue 9).
//!
//! - [`board`]: the [`board::Board`] trait (register writes and reads, z
//!   snapshots, "let N clocks pass") and [`board::SimBoard`], the model
//!   engine closing the loop over the gyroscope at a temperature, drifted
//!   converter gains and an unmodelled front-end phase.
//! - [`identify`]: host code. f1, f2, Q1, Q2 and the loop phase from
//!   carrier sweeps (I and Q through REF_PHASE), each with a 1-sigma
//!   uncertainty from the fit's residuals. It sees a `&mut dyn Board` and
//!   [`identify::Knowns`], never the true parameters.
//! - [`selfcal`]: host code. Identify, retune, correct the loop phase, run
//!   the staircase, predict the readout scale factor in z LSB per deg/s.
//! - [`drive_ratio`]: host code. The drive-gain ratio g2 / g1 from the
//!   Coriolis cross responses while the device turns, the one converter
//!   drift the cycle at rest cannot observe.
//! - [`profile`]: the `[profile]` section (a rate against time at every
//!   step) and the calibrated rate output, (z - null) / SF, it gives.
//! - [`scenario`]: the simulation around it: the device drifting over the
//!   `[drift]` steps, the rate table that gives the true scale factor, the
//!   factory-calibrated baseline.

pub mod board;
pub mod drive_ratio;
pub mod identify;
pub mod profile;
pub mod scenario;
pub mod selfcal;
