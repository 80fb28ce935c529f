//! The rust-hdl `GyroInterface` (or `FineGyroInterface`, the ECP5 core)
//! driven directly: the `rtl` engine's core.
//!
//! Same interface as the model (`crate::model::gyro_interface`): registers
//! and ADC words in, ports out, one rising edge per `step`.

use crate::drive::{prepare, tick};
use crate::gyro_interface::{FineGyroInterface, GyroInterface};
use crate::model::gyro_interface::{CarrierProfile, Outputs, Probes, Registers};
use crate::primitives::convert::{i128_to_signed, signed_to_i128, u128_to_bits};

/// One of the two cores; both have the same ports.
enum Design {
    Table(Box<GyroInterface>),
    Fine(Box<FineGyroInterface>),
}

/// `$body` with `$u` bound to the core, whichever it is (the two cores'
/// ports have the same names and types).
macro_rules! on_design {
    ($design:expr, $u:ident => $body:expr) => {
        match $design {
            Design::Table($u) => $body,
            Design::Fine($u) => $body,
        }
    };
}

/// rust-hdl's simulation of the datapath, stepped one clock at a time.
pub struct RtlGyroInterface {
    uut: Design,
    applied: Option<Registers>,
}

/// The first cycle on which two engines' outputs or internal signals
/// differ.
#[derive(Clone, Debug, PartialEq)]
pub struct Mismatch {
    /// Rising edge number (1 for the first).
    pub cycle: usize,
    /// Outputs and internal signals of the rust-hdl design.
    pub rtl: (Outputs, Probes),
    /// Outputs and internal signals of the model.
    pub model: (Outputs, Probes),
}

/// Drive the rust-hdl design and the model with the same ADC words and
/// registers (`regs[n]` during cycle n, `adc[n]` likewise) and return the
/// first cycle whose outputs or internal signals ([`Probes`]: the
/// modulation factors, the references, the mixers, the CIC) differ,
/// checking the power-up state first. The internal signals catch what the
/// ports cannot see: the modulation words while the carrier tables fill,
/// when every drive and reference is still zero.
pub fn first_mismatch(
    rtl: &mut RtlGyroInterface,
    adc: &[(i16, i16)],
    regs: &[Registers],
) -> Option<Mismatch> {
    let mut model = crate::model::gyro_interface::GyroInterface::with_profile(rtl.profile());
    let state = |rtl: &RtlGyroInterface, model: &crate::model::gyro_interface::GyroInterface| {
        (
            (rtl.outputs(), rtl.probes()),
            (model.outputs(), model.probes()),
        )
    };
    let (x, y) = state(rtl, &model);
    if x != y {
        return Some(Mismatch {
            cycle: 0,
            rtl: x,
            model: y,
        });
    }
    for (n, (a, r)) in adc.iter().zip(regs).enumerate() {
        rtl.step(*a, r);
        model.step(*a, r);
        let (x, y) = state(rtl, &model);
        if x != y {
            return Some(Mismatch {
                cycle: n + 1,
                rtl: x,
                model: y,
            });
        }
    }
    None
}

impl Default for RtlGyroInterface {
    fn default() -> Self {
        Self::new()
    }
}

impl RtlGyroInterface {
    /// The design at power-up, connected and checked.
    pub fn new() -> Self {
        Self::from_design(GyroInterface::new())
    }

    /// The core with this carrier profile at power-up, connected and checked.
    pub fn with_profile(profile: CarrierProfile) -> Self {
        match profile {
            CarrierProfile::Table => Self::new(),
            CarrierProfile::Fine => {
                let mut uut = Box::new(FineGyroInterface::new());
                prepare(uut.as_mut());
                Self {
                    uut: Design::Fine(uut),
                    applied: None,
                }
            }
        }
    }

    /// A given (unconnected) table design at power-up, connected and checked.
    pub fn from_design(design: GyroInterface) -> Self {
        let mut uut = Box::new(design);
        prepare(uut.as_mut());
        Self {
            uut: Design::Table(uut),
            applied: None,
        }
    }

    /// The core's carrier profile.
    pub fn profile(&self) -> CarrierProfile {
        match self.uut {
            Design::Table(_) => CarrierProfile::Table,
            Design::Fine(_) => CarrierProfile::Fine,
        }
    }

    fn apply(&mut self, regs: &Registers) {
        if self.applied.as_ref() == Some(regs) {
            return;
        }
        on_design!(&mut self.uut, u => {
            u.select.next = regs.select;
            u.carrier_step.next = u128_to_bits(regs.carrier_step as u128);
            u.ref_phase.next = u128_to_bits(regs.ref_phase as u128);
            u.ref_delay.next = u128_to_bits(regs.ref_delay as u128);
            u.mod_step.next = u128_to_bits(regs.mod_step as u128);
            u.amp1.next = i128_to_signed(regs.amp.0 as i128);
            u.amp2.next = i128_to_signed(regs.amp.1 as i128);
            u.cic_decimation.next = u128_to_bits(regs.cic_decimation as u128);
            u.cic_shift.next = u128_to_bits(regs.cic_shift as u128);
            u.iir_k0.next = i128_to_signed(regs.iir.k0 as i128);
            u.iir_k1.next = i128_to_signed(regs.iir.k1 as i128);
            u.iir_k2.next = i128_to_signed(regs.iir.k2 as i128);
            u.iir_alpha.next = i128_to_signed(regs.iir.alpha as i128);
        });
        self.applied = Some(*regs);
    }

    /// The output ports during the current cycle.
    pub fn outputs(&self) -> Outputs {
        on_design!(&self.uut, u => Outputs {
            dac: (
                signed_to_i128(u.dac1.val()) as i16,
                signed_to_i128(u.dac2.val()) as i16,
            ),
            z: (
                signed_to_i128(u.z1.val()) as i64,
                signed_to_i128(u.z2.val()) as i64,
            ),
            z_valid: u.z_valid.val(),
        })
    }

    /// One clock, like `model::gyro_interface::GyroInterface::step`.
    pub fn step(&mut self, adc: (i16, i16), regs: &Registers) -> Outputs {
        self.apply(regs);
        on_design!(&mut self.uut, u => {
            u.adc1.next = i128_to_signed(adc.0 as i128);
            u.adc2.next = i128_to_signed(adc.1 as i128);
            tick(u.as_mut());
        });
        self.outputs()
    }

    /// Internal signals during the current cycle, as in the model's `Probes`.
    pub fn probes(&self) -> Probes {
        on_design!(&self.uut, u => u.probes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gyro_interface::Mutation;
    use crate::settings::{FrequencyPlan, registers};
    use crate::test_util::Rng;

    /// The carrier table fill, then 3000 clocks of carriers.
    const CYCLES: usize = crate::carrier_table_fill::FILL_CLOCKS + 3000;

    /// Valid registers and stimulus the mutations below must disturb.
    fn stimulus(cycles: usize, calibration: bool) -> (Vec<(i16, i16)>, Vec<Registers>) {
        let plan = FrequencyPlan {
            clock_hz: 10e6,
            carrier_hz: 1.0123e6,
            cal_hz: 5e3,
            calibration,
            amplitude: (0.9, -0.7),
            // The least decimation: strobes as fast as the filter takes them.
            decimation: crate::filter_design::MIN_DECIMATION,
            butterworth_hz: 5e3,
            rc_hz: 10e3,
            dac_latency: 1,
            adc_latency: 2,
        };
        let (regs, _) = registers(&plan).unwrap();
        let mut rng = Rng::new(31);
        let adc = (0..cycles).map(|_| (rng.word16(), rng.word16())).collect();
        (adc, vec![regs; cycles])
    }

    #[test]
    fn the_unmodified_design_matches_the_model() {
        for calibration in [false, true] {
            let (adc, regs) = stimulus(CYCLES, calibration);
            assert_eq!(
                first_mismatch(&mut RtlGyroInterface::new(), &adc, &regs),
                None
            );
        }
    }

    #[test]
    fn the_fine_core_matches_its_model_and_not_the_table_model() {
        for calibration in [false, true] {
            let (adc, regs) = stimulus(CYCLES, calibration);
            let mut fine = RtlGyroInterface::with_profile(CarrierProfile::Fine);
            assert_eq!(first_mismatch(&mut fine, &adc, &regs), None);
        }
        // Negative control: the fine core's carriers are not the table's,
        // so against the table model the same comparison fails.
        let (adc, regs) = stimulus(CYCLES, false);
        let mut fine = RtlGyroInterface::with_profile(CarrierProfile::Fine);
        let mut table = crate::model::gyro_interface::GyroInterface::new();
        let differs = adc
            .iter()
            .zip(&regs)
            .any(|(a, r)| fine.step(*a, r) != table.step(*a, r));
        assert!(differs, "the fine core gave the table core's outputs");
    }

    #[test]
    fn a_hardware_change_not_mirrored_in_the_model_is_caught() {
        // Negative control for every rtl-vs-model comparison: each of these
        // one-constant changes to the hardware (not to the model) must make
        // the comparison fail within a few thousand cycles of the carrier
        // tables' fill.
        for mutation in Mutation::ALL {
            let (adc, regs) = stimulus(CYCLES, false);
            let mut design = GyroInterface::new();
            design.mutate(mutation);
            let found = first_mismatch(&mut RtlGyroInterface::from_design(design), &adc, &regs);
            assert!(found.is_some(), "{mutation:?} went unnoticed");
        }
    }
}
