//! Carrier table fill: at power-up, the 8192 words of the carriers'
//! quarter-wave table are interpolated from the modulation NCO's 4096-word
//! ROM and written into the four carrier table RAMs.
//!
//! ```text
//!  count ─► ROM entry k = count/2 - 1 ─► phase ─► (modulation NCO's Sine, 5 clocks) ─► r
//!  r, r two clocks earlier ─► e = (3 r_prev + r) / 4  (odd entry)  ─► [e] ─► word
//!                             e = (r_prev + 3 r) / 4  (even entry), rounded half to even
//!  3 <= count < 8195 ─► [6-clock delay] ─► write; address counter ─► address
//!  count == FILL_CLOCKS ─► ready (lookups from now on)
//! ```
//!
//! Entry i of the carrier table is the sine at the centre of the i-th of
//! 8192 intervals of the first quadrant. The ROM (`crate::sine_table`)
//! holds 4096 centres, one per pair of intervals, so entry 2j lies a
//! quarter of a ROM step before ROM centre j and entry 2j + 1 a quarter
//! after it, and linear interpolation between ROM neighbours gives
//!
//! ```text
//!   e[2j]     = round((r[j-1] + 3 r[j]) / 4)      e[2j+1] = round((3 r[j] + r[j+1]) / 4)
//! ```
//!
//! rounded half to even, where r\[k\] is the sine generator's output for the
//! centre of ROM interval k: r\[-1\] = -r\[0\] (quadrant 3) and r\[4096\] =
//! r\[4095\] (quadrant 1) come from the generator's own quadrant rules.
//! Error against the exact centre sine: the ROM's 0.5 LSB, the
//! interpolation's rounding 0.5 LSB and its curvature term,
//! 32767 (2 pi / 2^15)^2 3/32 = 4e-5 LSB: at most 1 LSB. The sums' quarter
//! fractions are equally likely, so rounding half up would add 1/8 LSB on
//! average, a fundamental gain of 1 + 4.5e-6; half to even adds nothing on
//! average. Every word lies in [0, 32767] (a convex combination of words
//! in \[-r\[0\], 32767\]; e\[0\] = r\[0\] / 2 >= 0).
//!
//! Schedule (cycles after power-up): during cycle c < 8195 the sine
//! generator is asked for ROM entry c/2 - 1 (each entry on two
//! consecutive clocks: `busy` high, it is taken from the modulation NCO);
//! its word comes out 5 clocks later, and the word two clocks before it is
//! its ROM predecessor. The arrival of entry k's first copy makes e[2k-1],
//! of its second e\[2k\]; the interpolation is registered, so the words are
//! written during cycles 9..8200, `address` 0..8191 in order. `count`
//! stops at `FILL_CLOCKS` = 8224 and `ready` is high from that cycle on,
//! forever: the 24 clocks after the last write let the modulation NCO's
//! last fill words leave the envelope path (`am_mixer`: 8 clocks) before
//! any carrier leaves zero, so the first drive words are made of regular
//! envelopes only.
//!
//! Nothing here depends on a setting: the fill is the same at every
//! power-up (164 us at 50 MHz), and the models rebuild the table it writes
//! from the sine generator's model (`crate::model::carrier_nco::table`).
//! There is no reset; the tables are filled once, at configuration.
//!
//! Widths: `count` 14 bits (0..=8224), `address` 13 bits, the
//! interpolation sums 18 bits (|r_prev + 3 r| <= 4 x 32767 + 2 < 2^17).
//! Resources: 14 + 6 + 13 + 2 x 16 + 16 flip-flops, two 18-bit adders.

use crate::quarter_wave::{PHASE_BELOW_INDEX, TABLE_BITS, TABLE_ENTRIES};
use rust_hdl::prelude::*;

/// Clocks during which the fill asks for ROM words: entries -1..=4095 on
/// two clocks each, then entry 4096 once.
pub const REQUESTS: usize = TABLE_ENTRIES + 3;
/// The first request whose word makes a table entry (entry 0's second copy).
const FIRST_WRITTEN_REQUEST: usize = 3;
/// Clocks from a request to the write of its entry: the sine generator and
/// the interpolation register.
pub const WRITE_DELAY: usize = crate::sine::LATENCY + 1;
/// Clocks from power-up until `ready`.
pub const FILL_CLOCKS: usize = TABLE_ENTRIES + 32;
/// Width of the fill counter: it holds 0..=FILL_CLOCKS.
const COUNT_BITS: usize = TABLE_BITS + 1;
const _: () = assert!(FILL_CLOCKS < (1 << COUNT_BITS));
const _: () = assert!(REQUESTS - FIRST_WRITTEN_REQUEST == TABLE_ENTRIES);
// The last write, then the sine generator and the envelope path (8 clocks)
// are clear of fill words before the first lookup goes live.
const _: () = assert!(FILL_CLOCKS >= REQUESTS + WRITE_DELAY + 8);
const _: () = assert!(WRITE_DELAY == 6, "the write delay line has 6 stages");

/// The 32-bit phase at the centre of the ROM interval `entry` (-1..=4096):
/// ROM intervals are two table intervals wide.
pub const fn rom_entry_phase(entry: i32) -> u32 {
    (entry << (PHASE_BELOW_INDEX + 1)) as u32 | (1 << PHASE_BELOW_INDEX)
}

/// Power-up fill of the carrier tables from the modulation sine generator.
#[derive(LogicBlock)]
pub struct CarrierTableFill {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// High while the modulation sine generator must evaluate `phase`
    /// (cycles 0..8194 after power-up).
    pub busy: Signal<Out, Bit>,
    /// The phase of the ROM entry asked for.
    pub phase: Signal<Out, Bits<32>>,
    /// The sine generator's output (its word for the phase of 5 clocks ago).
    pub sine: Signal<In, Signed<16>>,
    /// Write `word` at `address` at this edge.
    pub write: Signal<Out, Bit>,
    /// The entry being written.
    pub address: Signal<Out, Bits<TABLE_BITS>>,
    /// The entry's word.
    pub word: Signal<Out, Signed<16>>,
    /// The tables are complete: high from cycle `FILL_CLOCKS` on.
    pub ready: Signal<Out, Bit>,
    count: DFF<Bits<COUNT_BITS>>,
    pending: DFF<Bits<WRITE_DELAY>>,
    write_address: DFF<Bits<TABLE_BITS>>,
    previous_1: DFF<Signed<16>>,
    previous_2: DFF<Signed<16>>,
    entry: DFF<Signed<16>>,
    counting: Signal<Local, Bit>,
    wanted: Signal<Local, Bit>,
    near: Signal<Local, Signed<18>>,
    far: Signal<Local, Signed<18>>,
    sum: Signal<Local, Signed<18>>,
    rounded: Signal<Local, Signed<18>>,
    quotient: Signal<Local, Signed<16>>,
    last: Constant<Bits<COUNT_BITS>>,
    requests: Constant<Bits<COUNT_BITS>>,
    first_written: Constant<Bits<COUNT_BITS>>,
    entry_shift: Constant<Bits<32>>,
    half_rom_step: Constant<Bits<32>>,
    round_down: Constant<Signed<18>>,
    round_up: Constant<Signed<18>>,
    one: Constant<Bits<WRITE_DELAY>>,
}

impl CarrierTableFill {
    /// The fill at power-up: count 0, nothing written.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            busy: Default::default(),
            phase: Default::default(),
            sine: Default::default(),
            write: Default::default(),
            address: Default::default(),
            word: Default::default(),
            ready: Default::default(),
            count: Default::default(),
            pending: Default::default(),
            write_address: Default::default(),
            previous_1: Default::default(),
            previous_2: Default::default(),
            entry: Default::default(),
            counting: Default::default(),
            wanted: Default::default(),
            near: Default::default(),
            far: Default::default(),
            sum: Default::default(),
            rounded: Default::default(),
            quotient: Default::default(),
            last: Constant::new((FILL_CLOCKS as u64).into()),
            requests: Constant::new((REQUESTS as u64).into()),
            first_written: Constant::new((FIRST_WRITTEN_REQUEST as u64).into()),
            entry_shift: Constant::new(((PHASE_BELOW_INDEX + 1) as u64).into()),
            // Entry count/2 - 1 at its centre: (count/2) << 18, less half a ROM step.
            half_rom_step: Constant::new((1u64 << PHASE_BELOW_INDEX).into()),
            round_down: Constant::new(1.into()),
            round_up: Constant::new(2.into()),
            one: Constant::new(1.into()),
        }
    }
}

impl Default for CarrierTableFill {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for CarrierTableFill {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            count,
            pending,
            write_address,
            previous_1,
            previous_2,
            entry
        );
        self.counting.next = self.count.q.val() != self.last.val();
        if self.counting.val() {
            self.count.d.next = self.count.q.val() + 1;
        }
        // Requests: ROM entry count/2 - 1, each on two clocks.
        self.busy.next = self.count.q.val() < self.requests.val();
        self.phase.next =
            (bit_cast::<32, TABLE_BITS>(self.count.q.val().get_bits::<TABLE_BITS>(1))
                << self.entry_shift.val())
                - self.half_rom_step.val();
        self.wanted.next = self.busy.val() & (self.count.q.val() >= self.first_written.val());
        // The words: the current one and its ROM predecessor (two clocks back).
        self.previous_1.d.next = self.sine.val();
        self.previous_2.d.next = self.previous_1.q.val();
        // A first copy (odd cycle, count bit 0 set) makes the odd entry
        // before its ROM centre's pair, weights 3 : 1 to the predecessor;
        // a second copy the even entry, weights 1 : 3.
        self.near.next = signed_bit_cast::<18, 16>(self.sine.val());
        self.far.next = signed_bit_cast::<18, 16>(self.previous_2.q.val());
        if self.count.q.val().get_bit(0) {
            self.near.next = signed_bit_cast::<18, 16>(self.previous_2.q.val());
            self.far.next = signed_bit_cast::<18, 16>(self.sine.val());
        }
        // Divide by 4, rounding half to even: add 1, or 2 when the
        // quotient's lowest bit (sum bit 2) is set.
        self.sum.next = self.far.val() + self.near.val() + self.near.val() + self.near.val();
        self.rounded.next = self.sum.val() + self.round_down.val();
        if self.sum.val().get_bit(2) {
            self.rounded.next = self.sum.val() + self.round_up.val();
        }
        self.quotient.next = self.rounded.val().get_bits::<16>(2);
        self.entry.d.next = self.quotient.val();
        // Writes, WRITE_DELAY clocks after their requests.
        self.pending.d.next = self.pending.q.val() << 1;
        if self.wanted.val() {
            self.pending.d.next = (self.pending.q.val() << 1) | self.one.val();
        }
        self.write.next = self.pending.q.val().get_bit(5);
        if self.pending.q.val().get_bit(5) {
            self.write_address.d.next = self.write_address.q.val() + 1;
        }
        self.address.next = self.write_address.q.val();
        self.word.next = self.entry.q.val();
        self.ready.next = !self.counting.val();
    }
}

crate::impl_clocked!(CarrierTableFill);

/// Mutation hook for the negative control in `crate::rtl` (tests only).
#[cfg(test)]
impl CarrierTableFill {
    #[doc(hidden)]
    pub fn mutate_rounding(&mut self) {
        // Round every half down instead of to even.
        self.round_up = Constant::new(1.into());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::carrier_nco::table;
    use crate::model::sine::Sine;
    use crate::primitives::convert::{bits_to_u64, i128_to_signed, signed_to_i128};

    #[test]
    fn the_fill_writes_every_entry_once_in_order_and_the_model_table() {
        // Golden schedule from the header: requests during cycles 0..8194
        // for ROM entry c/2 - 1, writes during cycles 9..8200 at addresses
        // 0..8191, ready from FILL_CLOCKS on. The words written, with the
        // sine generator's model as the source, are the model's table.
        let mut uut = CarrierTableFill::new();
        prepare(&mut uut);
        let mut source = Sine::default();
        let mut written = vec![None; TABLE_ENTRIES];
        for cycle in 0..FILL_CLOCKS + 40 {
            uut.sine.next = i128_to_signed(source.output() as i128);
            crate::drive::settle(&mut uut);
            let busy = cycle < REQUESTS;
            assert_eq!(uut.busy.val(), busy, "busy, cycle {cycle}");
            let phase = bits_to_u64(uut.phase.val()) as u32;
            if busy {
                assert_eq!(
                    phase,
                    rom_entry_phase(cycle as i32 / 2 - 1),
                    "phase, cycle {cycle}"
                );
            }
            let write =
                (FIRST_WRITTEN_REQUEST + WRITE_DELAY..REQUESTS + WRITE_DELAY).contains(&cycle);
            assert_eq!(uut.write.val(), write, "write, cycle {cycle}");
            if write {
                let address = bits_to_u64(uut.address.val()) as usize;
                assert_eq!(
                    address,
                    cycle - FIRST_WRITTEN_REQUEST - WRITE_DELAY,
                    "cycle {cycle}"
                );
                assert!(written[address].is_none(), "entry {address} written twice");
                written[address] = Some(signed_to_i128(uut.word.val()) as i16);
            }
            assert_eq!(
                uut.ready.val(),
                cycle >= FILL_CLOCKS,
                "ready, cycle {cycle}"
            );
            source.step(phase, 0);
            tick(&mut uut);
        }
        let written: Vec<i16> = written
            .into_iter()
            .map(|w| w.expect("every entry"))
            .collect();
        assert_eq!(&written[..], &table()[..]);
    }

    #[test]
    fn rom_entry_phases_are_interval_centres() {
        // ROM entry k covers phases [k 2^18, (k + 1) 2^18) of the first quadrant.
        assert_eq!(rom_entry_phase(0), 1 << 17);
        assert_eq!(rom_entry_phase(-1), 0u32.wrapping_sub(1 << 17));
        assert_eq!(rom_entry_phase(4096), (1 << 30) + (1 << 17));
    }
}
