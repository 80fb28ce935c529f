//! Bit-true model of `crate::am_mixer::AmMixer` and
//! `crate::am_mixer::FineAmMixer`.

use super::carrier_nco::Carriers;
use super::q15_multiplier::Q15Multiplier;
use crate::q15_multiplier::LATENCY;
use gyrocal_regs::datapath::CarrierProfile;

/// Outputs of the AM mixers during one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Drives {
    /// DAC word of drive 1.
    pub dac1: i16,
    /// DAC word of drive 2.
    pub dac2: i16,
    /// Reference copy of drive 1.
    pub ref1: i16,
    /// Reference copy of drive 2.
    pub ref2: i16,
}

/// Cycle-true model of a carrier product, `crate::q15_multiplier` (16-bit
/// carriers) or `crate::carrier_multiplier` (quarter-LSB carriers): the
/// factor, product and rounding registers, `round(a c / 2^shift)` rounded
/// half up.
#[derive(Clone, Copy, Debug)]
pub struct CarrierMultiplier {
    factors: (i16, i32),
    product: i64,
    y: i16,
    shift: u32,
}

impl CarrierMultiplier {
    /// The product for carriers with `fraction_bits` below the LSB.
    pub fn new(fraction_bits: u32) -> Self {
        Self {
            factors: (0, 0),
            product: 0,
            y: 0,
            shift: 15 + fraction_bits,
        }
    }

    /// `y` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> i16 {
        self.y
    }

    /// One clock; returns `y` after the edge.
    #[inline(always)]
    pub fn step(&mut self, a: i16, c: i32) -> i16 {
        // The two cores' shifts as constants: with a shift by a variable the
        // model engine ran 1.5% slower (`gyrocal bench --engines model`).
        self.y = match self.shift {
            15 => round_product(self.product, 15),
            17 => round_product(self.product, 17),
            shift => round_product(self.product, shift),
        };
        self.product = i64::from(self.factors.0) * i64::from(self.factors.1);
        self.factors = (a, c);
        self.y
    }
}

/// `round(p / 2^shift)`, rounded half up: |p| < 2^33 and the result
/// within 16 bits for every product of the mixers (`crate::am_mixer`).
#[inline(always)]
fn round_product(p: i64, shift: u32) -> i16 {
    ((p + (1 << (shift - 1))) >> shift) as i16
}

/// The DAC or reference word of the core with this profile for the
/// envelope F A `a` and the carrier word `c` (`Carriers`' scale): the
/// carrier product's output, without its pipeline.
pub fn carrier_product(profile: CarrierProfile, a: i16, c: i32) -> i16 {
    round_product(
        i64::from(a) * i64::from(c),
        15 + carrier_fraction_bits(profile),
    )
}

/// Fraction bits of the carrier words a core's mixer takes.
pub fn carrier_fraction_bits(profile: CarrierProfile) -> u32 {
    match profile {
        CarrierProfile::Table => 0,
        CarrierProfile::Fine => crate::fine_sine_table::OUTPUT_FRACTION_BITS,
    }
}

/// Cycle-true model of the two AM channels.
#[derive(Clone, Debug)]
pub struct AmMixer {
    envelope: Q15Multiplier,
    /// false: channel 1 enters the envelope multiplier; true: channel 2.
    turn: bool,
    fa: (i16, i16),
    drive1: CarrierMultiplier,
    drive2: CarrierMultiplier,
    reference1: CarrierMultiplier,
    reference2: CarrierMultiplier,
}

impl Default for AmMixer {
    fn default() -> Self {
        Self::new(CarrierProfile::Table)
    }
}

impl AmMixer {
    /// The mixers of the core with this carrier profile, at power-up.
    pub fn new(profile: CarrierProfile) -> Self {
        let product = CarrierMultiplier::new(carrier_fraction_bits(profile));
        Self {
            envelope: Q15Multiplier::default(),
            turn: false,
            fa: (0, 0),
            drive1: product,
            drive2: product,
            reference1: product,
            reference2: product,
        }
    }

    /// The outputs during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> Drives {
        Drives {
            dac1: self.drive1.output(),
            dac2: self.drive2.output(),
            ref1: self.reference1.output(),
            ref2: self.reference2.output(),
        }
    }

    /// One clock with amplitudes F, modulation factors A and the carriers.
    #[inline(always)]
    pub fn step(&mut self, amp: (i16, i16), am: (i16, i16), carriers: Carriers) -> Drives {
        let (fa1, fa2) = self.fa;
        // Channel 1's product leaves the multiplier LATENCY toggles after
        // it entered on turn false.
        if self.turn == (LATENCY % 2 == 1) {
            self.fa.0 = self.envelope.output();
        } else {
            self.fa.1 = self.envelope.output();
        }
        if self.turn {
            self.envelope.step(amp.1, am.1);
        } else {
            self.envelope.step(amp.0, am.0);
        }
        self.turn = !self.turn;
        self.drive1.step(fa1, carriers.drive_cos);
        self.drive2.step(fa2, carriers.drive_sin);
        self.reference1.step(fa1, carriers.ref_cos);
        self.reference2.step(fa2, carriers.ref_sin);
        self.output()
    }
}
