//! `GyroInterface`: the top of the datapath, paper Fig. 1 in one clock domain.
//!
//! ```text
//!                       ┌────────────┐ drive_cos/sin ┌──────────┐ dac1, dac2
//!  carrier_step ───────►│ CarrierNco ├──────────────►│          ├─────────────► to the DACs
//!  ref_phase ──────────►│            ├──────────────►│ AmMixer  │ ref1, ref2
//!                       └────────────┘ ref_cos/sin   │          ├──────┐
//!     fill ▲▼  (carrier tables at power-up)          │          │      │
//!  mod_step ──►┌───────────────┐ am1, am2            │          │      │
//!  select ────►│ ModulationNco ├────────────────────►│          │      ▼
//!              └───────────────┘       amp1, amp2 ──►└──────────┘ ┌────────────────────┐
//!                                                   ref_delay ──►│ ReferenceAlignment │
//!                                                                └─────────┬──────────┘
//!  adc1, adc2 (from the ADCs) ──────────────────────►┌──────────┐ aligned1,2│
//!  select ──────────────────────────────────────────►│ DemodMux │◄──────────┘
//!                                                    └──┬────┬──┘
//!                                                    w1 │    │ w2
//!  cic_decimation, cic_shift ──────────────────►  CicDecimator (both channels)
//!  iir_k0, iir_k1, iir_k2, iir_alpha ──────────►  IirLowpass (both channels) ──► z1, z2, z_valid
//! ```
//!
//! Follow a sample in file order: `carrier_nco` (with `carrier_table_fill`,
//! `table_sine`, `quarter_wave`), `modulation_nco` (with `sine`,
//! `sine_table`), `am_mixer` (with `q15_multiplier`), the
//! DACs and the gyroscope (in the simulator), `reference_alignment`,
//! `demod_mux`, `cic_integrators`, `cic_decimator`, `iir_lowpass`.
//!
//! Every input is sampled at the rising edge of `clock`; the run-time
//! settings are meant to be driven from a register bank in the same clock
//! domain. Every register has a power-up value (Verilog `initial`); there is
//! no reset. The carriers' four table RAMs have no power-up contents (an
//! iCE40 SPRAM cannot be initialized): they are filled during the first
//! 8200 clocks (`crate::carrier_table_fill`), and the DAC words are 0 until
//! cycle `DRIVE_START_CLOCKS` = 8232. `crate::settings::Settings` computes all the settings from
//! frequencies in Hz; the port list with formats is in
//! `verilog-out/PORTS.md`.
//!
//! Two cores share this file (`datapath!` below): `GyroInterface`, the
//! table core above, and `FineGyroInterface`, whose carrier NCO is
//! `crate::fine_carrier_nco` (interpolated sines from an initialized ROM
//! and four multipliers: an ECP5 or larger part) and whose mixer is
//! `crate::am_mixer::FineAmMixer` (the carriers in quarter LSB, one
//! rounding to the DAC word, its error fed back away from the carrier).
//! Their ports, registers, latencies and
//! power-up timing are the same; only the carrier words and their product's
//! rounding differ (`gyrocal_regs::datapath::CarrierProfile`).
//!
//! Latencies (clocks): carrier phase to DAC word 8 (the sum of
//! `carrier_nco::LATENCY` and `am_mixer::CARRIER_LATENCY`), ADC word to
//! mixer output 2, mixer output to CIC output R + 21 at most
//! (`cic_decimator::SAMPLE_TO_OUTPUT`), CIC output to z 168
//! (`crate::iir_lowpass::LATENCY`); `amp1`/`amp2` or the modulation factors to
//! DAC word 7 or 8 (`am_mixer::AMPLITUDE_LATENCY`, the shared envelope
//! multiplier's turn).

use crate::am_mixer::{AmMixer, FineAmMixer};

/// Clocks from power-up until the DAC words can leave 0: the carrier table
/// fill (`carrier_table_fill::FILL_CLOCKS`), the carrier lookup and the AM
/// product.
pub const DRIVE_START_CLOCKS: usize = crate::carrier_table_fill::FILL_CLOCKS
    + crate::carrier_nco::LATENCY
    + crate::am_mixer::CARRIER_LATENCY;
// The register map and the host read the figure from the leaf crate.
const _: () = assert!(DRIVE_START_CLOCKS as u64 == gyrocal_regs::datapath::DRIVE_START_CLOCKS);
use crate::carrier_nco::CarrierNco;
use crate::cic_decimator::{CicDecimator, DECIMATION_BITS, OUTPUT_BITS, SHIFT_BITS};
use crate::demod_mux::DemodMux;
use crate::fine_carrier_nco::FineCarrierNco;
use crate::iir_lowpass::IirLowpass;
use crate::modulation_nco::ModulationNco;
use crate::reference_alignment::{DELAY_BITS, ReferenceAlignment};
use rust_hdl::prelude::*;

/// Declares a datapath top with the given carrier NCO and mixer: the struct, its
/// constructor, its wiring (`update`) and its probes, written once for
/// both cores. The carrier NCOs have the same ports, and so have the
/// mixers, but for the carriers' width (16 bits or 18 in quarter LSB).
macro_rules! datapath {
    ($(#[$meta:meta])* $name:ident, $carrier:ident, $mixer:ident) => {
        $(#[$meta])*
        #[derive(LogicBlock)]
        pub struct $name {
            /// The clock; every register of the design uses its rising edge.
            pub clock: Signal<In, Clock>,
            /// ADC word of gyroscope output 1 (16-bit two's complement).
            pub adc1: Signal<In, Signed<16>>,
            /// ADC word of gyroscope output 2 (16-bit two's complement).
            pub adc2: Signal<In, Signed<16>>,
            /// DAC word of drive 1, F1 A1 cos(wt): 16-bit two's complement, |dac1| <= 32767.
            pub dac1: Signal<Out, Signed<16>>,
            /// DAC word of drive 2, F2 A2 sin(wt): 16-bit two's complement, |dac2| <= 32767.
            pub dac2: Signal<Out, Signed<16>>,
            /// Filtered demodulator output 1: 40-bit two's complement, 8 fractional bits.
            pub z1: Signal<Out, Signed<OUTPUT_BITS>>,
            /// Filtered demodulator output 2: 40-bit two's complement, 8 fractional bits.
            pub z2: Signal<Out, Signed<OUTPUT_BITS>>,
            /// One-clock pulse when z1 and z2 are updated (once per CIC output).
            pub z_valid: Signal<Out, Bit>,
            /// SELECT: 0 readout (A = 1, own references), 1 calibration (A = cos/sin, crossed references).
            pub select: Signal<In, Bit>,
            /// Carrier phase step: f_carrier = carrier_step * f_clk / 2^32.
            pub carrier_step: Signal<In, Bits<32>>,
            /// Phase advance of the demodulation references over the drives, 2^32 = 360 degrees.
            pub ref_phase: Signal<In, Bits<32>>,
            /// Reference delay: references are delayed by ref_delay + 1 clocks (0..63).
            pub ref_delay: Signal<In, Bits<DELAY_BITS>>,
            /// Modulation (calibration rate) phase step: f_cal = mod_step * f_clk / 2^48.
            pub mod_step: Signal<In, Bits<48>>,
            /// Drive amplitude F1, Q1.15 (32767 = full scale).
            pub amp1: Signal<In, Signed<16>>,
            /// Drive amplitude F2, Q1.15 (32767 = full scale).
            pub amp2: Signal<In, Signed<16>>,
            /// CIC decimation R, 166..=4096 (`filter_design::MIN_DECIMATION`; z rate f_clk / R).
            pub cic_decimation: Signal<In, Bits<DECIMATION_BITS>>,
            /// CIC output shift, ceil(4 log2 R) - 8.
            pub cic_shift: Signal<In, Bits<SHIFT_BITS>>,
            /// Biquad numerator gain g, Q2.30.
            pub iir_k0: Signal<In, Signed<32>>,
            /// Biquad feedback -a1 - 2, Q2.30.
            pub iir_k1: Signal<In, Signed<32>>,
            /// Biquad feedback 1 - a2, Q2.30.
            pub iir_k2: Signal<In, Signed<32>>,
            /// RC section coefficient 1 - exp(-2 pi f_rc / f_z), Q2.30.
            pub iir_alpha: Signal<In, Signed<32>>,
            carrier_nco: $carrier,
            modulation_nco: ModulationNco,
            am_mixer: $mixer,
            reference_alignment: ReferenceAlignment,
            demod_mux: DemodMux,
            cic: CicDecimator,
            iir: IirLowpass,
        }

        impl $name {
            /// The datapath at its power-up state.
            pub fn new() -> Self {
                Self {
                    clock: Default::default(),
                    adc1: Default::default(),
                    adc2: Default::default(),
                    dac1: Default::default(),
                    dac2: Default::default(),
                    z1: Default::default(),
                    z2: Default::default(),
                    z_valid: Default::default(),
                    select: Default::default(),
                    carrier_step: Default::default(),
                    ref_phase: Default::default(),
                    ref_delay: Default::default(),
                    mod_step: Default::default(),
                    amp1: Default::default(),
                    amp2: Default::default(),
                    cic_decimation: Default::default(),
                    cic_shift: Default::default(),
                    iir_k0: Default::default(),
                    iir_k1: Default::default(),
                    iir_k2: Default::default(),
                    iir_alpha: Default::default(),
                    carrier_nco: $carrier::new(),
                    modulation_nco: ModulationNco::new(),
                    am_mixer: $mixer::new(),
                    reference_alignment: ReferenceAlignment::new(),
                    demod_mux: DemodMux::new(),
                    cic: CicDecimator::new(),
                    iir: IirLowpass::new(),
                }
            }
        }

        impl Default for $name {
            fn default() -> Self {
                Self::new()
            }
        }

        impl Logic for $name {
            #[hdl_gen]
            fn update(&mut self) {
                self.carrier_nco.clock.next = self.clock.val();
                self.modulation_nco.clock.next = self.clock.val();
                self.am_mixer.clock.next = self.clock.val();
                self.reference_alignment.clock.next = self.clock.val();
                self.demod_mux.clock.next = self.clock.val();
                self.cic.clock.next = self.clock.val();
                self.iir.clock.next = self.clock.val();
                // Excitation.
                self.carrier_nco.step.next = self.carrier_step.val();
                self.carrier_nco.ref_offset.next = self.ref_phase.val();
                self.modulation_nco.step.next = self.mod_step.val();
                self.modulation_nco.select.next = self.select.val();
                self.modulation_nco.filling.next = self.carrier_nco.filling.val();
                self.modulation_nco.fill_phase.next = self.carrier_nco.fill_phase.val();
                self.carrier_nco.fill_word.next = self.modulation_nco.fill_word.val();
                self.am_mixer.amp1.next = self.amp1.val();
                self.am_mixer.amp2.next = self.amp2.val();
                self.am_mixer.am1.next = self.modulation_nco.am1.val();
                self.am_mixer.am2.next = self.modulation_nco.am2.val();
                self.am_mixer.drive_cos.next = self.carrier_nco.drive_cos.val();
                self.am_mixer.drive_sin.next = self.carrier_nco.drive_sin.val();
                self.am_mixer.ref_cos.next = self.carrier_nco.ref_cos.val();
                self.am_mixer.ref_sin.next = self.carrier_nco.ref_sin.val();
                self.dac1.next = self.am_mixer.dac1.val();
                self.dac2.next = self.am_mixer.dac2.val();
                // Demodulation.
                self.reference_alignment.ref1.next = self.am_mixer.ref1.val();
                self.reference_alignment.ref2.next = self.am_mixer.ref2.val();
                self.reference_alignment.delay.next = self.ref_delay.val();
                self.demod_mux.adc1.next = self.adc1.val();
                self.demod_mux.adc2.next = self.adc2.val();
                self.demod_mux.aligned1.next = self.reference_alignment.aligned1.val();
                self.demod_mux.aligned2.next = self.reference_alignment.aligned2.val();
                self.demod_mux.select.next = self.select.val();
                // Decimation and filtering.
                self.cic.x1.next = self.demod_mux.w1.val();
                self.cic.x2.next = self.demod_mux.w2.val();
                self.cic.decimation.next = self.cic_decimation.val();
                self.cic.shift.next = self.cic_shift.val();
                self.iir.x1.next = self.cic.y1.val();
                self.iir.x2.next = self.cic.y2.val();
                self.iir.x_valid.next = self.cic.valid.val();
                self.iir.k0.next = self.iir_k0.val();
                self.iir.k1.next = self.iir_k1.val();
                self.iir.k2.next = self.iir_k2.val();
                self.iir.alpha.next = self.iir_alpha.val();
                self.z1.next = self.iir.z1.val();
                self.z2.next = self.iir.z2.val();
                self.z_valid.next = self.iir.z_valid.val();
            }
        }

        crate::impl_clocked!($name);

        impl $name {
            /// Internal signals during the current cycle (for waveforms and tests).
            pub fn probes(&self) -> crate::model::gyro_interface::Probes {
                use crate::primitives::convert::signed_to_i128 as v;
                let a = &self.am_mixer;
                crate::model::gyro_interface::Probes {
                    reference: (v(a.ref1.val()) as i16, v(a.ref2.val()) as i16),
                    w: (
                        v(self.demod_mux.w1.val()) as i32,
                        v(self.demod_mux.w2.val()) as i32,
                    ),
                    cic: (v(self.cic.y1.val()) as i64, v(self.cic.y2.val()) as i64),
                    cic_valid: self.cic.valid.val(),
                    am: (
                        v(self.modulation_nco.am1.val()) as i16,
                        v(self.modulation_nco.am2.val()) as i16,
                    ),
                }
            }
        }
    };
}

datapath!(
    /// The reconfigurable phase-readout and self-calibration datapath: the
    /// table core (`crate::carrier_nco`), which fits an iCE40 UltraPlus.
    GyroInterface,
    CarrierNco,
    AmMixer
);

datapath!(
    /// The same datapath with the fine carriers
    /// (`crate::fine_carrier_nco`): the ECP5 core. Ports, registers and
    /// latencies are `GyroInterface`'s; only the carrier sines differ.
    FineGyroInterface,
    FineCarrierNco,
    FineAmMixer
);

/// One-constant changes to the hardware, for the negative control of the
/// model-vs-rtl comparisons (they must fail when the hardware changes).
/// Test builds only: the exported design cannot carry them.
#[cfg(test)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mutation {
    /// The drive 1 rounding adds 2^13 instead of 2^14.
    DriveRounding,
    /// The carrier table's interpolation rounds with 1 instead of 2 quarter LSBs.
    FillRounding,
    /// The readout amplitude is 32766 instead of 32767.
    ModulationFullScale,
}

#[cfg(test)]
impl Mutation {
    /// Every mutation.
    pub const ALL: [Mutation; 3] = [
        Mutation::DriveRounding,
        Mutation::FillRounding,
        Mutation::ModulationFullScale,
    ];
}

#[cfg(test)]
impl GyroInterface {
    /// Apply a mutation (before the design is connected).
    pub fn mutate(&mut self, mutation: Mutation) {
        match mutation {
            Mutation::DriveRounding => self.am_mixer.mutate_drive_rounding(),
            Mutation::FillRounding => self.carrier_nco.mutate_fill_rounding(),
            Mutation::ModulationFullScale => self.modulation_nco.mutate_full_scale(),
        }
    }
}
