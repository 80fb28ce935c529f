//! The rust-hdl `GyroInterface` driven directly: the `rtl` engine's core.
//!
//! Same interface as the model (`crate::model::gyro_interface`): registers
//! and ADC words in, ports out, one rising edge per `step`.

use crate::drive::{prepare, tick};
use crate::gyro_interface::GyroInterface;
use crate::model::gyro_interface::{Outputs, Probes, Registers};
use crate::primitives::convert::{i128_to_signed, signed_to_i128, u128_to_bits};

/// rust-hdl's simulation of the datapath, stepped one clock at a time.
pub struct RtlGyroInterface {
    uut: Box<GyroInterface>,
    applied: Option<Registers>,
}

impl Default for RtlGyroInterface {
    fn default() -> Self {
        Self::new()
    }
}

impl RtlGyroInterface {
    /// The design at power-up, connected and checked.
    pub fn new() -> Self {
        let mut uut = Box::new(GyroInterface::new());
        prepare(uut.as_mut());
        Self { uut, applied: None }
    }

    fn apply(&mut self, regs: &Registers) {
        if self.applied.as_ref() == Some(regs) {
            return;
        }
        let u = &mut self.uut;
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
        self.applied = Some(*regs);
    }

    /// The output ports during the current cycle.
    pub fn outputs(&self) -> Outputs {
        let u = &self.uut;
        Outputs {
            dac: (
                signed_to_i128(u.dac1.val()) as i16,
                signed_to_i128(u.dac2.val()) as i16,
            ),
            z: (
                signed_to_i128(u.z1.val()) as i64,
                signed_to_i128(u.z2.val()) as i64,
            ),
            z_valid: u.z_valid.val(),
        }
    }

    /// One clock, like `model::gyro_interface::GyroInterface::step`.
    pub fn step(&mut self, adc: (i16, i16), regs: &Registers) -> Outputs {
        self.apply(regs);
        self.uut.adc1.next = i128_to_signed(adc.0 as i128);
        self.uut.adc2.next = i128_to_signed(adc.1 as i128);
        tick(self.uut.as_mut());
        self.outputs()
    }

    /// The design itself, for reading internal signals.
    pub fn design(&self) -> &GyroInterface {
        &self.uut
    }
}

/// Internal signals of the rust-hdl design, as in the model's `Probes`.
pub fn probes(design: &GyroInterface) -> Probes {
    design.probes()
}
