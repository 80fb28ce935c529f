//! The host code's errors: one line each, naming what failed and why.

use gyrocal_regs::PlanError;
use gyrocal_regs::map::BusError;

/// Why a host step could not produce its figure.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Error {
    /// The board or its transport refused a register access.
    #[error("board refused a register access: {0}")]
    Bus(#[from] BusError),
    /// A frequency plan the datapath cannot realize.
    #[error("{0}")]
    Plan(#[from] PlanError),
    /// Identification of a mode failed.
    #[error("identification of mode {mode}: {reason}")]
    Identification {
        /// The mode, 1 or 2.
        mode: usize,
        /// What went wrong.
        reason: String,
    },
    /// An ADC sat at a rail during a measurement whose figure it would
    /// falsify.
    #[error("{what}: ADC {adc} clipped on {clocks} clocks ({detail})")]
    Clipped {
        /// The measurement.
        what: &'static str,
        /// The converter, 1 or 2.
        adc: usize,
        /// Clipped clocks counted (saturating).
        clocks: u32,
        /// What the host had done about it.
        detail: String,
    },
    /// A measurement that cannot give a figure (a zero drive, a rate too
    /// small to see): what and why.
    #[error("{what}: {reason}")]
    Measurement {
        /// The measurement.
        what: &'static str,
        /// Why.
        reason: String,
    },
}
