//! AM mixers: the two drive signals and their reference copies.
//!
//! ```text
//!  turn 0: F1, A1 ─┐                              ┌─► x drive_cos ──► dac1 = F1 A1 cos(wt)
//!  turn 1: F2, A2 ─┴─ x ──► fa1 (held, turn 0) ───┤
//!       (one envelope      └► fa2 (held, turn 1) ─┼─► x ref_cos   ──► ref1 = F1 A1 cos(wt + offset)
//!        multiplier)                              ├─► x drive_sin ──► dac2 = F2 A2 sin(wt)
//!                                                 └─► x ref_sin   ──► ref2 = F2 A2 sin(wt + offset)
//! ```
//!
//! Every product is a `Q15Multiplier`: Q1.15 factors, rounded half up to
//! 16 bits. F1 and F2 are run-time amplitudes (any 16-bit value, -32768
//! included); A1, A2 come from the modulation NCO and the carriers from the
//! carrier NCO, all with peak 32767, so no product can overflow (see
//! `q15_multiplier`) and the DAC words stay within [-32767, 32767]:
//! dac1 = round(round(F1 A1 / 2^15) cos / 2^15), a full-scale drive being
//! F1 = 32767 with A1 = 32767.
//!
//! The envelopes F A move only with a bus write or the modulation (f_cal,
//! hertz against a clock of tens of megahertz), so one multiplier serves
//! both channels on alternate clocks: a `turn` bit (power-up 0, toggled
//! every clock) picks channel 1 on turn 0 and channel 2 on turn 1, and the
//! product is held in fa1 or fa2 when it comes out `LATENCY` clocks later.
//! Each envelope is therefore a two-clock hold of its products, the two
//! channels' on alternate clocks. The modulation NCO staggers A1 and A2 the
//! same way, so each channel's multiplier takes its A one clock after the
//! NCO refreshed it: both envelopes lag their modulation phase by the same
//! number of clocks, and both holds add the same mean delay. Drive and
//! reference of one channel share the held word, so the alignment of the
//! references to the drives (`crate::settings`) is untouched.
//!
//! The reference words are the drive words computed from the reference
//! carrier: in readout they equal the drives up to the phase offset, in
//! calibration they carry the same modulation. Latency: carriers to outputs
//! 3 clocks (`q15_multiplier::LATENCY`), amplitudes to outputs 7 or 8
//! clocks (product, hold, product, and a clock's wait when the other
//! channel has the multiplier), the same for drives and references.
//! Resources: 5 16x16 multipliers.

use crate::q15_multiplier::Q15Multiplier;
use rust_hdl::prelude::*;

/// Clock cycles from the carrier inputs to the drive and reference outputs.
pub const CARRIER_LATENCY: usize = crate::q15_multiplier::LATENCY;
/// Clock cycles from the amplitudes and modulation factors to the outputs,
/// at most: two products, the hold register, and one clock's wait for the
/// shared envelope multiplier.
pub const AMPLITUDE_LATENCY: usize = 2 * crate::q15_multiplier::LATENCY + 2;
/// The `turn` during which the envelope product of channel 1 leaves the
/// multiplier: it entered on turn 0, `LATENCY` toggles earlier.
const CHANNEL1_OUT_TURN: bool = crate::q15_multiplier::LATENCY % 2 == 1;

/// Two AM drive channels with reference copies.
#[derive(LogicBlock)]
pub struct AmMixer {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Drive amplitude F1 of mode 1, Q1.15.
    pub amp1: Signal<In, Signed<16>>,
    /// Drive amplitude F2 of mode 2, Q1.15.
    pub amp2: Signal<In, Signed<16>>,
    /// Amplitude factor A1 from the modulation NCO.
    pub am1: Signal<In, Signed<16>>,
    /// Amplitude factor A2 from the modulation NCO.
    pub am2: Signal<In, Signed<16>>,
    /// In-phase drive carrier.
    pub drive_cos: Signal<In, Signed<16>>,
    /// Quadrature drive carrier.
    pub drive_sin: Signal<In, Signed<16>>,
    /// In-phase reference carrier.
    pub ref_cos: Signal<In, Signed<16>>,
    /// Quadrature reference carrier.
    pub ref_sin: Signal<In, Signed<16>>,
    /// DAC word of drive 1: F1 A1 cos.
    pub dac1: Signal<Out, Signed<16>>,
    /// DAC word of drive 2: F2 A2 sin.
    pub dac2: Signal<Out, Signed<16>>,
    /// Reference copy of drive 1, from the reference carrier.
    pub ref1: Signal<Out, Signed<16>>,
    /// Reference copy of drive 2, from the reference carrier.
    pub ref2: Signal<Out, Signed<16>>,
    envelope: Q15Multiplier,
    turn: DFF<Bit>,
    fa1: DFF<Signed<16>>,
    fa2: DFF<Signed<16>>,
    channel1_out_turn: Constant<Bit>,
    drive1: Q15Multiplier,
    drive2: Q15Multiplier,
    reference1: Q15Multiplier,
    reference2: Q15Multiplier,
}

impl AmMixer {
    /// The two AM channels.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            amp1: Default::default(),
            amp2: Default::default(),
            am1: Default::default(),
            am2: Default::default(),
            drive_cos: Default::default(),
            drive_sin: Default::default(),
            ref_cos: Default::default(),
            ref_sin: Default::default(),
            dac1: Default::default(),
            dac2: Default::default(),
            ref1: Default::default(),
            ref2: Default::default(),
            envelope: Q15Multiplier::new(),
            turn: Default::default(),
            fa1: Default::default(),
            fa2: Default::default(),
            channel1_out_turn: Constant::new(CHANNEL1_OUT_TURN),
            drive1: Q15Multiplier::new(),
            drive2: Q15Multiplier::new(),
            reference1: Q15Multiplier::new(),
            reference2: Q15Multiplier::new(),
        }
    }
}

impl Default for AmMixer {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for AmMixer {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, turn, fa1, fa2);
        self.envelope.clock.next = self.clock.val();
        self.drive1.clock.next = self.clock.val();
        self.drive2.clock.next = self.clock.val();
        self.reference1.clock.next = self.clock.val();
        self.reference2.clock.next = self.clock.val();
        // One envelope multiplier, channel 1 on turn 0, channel 2 on turn 1.
        self.turn.d.next = !self.turn.q.val();
        self.envelope.a.next = self.amp1.val();
        self.envelope.b.next = self.am1.val();
        if self.turn.q.val() {
            self.envelope.a.next = self.amp2.val();
            self.envelope.b.next = self.am2.val();
        }
        if self.turn.q.val() == self.channel1_out_turn.val() {
            self.fa1.d.next = self.envelope.y.val();
        } else {
            self.fa2.d.next = self.envelope.y.val();
        }
        self.drive1.a.next = self.fa1.q.val();
        self.drive1.b.next = self.drive_cos.val();
        self.drive2.a.next = self.fa2.q.val();
        self.drive2.b.next = self.drive_sin.val();
        self.reference1.a.next = self.fa1.q.val();
        self.reference1.b.next = self.ref_cos.val();
        self.reference2.a.next = self.fa2.q.val();
        self.reference2.b.next = self.ref_sin.val();
        self.dac1.next = self.drive1.y.val();
        self.dac2.next = self.drive2.y.val();
        self.ref1.next = self.reference1.y.val();
        self.ref2.next = self.reference2.y.val();
    }
}

crate::impl_clocked!(AmMixer);

/// Mutation hooks for the negative control in `crate::rtl` (tests only).
#[cfg(test)]
impl AmMixer {
    #[doc(hidden)]
    pub fn mutate_drive_rounding(&mut self) {
        self.drive1.mutate_rounding();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::am_mixer::{AmMixer as Model, Drives};
    use crate::model::carrier_nco::Carriers;
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use crate::test_util::{sample16, word16};
    use proptest::prelude::*;

    fn carriers() -> impl Strategy<Value = Carriers> {
        (sample16(), sample16(), sample16(), sample16()).prop_map(|(a, b, c, d)| Carriers {
            drive_cos: a,
            drive_sin: b,
            ref_cos: c,
            ref_sin: d,
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(8))]
        #[test]
        fn rtl_matches_model_including_full_scale_words(
            cycles in prop::collection::vec(((word16(), word16()), (sample16(), sample16()), carriers()), 400),
        ) {
            let mut uut = AmMixer::new();
            prepare(&mut uut);
            let mut model = Model::default();
            for (n, &(amp, am, c)) in cycles.iter().enumerate() {
                let s = |x: i16| i128_to_signed(x as i128);
                uut.amp1.next = s(amp.0);
                uut.amp2.next = s(amp.1);
                uut.am1.next = s(am.0);
                uut.am2.next = s(am.1);
                uut.drive_cos.next = s(c.drive_cos);
                uut.drive_sin.next = s(c.drive_sin);
                uut.ref_cos.next = s(c.ref_cos);
                uut.ref_sin.next = s(c.ref_sin);
                tick(&mut uut);
                let v = |x: Signed<16>| signed_to_i128(x) as i16;
                let hw = Drives {
                    dac1: v(uut.dac1.val()),
                    dac2: v(uut.dac2.val()),
                    ref1: v(uut.ref1.val()),
                    ref2: v(uut.ref2.val()),
                };
                prop_assert_eq!(hw, model.step(amp, am, c), "cycle {}", n);
            }
        }
    }

    #[test]
    fn every_register_value_gives_an_in_range_drive() {
        // Drive word = round(round(F A / 2^15) c / 2^15) for all F (any
        // 16-bit value) and A, c within +-32767 (the NCO outputs): sweep F
        // over all 65536 values against the extreme A and c.
        let mut model = Model::default();
        let extremes = [-32767i16, -1, 0, 1, 32767];
        for f in i16::MIN..=i16::MAX {
            for &a in &extremes {
                for &c in &[-32767i16, 32767] {
                    let exact = |x: i64, y: i64| (x * y + (1 << 14)).div_euclid(1 << 15);
                    let want = exact(exact(f as i64, a as i64), c as i64);
                    assert!((-32767..=32767).contains(&want));
                    let carriers = Carriers {
                        drive_cos: c,
                        drive_sin: c,
                        ref_cos: c,
                        ref_sin: c,
                    };
                    let mut out = Drives::default();
                    for _ in 0..AMPLITUDE_LATENCY {
                        out = model.step((f, f), (a, a), carriers);
                    }
                    assert_eq!(out.dac1 as i64, want, "F {f} A {a} c {c}");
                }
            }
        }
    }
}
