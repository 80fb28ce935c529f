//! The analog side of the loop, what lies between the FPGA's DAC and ADC
//! pins: the DACs, the gyroscope, an unmodelled pick-off phase lag and
//! the ADCs. The co-simulation (`crate::cosim`) and the simulated board
//! (`crate::field::board`) both close their engine over one.
//!
//! Per clock n: the ADCs sample x(nT) (through the phase lag, when there
//! is one), the converters return the ADC words of cycle n and the force
//! the DACs hold over [nT, (n+1)T), the gyroscope advances to (n+1)T under
//! it (`Analog::step`). Nothing here reads the engine's state and the
//! forces come from the DAC words alone, so the gyroscope can advance
//! through a block of clocks before any of its ADC words is converted: the
//! schedule `AnalogSide` gives the model engine's blocks
//! (`crate::engine::Engine::run`).

use crate::frontend::{Converters, PickoffPhase};
use crate::gyro::GyroModel;
use gyrocal_hdl::model::gyro_interface::{AnalogSide, BLOCK, Words};

/// DACs, gyroscope, pick-off phase lag and ADCs.
#[derive(Clone, Debug)]
pub struct Analog {
    /// The converters.
    pub converters: Converters,
    /// The gyroscope.
    pub gyro: GyroModel,
    /// The pick-off's phase lag (`None`: none).
    pub phase: Option<PickoffPhase>,
    /// The ADC noise of a block, in the order `step` draws it.
    noise: Vec<f64>,
    /// What the ADCs see at each edge advanced and not yet converted.
    pending: Vec<(f64, f64)>,
    /// The DAC forces of a block (`advance_block`).
    forces: Vec<(f64, f64)>,
}

impl Analog {
    /// The analog side at rest.
    pub fn new(converters: Converters, gyro: GyroModel, phase: Option<PickoffPhase>) -> Self {
        Self {
            converters,
            gyro,
            phase,
            noise: vec![],
            pending: Vec::with_capacity(BLOCK),
            forces: Vec::with_capacity(BLOCK),
        }
    }

    /// The displacements the ADCs see at the current clock edge (m).
    #[inline(always)]
    fn sensed(&self) -> (f64, f64) {
        sense(self.phase, self.gyro.state())
    }

    /// One clock: the DAC words during it in, the ADC words during it out.
    #[inline(always)]
    pub fn step(&mut self, dac: Words) -> Words {
        let (adc, force) = self.converters.step(dac, self.sensed());
        self.gyro.step(force.0, force.1);
        adc
    }
}

/// The displacements the ADCs see from the gyroscope's state `[x1, v1,
/// x2, v2]`, through the pick-off's phase lag if any.
#[inline(always)]
fn sense(phase: Option<PickoffPhase>, s: [f64; 4]) -> (f64, f64) {
    match phase {
        None => (s[0], s[2]),
        Some(p) => (p.apply(s[0], s[1]), p.apply(s[2], s[3])),
    }
}

/// The block schedule of `GyroInterface::run`: `advance` keeps what the
/// ADCs see at each edge (the gyroscope's forces come from the DAC words
/// alone), `convert` draws the block's ADC noise in the order `step`
/// draws it and converts, so the words are `step`'s.
impl AnalogSide for Analog {
    #[inline(always)]
    fn advance(&mut self, dac: Words) {
        let x = self.sensed();
        self.pending.push(x);
        let force = self.converters.dac_step(dac);
        self.gyro.step(force.0, force.1);
    }

    /// The DAC forces of the block in one pass, then the gyroscope's
    /// clocks in another (`GyroModel::steps`).
    #[inline(always)]
    fn advance_block(&mut self, dac: impl Iterator<Item = Words>, mut beside: impl FnMut(usize)) {
        self.forces.resize(BLOCK, (0.0, 0.0));
        let clocks = self.converters.dac_block(dac, &mut self.forces);
        self.forces.truncate(clocks);
        let start = self.pending.len();
        self.pending.resize(start + self.forces.len(), (0.0, 0.0));
        let phase = self.phase;
        self.gyro
            .steps(&self.forces, &mut self.pending[start..], |t, s| {
                beside(t);
                sense(phase, s)
            });
    }

    #[inline(always)]
    fn convert(&mut self, adc: &mut [Words]) {
        debug_assert_eq!(adc.len(), self.pending.len());
        let mut noise = std::mem::take(&mut self.noise);
        if !self.converters.draw_noise(adc.len(), &mut noise) {
            noise.clear();
            noise.resize(2 * adc.len(), 0.0);
        }
        self.converters.adc_block(&self.pending, &noise, adc);
        self.pending.clear();
        self.noise = noise;
    }
}

/// An analog side that shows each block's ADC words to `watch` once
/// converted (the last word, the clip counters).
pub struct Watched<'a, W: FnMut(&[Words])> {
    /// The analog side.
    pub analog: &'a mut Analog,
    /// Sees the ADC words, in order.
    pub watch: W,
}

impl<W: FnMut(&[Words])> AnalogSide for Watched<'_, W> {
    #[inline(always)]
    fn advance(&mut self, dac: Words) {
        self.analog.advance(dac);
    }

    #[inline(always)]
    fn advance_block(&mut self, dac: impl Iterator<Item = Words>, beside: impl FnMut(usize)) {
        self.analog.advance_block(dac, beside);
    }

    #[inline(always)]
    fn convert(&mut self, adc: &mut [Words]) {
        self.analog.convert(adc);
        (self.watch)(adc);
    }
}
