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
use gyrocal_hdl::model::lanes::AnalogLanes;

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
    pending: Pending,
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
            pending: Pending::default(),
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
        self.pending.next(1)[0] = x;
        let force = self.converters.dac_step(dac);
        self.gyro.step(force.0, force.1);
    }

    /// The DAC forces of the block in one pass, then the gyroscope's
    /// clocks in another (`GyroModel::steps`).
    #[inline(always)]
    fn advance_block(&mut self, dac: impl Iterator<Item = Words>, beside: impl FnMut(usize)) {
        let mut forces = std::mem::take(&mut self.forces);
        self.converters.forces_block(dac, &mut forces);
        self.advance_under(&forces, beside);
        self.forces = forces;
    }

    #[inline(always)]
    fn convert(&mut self, adc: &mut [Words]) {
        let mut noise = std::mem::take(&mut self.noise);
        self.converters.noise_block(adc.len(), &mut noise);
        self.convert_with(&noise, adc);
        self.noise = noise;
    }
}

impl Analog {
    /// The gyroscope's clocks under `forces` (`GyroModel::steps`), what
    /// the ADCs see at each edge kept, `beside(t)` at clock t.
    #[inline(always)]
    fn advance_under(&mut self, forces: &[(f64, f64)], mut beside: impl FnMut(usize)) {
        let phase = self.phase;
        let out = self.pending.next(forces.len());
        self.gyro.steps(forces, out, |t, s| {
            beside(t);
            sense(phase, s)
        });
    }

    /// `advance_under` on `a` and `b` without a `beside`, their
    /// gyroscopes' clocks in one loop (`GyroModel::steps_abreast`).
    #[inline(always)]
    fn advance_abreast(a: &mut Analog, b: &mut Analog, forces: &[(f64, f64)]) {
        let (pa, pb) = (a.phase, b.phase);
        let seen = (a.pending.next(forces.len()), b.pending.next(forces.len()));
        GyroModel::steps_abreast(
            &mut a.gyro,
            &mut b.gyro,
            forces,
            seen,
            |_, s| sense(pa, s),
            |_, s| sense(pb, s),
        );
    }

    /// The ADC words of the edges advanced, with their standard normal
    /// draws `noise` (two a clock).
    #[inline(always)]
    fn convert_with(&mut self, noise: &[f64], adc: &mut [Words]) {
        let pending = self.pending.take();
        debug_assert_eq!(adc.len(), pending.len());
        self.converters.adc_block(pending, noise, adc);
    }
}

/// The displacements the ADCs see at the edges advanced and not yet
/// converted: the first `filled` words of a buffer that keeps its length
/// between blocks, so a block's gyroscope writes its slots without their
/// being cleared first (a memset per block and lane, 1.9% of a one-core
/// `reproduce`).
#[derive(Clone, Debug, Default)]
struct Pending {
    words: Vec<(f64, f64)>,
    filled: usize,
}

impl Pending {
    /// The next `n` slots, counted as filled (the buffer grown if need be).
    #[inline(always)]
    fn next(&mut self, n: usize) -> &mut [(f64, f64)] {
        let (start, end) = (self.filled, self.filled + n);
        if self.words.len() < end {
            self.words.resize(end, (0.0, 0.0));
        }
        self.filled = end;
        &mut self.words[start..end]
    }

    /// The slots filled since the last `take`, then none.
    #[inline(always)]
    fn take(&mut self) -> &[(f64, f64)] {
        let filled = std::mem::take(&mut self.filled);
        &self.words[..filled]
    }
}

/// Analog sides in lanes (`gyrocal_hdl::model::lanes`): each lane its own
/// gyroscope and pick-off (one device at several rates: a rate table), the
/// converters' settings, DAC words in flight and noise generator equal in
/// every lane (`Converters::shares_with`). The DAC words are the lanes'
/// one set, so one pass makes the forces, and each lane would draw the
/// same noise alone, so one block of draws serves them all; each lane then
/// advances its own gyroscope and converts its own ADC words. Every lane's
/// words are those its own `Analog` gives alone.
///
/// The block's forces and noise are kept in the first lane's own buffers
/// (those its `AnalogSide` methods use alone), so making lanes for a run
/// allocates nothing.
pub struct Lanes<'a, W: FnMut(usize, &[Words]) = fn(usize, &[Words])> {
    analogs: &'a mut [Analog],
    /// Sees each lane's ADC words once converted (lane, words).
    watch: W,
}

/// Why analog sides cannot run as lanes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LanesError {
    /// No analog side.
    Empty,
    /// This lane does not share its converters' settings and state with
    /// the first (`Converters::shares_with`).
    NotShared(usize),
}

impl std::fmt::Display for LanesError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LanesError::Empty => write!(f, "analog lanes: none given (allowed 1 or more)"),
            LanesError::NotShared(l) => write!(
                f,
                "analog lanes: lane {l}'s converters differ from lane 0's (settings, DAC words in flight or noise state); lanes must share them"
            ),
        }
    }
}

impl std::error::Error for LanesError {}

impl<'a> Lanes<'a> {
    /// `analogs` as lanes, or why they cannot be.
    pub fn new(analogs: &'a mut [Analog]) -> Result<Self, LanesError> {
        Lanes::watched(analogs, |_, _| {})
    }
}

impl<'a, W: FnMut(usize, &[Words])> Lanes<'a, W> {
    /// `analogs` as lanes, `watch(lane, words)` seeing each lane's ADC
    /// words once converted (the clip counters); or why they cannot be.
    pub fn watched(analogs: &'a mut [Analog], watch: W) -> Result<Self, LanesError> {
        let (lead, rest) = analogs.split_first().ok_or(LanesError::Empty)?;
        if let Some(l) = rest
            .iter()
            .position(|a| !a.converters.shares_with(&lead.converters))
        {
            return Err(LanesError::NotShared(l + 1));
        }
        Ok(Self { analogs, watch })
    }
}

impl<W: FnMut(usize, &[Words])> AnalogLanes for Lanes<'_, W> {
    #[inline(always)]
    fn lanes(&self) -> usize {
        self.analogs.len()
    }

    /// The forces once, from the first lane's converters; every lane's
    /// gyroscope under them, `beside` beside the first's, the others two
    /// by two (`GyroModel::steps_abreast`).
    #[inline(always)]
    fn advance_block(&mut self, dac: impl Iterator<Item = Words>, beside: impl FnMut(usize)) {
        let (lead, rest) = self
            .analogs
            .split_first_mut()
            .expect("lanes are never empty");
        let mut forces = std::mem::take(&mut lead.forces);
        lead.converters.forces_block(dac, &mut forces);
        lead.advance_under(&forces, beside);
        for two in rest.chunks_mut(2) {
            match two {
                [a, b] => Analog::advance_abreast(a, b, &forces),
                [a] => a.advance_under(&forces, |_| {}),
                _ => unreachable!("chunks of one or two"),
            }
        }
        lead.forces = forces;
    }

    /// The block's noise drawn by the first lane's converters when it
    /// converts (into its buffer), the same draws for the others, which
    /// then take on its DAC words and generator (`Converters::follow`).
    #[inline(always)]
    fn convert(&mut self, lane: usize, adc: &mut [Words]) {
        let (lead, rest) = self
            .analogs
            .split_first_mut()
            .expect("lanes are never empty");
        if lane == 0 {
            let mut noise = std::mem::take(&mut lead.noise);
            lead.converters.noise_block(adc.len(), &mut noise);
            lead.convert_with(&noise, adc);
            lead.noise = noise;
        } else {
            let analog = &mut rest[lane - 1];
            analog.converters.follow(&lead.converters);
            analog.convert_with(&lead.noise, adc);
        }
        (self.watch)(lane, adc);
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
