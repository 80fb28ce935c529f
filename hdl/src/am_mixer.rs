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
//!
//! Two mixers share this file (`am_mixer!` below). `AmMixer`, the table
//! core's, is the above. `FineAmMixer`, the fine core's, takes the carriers
//! of `crate::sine_pair` in quarter LSB (18 bits, peak 4 x 32767) and its
//! four carrier products are `CarrierMultiplier`s: dac1 = round(round(F1
//! A1 / 2^15) cos4 / 2^17), the carrier never rounded to an integer on its
//! own, and that one rounding's error fed back with zeros at the carrier
//! (`CarrierMultiplier`'s k, 2 cos(2w), from one `NotchCoefficient` on
//! the drive carriers, a bit-serial sum). Same ports otherwise, same
//! latencies; 1 16x16 and 4 16x18 multipliers, and four 9x9 products in
//! LUTs (`crate::small_multiplier`). Why: a rounding at the carrier rate has
//! a pattern that a fold of the clock, of any period, turns into a slow
//! error of drive and reference (docs/field.md, "One rounding" and
//! "Rounding shaped away from the carrier").

use crate::carrier_multiplier::CarrierMultiplier;
use crate::fine_sine_table::OUTPUT_BITS;
use crate::notch_coefficient::NotchCoefficient;
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
// Both mixers' carrier products have the same latency.
const _: () = assert!(crate::carrier_multiplier::LATENCY == crate::q15_multiplier::LATENCY);

/// Declares a pair of AM channels whose carrier products are `$product`
/// (ports `a`, `b`, `y`, latency `q15_multiplier::LATENCY`) on carriers of
/// `$carrier_bits`: the struct, its constructor and its wiring, written
/// once for both cores. With a last argument, the field of that name is a
/// `NotchCoefficient` on the drive carriers whose `k` feeds every product's
/// port `k` (the fine core).
macro_rules! am_mixer {
    ($(#[$meta:meta])* $name:ident, $product:ident, $carrier_bits:tt $(, $notch:ident)?) => {
        $(#[$meta])*
        #[derive(LogicBlock)]
        pub struct $name {
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
            pub drive_cos: Signal<In, Signed<$carrier_bits>>,
            /// Quadrature drive carrier.
            pub drive_sin: Signal<In, Signed<$carrier_bits>>,
            /// In-phase reference carrier.
            pub ref_cos: Signal<In, Signed<$carrier_bits>>,
            /// Quadrature reference carrier.
            pub ref_sin: Signal<In, Signed<$carrier_bits>>,
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
            drive1: $product,
            drive2: $product,
            reference1: $product,
            reference2: $product,
            $($notch: NotchCoefficient,)?
        }

        impl $name {
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
                    drive1: $product::new(),
                    drive2: $product::new(),
                    reference1: $product::new(),
                    reference2: $product::new(),
                    $($notch: NotchCoefficient::new(),)?
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
                $(
                    self.$notch.clock.next = self.clock.val();
                    self.$notch.cos.next = self.drive_cos.val();
                    self.$notch.sin.next = self.drive_sin.val();
                    self.drive1.k.next = self.$notch.k.val();
                    self.drive2.k.next = self.$notch.k.val();
                    self.reference1.k.next = self.$notch.k.val();
                    self.reference2.k.next = self.$notch.k.val();
                )?
            }
        }

        crate::impl_clocked!($name);
    };
}

am_mixer!(
    /// Two AM drive channels with reference copies: the table core's,
    /// 16-bit carriers (`Q15Multiplier`, two roundings).
    AmMixer,
    Q15Multiplier,
    16
);

am_mixer!(
    /// Two AM drive channels with reference copies: the fine core's,
    /// quarter-LSB carriers of `crate::sine_pair` (`CarrierMultiplier`,
    /// one rounding of F A x carrier, its error fed back with zeros at the
    /// carrier).
    FineAmMixer,
    CarrierMultiplier,
    OUTPUT_BITS,
    notch
);

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
    use crate::fine_sine_table::OUTPUT_PEAK;
    use crate::model::am_mixer::{AmMixer as Model, Drives};
    use crate::model::carrier_nco::Carriers;
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use crate::test_util::{sample16, word16};
    use gyrocal_regs::datapath::CarrierProfile;
    use proptest::prelude::*;

    /// Four carrier words within +-`peak`, its extremes and 0 included.
    fn carriers(peak: i32) -> impl Strategy<Value = Carriers> {
        let word = prop_oneof![Just(peak), Just(-peak), Just(0), -peak..=peak];
        (word.clone(), word.clone(), word.clone(), word).prop_map(|(a, b, c, d)| Carriers {
            drive_cos: a,
            drive_sin: b,
            ref_cos: c,
            ref_sin: d,
        })
    }

    /// The RTL mixer `$mixer` against the model of `$profile`, cycle by
    /// cycle, on random envelopes and carriers within +-`$peak`.
    macro_rules! rtl_matches_model {
        ($test:ident, $mixer:ident, $profile:expr, $peak:expr) => {
            proptest! {
                #![proptest_config(ProptestConfig::with_cases(8))]
                #[test]
                fn $test(
                    cycles in prop::collection::vec(((word16(), word16()), (sample16(), sample16()), carriers($peak)), 400),
                ) {
                    let mut uut = $mixer::new();
                    prepare(&mut uut);
                    let mut model = Model::new($profile);
                    for (n, &(amp, am, c)) in cycles.iter().enumerate() {
                        let s = |x: i16| i128_to_signed(x as i128);
                        let w = |x: i32| i128_to_signed(x as i128);
                        uut.amp1.next = s(amp.0);
                        uut.amp2.next = s(amp.1);
                        uut.am1.next = s(am.0);
                        uut.am2.next = s(am.1);
                        uut.drive_cos.next = w(c.drive_cos);
                        uut.drive_sin.next = w(c.drive_sin);
                        uut.ref_cos.next = w(c.ref_cos);
                        uut.ref_sin.next = w(c.ref_sin);
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
        };
    }

    rtl_matches_model!(
        rtl_matches_model_including_full_scale_words,
        AmMixer,
        CarrierProfile::Table,
        32767
    );
    rtl_matches_model!(
        the_fine_mixer_matches_its_model_including_full_scale_words,
        FineAmMixer,
        CarrierProfile::Fine,
        OUTPUT_PEAK
    );

    #[test]
    fn every_register_value_gives_an_in_range_drive() {
        // Drive word = round(round(F A / 2^15) c / 2^(15 + f)) for all F
        // (any 16-bit value) and A within +-32767, c within +-32767 x 2^f
        // (the NCO outputs; f = 0 on the table core, 2 on the fine one):
        // sweep F over all 65536 values against the extreme A and c. The
        // table core's word is that; the fine core's carries its fed-back
        // rounding error, r - k r[n-2] + r[n-4] with |r| <= 1/2 LSB and,
        // for these constant words, k = 2 c^2 / 2^18, nearly 4 in Q2.15:
        // within 3 LSB of it, and saturated to +-32767.
        for profile in CarrierProfile::ALL {
            let feedback = match profile {
                CarrierProfile::Table => 0,
                CarrierProfile::Fine => 3,
            };
            let f = crate::model::am_mixer::carrier_fraction_bits(profile);
            let peak = 32767i64 << f;
            let mut model = Model::new(profile);
            let extremes = [-32767i16, -1, 0, 1, 32767];
            for f_word in i16::MIN..=i16::MAX {
                for &a in &extremes {
                    for c in [-peak, peak] {
                        let exact =
                            |x: i64, y: i64, s: u32| (x * y + (1 << (s - 1))).div_euclid(1 << s);
                        let want = exact(exact(f_word.into(), a.into(), 15), c, 15 + f);
                        assert!((-32767..=32767).contains(&want));
                        let c = c as i32;
                        let carriers = Carriers {
                            drive_cos: c,
                            drive_sin: c,
                            ref_cos: c,
                            ref_sin: c,
                        };
                        let mut out = Drives::default();
                        for _ in 0..AMPLITUDE_LATENCY {
                            out = model.step((f_word, f_word), (a, a), carriers);
                        }
                        let word = i64::from(out.dac1);
                        assert!(
                            (word - want).abs() <= feedback && (-32767..=32767).contains(&word),
                            "{profile}: F {f_word} A {a} c {c}: {word} against {want}"
                        );
                    }
                }
            }
        }
    }
}
