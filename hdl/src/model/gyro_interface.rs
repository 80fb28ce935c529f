//! Bit-true, cycle-true model of `crate::gyro_interface::GyroInterface`:
//! the blocks' models wired as in the hardware. This is the `model` engine.

use super::am_mixer::AmMixer;
use super::carrier_nco::CarrierNco;
use super::cic_decimator::CicDecimator;
use super::demod_mux::DemodMux;
use super::iir_lowpass::IirLowpass;
use super::modulation_nco::ModulationNco;
use super::reference_alignment::ReferenceAlignment;
pub use gyrocal_regs::Registers;
pub use gyrocal_regs::datapath::CarrierProfile;

/// The output ports of `GyroInterface` during one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Outputs {
    /// DAC words.
    pub dac: (i16, i16),
    /// Filtered outputs z1, z2 (40 bits, 8 fractional bits).
    pub z: (i64, i64),
    /// New z this cycle.
    pub z_valid: bool,
}

/// Internal signals worth watching (waveform dumps).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Probes {
    /// Reference copies of the drives, before alignment.
    pub reference: (i16, i16),
    /// Mixer outputs w1, w2.
    pub w: (i32, i32),
    /// CIC outputs.
    pub cic: (i64, i64),
    /// CIC output strobe.
    pub cic_valid: bool,
    /// Modulation factors A1, A2.
    pub am: (i16, i16),
}

/// Cycle-true model of the whole datapath.
#[derive(Clone, Debug, Default)]
pub struct GyroInterface {
    carrier_nco: CarrierNco,
    modulation_nco: ModulationNco,
    am_mixer: AmMixer,
    reference_alignment: ReferenceAlignment,
    demod_mux: DemodMux,
    cic: CicDecimator,
    iir: IirLowpass,
}

impl GyroInterface {
    /// The datapath at its power-up state (the table core).
    pub fn new() -> Self {
        Self::default()
    }

    /// The datapath of the core with this carrier profile, at power-up.
    pub fn with_profile(profile: CarrierProfile) -> Self {
        Self {
            carrier_nco: CarrierNco::new(profile),
            am_mixer: AmMixer::new(profile),
            ..Self::default()
        }
    }

    /// The output ports during the current cycle.
    #[inline(always)]
    pub fn outputs(&self) -> Outputs {
        let drives = self.am_mixer.output();
        let (z1, z2, z_valid) = self.iir.output();
        Outputs {
            dac: (drives.dac1, drives.dac2),
            z: (z1, z2),
            z_valid,
        }
    }

    /// Internal signals during the current cycle.
    pub fn probes(&self) -> Probes {
        let drives = self.am_mixer.output();
        let (cic, cic_valid) = self.cic.output();
        Probes {
            reference: (drives.ref1, drives.ref2),
            w: self.demod_mux.output(),
            cic,
            cic_valid,
            am: self.modulation_nco.output(),
        }
    }

    /// One clock: `adc` and `regs` are the inputs during the current cycle;
    /// returns the outputs after the rising edge.
    #[inline(always)]
    pub fn step(&mut self, adc: (i16, i16), regs: &Registers) -> Outputs {
        let regs = &regs.at_ports();
        // Read every block's current outputs before any register moves.
        let carriers = self.carrier_nco.output();
        let am = self.modulation_nco.output();
        let drives = self.am_mixer.output();
        let aligned = self.reference_alignment.output();
        let w = self.demod_mux.output();
        let (cic, cic_valid) = self.cic.output();

        let fill = self.carrier_nco.fill_request();
        self.carrier_nco.step(regs.carrier_step, regs.ref_phase);
        self.modulation_nco.step(regs.mod_step, regs.select, fill);
        self.am_mixer.step(regs.amp, am, carriers);
        self.reference_alignment
            .step(drives.ref1, drives.ref2, regs.ref_delay);
        self.demod_mux.step(adc, aligned, regs.select);
        let r = regs.cic_decimation as u32;
        let shift = regs.cic_shift as u32;
        self.cic.step(w, r, shift);
        self.iir.step(cic, cic_valid, &regs.iir);
        self.outputs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gyro_interface::DRIVE_START_CLOCKS;

    #[test]
    fn the_drives_leave_zero_at_drive_start_clocks() {
        // Readout at full envelope: the DAC words are 0 while the carrier
        // tables fill (or, on the fine core, for as long), and not during
        // cycle DRIVE_START_CLOCKS.
        let regs = Registers {
            carrier_step: 0x1234_5679,
            amp: (20000, -20000),
            ..Default::default()
        };
        for profile in CarrierProfile::ALL {
            let mut m = GyroInterface::with_profile(profile);
            // `step` returns the outputs of the next cycle.
            for cycle in 1..DRIVE_START_CLOCKS {
                assert_eq!(
                    m.step((0, 0), &regs).dac,
                    (0, 0),
                    "{profile}, cycle {cycle}"
                );
            }
            let first = m.step((0, 0), &regs).dac;
            assert!(
                first.0 != 0 && first.1 != 0,
                "{profile}, cycle {DRIVE_START_CLOCKS}: {first:?}"
            );
        }
    }

    #[test]
    fn the_profiles_differ_only_in_the_carriers() {
        // Same settings, same ADC words: the two cores' carriers differ by
        // at most 4.2 + 0.65 LSB (their error bounds), which an envelope of
        // 20000 / 32767 scales to 3.0 LSB; with the two products' roundings
        // (0.5 each) the DAC words differ by at most 4. They do differ, and
        // nothing else in the datapath sees the profile.
        let regs = Registers {
            carrier_step: 0x1234_5679,
            amp: (20000, -20000),
            ..Default::default()
        };
        let mut table = GyroInterface::with_profile(CarrierProfile::Table);
        let mut fine = GyroInterface::with_profile(CarrierProfile::Fine);
        let mut differ = 0;
        for _ in 0..DRIVE_START_CLOCKS + 5000 {
            let (a, b) = (table.step((0, 0), &regs).dac, fine.step((0, 0), &regs).dac);
            assert!(
                (a.0 - b.0).abs() <= 4 && (a.1 - b.1).abs() <= 4,
                "{a:?} {b:?}"
            );
            differ += usize::from(a != b);
        }
        assert!(differ > 100, "the fine carriers never differed: {differ}");
    }
}
