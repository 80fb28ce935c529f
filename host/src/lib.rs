//! gyrocal-host: the host code of the gyrocal interface. It identifies a
//! drifting MEMS gyroscope and self-calibrates it through the register map
//! alone, on any board: the in-process simulator, a board over Etherbone
//! (LiteX's `litex_server`: UART, Ethernet, PCIe), or a memory-mapped
//! window on a Zynq-class Linux board. It depends on neither rust-hdl nor
//! the simulator.
//!
//! Read in order, from a call to [`selfcal::self_calibrate`] down to a
//! register write:
//!
//! - [`device`]: the gyroscope's parameters (datasheet, identified, truth),
//!   and [`datasheet`], what the host is told;
//! - [`knowns`]: what the host knows (clock, datasheet, its settings) and
//!   the registers it writes for a carrier, a calibration frequency, drive
//!   amplitudes and a phase correction (`gyrocal_regs::plan`);
//! - [`board`]: the [`board::Board`] trait (registers, z snapshots, clocks),
//!   and [`board::Polled`], which gives any register transport a clock from
//!   SAMPLE_COUNT;
//! - [`sampling`]: successive z samples and exact window means;
//! - [`identify`]: f1, f2, Q1, Q2, the loop phase and group delay from
//!   carrier sweeps;
//! - [`selfcal`]: retune, correct, run the staircase, predict the readout
//!   scale factor with the exact theory ([`theory`]);
//! - [`drive_ratio`]: the drive-gain ratio while the device turns;
//! - [`rate`]: the null and the calibrated rate output;
//! - [`transport`]: Etherbone over TCP and memory-mapped boards;
//! - [`fake`]: a board of two exact Lorentzian modes, for examples and tests.
//!
//! Errors are [`error::Error`], one line each.

pub mod average;
pub mod board;
mod carrier_lines;
pub mod clip;
pub mod coupling;
pub mod datasheet;
pub mod device;
pub mod drive_ratio;
pub mod error;
pub mod fake;
pub mod identify;
pub mod images;
pub mod knowns;
pub mod rate;
pub mod sampling;
pub mod selfcal;
pub mod stats;
pub mod theory;
pub mod transport;

pub use board::{Board, Polled, ZSample};
pub use device::GyroParams;
pub use error::Error;
pub use knowns::{Derived, Knowns};
