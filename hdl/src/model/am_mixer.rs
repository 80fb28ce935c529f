//! Bit-true model of `crate::am_mixer::AmMixer` and
//! `crate::am_mixer::FineAmMixer`.

use super::carrier_nco::Carriers;
use super::delay_ring::{latch_alternate, latch_alternate_block};
use super::notch_coefficient::NotchCoefficient;
use super::q15_multiplier::{Q15Multiplier, product_in_flight, product_skip};
use crate::carrier_multiplier::{FEEDBACK_SCALE, RESIDUE_DROP, SHIFT, WORD_LIMIT};
use crate::fine_sine_table::OUTPUT_FRACTION_BITS;
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

/// Cycle-true model of a carrier product: `crate::q15_multiplier` (the
/// table core's 16-bit carriers: factor, product and rounding registers),
/// `round(a c / 2^15)` rounded half up; or `crate::carrier_multiplier`
/// (the fine core's quarter-LSB carriers: product, rounding and
/// saturation registers), `a c / 2^17` rounded half up with its rounding
/// error fed back through `1 - k z^-2 + z^-4` (`k` from
/// `crate::notch_coefficient`).
#[derive(Clone, Copy, Debug)]
pub struct CarrierMultiplier {
    factors: (i16, i32),
    product: i64,
    /// The fine core's error feedback: `k` times the residue of two
    /// cycles back without its low `RESIDUE_DROP` bits (the feedback
    /// product's register), ...
    feedback: i64,
    /// ... the residues u - 2^17 y of the last three cycles, newest
    /// first, ...
    residues: [i32; 3],
    /// ... 2^16 minus the residue of four cycles back ...
    offset: i32,
    /// ... and the word before saturation.
    word: i64,
    y: i16,
    shaped: bool,
}

impl CarrierMultiplier {
    /// The product for carriers with `fraction_bits` below the LSB: the
    /// table core's (0) or the fine core's (`OUTPUT_FRACTION_BITS`).
    pub fn new(fraction_bits: u32) -> Self {
        assert!(
            fraction_bits == 0 || fraction_bits == OUTPUT_FRACTION_BITS,
            "carrier fraction bits {fraction_bits}: the cores have 0 or {OUTPUT_FRACTION_BITS}"
        );
        Self {
            factors: (0, 0),
            product: 0,
            feedback: 0,
            residues: [0; 3],
            offset: 1 << (SHIFT - 1),
            word: 0,
            y: 0,
            shaped: fraction_bits != 0,
        }
    }

    /// `y` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> i16 {
        self.y
    }

    /// One clock with the notch coefficient `k` (unused by the table
    /// core's product); returns `y` after the edge.
    #[inline(always)]
    pub fn step(&mut self, a: i16, c: i32, k: i32) -> i16 {
        if self.shaped {
            self.shape(k);
            self.product = i64::from(a) * i64::from(c);
        } else {
            self.y = round_product(self.product);
            self.product = table_multiply(self.factors);
            self.factors = (a, c);
        }
        self.y
    }

    /// The table core's `y` during cycle `k` < 3 of a block, from the
    /// registers (`super::q15_multiplier::product_in_flight`).
    #[inline(always)]
    fn in_flight(&self, k: usize) -> i16 {
        let held = (self.factors, self.product, self.y);
        product_in_flight(held, k, table_multiply, round_product)
    }

    /// The table core's registers after `m` edges with `input(k)` (a, c)
    /// at edge k (`super::q15_multiplier::product_skip`).
    /// `AmMixer::block` computes the words of the cycles between for the
    /// four products at once.
    #[inline(always)]
    fn skip(&mut self, m: usize, input: impl Fn(usize) -> (i16, i32)) {
        debug_assert!(!self.shaped);
        let registers = (&mut self.factors, &mut self.product, &mut self.y);
        product_skip(registers, m, input, table_multiply, round_product);
    }

    /// The fine core's rounding and saturation stages and its feedback
    /// registers.
    #[inline(always)]
    fn shape(&mut self, k: i32) {
        self.y = self.word.clamp(-WORD_LIMIT, WORD_LIMIT) as i16;
        // rounded = u + 2^16 = p + 8 k (r[n-2] >> 8) + 2^16 - r[n-4].
        let rounded = self.product + (self.feedback << FEEDBACK_SCALE) + i64::from(self.offset);
        self.word = rounded >> SHIFT;
        // r = u - 2^17 round(u / 2^17): the low 17 bits of u, signed.
        let low = (rounded as i32) & ((1 << SHIFT) - 1);
        let residue = ((low ^ (1 << (SHIFT - 1))) << (32 - SHIFT)) >> (32 - SHIFT);
        self.feedback = i64::from(k) * i64::from(self.residues[0] >> RESIDUE_DROP);
        self.offset = (1 << (SHIFT - 1)) - self.residues[2];
        self.residues = [residue, self.residues[0], self.residues[1]];
    }
}

/// The envelope multiplier's product into the F A it belongs to, at an
/// edge of `turn` (`latch_alternate`).
#[inline(always)]
fn latch(fa: &mut (i16, i16), turn: bool, product: i16) {
    latch_alternate(fa, turn, LATENCY, product);
}

/// The table core's product register's word.
#[inline(always)]
fn table_multiply((a, c): (i16, i32)) -> i64 {
    i64::from(a) * i64::from(c)
}

/// `round(p / 2^15)`, rounded half up, the table core's one shift: |p| <
/// 2^33 and the result within 16 bits for every product of the mixers
/// (`crate::am_mixer`).
#[inline(always)]
fn round_product(p: i64) -> i16 {
    ((p + (1 << 14)) >> 15) as i16
}

/// The DAC or reference word of the core with this profile for the
/// envelope F A `a` and the carrier word `c` (`Carriers`' scale), as the
/// carrier sees it, without the pipeline: on the table core the word
/// itself, `a c / 2^15` rounded half up; on the fine core the exact `a c /
/// 2^17`, since its rounding error is fed back with zeros at the carrier
/// and none of it stays at the carrier's frequency.
pub fn carrier_product(profile: CarrierProfile, a: i16, c: i32) -> f64 {
    let p = i64::from(a) * i64::from(c);
    match profile {
        CarrierProfile::Table => f64::from(round_product(p)),
        CarrierProfile::Fine => p as f64 / f64::from(1 << SHIFT),
    }
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
    /// The fine core's notch coefficient (`None` on the table core).
    notch: Option<NotchCoefficient>,
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
            notch: match profile {
                CarrierProfile::Table => None,
                CarrierProfile::Fine => Some(NotchCoefficient::default()),
            },
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
        latch(&mut self.fa, self.turn, self.envelope.output());
        if self.turn {
            self.envelope.step(amp.1, am.1);
        } else {
            self.envelope.step(amp.0, am.0);
        }
        self.turn = !self.turn;
        let k = match &mut self.notch {
            Some(notch) => {
                let k = notch.output();
                notch.step(carriers.drive_cos, carriers.drive_sin);
                k
            }
            None => 0,
        };
        self.drive1.step(fa1, carriers.drive_cos, k);
        self.drive2.step(fa2, carriers.drive_sin, k);
        self.reference1.step(fa1, carriers.ref_cos, k);
        self.reference2.step(fa2, carriers.ref_sin, k);
        self.output()
    }

    /// The four carrier products of a block (`block`), the table core's:
    /// the words in flight, then from cycle 3 on the four products of the
    /// F A and the carriers of three cycles before, rounded together.
    /// Table carriers are 16-bit words, so a product and its rounding
    /// bias stay within i32 (2^30 + 2^14), which `round_product`'s i64
    /// gives the same; in i32 the pass is 2% faster with the gyroscope.
    #[inline(always)]
    fn products_block(&mut self, fa: &[(i16, i16)], carriers: &[Carriers], out: &mut [Drives]) {
        let m = out.len();
        for (k, o) in out.iter_mut().enumerate().take(3) {
            *o = Drives {
                dac1: self.drive1.in_flight(k),
                dac2: self.drive2.in_flight(k),
                ref1: self.reference1.in_flight(k),
                ref2: self.reference2.in_flight(k),
            };
        }
        let round = |a: i16, c: i32| ((i32::from(a) * c + (1 << 14)) >> 15) as i16;
        for ((o, f), c) in out.iter_mut().skip(3).zip(fa).zip(carriers) {
            *o = Drives {
                dac1: round(f.0, c.drive_cos),
                dac2: round(f.1, c.drive_sin),
                ref1: round(f.0, c.ref_cos),
                ref2: round(f.1, c.ref_sin),
            };
        }
        self.drive1.skip(m, |k| (fa[k].0, carriers[k].drive_cos));
        self.drive2.skip(m, |k| (fa[k].1, carriers[k].drive_sin));
        self.reference1.skip(m, |k| (fa[k].0, carriers[k].ref_cos));
        self.reference2.skip(m, |k| (fa[k].1, carriers[k].ref_sin));
    }

    /// True when `block` may play the next clocks: the table core.
    #[inline(always)]
    pub fn blocks(&self) -> bool {
        self.notch.is_none()
    }

    /// The outputs during the next `out.len()` cycles, then as many edges
    /// with `amp` held, `am[k]` and `carriers[k]` the inputs during cycle
    /// k: `output` and `step` clock by clock, where `blocks()`. In passes
    /// over chunks of the block: the envelope multiplier, the latching of
    /// F A by channel, then the four carrier products together.
    #[inline(always)]
    pub fn block(
        &mut self,
        amp: (i16, i16),
        am: &[(i16, i16)],
        carriers: &[Carriers],
        out: &mut [Drives],
    ) {
        debug_assert!(self.blocks());
        const CHUNK: usize = 64;
        let mut envelope = [0i16; CHUNK];
        let mut fa = [(0i16, 0i16); CHUNK];
        for ((out, am), carriers) in out
            .chunks_mut(CHUNK)
            .zip(am.chunks(CHUNK))
            .zip(carriers.chunks(CHUNK))
        {
            let m = out.len();
            let turn = self.turn;
            let channel = |k: usize| turn ^ (k % 2 == 1);
            // The channel alternates: picked by index, not by a branch.
            self.envelope.block(&mut envelope[..m], |k| {
                let c = usize::from(channel(k));
                ([amp.0, amp.1][c], [am[k].0, am[k].1][c])
            });
            // F A latches alternate too.
            latch_alternate_block(&mut self.fa, turn, LATENCY, &envelope[..m], &mut fa[..m]);
            self.turn = channel(m);
            self.products_block(&fa[..m], carriers, out);
        }
    }
}
