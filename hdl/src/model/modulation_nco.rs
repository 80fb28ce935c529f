//! Bit-true model of `crate::modulation_nco::ModulationNco`.

use super::sincos::SinCos;
use crate::sine_table::PEAK;

const PHASE_MASK: u64 = (1 << 48) - 1;

/// Cycle-true model of the modulation NCO.
#[derive(Clone, Debug, Default)]
pub struct ModulationNco {
    phase: u64,
    sincos: SinCos,
    am: (i16, i16),
}

impl ModulationNco {
    /// `(am1, am2)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i16, i16) {
        self.am
    }

    /// One clock; returns `(am1, am2)` after the edge.
    #[inline(always)]
    pub fn step(&mut self, step: u64, select: bool) -> (i16, i16) {
        let (sin, cos) = self.sincos.output();
        self.am = if select {
            (cos, sin)
        } else {
            (PEAK as i16, PEAK as i16)
        };
        self.sincos.step((self.phase >> 16) as u32);
        self.phase = (self.phase + step) & PHASE_MASK;
        self.am
    }
}
