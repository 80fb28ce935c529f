//! `ClipCounter`: clocks on which one ADC word sat at a rail, for the
//! `ADC_CLIP` status word.
//!
//! ```text
//!  adc ──► high = adc[15:8]
//!          at_rail = (high == 8'h7f) | (high == 8'h80)
//!  count <= clear ? at_rail : (count == 65535 ? 65535 : count + at_rail)
//! ```
//!
//! 16-bit saturating count, power-up 0, synchronous `reset` to 0. `clear`
//! is the bus read of `ADC_CLIP`: the read returns `count` as it is during
//! that clock, and a rail code sampled at the same edge starts the next
//! count, so every clipped clock is reported by exactly one read (until the
//! count saturates).
//!
//! The ADC words are left-justified: a converter of b bits fills the top b
//! bits and leaves the rest 0, so its positive rail is 32768 - 2^(16-b),
//! +32767 only at 16 bits (+32752 at 12). A word counts as at a rail when
//! it lies within 1/128 of full scale (`RAIL_HIGH_BYTES`: its top byte
//! 0x7f or 0x80), which holds every rail code of every converter of
//! `MIN_CONVERTER_BITS` (8) to 16 bits; a compare with +32767 never saw a
//! 12-bit converter clip high. On a 16-bit converter the band is its last
//! 256 codes: above the 0.95 of full scale the host plans its peaks at,
//! and nearer the rail than any measurement stays linear to with
//! certainty. Cost: 16 flip-flops, a 16-bit incrementer and two 8-bit
//! compares.

use rust_hdl::prelude::*;

/// Width of the count.
pub const COUNT_BITS: usize = 16;
/// The count saturates here.
pub const COUNT_MAX: u64 = (1 << COUNT_BITS) - 1;
/// The top bytes of a word at a rail (positive, negative): the words
/// +32512..=+32767 and -32768..=-32513.
pub const RAIL_HIGH_BYTES: [u8; 2] = [0x7f, 0x80];
/// The narrowest converter whose rail codes all lie in that band: its
/// positive rail, 32768 - 2^(16-8) = +32512, has the top byte 0x7f.
pub const MIN_CONVERTER_BITS: u32 = 8;

/// One ADC's clip counter.
#[derive(LogicBlock)]
pub struct ClipCounter {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset of the count (active high).
    pub reset: Signal<In, Bit>,
    /// The ADC word of this clock.
    pub adc: Signal<In, Signed<16>>,
    /// The count is read at this edge: restart it.
    pub clear: Signal<In, Bit>,
    /// Clipped clocks since the last clear (saturating).
    pub count: Signal<Out, Bits<COUNT_BITS>>,
    counter: DFF<Bits<COUNT_BITS>>,
    top: Constant<Signed<8>>,
    bottom: Constant<Signed<8>>,
    full: Constant<Bits<COUNT_BITS>>,
    /// The word's top byte (a signed local: only compared for equality).
    high: Signal<Local, Signed<8>>,
    at_rail: Signal<Local, Bit>,
}

impl ClipCounter {
    /// A counter at 0.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            reset: Default::default(),
            adc: Default::default(),
            clear: Default::default(),
            count: Default::default(),
            counter: Default::default(),
            top: Constant::new(i64::from(RAIL_HIGH_BYTES[0] as i8).into()),
            bottom: Constant::new(i64::from(RAIL_HIGH_BYTES[1] as i8).into()),
            full: Constant::new(COUNT_MAX.into()),
            high: Default::default(),
            at_rail: Default::default(),
        }
    }
}

impl Default for ClipCounter {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for ClipCounter {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, counter);
        self.high.next = self.adc.val().get_bits::<8>(8);
        self.at_rail.next =
            (self.high.val() == self.top.val()) | (self.high.val() == self.bottom.val());
        self.count.next = self.counter.q.val();
        if self.clear.val() {
            self.counter.d.next = 0.into();
            if self.at_rail.val() {
                self.counter.d.next = 1.into();
            }
        } else if self.at_rail.val() & (self.counter.q.val() != self.full.val()) {
            self.counter.d.next = self.counter.q.val() + 1;
        }
        if self.reset.val() {
            self.counter.d.next = 0.into();
        }
    }
}

crate::impl_clocked!(ClipCounter);

/// Bit-true model of one `ClipCounter`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClipCount {
    count: u16,
}

impl ClipCount {
    /// The count during the current cycle.
    pub fn count(&self) -> u16 {
        self.count
    }

    /// One edge with this clock's ADC word and read strobe.
    #[inline(always)]
    pub fn step(&mut self, adc: i16, clear: bool) {
        let at_rail = u16::from(at_rail(adc));
        self.count = if clear {
            at_rail
        } else {
            self.count.saturating_add(at_rail)
        };
    }

    /// `step` without a clear at each of these words: every edge adds 0 or
    /// 1 and the count stops at its top, so the rails counted over the
    /// words and added once, saturating, give the same count (a loop the
    /// compiler vectorizes, where the steps' saturation chained them).
    #[inline(always)]
    pub fn steps(&mut self, adc: impl Iterator<Item = i16>) {
        let rails = adc.map(|a| u32::from(at_rail(a))).sum::<u32>();
        self.count = u16::try_from(u32::from(self.count) + rails).unwrap_or(u16::MAX);
    }
}

/// Whether `adc` counts as at a rail (module header): its top byte is one
/// of `RAIL_HIGH_BYTES`. Two compares, where `contains` on the array was
/// a call to a byte search at every word (4% of a field's closed loop).
#[inline(always)]
pub fn at_rail(adc: i16) -> bool {
    let [low, high] = RAIL_HIGH_BYTES;
    let top = (adc as u16 >> 8) as u8;
    top == low || top == high
}

/// The `ADC_CLIP` word of two counts: ADC1 in bits 15..0, ADC2 in 31..16.
pub fn clip_word(counts: [ClipCount; 2]) -> u32 {
    u32::from(counts[0].count()) | (u32::from(counts[1].count()) << 16)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};

    /// The block against its model on rail-heavy random words and
    /// random clears, through saturation.
    #[test]
    fn counter_matches_its_model() {
        let mut uut = ClipCounter::new();
        prepare(&mut uut);
        let mut model = ClipCount::default();
        let mut rng = crate::test_util::Rng::new(11);
        for cycle in 0..70_000u32 {
            let r = rng.next_u64();
            // Rails, the band's edges and their neighbours, and any word.
            let edges = [i16::MAX, i16::MIN, 32_512, 32_511, -32_513, -32_512, 32_752];
            let adc = match r % 4 {
                0 | 1 => edges[(r >> 8) as usize % edges.len()],
                _ => (r >> 8) as i16,
            };
            // Rare clears early on, none in the middle stretch: the count saturates.
            let clear = !(2000..=68_000).contains(&cycle) && (r >> 40).is_multiple_of(50);
            uut.adc.next = i64::from(adc).into();
            uut.clear.next = clear;
            uut.reset.next = false;
            assert_eq!(
                uut.count.val().index() as u16,
                model.count(),
                "cycle {cycle}"
            );
            tick(&mut uut);
            model.step(adc, clear);
        }
        assert!(model.count() < u16::MAX, "cleared at the end");
    }

    /// `steps` over a stretch of words is `step` without a clear at each:
    /// stretches of every length up to 70,000 words, rail-heavy and not,
    /// from counts anywhere (near the top too), so that some saturate.
    #[test]
    fn a_stretch_of_steps_counts_as_its_edges() {
        let mut rng = crate::test_util::Rng::new(19);
        for case in 0..400 {
            let len = match case % 4 {
                0 => (rng.next_u64() % 4) as usize,
                1 => (rng.next_u64() % 300) as usize,
                _ => (rng.next_u64() % 70_000) as usize,
            };
            let share = rng.next_u64() % 5;
            let words: Vec<i16> = (0..len)
                .map(|_| {
                    let r = rng.next_u64();
                    if r % 5 < share {
                        [i16::MAX, i16::MIN, 32_512, -32_513][(r >> 8) as usize % 4]
                    } else {
                        (r >> 16) as i16
                    }
                })
                .collect();
            let start = ClipCount {
                count: match case % 3 {
                    0 => 0,
                    1 => u16::MAX - (rng.next_u64() % 300) as u16,
                    _ => rng.next_u64() as u16,
                },
            };
            let (mut stretch, mut stepped) = (start, start);
            stretch.steps(words.iter().copied());
            for &w in &words {
                stepped.step(w, false);
            }
            assert_eq!(stretch, stepped, "case {case}: {len} words from {start:?}");
        }
    }

    /// Both rail codes of every converter from `MIN_CONVERTER_BITS` to 16
    /// bits are counted, and exactly the words within 1/128 of full
    /// scale are.
    #[test]
    fn every_converters_rails_are_counted() {
        for bits in MIN_CONVERTER_BITS..=16 {
            let step = 1i32 << (16 - bits);
            let rails = [32_768 - step, -32_768];
            for rail in rails {
                assert!(at_rail(rail as i16), "{bits}-bit rail {rail}");
            }
        }
        let counted = (i16::MIN..=i16::MAX).filter(|&w| at_rail(w)).count();
        assert_eq!(counted, 512);
        assert!(at_rail(32_512) && !at_rail(32_511));
        assert!(at_rail(-32_513) && !at_rail(-32_512));
        // Narrower than that, the positive rail lies below the band.
        let seven_bit_rail = 32_768 - (1i32 << (16 - (MIN_CONVERTER_BITS - 1)));
        assert!(!at_rail(seven_bit_rail as i16));
    }

    #[test]
    fn saturates_and_restarts_on_a_read() {
        let mut c = ClipCount::default();
        for _ in 0..70_000 {
            c.step(i16::MIN, false);
        }
        assert_eq!(c.count(), u16::MAX);
        c.step(i16::MAX, true);
        assert_eq!(c.count(), 1);
        c.step(32_511, false);
        assert_eq!(c.count(), 1);
    }
}
