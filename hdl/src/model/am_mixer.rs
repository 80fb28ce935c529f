//! Bit-true model of `crate::am_mixer::AmMixer`.

use super::carrier_nco::Carriers;
use super::q15_multiplier::Q15Multiplier;
use crate::q15_multiplier::LATENCY;

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

/// Cycle-true model of the two AM channels.
#[derive(Clone, Debug, Default)]
pub struct AmMixer {
    envelope: Q15Multiplier,
    /// false: channel 1 enters the envelope multiplier; true: channel 2.
    turn: bool,
    fa: (i16, i16),
    drive1: Q15Multiplier,
    drive2: Q15Multiplier,
    reference1: Q15Multiplier,
    reference2: Q15Multiplier,
}

impl AmMixer {
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
