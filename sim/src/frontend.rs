//! The analog front end between the FPGA and the gyroscope: DACs, force
//! transducers, pick-offs and ADCs.
//!
//! ```text
//!  dac word ──► [L_dac clocks] ──► hold one clock ──► x force_per_lsb ──► gyro force (N/kg)
//!  gyro x(nT) ──► x adc_per_meter (+ noise) ──► round, saturate ──► [L_adc clocks] ──► adc word
//! ```
//!
//! The DAC holds each word for one clock (zero-order hold, modelled exactly
//! by the gyro's discretization) after a pipeline latency of L_dac clocks.
//! The ADC samples the displacement at the clock edge, scales it by the
//! pick-off, TIA and converter gain (LSB per metre), adds optional Gaussian
//! noise (seeded), rounds half away from zero to `adc_bits` bits
//! (left-justified in the 16-bit word, like a narrower converter on a
//! 16-bit bus), saturates at full
//! scale, and presents the word L_adc clocks later. A DAC with fewer bits
//! drops the LSBs of the word (truncation, as a narrower DAC wired to the
//! top bits does).

use crate::error::ModelError;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::SeedableRng;

/// Front-end parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontEnd {
    /// DAC pipeline latency in clocks.
    pub dac_latency: u32,
    /// ADC pipeline latency in clocks.
    pub adc_latency: u32,
    /// DAC resolution in bits (1..=16), MSB-aligned in the 16-bit word.
    pub dac_bits: u32,
    /// ADC resolution in bits (1..=16), MSB-aligned in the 16-bit word.
    pub adc_bits: u32,
    /// Force per unit mass per DAC LSB, per channel (N/kg per LSB).
    pub force_per_lsb: [f64; 2],
    /// ADC LSBs per metre of displacement, per channel.
    pub adc_per_meter: [f64; 2],
    /// RMS noise added at the ADC input, in ADC LSBs (0: none).
    pub noise_lsb: f64,
    /// Seed of the noise generator.
    pub seed: u64,
}

/// Whether Gaussian noise of `noise_lsb` (RMS, 16-bit word LSB) at the
/// input dithers an ADC of `adc_bits`, whose step is `D = 2^(16 - adc_bits)`
/// word LSB: at least `D / 2`.
///
/// Why `D / 2`: the undithered quantizer's error on a slow input is a
/// periodic function of the input with period `D`; Gaussian noise of RMS
/// `s` multiplies its k-th harmonic, and so the static bias a mean
/// carries, by `exp(-2 pi^2 k^2 s^2 / D^2)` (Widrow's characteristic-
/// function argument), which is 0.7% at `s = D / 2` and 17% at `D / 3.3`.
/// Below it a figure taken from an output far below the ADC's range
/// carries a bias its batches cannot see (on a detuned output at 1/11 of
/// the range, 1e-3 to 4e-3 with `noise_lsb = 0`).
///
/// ```
/// use gyrocal_sim::frontend::dithers;
/// assert!(dithers(1.0, 16) && dithers(0.5, 16) && !dithers(0.3, 16));
/// assert!(!dithers(1.0, 12) && dithers(8.0, 12)); // a 12-bit step is 16 word LSB
/// ```
pub fn dithers(noise_lsb: f64, adc_bits: u32) -> bool {
    noise_lsb >= dither_lsb(adc_bits)
}

/// The least noise (RMS, 16-bit word LSB) that dithers an ADC of
/// `adc_bits` ([`dithers`]): half its step `2^(16 - adc_bits)`.
pub fn dither_lsb(adc_bits: u32) -> f64 {
    0.5 * f64::from(1u32 << (16 - adc_bits.min(16)))
}

/// Longest converter latency the ring buffers hold.
pub const MAX_LATENCY: u32 = 31;

/// The converters' state during a run.
#[derive(Clone, Debug)]
pub struct Converters {
    config: FrontEnd,
    dac_ring: LatencyRing,
    adc_ring: LatencyRing,
    dac_mask: i16,
    adc_step_inv: f64,
    /// Lowest and highest ADC code, -2^(bits-1) and 2^(bits-1) - 1.
    adc_code_range: (f64, f64),
    noise: Option<Gaussian>,
}

impl Converters {
    /// Converters at rest (all words zero).
    pub fn new(config: &FrontEnd) -> Result<Self, ModelError> {
        for (name, v) in [
            ("dac_latency", config.dac_latency),
            ("adc_latency", config.adc_latency),
        ] {
            if v > MAX_LATENCY {
                let rule = format!("allowed 0..={MAX_LATENCY} clocks");
                return Err(ModelError::parameter(name, v, rule));
            }
        }
        for (name, v) in [("dac_bits", config.dac_bits), ("adc_bits", config.adc_bits)] {
            if !(1..=16).contains(&v) {
                return Err(ModelError::parameter(name, v, "allowed 1..=16"));
            }
        }
        for (name, v) in [
            ("force gain of channel 1", config.force_per_lsb[0]),
            ("force gain of channel 2", config.force_per_lsb[1]),
            ("ADC gain of channel 1", config.adc_per_meter[0]),
            ("ADC gain of channel 2", config.adc_per_meter[1]),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(ModelError::parameter(name, v, "must be a positive number"));
            }
        }
        if !(config.noise_lsb.is_finite() && config.noise_lsb >= 0.0) {
            return Err(ModelError::parameter(
                "noise_lsb",
                config.noise_lsb,
                "must be >= 0",
            ));
        }
        Ok(Self {
            config: config.clone(),
            dac_ring: LatencyRing::default(),
            adc_ring: LatencyRing::default(),
            dac_mask: !((1i32 << (16 - config.dac_bits)) - 1) as i16,
            adc_step_inv: 1.0 / f64::from(1u32 << (16 - config.adc_bits)),
            adc_code_range: (
                -f64::from(1u32 << (config.adc_bits - 1)),
                f64::from(1u32 << (config.adc_bits - 1)) - 1.0,
            ),
            noise: (config.noise_lsb > 0.0).then(|| Gaussian::new(config.seed)),
        })
    }

    /// The configuration.
    pub fn config(&self) -> &FrontEnd {
        &self.config
    }

    /// Standard normal draws for `clocks` clocks into `out` (cleared
    /// first), both channels' of a clock in turn, the order `step` draws
    /// them; false (and nothing drawn) without noise.
    #[inline(always)]
    pub fn draw_noise(&mut self, clocks: usize, out: &mut Vec<f64>) -> bool {
        out.clear();
        match &mut self.noise {
            Some(g) => {
                // The generator in a local over the block: through `self`
                // its state went to memory at every draw (1.3x the time).
                out.resize(2 * clocks, 0.0);
                let mut local = g.clone();
                for o in out.iter_mut() {
                    *o = local.sample();
                }
                *g = local;
                true
            }
            None => false,
        }
    }

    /// Whether `other` holds what these converters share with it in lanes
    /// (`crate::analog::Lanes`): the same settings, DAC words in flight
    /// and noise generator state, so that its DAC forces and noise draws
    /// would be these ones's. The ADC words in flight are each lane's own.
    pub fn shares_with(&self, other: &Converters) -> bool {
        self.config == other.config && self.dac_ring == other.dac_ring && self.noise == other.noise
    }

    /// Takes on `lead`'s shared state ([`Converters::shares_with`]): after
    /// `lead` played the lanes' DAC words and drew their noise, this lane
    /// is where its own run would have left it.
    pub fn follow(&mut self, lead: &Converters) {
        self.dac_ring = lead.dac_ring;
        self.noise.clone_from(&lead.noise);
    }

    /// `draw_noise` for a block of `clocks`, zeros without noise: the
    /// draws `adc_block` takes.
    #[inline(always)]
    pub fn noise_block(&mut self, clocks: usize, out: &mut Vec<f64>) {
        if !self.draw_noise(clocks, out) {
            out.clear();
            out.resize(2 * clocks, 0.0);
        }
    }

    /// `dac_block` over all of `dac`'s words (at most `BLOCK`), `forces`
    /// resized to them.
    #[inline(always)]
    pub fn forces_block(
        &mut self,
        dac: impl Iterator<Item = (i16, i16)>,
        forces: &mut Vec<(f64, f64)>,
    ) {
        forces.resize(gyrocal_hdl::model::gyro_interface::BLOCK, (0.0, 0.0));
        let clocks = self.dac_block(dac, forces);
        forces.truncate(clocks);
    }

    /// One ADC conversion of the displacement `x` (m) on `channel` (0, 1)
    /// with the standard normal draw `g`. Without noise `g` is 0 and so is
    /// `noise_lsb` (the generator exists exactly when it is positive), and
    /// the term adds 0: the same code as the bare displacement (a -0
    /// becoming +0 rounds to the same 0).
    #[inline(always)]
    fn convert(&self, channel: usize, x: f64, g: f64) -> i16 {
        self.code(x * self.config.adc_per_meter[channel] + self.config.noise_lsb * g)
    }

    /// The ADC word of `v` (16-bit LSB, noise included).
    #[inline(always)]
    fn code(&self, v: f64) -> i16 {
        // Round half away from zero by truncating v +- 1/2, saturate to the
        // converter's codes, then left-justify in the 16-bit word. Clamping
        // before the truncation is exact (every code is an integer) and
        // keeps the work to a few branch-free instructions, where
        // f64::round is a library call.
        let steps = v * self.adc_step_inv;
        let clamped = (steps + 0.5f64.copysign(steps))
            .max(self.adc_code_range.0)
            .min(self.adc_code_range.1);
        // SAFETY: `max` and `min` leave a number within the code range
        // (a NaN becomes the lowest code), which every i32 holds.
        let code: i32 = unsafe { clamped.to_int_unchecked() };
        (code << (16 - self.config.adc_bits)) as i16
    }

    /// One clock. `dac` is the DAC word pair during this cycle, `x` the
    /// displacements sampled at this cycle's edge. Returns the ADC words
    /// presented to the FPGA during this cycle and the forces (N/kg) the
    /// DACs apply over this clock period.
    #[inline(always)]
    pub fn step(&mut self, dac: (i16, i16), x: (f64, f64)) -> ((i16, i16), (f64, f64)) {
        let g = match &mut self.noise {
            Some(g) => (g.sample(), g.sample()),
            None => (0.0, 0.0),
        };
        (self.adc_step(x, g), self.dac_step(dac))
    }

    /// The ADC half of `step`, with the clock's standard normal draws `g`
    /// given (from `draw_noise`): the words presented during this cycle.
    #[inline(always)]
    pub fn adc_step(&mut self, x: (f64, f64), g: (f64, f64)) -> (i16, i16) {
        let sample = (self.convert(0, x.0, g.0), self.convert(1, x.1, g.1));
        self.adc_ring.delay(sample, self.config.adc_latency)
    }

    /// `adc_step` over a block: the ADC words during the clocks whose
    /// edges sampled `x`, with their draws `g` (two a clock, as
    /// `draw_noise` gives them). The ring and its head stay in locals
    /// over the block, so no store into the ring makes the compiler read
    /// the latency and the gains again at every clock.
    #[inline(always)]
    pub fn adc_block(&mut self, x: &[(f64, f64)], g: &[f64], out: &mut [(i16, i16)]) {
        debug_assert!(x.len() == out.len() && g.len() == 2 * out.len());
        // The conversions in a loop of their own, which the compiler
        // vectorizes (packed conversions in the x86-64-v3 build; the
        // ring's indexing in the loop kept it scalar), then the latency
        // over the block. Without noise `g` is zeros (`convert`).
        for ((o, &x), g) in out.iter_mut().zip(x).zip(g.chunks_exact(2)) {
            *o = (self.convert(0, x.0, g[0]), self.convert(1, x.1, g[1]));
        }
        self.adc_ring.delay_block(out, self.config.adc_latency);
    }

    /// `dac_step` over a block: `forces[k]`, the forces held over clock k
    /// of `dac`'s words, the ring in locals as in `adc_block`. Returns the
    /// clocks played: `dac`'s words, at most `forces.len()`.
    #[inline(always)]
    pub fn dac_block(
        &mut self,
        dac: impl Iterator<Item = (i16, i16)>,
        forces: &mut [(f64, f64)],
    ) -> usize {
        let mut clocks = 0;
        let (mut ring, latency) = (self.dac_ring, self.config.dac_latency);
        for (f, d) in forces.iter_mut().zip(dac) {
            *f = self.force(ring.delay(self.dac_word(d), latency));
            clocks += 1;
        }
        self.dac_ring = ring;
        clocks
    }

    /// The DAC half of `step`: the forces held over this clock.
    #[inline(always)]
    pub fn dac_step(&mut self, dac: (i16, i16)) -> (f64, f64) {
        let word = self.dac_word(dac);
        let held = self.dac_ring.delay(word, self.config.dac_latency);
        self.force(held)
    }

    /// The DAC's word: `dac` narrowed to its bits.
    #[inline(always)]
    fn dac_word(&self, dac: (i16, i16)) -> (i16, i16) {
        (dac.0 & self.dac_mask, dac.1 & self.dac_mask)
    }

    /// The forces (N/kg) of the held DAC words.
    #[inline(always)]
    fn force(&self, held: (i16, i16)) -> (f64, f64) {
        let gain = self.config.force_per_lsb;
        (held.0 as f64 * gain[0], held.1 as f64 * gain[1])
    }
}

/// A converter's latency: the words of the last `MAX_LATENCY + 1` clocks.
/// Small and `Copy`, so a block can keep it in locals (`adc_block`,
/// `dac_block`) while a clock's step updates it in place.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct LatencyRing {
    words: [(i16, i16); MAX_LATENCY as usize + 1],
    head: usize,
}

impl LatencyRing {
    /// `delay` over a block in place: `words` entered in order, each
    /// replaced by the word `latency` clocks before it.
    #[inline(always)]
    fn delay_block(&mut self, words: &mut [(i16, i16)], latency: u32) {
        const N: usize = MAX_LATENCY as usize + 1;
        let (n, l) = (words.len(), latency as usize);
        // The ring's last l words, oldest first: those the block's first
        // l clocks return.
        let mut before = [(0, 0); N];
        for (k, b) in before[..l].iter_mut().enumerate() {
            *b = self.words[(self.head + 1 + N + k - l) % N];
        }
        let first = n.saturating_sub(N);
        for (i, &w) in words.iter().enumerate().skip(first) {
            self.words[(self.head + 1 + i) % N] = w;
        }
        self.head = (self.head + n) % N;
        let m = n.min(l);
        if n > l {
            words.copy_within(0..n - l, l);
        }
        words[..m].copy_from_slice(&before[..m]);
    }

    /// Enters `word` and returns the one entered `latency` clocks ago
    /// (`word` itself for 0).
    #[inline(always)]
    fn delay(&mut self, word: (i16, i16), latency: u32) -> (i16, i16) {
        let n = self.words.len();
        self.head = (self.head + 1) % n;
        self.words[self.head] = word;
        self.words[(self.head + n - latency as usize) % n]
    }
}

/// An unmodelled phase lag of the pick-off (TIA and wiring), which the
/// gateware's reference alignment knows nothing about: the ADC sees
///
/// ```text
/// x' = x cos(phi) - (v / w_ref) sin(phi)        (v = dx/dt, w_ref = 2 pi reference_hz)
/// ```
///
/// For a tone at w this is a gain sqrt(cos^2 + (w / w_ref)^2 sin^2) and a
/// lag atan((w / w_ref) tan phi): exactly `phi` at the reference frequency,
/// and within phi dw / w_ref of it nearby (5 deg over 3 kHz at 9.64 MHz:
/// 0.0015 deg). Two multiplies and an add per channel and clock; a run
/// without it (`None` in the board) costs nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PickoffPhase {
    cos: f64,
    sin_over_w: f64,
}

impl PickoffPhase {
    /// A lag of `phase_deg` (|phase| <= 180) at `reference_hz` (> 0).
    pub fn new(phase_deg: f64, reference_hz: f64) -> Result<Self, ModelError> {
        if !(phase_deg.is_finite() && phase_deg.abs() <= 180.0) {
            let value = format!("{phase_deg} deg");
            return Err(ModelError::parameter(
                "front-end phase",
                value,
                "allowed -180..=180",
            ));
        }
        if !(reference_hz.is_finite() && reference_hz > 0.0) {
            let value = format!("{reference_hz} Hz");
            return Err(ModelError::parameter(
                "front-end phase reference",
                value,
                "must be a positive number",
            ));
        }
        let phi = phase_deg.to_radians();
        Ok(Self {
            cos: phi.cos(),
            sin_over_w: phi.sin() / (std::f64::consts::TAU * reference_hz),
        })
    }

    /// The shifted displacement from a position `x` (m) and velocity `v` (m/s).
    #[inline(always)]
    pub fn apply(&self, x: f64, v: f64) -> f64 {
        x * self.cos - v * self.sin_over_w
    }
}

/// Standard normal samples, seeded: the ziggurat of `rand_distr` on
/// xoshiro256++, the generator of the thermal noise (`crate::noise`). Two
/// samples per clock must cost little beside the datapath model (about
/// 27 ns per clock): the ziggurat takes a few ns where Box-Muller's
/// logarithm and sine took about 15.
#[derive(Clone, Debug, PartialEq)]
struct Gaussian {
    rng: Xoshiro256PlusPlus,
}

impl Gaussian {
    fn new(seed: u64) -> Self {
        Self {
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
        }
    }

    #[inline(always)]
    fn sample(&mut self) -> f64 {
        StandardNormal.sample(&mut self.rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_xoshiro::rand_core::Rng;

    fn front_end() -> FrontEnd {
        FrontEnd {
            dac_latency: 2,
            adc_latency: 3,
            dac_bits: 16,
            adc_bits: 16,
            force_per_lsb: [1.0, 2.0],
            adc_per_meter: [1.0, 1.0],
            noise_lsb: 0.0,
            seed: 1,
        }
    }

    #[test]
    fn a_block_through_the_ring_is_its_words_one_by_one() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(47);
        let mut next = |m: u64| rng.next_u64() % m;
        for latency in 0..=MAX_LATENCY {
            let (mut block, mut single) = (LatencyRing::default(), LatencyRing::default());
            for _ in 0..12 {
                let n = next(300) as usize;
                let mut words: Vec<(i16, i16)> = (0..n)
                    .map(|_| (next(65536) as i16, next(65536) as i16))
                    .collect();
                let expected: Vec<_> = words.iter().map(|&w| single.delay(w, latency)).collect();
                block.delay_block(&mut words, latency);
                assert_eq!(words, expected, "latency {latency}, {n} words");
            }
        }
    }

    #[test]
    fn latencies_delay_by_whole_clocks() {
        let mut c = Converters::new(&front_end()).unwrap();
        let mut log = vec![];
        for n in 0..10i16 {
            log.push(c.step((n, n), (f64::from(n) * 10.0, 0.0)));
        }
        // Word of cycle k is applied during cycle k + 2; the sample of edge m
        // is presented during cycle m + 3.
        assert_eq!(log[5].1, (3.0, 6.0));
        assert_eq!((log[5].0).0, 20);
    }

    #[test]
    fn adc_rounds_saturates_and_narrows() {
        let mut fe = front_end();
        fe.adc_latency = 0;
        let mut c = Converters::new(&fe).unwrap();
        assert_eq!(c.step((0, 0), (1e9, -1e9)).0, (32767, -32768));
        assert_eq!(c.step((0, 0), (2.5, -2.5)).0, (3, -3));
        fe.adc_bits = 12;
        let mut c = Converters::new(&fe).unwrap();
        assert_eq!(c.step((0, 0), (25.0, 1e9)).0, (32, 32752));
    }

    /// The conversion as first written: f64 rounding, then clamping the
    /// left-justified word; the fast path must agree on every input.
    fn reference_convert(v: f64, bits: u32) -> i16 {
        let step = f64::from(1u32 << (16 - bits));
        let code = (v / step).round() * step;
        code.clamp(-32768.0, 32767.0 - (step - 1.0)) as i16
    }

    #[test]
    fn conversion_matches_the_reference_rounding_at_every_width() {
        let mut fe = front_end();
        fe.adc_latency = 0;
        let mut rng = Gaussian::new(7);
        for bits in 1..=16 {
            fe.adc_bits = bits;
            let mut c = Converters::new(&fe).unwrap();
            let step = f64::from(1u32 << (16 - bits));
            // Ties, both saturation edges and random values across +-2 full scales.
            let ties = (-70_000..70_000)
                .step_by(997)
                .map(|k| (f64::from(k) + 0.5) * step);
            let random = (0..20_000).map(|_| rng.sample() * 40_000.0);
            for v in ties
                .chain(random)
                .chain([32767.4, 32767.6, -32768.4, -32768.6, 0.0])
            {
                let got = c.step((0, 0), (v, 0.0)).0.0;
                assert_eq!(got, reference_convert(v, bits), "v {v}, {bits} bits");
            }
        }
    }

    #[test]
    fn noise_is_seeded_and_has_the_asked_rms() {
        let mut fe = front_end();
        fe.adc_latency = 0;
        fe.noise_lsb = 100.0;
        let run = |fe: &FrontEnd| {
            let mut c = Converters::new(fe).unwrap();
            (0..20000)
                .map(|_| c.step((0, 0), (0.0, 0.0)).0.0 as f64)
                .collect::<Vec<_>>()
        };
        let a = run(&fe);
        assert_eq!(a, run(&fe));
        let rms = (a.iter().map(|v| v * v).sum::<f64>() / a.len() as f64).sqrt();
        // 20000 samples: the RMS estimate has relative spread 1/sqrt(2N) = 0.5%.
        assert!((rms - 100.0).abs() < 3.0, "rms {rms}");
    }

    #[test]
    fn pickoff_phase_lags_a_tone_by_its_phase_at_the_reference() {
        let (f, phase) = (1.0e6, 5.0f64);
        let p = PickoffPhase::new(phase, f).unwrap();
        let w = std::f64::consts::TAU * f;
        // x = cos(w t): the output must be cos(w t - phi) at every t.
        for t in [0.0, 0.13e-6, 0.71e-6] {
            let (x, v) = ((w * t).cos(), -w * (w * t).sin());
            let want = (w * t - phase.to_radians()).cos();
            assert!((p.apply(x, v) - want).abs() < 1e-12);
        }
        assert!(PickoffPhase::new(200.0, f).is_err());
        assert!(PickoffPhase::new(1.0, 0.0).is_err());
    }

    #[test]
    fn bad_settings_name_the_setting() {
        let mut fe = front_end();
        fe.adc_latency = 40;
        let e = Converters::new(&fe).unwrap_err();
        assert_eq!(e.to_string(), "adc_latency = 40: allowed 0..=31 clocks");
        assert!(matches!(e, ModelError::Parameter { name, .. } if name == "adc_latency"));
        let mut fe = front_end();
        fe.dac_bits = 0;
        let e = Converters::new(&fe).unwrap_err();
        assert_eq!(e.to_string(), "dac_bits = 0: allowed 1..=16");
    }
}
