//! `StatusCounters`: the sources of the bus top's status words: the sample
//! and overflow counters, the coherent z snapshot, the two ADC clip
//! counters; and the stream beat.
//!
//! ```text
//!  z_valid ──► count = sample_count + z_valid ──► sample_count <= count   (SAMPLE_COUNT)
//!  dropped ──► overflow_count <= overflow_count + 1                        (STREAM_OVERFLOW)
//!  snapshot ─► snapshot_z1, snapshot_z2 <= z1, z2   (the edge that returns count)
//!              z1_low, z1_high, z2_low, z2_high = their bits 31..0, 39..32 (Z1_LO..Z2_HI)
//!  adc1, adc2, clip_clear ──► ClipCounter x2 ──► clip = {count2, count1}   (ADC_CLIP)
//!  beat = {count[15:0], z2, z1}                       (96 bits, to the stream FIFO)
//! ```
//!
//! Widths: z 40-bit two's complement (8 fractional bits), counts 32 bits
//! (wrapping), clip counts 16 bits (saturating), beat 96 bits. `count`
//! during a `z_valid` clock includes that sample, whose z the core's ports
//! hold during that clock, so a read of SAMPLE_COUNT at that edge
//! (`snapshot`) latches exactly the sample it counts. `reset` (active
//! high, synchronous) zeroes the counts and the snapshot. Cost: 176
//! flip-flops, two 32-bit and two 16-bit incrementers.

use super::clip_counter::{COUNT_BITS, ClipCount, ClipCounter, clip_word};
use super::register_map::DATA_BITS;
use super::sample_fifo::SAMPLE_BITS;
use super::{Z_BITS, Z_MASK};
use rust_hdl::prelude::*;

const _: () = assert!(Z_BITS == 40 && SAMPLE_BITS == 2 * Z_BITS + 16 && COUNT_BITS == 16);

/// The status words' counters, the z snapshot and the stream beat.
#[derive(LogicBlock)]
pub struct StatusCounters {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset of the counts and the snapshot (active high).
    pub reset: Signal<In, Bit>,
    /// The core's z1.
    pub z1: Signal<In, Signed<Z_BITS>>,
    /// The core's z2.
    pub z2: Signal<In, Signed<Z_BITS>>,
    /// The core publishes a new z during this clock.
    pub z_valid: Signal<In, Bit>,
    /// The stream FIFO drops a sample at this edge.
    pub dropped: Signal<In, Bit>,
    /// Latch z1 and z2 at this edge (the read of SAMPLE_COUNT).
    pub snapshot: Signal<In, Bit>,
    /// ADC word 1, for its clip counter.
    pub adc1: Signal<In, Signed<16>>,
    /// ADC word 2, for its clip counter.
    pub adc2: Signal<In, Signed<16>>,
    /// Restart the clip counts at this edge (the read of ADC_CLIP).
    pub clip_clear: Signal<In, Bit>,
    /// Samples published, this clock's included (SAMPLE_COUNT).
    pub count: Signal<Out, Bits<DATA_BITS>>,
    /// Samples the stream dropped (STREAM_OVERFLOW).
    pub overflow: Signal<Out, Bits<DATA_BITS>>,
    /// z1 at the last snapshot, bits 31..0 (Z1_LO).
    pub z1_low: Signal<Out, Bits<DATA_BITS>>,
    /// z1 at the last snapshot, bits 39..32 zero-extended (Z1_HI; the
    /// status word sign-extends its 8-bit field).
    pub z1_high: Signal<Out, Bits<DATA_BITS>>,
    /// z2 at the last snapshot, bits 31..0 (Z2_LO).
    pub z2_low: Signal<Out, Bits<DATA_BITS>>,
    /// z2 at the last snapshot, bits 39..32 zero-extended (Z2_HI).
    pub z2_high: Signal<Out, Bits<DATA_BITS>>,
    /// Clipped clocks of ADC1 (bits 15..0) and ADC2 (31..16) (ADC_CLIP).
    pub clip: Signal<Out, Bits<DATA_BITS>>,
    /// The stream beat {count\[15:0\], z2, z1}.
    pub beat: Signal<Out, Bits<SAMPLE_BITS>>,
    clip_counters: [ClipCounter; 2],
    sample_count: DFF<Bits<DATA_BITS>>,
    overflow_count: DFF<Bits<DATA_BITS>>,
    snapshot_z1: DFF<Bits<Z_BITS>>,
    snapshot_z2: DFF<Bits<Z_BITS>>,
    z1_bits: Signal<Local, Bits<Z_BITS>>,
    z2_bits: Signal<Local, Bits<Z_BITS>>,
    count_now: Signal<Local, Bits<DATA_BITS>>,
}

impl StatusCounters {
    /// Counts and snapshot at 0.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            reset: Default::default(),
            z1: Default::default(),
            z2: Default::default(),
            z_valid: Default::default(),
            dropped: Default::default(),
            snapshot: Default::default(),
            adc1: Default::default(),
            adc2: Default::default(),
            clip_clear: Default::default(),
            count: Default::default(),
            overflow: Default::default(),
            z1_low: Default::default(),
            z1_high: Default::default(),
            z2_low: Default::default(),
            z2_high: Default::default(),
            clip: Default::default(),
            beat: Default::default(),
            clip_counters: Default::default(),
            sample_count: Default::default(),
            overflow_count: Default::default(),
            snapshot_z1: Default::default(),
            snapshot_z2: Default::default(),
            z1_bits: Default::default(),
            z2_bits: Default::default(),
            count_now: Default::default(),
        }
    }
}

impl Default for StatusCounters {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for StatusCounters {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            sample_count,
            overflow_count,
            snapshot_z1,
            snapshot_z2
        );
        self.z1_bits.next = unsigned_cast(self.z1.val());
        self.z2_bits.next = unsigned_cast(self.z2.val());
        self.count_now.next = self.sample_count.q.val();
        if self.z_valid.val() {
            self.count_now.next = self.sample_count.q.val() + 1;
        }
        self.sample_count.d.next = self.count_now.val();
        if self.dropped.val() {
            self.overflow_count.d.next = self.overflow_count.q.val() + 1;
        }
        if self.snapshot.val() {
            self.snapshot_z1.d.next = self.z1_bits.val();
            self.snapshot_z2.d.next = self.z2_bits.val();
        }
        self.count.next = self.count_now.val();
        self.overflow.next = self.overflow_count.q.val();
        self.z1_low.next = self.snapshot_z1.q.val().get_bits::<DATA_BITS>(0);
        self.z1_high.next = bit_cast::<DATA_BITS, 8>(self.snapshot_z1.q.val().get_bits::<8>(32));
        self.z2_low.next = self.snapshot_z2.q.val().get_bits::<DATA_BITS>(0);
        self.z2_high.next = bit_cast::<DATA_BITS, 8>(self.snapshot_z2.q.val().get_bits::<8>(32));
        self.clip_counters[0].adc.next = self.adc1.val();
        self.clip_counters[1].adc.next = self.adc2.val();
        for i in 0..2 {
            self.clip_counters[i].clock.next = self.clock.val();
            self.clip_counters[i].reset.next = self.reset.val();
            self.clip_counters[i].clear.next = self.clip_clear.val();
        }
        // Over-range counts of ADC1 (bits 15..0) and ADC2 (31..16), 16 = COUNT_BITS.
        self.clip.next = bit_cast::<DATA_BITS, COUNT_BITS>(self.clip_counters[0].count.val())
            | (bit_cast::<DATA_BITS, COUNT_BITS>(self.clip_counters[1].count.val()) << 16);
        // Shifts by Z_BITS = 40 and 2 Z_BITS = 80 (literals: #[hdl_gen] takes no const).
        self.beat.next = bit_cast::<SAMPLE_BITS, Z_BITS>(self.z1_bits.val())
            | (bit_cast::<SAMPLE_BITS, Z_BITS>(self.z2_bits.val()) << 40)
            | (bit_cast::<SAMPLE_BITS, 16>(self.count_now.val().get_bits::<16>(0)) << 80);
        if self.reset.val() {
            self.sample_count.d.next = 0.into();
            self.overflow_count.d.next = 0.into();
            self.snapshot_z1.d.next = 0.into();
            self.snapshot_z2.d.next = 0.into();
        }
    }
}

crate::impl_clocked!(StatusCounters);

/// The inputs of `StatusCounters` during one cycle (its ports but the
/// clock and reset).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StatusInputs {
    /// The core's z1, z2.
    pub z: (i64, i64),
    /// The core publishes `z` during this clock.
    pub z_valid: bool,
    /// The stream FIFO drops a sample at this edge.
    pub dropped: bool,
    /// Latch `z` at this edge (the read of SAMPLE_COUNT).
    pub snapshot: bool,
    /// The ADC words.
    pub adc: (i16, i16),
    /// Restart the clip counts at this edge (the read of ADC_CLIP).
    pub clip_clear: bool,
}

/// What `StatusCounters` shows the status words during one cycle: its
/// `overflow`, `count`, `z1_low`, `z1_high`, `z2_low`, `z2_high` and
/// `clip` ports (the z snapshot's 40 bits as a low word and the high
/// byte).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CounterWords {
    /// STREAM_OVERFLOW.
    pub overflow: u32,
    /// SAMPLE_COUNT.
    pub count: u32,
    /// Z1_LO.
    pub z1_low: u32,
    /// Z1_HI (8 bits).
    pub z1_high: u32,
    /// Z2_LO.
    pub z2_low: u32,
    /// Z2_HI (8 bits).
    pub z2_high: u32,
    /// ADC_CLIP.
    pub clip: u32,
}

/// Bit-true model of `StatusCounters`: its registers, an edge at a time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    sample_count: u32,
    overflow_count: u32,
    /// z1, z2 at the last snapshot, as their 40 bits.
    snapshot: (u64, u64),
    clip: [ClipCount; 2],
}

impl Counters {
    /// SAMPLE_COUNT during the current cycle (`count`), this cycle's
    /// sample included when `z_valid`.
    pub fn count(&self, z_valid: bool) -> u32 {
        self.sample_count.wrapping_add(u32::from(z_valid))
    }

    /// The words the block shows the status words during the current
    /// cycle, this cycle's sample counted when `z_valid`.
    pub fn words(&self, z_valid: bool) -> CounterWords {
        let (z1, z2) = self.snapshot;
        CounterWords {
            overflow: self.overflow_count,
            count: self.count(z_valid),
            z1_low: z1 as u32,
            z1_high: (z1 >> DATA_BITS) as u32,
            z2_low: z2 as u32,
            z2_high: (z2 >> DATA_BITS) as u32,
            clip: clip_word(self.clip),
        }
    }

    /// The stream beat {count\[15:0\], z2, z1} of a cycle with the core's
    /// `z` and `z_valid`.
    pub fn beat(&self, z: (i64, i64), z_valid: bool) -> u128 {
        let bits = |v: i64| u128::from(v as u64 & Z_MASK);
        let count = u128::from(self.count(z_valid) & 0xffff);
        bits(z.0) | (bits(z.1) << Z_BITS) | (count << (2 * Z_BITS))
    }

    /// One edge with this cycle's inputs.
    pub fn step(&mut self, i: &StatusInputs) {
        self.sample_count = self.count(i.z_valid);
        if i.dropped {
            self.overflow_count = self.overflow_count.wrapping_add(1);
        }
        if i.snapshot {
            self.snapshot = (i.z.0 as u64 & Z_MASK, i.z.1 as u64 & Z_MASK);
        }
        self.clip[0].step(i.adc.0, i.clip_clear);
        self.clip[1].step(i.adc.1, i.clip_clear);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::test_util::Rng;

    /// The block against its model: random z near the rails, strobes,
    /// drops, rail-heavy ADC words, clears and rare resets; every output
    /// every clock (the counts pass 2^16, where the beat keeps 16 bits).
    #[test]
    fn the_counters_match_their_model() {
        let mut uut = StatusCounters::new();
        prepare(&mut uut);
        let mut model = Counters::default();
        let mut rng = Rng::new(23);
        let z_max = (1i64 << (Z_BITS - 1)) - 1;
        let mut most = 0;
        for cycle in 0..100_000 {
            let r = rng.next_u64();
            let z = |k: u64| match k % 4 {
                0 => z_max,
                1 => -z_max - 1,
                // Any 40-bit word: the low 40 bits of r rotated, sign-extended.
                _ => (r.rotate_left(k as u32 % 64) << 24) as i64 >> 24,
            };
            let z = (z(r >> 8), z(r >> 10));
            let (z_valid, dropped, snapshot) = (r & 3 != 0, r >> 1 & 7 == 0, r >> 4 & 7 == 0);
            let adc = |k: u64| match k % 4 {
                0 => i16::MAX,
                1 => i16::MIN,
                _ => (k >> 2) as i16,
            };
            let adc = (adc(r >> 16), adc(r >> 36));
            let (clip_clear, reset) = (r >> 60 == 0, cycle == 95_000);
            uut.z1.next = z.0.into();
            uut.z2.next = z.1.into();
            uut.z_valid.next = z_valid;
            uut.dropped.next = dropped;
            uut.snapshot.next = snapshot;
            uut.adc1.next = i64::from(adc.0).into();
            uut.adc2.next = i64::from(adc.1).into();
            uut.clip_clear.next = clip_clear;
            uut.reset.next = reset;
            crate::drive::settle(&mut uut);
            let want = model.words(z_valid);
            let words = [
                (uut.count.val().index() as u32, want.count),
                (uut.overflow.val().index() as u32, want.overflow),
                (uut.z1_low.val().index() as u32, want.z1_low),
                (uut.z1_high.val().index() as u32, want.z1_high),
                (uut.z2_low.val().index() as u32, want.z2_low),
                (uut.z2_high.val().index() as u32, want.z2_high),
                (uut.clip.val().index() as u32, want.clip),
            ];
            for (n, (got, want)) in words.into_iter().enumerate() {
                assert_eq!(got, want, "cycle {cycle}, word {n}");
            }
            let beat = uut.beat.val();
            let beat = (0..3)
                .map(|k| (beat.get_bits::<32>(32 * k).index() as u128) << (32 * k))
                .sum::<u128>();
            assert_eq!(beat, model.beat(z, z_valid), "cycle {cycle}");
            tick(&mut uut);
            model.step(&StatusInputs {
                z,
                z_valid,
                dropped,
                snapshot,
                adc,
                clip_clear,
            });
            most = most.max(model.count(false));
            if reset {
                model = Counters::default();
            }
        }
        assert!(most > 1 << 16, "the count never passed 2^16: {most}");
    }
}
