//! gyrocal-regs: the register map and the frequency plan of the gyrocal
//! interface, the one source of truth that the gateware and the host code
//! both import.
//!
//! ```text
//!   datapath  (widths, limits, PEAK, power-up timing)
//!      │
//!      ├──► registers  (Registers: one field per core input port)
//!      │        │
//!      │        ├──► map  (bus words: offsets, widths, encode / decode,
//!      │        │          REGISTERS.md, the C header, RegisterAccess)
//!      │        │     └──► systemrdl  (the same map as SystemRDL 2.0)
//!      │        │
//!      └──► filter_design ──► plan  (FrequencyPlan in Hz ──► Registers)
//! ```
//!
//! Nothing here depends on rust-hdl or on the simulator: `gyrocal-hdl`
//! builds the AXI4-Lite slave's decoding from [`map::REGISTERS`] and takes
//! its widths from [`datapath`]; `gyrocal-host` programs a board with
//! [`plan::registers`] and [`map::encode`].

pub mod datapath;
pub mod filter_design;
pub mod map;
pub mod plan;
pub mod registers;
pub mod systemrdl;

pub use registers::{Coefficients, Registers};

/// A frequency plan or filter the datapath cannot realize: one line naming
/// the setting, its value and what is allowed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A setting outside its range.
    #[error("{setting} = {value}: {allowed}")]
    OutOfRange {
        /// The setting, as the user names it (`carrier_hz`, ...).
        setting: String,
        /// Its value.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// A filter coefficient outside Q2.30.
    #[error("filter coefficient {name} = {value} does not fit Q2.30")]
    Coefficient {
        /// k0, k1, k2 or alpha.
        name: &'static str,
        /// Its unquantized value.
        value: f64,
    },
    /// A filter whose quantized feedback leaves the stability triangle.
    #[error(
        "filter with butterworth_hz = {butterworth_hz}, rc_hz = {rc_hz} is unstable once quantized"
    )]
    Unstable {
        /// Butterworth cut-off (Hz).
        butterworth_hz: f64,
        /// RC cut-off (Hz).
        rc_hz: f64,
    },
}

impl PlanError {
    /// A setting out of range.
    pub fn out_of_range(
        setting: impl Into<String>,
        value: impl std::fmt::Display,
        allowed: impl Into<String>,
    ) -> Self {
        Self::OutOfRange {
            setting: setting.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }
}
