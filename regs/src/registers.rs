//! The datapath's run-time settings as the core's input ports hold them:
//! one field per port of `gyro_interface`. The register map
//! ([`crate::map`]) converts them to and from bus words, the frequency plan
//! ([`crate::plan`]) computes them from frequencies in Hz, and every engine
//! of the co-simulation drives its ports from them.

use crate::datapath::{DECIMATION_BITS, DELAY_BITS, MOD_STEP_BITS, SHIFT_BITS};

/// The four IIR filter coefficients, Q2.30 (`crate::filter_design`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Coefficients {
    /// Biquad numerator gain g.
    pub k0: i32,
    /// Biquad feedback -a1 - 2.
    pub k1: i32,
    /// Biquad feedback 1 - a2.
    pub k2: i32,
    /// RC section coefficient.
    pub alpha: i32,
}

/// The run-time settings of `GyroInterface`, one field per input port.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Registers {
    /// SELECT: false readout, true calibration.
    pub select: bool,
    /// Carrier phase step (32 bits).
    pub carrier_step: u32,
    /// Reference phase advance (32 bits).
    pub ref_phase: u32,
    /// Reference delay (6 bits).
    pub ref_delay: u8,
    /// Modulation phase step (48 bits).
    pub mod_step: u64,
    /// Drive amplitudes F1, F2 (Q1.15).
    pub amp: (i16, i16),
    /// CIC decimation R (13 bits).
    pub cic_decimation: u16,
    /// CIC output shift (6 bits).
    pub cic_shift: u8,
    /// IIR coefficients (Q2.30).
    pub iir: Coefficients,
}

impl Registers {
    /// Width of the `ref_delay` port (bits).
    pub const REF_DELAY_BITS: u32 = DELAY_BITS;
    /// Width of the `mod_step` port (bits).
    pub const MOD_STEP_BITS: u32 = MOD_STEP_BITS;
    /// Width of the `cic_decimation` port (bits).
    pub const CIC_DECIMATION_BITS: u32 = DECIMATION_BITS;
    /// Width of the `cic_shift` port (bits).
    pub const CIC_SHIFT_BITS: u32 = SHIFT_BITS;

    /// The words as the ports hold them: a register word wider than its port
    /// keeps only its low bits, as in the hardware (and in the rtl and
    /// Verilator engines). Every engine sees registers through this.
    #[inline(always)]
    pub fn at_ports(&self) -> Self {
        let low = |v: u64, bits: u32| v & ((1u64 << bits) - 1);
        Self {
            ref_delay: low(self.ref_delay.into(), Self::REF_DELAY_BITS) as u8,
            mod_step: low(self.mod_step, Self::MOD_STEP_BITS),
            cic_decimation: low(self.cic_decimation.into(), Self::CIC_DECIMATION_BITS) as u16,
            cic_shift: low(self.cic_shift.into(), Self::CIC_SHIFT_BITS) as u8,
            ..*self
        }
    }
}
