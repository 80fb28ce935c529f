//! Modulation NCO: the "rotating" excitation A1 = cos(Om t), A2 = sin(Om t).
//!
//! ```text
//!            ┌──────────────┐ phase[47:16]
//!  step ────►│ acc += step  ├────────────► Sine ──► turn 0's output: select ? cos : 32767 ──► am1
//!            └──────────────┘   advance: │          turn 1's output: select ? sin : 32767 ──► am2
//!                       turn 0: cos (1), turn 1: sin (0)
//! ```
//!
//! In calibration (`select` = 1) the two carriers are amplitude modulated by
//! the quadrature pair of a slow NCO, which makes the excitation rotate at
//! Om = 2 pi f_cal in the plane of the two modes (paper eq. 3). In readout
//! (`select` = 0) both outputs are the constant 32767, exactly the peak of
//! the sine generator, so "A = 1" in readout has the same full scale as the
//! crest of the modulation: the calibration excitation amplitude equals the
//! readout one, as in the paper's measurement.
//!
//! The accumulator has 48 bits: f_cal = step * f_clk / 2^48, resolution
//! 0.18 uHz at 50 MHz (a 32-bit NCO would be off by up to 0.06% at 10 Hz).
//! The top 32 bits address the sine generator.
//!
//! One `crate::sine::Sine` serves both outputs on alternate clocks: a
//! `turn` bit (power-up 0, toggled every clock) asks for the cosine (A1) on
//! turn 0 and the sine (A2) on turn 1, and each answer is held in its
//! output register when it leaves the pipeline `sine::LATENCY` clocks
//! later. So each output is a two-clock hold of samples taken on its own
//! clocks, A1 on the even ones and A2 on the odd ones: the skew between
//! them alternates between +1 and -1 clock (2 pi f_cal / f_clk = 1.3e-6
//! rad at 10 Hz and 50 MHz) and is zero on average, and both holds add the
//! same mean delay, half a clock. Latency from the
//! phase register to `am1`/`am2`: 6 clocks (5 in `Sine`, 1 for the output
//! register). `select` acts after 1 clock on the output whose answer is
//! due, after 2 on the other (which holds its previous word for one clock).
//! Resources: one table ROM port (`crate::sine`: 4096 words, no
//! multiplier).
//!
//! During the first 8195 clocks after power-up the sine generator is lent
//! to the carrier table fill (`filling`: it evaluates `fill_phase`, with no
//! quarter-turn advance, and `fill_word` carries its output out); the
//! outputs follow the same rules meanwhile, and the carriers stay 0 until
//! the words it made have left the envelope path
//! (`crate::carrier_table_fill`).

use crate::sine::Sine;
use rust_hdl::prelude::*;

/// The `turn` during which the cosine (A1) leaves the sine generator: it
/// was asked for on turn 0, `sine::LATENCY` toggles earlier.
const COSINE_OUT_TURN: bool = crate::sine::LATENCY % 2 == 1;

/// 48-bit modulation NCO with the readout/calibration amplitude select.
#[derive(LogicBlock)]
pub struct ModulationNco {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Phase increment per clock: f_cal = step * f_clk / 2^48.
    pub step: Signal<In, Bits<48>>,
    /// 0: readout (am1 = am2 = 32767); 1: calibration (am1, am2 = cos, sin).
    pub select: Signal<In, Bit>,
    /// Carrier table fill: the sine generator evaluates `fill_phase` instead.
    pub filling: Signal<In, Bit>,
    /// Carrier table fill: the phase asked for while `filling`.
    pub fill_phase: Signal<In, Bits<32>>,
    /// The sine generator's output, `sine::LATENCY` clocks after its phase
    /// (the carrier tables' words during the fill).
    pub fill_word: Signal<Out, Signed<16>>,
    /// Amplitude factor A1 for drive 1, 16-bit, full scale 32767.
    pub am1: Signal<Out, Signed<16>>,
    /// Amplitude factor A2 for drive 2, 16-bit, full scale 32767.
    pub am2: Signal<Out, Signed<16>>,
    phase: DFF<Bits<48>>,
    sine: Sine,
    turn: DFF<Bit>,
    am1_out: DFF<Signed<16>>,
    am2_out: DFF<Signed<16>>,
    full_scale: Constant<Signed<16>>,
    cosine_advance: Constant<Bits<2>>,
    sine_advance: Constant<Bits<2>>,
    cosine_out_turn: Constant<Bit>,
}

impl ModulationNco {
    /// A modulation NCO at phase zero.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            step: Default::default(),
            select: Default::default(),
            filling: Default::default(),
            fill_phase: Default::default(),
            fill_word: Default::default(),
            am1: Default::default(),
            am2: Default::default(),
            phase: Default::default(),
            sine: Sine::new(),
            turn: Default::default(),
            am1_out: Default::default(),
            am2_out: Default::default(),
            full_scale: Constant::new((crate::sine_table::PEAK as i64).into()),
            cosine_advance: Constant::new(1.into()),
            sine_advance: Constant::new(0.into()),
            cosine_out_turn: Constant::new(COSINE_OUT_TURN),
        }
    }
}

impl Default for ModulationNco {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for ModulationNco {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, phase, turn, am1_out, am2_out);
        self.sine.clock.next = self.clock.val();
        self.phase.d.next = self.phase.q.val() + self.step.val();
        self.turn.d.next = !self.turn.q.val();
        self.sine.phase.next = self.phase.q.val().get_bits::<32>(16);
        self.sine.advance.next = self.cosine_advance.val();
        if self.turn.q.val() {
            self.sine.advance.next = self.sine_advance.val();
        }
        if self.filling.val() {
            self.sine.phase.next = self.fill_phase.val();
            self.sine.advance.next = self.sine_advance.val();
        }
        self.fill_word.next = self.sine.sin.val();
        if self.select.val() {
            if self.turn.q.val() == self.cosine_out_turn.val() {
                self.am1_out.d.next = self.sine.sin.val();
            } else {
                self.am2_out.d.next = self.sine.sin.val();
            }
        } else {
            self.am1_out.d.next = self.full_scale.val();
            self.am2_out.d.next = self.full_scale.val();
        }
        self.am1.next = self.am1_out.q.val();
        self.am2.next = self.am2_out.q.val();
    }
}

crate::impl_clocked!(ModulationNco);

/// Mutation hooks for the negative control in `crate::rtl` (tests only).
#[cfg(test)]
impl ModulationNco {
    #[doc(hidden)]
    pub fn mutate_full_scale(&mut self) {
        self.full_scale = Constant::new(((crate::sine_table::PEAK - 1) as i64).into());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::modulation_nco::ModulationNco as Model;
    use crate::primitives::convert::{signed_to_i128, u128_to_bits};
    use crate::sine_table::PEAK;
    use crate::test_util::segments;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(8))]
        #[test]
        fn rtl_matches_model_across_select_changes_and_fill_requests(
            // Large steps (up to 2^48 / 2^4) so the sine moves within the test;
            // some segments take the sine generator for the carrier tables.
            settings in segments(
                (0u64..(1 << 44), any::<bool>(), prop::option::of(any::<u32>())),
                2..8,
                30..150,
            ),
        ) {
            let mut uut = ModulationNco::new();
            prepare(&mut uut);
            let mut model = Model::default();
            for (n, &(step, select, fill)) in settings.iter().enumerate() {
                uut.step.next = u128_to_bits(step as u128);
                uut.select.next = select;
                uut.filling.next = fill.is_some();
                uut.fill_phase.next = u128_to_bits(fill.unwrap_or(0) as u128);
                tick(&mut uut);
                let v = |x: Signed<16>| signed_to_i128(x) as i16;
                let hw = (v(uut.am1.val()), v(uut.am2.val()));
                prop_assert_eq!(hw, model.step(step, select, fill), "cycle {}", n);
                prop_assert_eq!(v(uut.fill_word.val()), model.fill_word(), "cycle {}", n);
            }
        }
    }

    #[test]
    fn readout_amplitude_equals_the_modulation_crest() {
        // A = 1 in readout is the same word as the peak of cos/sin.
        let mut model = Model::default();
        let mut crest = 0;
        for n in 0..(1 << 20) {
            let (c, s) = model.step(1 << 28, true, None);
            if n > 8 {
                crest = crest.max(c).max(s);
            }
        }
        assert_eq!(crest as i32, PEAK);
        for _ in 0..3 {
            model.step(1 << 28, false, None);
        }
        assert_eq!(model.step(1 << 28, false, None), (PEAK as i16, PEAK as i16));
    }
}
