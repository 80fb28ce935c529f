//! `ClipCounter`: clocks on which one ADC word sat at a rail, for the
//! `ADC_CLIP` status word.
//!
//! ```text
//!  adc ──► at_rail = (adc == +32767) | (adc == -32768)
//!  count <= clear ? at_rail : (count == 65535 ? 65535 : count + at_rail)
//! ```
//!
//! 16-bit saturating count, power-up 0, synchronous `reset` to 0. `clear`
//! is the bus read of `ADC_CLIP`: the read returns `count` as it is during
//! that clock, and a rail code sampled at the same edge starts the next
//! count, so every clipped clock is reported by exactly one read (until the
//! count saturates). A converter at a rail code is over range or exactly
//! at full scale: either way the measurement it feeds is no longer linear.
//! Cost: 16 flip-flops, a 16-bit incrementer and two 16-bit compares.

use rust_hdl::prelude::*;

/// Width of the count.
pub const COUNT_BITS: usize = 16;
/// The count saturates here.
pub const COUNT_MAX: u64 = (1 << COUNT_BITS) - 1;

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
    top: Constant<Signed<16>>,
    bottom: Constant<Signed<16>>,
    full: Constant<Bits<COUNT_BITS>>,
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
            top: Constant::new(i64::from(i16::MAX).into()),
            bottom: Constant::new(i64::from(i16::MIN).into()),
            full: Constant::new(COUNT_MAX.into()),
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
        self.at_rail.next =
            (self.adc.val() == self.top.val()) | (self.adc.val() == self.bottom.val());
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
        let at_rail = u16::from(adc == i16::MAX || adc == i16::MIN);
        self.count = if clear {
            at_rail
        } else {
            self.count.saturating_add(at_rail)
        };
    }
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
            let adc = match r % 4 {
                0 => i16::MAX,
                1 => i16::MIN,
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

    #[test]
    fn saturates_and_restarts_on_a_read() {
        let mut c = ClipCount::default();
        for _ in 0..70_000 {
            c.step(i16::MIN, false);
        }
        assert_eq!(c.count(), u16::MAX);
        c.step(i16::MAX, true);
        assert_eq!(c.count(), 1);
        c.step(i16::MAX - 1, false);
        assert_eq!(c.count(), 1);
    }
}
