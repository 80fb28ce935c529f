//! Fine carrier NCO: the ECP5 core's carriers. One 32-bit phase
//! accumulator, two interpolated sine pairs from an initialized ROM.
//!
//! ```text
//!            ┌──────────────┐  phase
//!  step ────►│ acc += step  ├──────┬──────────► SinePair ──► drive_cos, drive_sin
//!            └──────────────┘      │
//!  ref_offset ───────────────────► + ────────► SinePair ──► ref_cos,   ref_sin
//!  power-up count == FILL_CLOCKS ──► live ──────────▲
//! ```
//!
//! The same ports, phase, latency and power-up timing as
//! `crate::carrier_nco::CarrierNco`, so that the core around it
//! (`crate::gyro_interface`), the register map and the host are the same
//! for both parts; only the sines differ (`crate::sine_pair`: error at most
//! 0.65 LSB against 4.2, in quarter LSB for `crate::am_mixer::FineAmMixer`
//! to round once; spurs 107 dBc down against 90, measured below; no slow
//! error at a short fold of the clock). The
//! ROM needs no fill: `filling` stays low and `fill_phase` 0, and the
//! modulation NCO keeps its sine generator. The outputs still wait for
//! cycle `FILL_CLOCKS` (a 14-bit counter), so the DAC words leave 0 at
//! `DRIVE_START_CLOCKS` on both cores. `fill_word` is unused.
//!
//! Widths: outputs 18-bit, quarter LSB, peak 4 x 32767. Phase during cycle n: the sum of
//! the steps presented during cycles 0..n-1; outputs during cycle n belong
//! to the phase of cycle n - 5 (`crate::sine_pair::LATENCY`). Resources:
//! two `SinePair`s (16 ECP5 `DP16KD`, 4 `MULT18X18D`), 32 + 14 flip-flops
//! of phase and count.

use crate::carrier_table_fill::FILL_CLOCKS;
use crate::fine_sine_table::OUTPUT_BITS;
use crate::sine_pair::SinePair;
use rust_hdl::prelude::*;

/// Clock cycles from a phase to the carrier outputs (as the table core's).
pub const LATENCY: usize = crate::sine_pair::LATENCY;
const _: () = assert!(LATENCY == crate::carrier_nco::LATENCY);
/// Width of the power-up counter: it holds 0..=FILL_CLOCKS.
const COUNT_BITS: usize = 14;
const _: () = assert!(FILL_CLOCKS < 1 << COUNT_BITS);

/// 32-bit carrier NCO with a drive and a phase-shifted reference output,
/// interpolated sines.
#[derive(LogicBlock)]
pub struct FineCarrierNco {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Phase increment per clock: f_carrier = step * f_clk / 2^32.
    pub step: Signal<In, Bits<32>>,
    /// Phase advance of the reference pair over the drive pair (2^32 = 1 turn).
    pub ref_offset: Signal<In, Bits<32>>,
    /// Unused (the table core's fill input; this core's ROM needs none).
    pub fill_word: Signal<In, Signed<16>>,
    /// Always low: this core never asks for the modulation NCO's sine.
    pub filling: Signal<Out, Bit>,
    /// Always 0.
    pub fill_phase: Signal<Out, Bits<32>>,
    /// 4 x 32767 cos(phase): in-phase drive carrier (mode 1).
    pub drive_cos: Signal<Out, Signed<OUTPUT_BITS>>,
    /// 4 x 32767 sin(phase): quadrature drive carrier (mode 2).
    pub drive_sin: Signal<Out, Signed<OUTPUT_BITS>>,
    /// 32767 cos(phase + ref_offset).
    pub ref_cos: Signal<Out, Signed<OUTPUT_BITS>>,
    /// 32767 sin(phase + ref_offset).
    pub ref_sin: Signal<Out, Signed<OUTPUT_BITS>>,
    phase: DFF<Bits<32>>,
    count: DFF<Bits<COUNT_BITS>>,
    live: Signal<Local, Bit>,
    ref_phase: Signal<Local, Bits<32>>,
    drive: SinePair,
    reference: SinePair,
    last: Constant<Bits<COUNT_BITS>>,
}

impl FineCarrierNco {
    /// A carrier NCO at phase zero, its outputs 0 until `FILL_CLOCKS`.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            step: Default::default(),
            ref_offset: Default::default(),
            fill_word: Default::default(),
            filling: Default::default(),
            fill_phase: Default::default(),
            drive_cos: Default::default(),
            drive_sin: Default::default(),
            ref_cos: Default::default(),
            ref_sin: Default::default(),
            phase: Default::default(),
            count: Default::default(),
            live: Default::default(),
            ref_phase: Default::default(),
            drive: SinePair::new(),
            reference: SinePair::new(),
            last: Constant::new((FILL_CLOCKS as u64).into()),
        }
    }
}

impl Default for FineCarrierNco {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for FineCarrierNco {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, phase, count);
        self.drive.clock.next = self.clock.val();
        self.reference.clock.next = self.clock.val();
        self.phase.d.next = self.phase.q.val() + self.step.val();
        self.ref_phase.next = self.phase.q.val() + self.ref_offset.val();
        // Live from cycle FILL_CLOCKS on, as the table core.
        self.live.next = self.count.q.val() == self.last.val();
        if !self.live.val() {
            self.count.d.next = self.count.q.val() + 1;
        }
        self.filling.next = false;
        self.fill_phase.next = 0.into();
        self.drive.phase.next = self.phase.q.val();
        self.drive.live.next = self.live.val();
        self.reference.phase.next = self.ref_phase.val();
        self.reference.live.next = self.live.val();
        self.drive_cos.next = self.drive.cos.val();
        self.drive_sin.next = self.drive.sin.val();
        self.ref_cos.next = self.reference.cos.val();
        self.ref_sin.next = self.reference.sin.val();
    }
}

crate::impl_clocked!(FineCarrierNco);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::carrier_nco::{CarrierNco as Model, Carriers};
    use crate::primitives::convert::signed_to_i128;
    use gyrocal_regs::datapath::CarrierProfile;

    #[test]
    fn rtl_matches_the_fine_model_through_power_up_and_changing_settings() {
        let mut uut = FineCarrierNco::new();
        prepare(&mut uut);
        let mut model = Model::new(CarrierProfile::Fine);
        let mut rng = crate::test_util::Rng::new(21);
        let (mut step, mut offset) = (0x1234_5679u32, 0x4000_0000u32);
        for n in 0..FILL_CLOCKS + 3000 {
            if n % 400 == 0 && n > FILL_CLOCKS - 200 {
                step = rng.next_u64() as u32;
                offset = rng.next_u64() as u32;
            }
            uut.step.next = u64::from(step).into();
            uut.ref_offset.next = u64::from(offset).into();
            assert!(!uut.filling.val());
            assert_eq!(model.fill_request(), None);
            tick(&mut uut);
            let v = |x: Signed<OUTPUT_BITS>| signed_to_i128(x) as i32;
            let hw = Carriers {
                drive_cos: v(uut.drive_cos.val()),
                drive_sin: v(uut.drive_sin.val()),
                ref_cos: v(uut.ref_cos.val()),
                ref_sin: v(uut.ref_sin.val()),
            };
            assert_eq!(hw, model.step(step, offset), "cycle {n}");
        }
    }

    #[test]
    fn spur_free_dynamic_range_above_95_dbc_near_9_64_mhz() {
        // The table core's test (`crate::carrier_nco`) at the same
        // carriers: the phase truncated below 18 bits bounds the largest
        // spur near -6.02 x 18 + 3.9 = -104 dBc (Nicholas and Samueli),
        // the 18-bit (quarter-LSB) output's rounding spreads about -110
        // dBc of noise over the band; 95 dBc leaves room for the window's
        // leakage. Measured 108.2 to 108.3 dBc (107.1 to 108.2 when the
        // outputs were rounded to whole LSB).
        use crate::test_util::sfdr_dbc;
        for carrier_hz in [9.64e6, 9.640_125e6, 9.6513e6] {
            let step = (carrier_hz / 50e6 * 2f64.powi(32)).round() as u32;
            let mut nco = Model::new(CarrierProfile::Fine);
            let n = 1 << 17;
            let start = FILL_CLOCKS + LATENCY;
            let samples: Vec<Carriers> = (0..n + start)
                .map(|_| nco.step(step, 0))
                .skip(start)
                .collect();
            let i: Vec<f64> = samples.iter().map(|c| c.drive_cos as f64).collect();
            let q: Vec<f64> = samples.iter().map(|c| c.drive_sin as f64).collect();
            let (sfdr_i, sfdr_q) = (sfdr_dbc(&i), sfdr_dbc(&q));
            eprintln!("carrier {carrier_hz} Hz: SFDR I {sfdr_i:.1} dBc, Q {sfdr_q:.1} dBc");
            assert!(
                sfdr_i > 95.0 && sfdr_q > 95.0,
                "I {sfdr_i:.1} Q {sfdr_q:.1} dBc"
            );
        }
    }
}
