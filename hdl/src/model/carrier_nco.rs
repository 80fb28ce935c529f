//! Bit-true model of `crate::carrier_nco::CarrierNco`.

use super::sincos::SinCos;

/// Outputs of the carrier NCO during one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Carriers {
    /// In-phase drive carrier.
    pub drive_cos: i16,
    /// Quadrature drive carrier.
    pub drive_sin: i16,
    /// In-phase reference carrier.
    pub ref_cos: i16,
    /// Quadrature reference carrier.
    pub ref_sin: i16,
}

/// Cycle-true model of the carrier NCO.
#[derive(Clone, Debug, Default)]
pub struct CarrierNco {
    phase: u32,
    drive: SinCos,
    reference: SinCos,
}

impl CarrierNco {
    /// The outputs during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> Carriers {
        let (drive_sin, drive_cos) = self.drive.output();
        let (ref_sin, ref_cos) = self.reference.output();
        Carriers {
            drive_cos,
            drive_sin,
            ref_cos,
            ref_sin,
        }
    }

    /// One clock with the given step and reference offset; outputs after the edge.
    #[inline(always)]
    pub fn step(&mut self, step: u32, ref_offset: u32) -> Carriers {
        self.drive.step(self.phase);
        self.reference.step(self.phase.wrapping_add(ref_offset));
        self.phase = self.phase.wrapping_add(step);
        self.output()
    }
}
