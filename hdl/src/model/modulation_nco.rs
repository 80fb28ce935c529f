//! Bit-true model of `crate::modulation_nco::ModulationNco`.

use super::sine::Sine;
use crate::sine::LATENCY;
use crate::sine_table::PEAK;

const PHASE_MASK: u64 = (1 << 48) - 1;

/// Cycle-true model of the modulation NCO.
#[derive(Clone, Debug, Default)]
pub struct ModulationNco {
    phase: u64,
    /// false: the sine generator is asked for the cosine (A1); true: the sine (A2).
    turn: bool,
    sine: Sine,
    am: (i16, i16),
}

impl ModulationNco {
    /// `(am1, am2)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i16, i16) {
        self.am
    }

    /// The sine generator's output during the current cycle (the carrier
    /// tables' word during the fill).
    #[inline(always)]
    pub fn fill_word(&self) -> i16 {
        self.sine.output()
    }

    /// One clock; `fill` is the carrier table fill's request for the sine
    /// generator (`CarrierNco::fill_request`). Returns `(am1, am2)` after
    /// the edge.
    #[inline(always)]
    pub fn step(&mut self, step: u64, select: bool, fill: Option<u32>) -> (i16, i16) {
        if !select {
            self.am = (PEAK as i16, PEAK as i16);
        } else if self.turn == (LATENCY % 2 == 1) {
            // The cosine asked for LATENCY toggles ago leaves the pipeline.
            self.am.0 = self.sine.output();
        } else {
            self.am.1 = self.sine.output();
        }
        match fill {
            Some(phase) => self.sine.step(phase, 0),
            None => self
                .sine
                .step((self.phase >> 16) as u32, if self.turn { 0 } else { 1 }),
        };
        self.turn = !self.turn;
        self.phase = (self.phase + step) & PHASE_MASK;
        self.am
    }
}
