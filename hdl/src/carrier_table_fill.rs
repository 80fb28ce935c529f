//! Carrier table fill: at power-up, the modulation NCO's sine generator
//! computes the 8192 words of the carriers' quarter-wave table, and this
//! block writes them into the four table RAMs.
//!
//! ```text
//!  count 0..8191 ──► phase of entry count ──► (modulation NCO's Sine, 5 clocks) ──► word
//!  busy (count < 8192) ─► [5-clock delay] ─► write ──┐
//!                                   address counter ─┴─► write `word` at `address` (4 RAMs)
//!  count == FILL_CLOCKS ──► ready (the tables are complete; lookups from now on)
//! ```
//!
//! Entry i of the table is the sample at the centre of the i-th of the
//! 8192 intervals of the first quadrant: 32767 sin(2 pi (i + 1/2) / 32768),
//! as `crate::sine::Sine` computes it from phase `(i << 17) | (1 << 16)`.
//! `count` runs from 0 at power-up; during cycles 0..8191 the modulation
//! sine generator is asked for entry `count` (`busy` high: it is taken
//! from the modulation NCO), and its word comes out `sine::LATENCY` = 5
//! clocks later, when `write` is high and `address` names the entry: the
//! words are written during cycles 5..8196. `count` stops at
//! `FILL_CLOCKS` = 8208; `ready` is high from that cycle on, forever.
//! The 11 clocks between the last write and `ready` let the modulation
//! NCO's last fill words leave the envelope path (`am_mixer`: 8 clocks)
//! before any carrier leaves zero, so the first drive words are made of
//! regular envelopes only.
//!
//! Nothing here depends on a setting: the fill is the same at every
//! power-up, and the models read the table it writes from
//! `crate::model::carrier_nco::table()`. Fill time 8208 clocks: 164 us at
//! 50 MHz. There is no reset; the tables are filled once, at configuration.
//!
//! Widths: `count` 14 bits (0..=8208), `address` 13 bits (`TABLE_BITS`).
//! Resources: 14 + 5 + 13 flip-flops and their incrementers.

use rust_hdl::prelude::*;

/// Index bits of the quarter-wave table: 2^13 entries per quadrant.
pub const TABLE_BITS: usize = 13;
/// Entries of the quarter-wave table.
pub const TABLE_ENTRIES: usize = 1 << TABLE_BITS;
/// Phase bits below the table index (32 - 2 quadrant bits - 13).
pub const PHASE_BELOW_INDEX: usize = 32 - 2 - TABLE_BITS;
/// Clocks from power-up until `ready`: one per entry, the sine generator's
/// latency, and the envelope path's flush.
pub const FILL_CLOCKS: usize = TABLE_ENTRIES + 16;
/// Width of the fill counter: it holds 0..=FILL_CLOCKS.
const COUNT_BITS: usize = TABLE_BITS + 1;
const _: () = assert!(FILL_CLOCKS < (1 << COUNT_BITS));
const _: () = assert!(FILL_CLOCKS >= TABLE_ENTRIES + crate::sine::LATENCY + 8);
const _: () = assert!(
    crate::sine::LATENCY == 5,
    "the write delay line has 5 stages"
);

/// The 32-bit phase at the centre of table entry `entry`.
pub const fn entry_phase(entry: usize) -> u32 {
    ((entry as u32) << PHASE_BELOW_INDEX) | (1 << (PHASE_BELOW_INDEX - 1))
}

/// Power-up fill of the carrier tables from the modulation sine generator.
#[derive(LogicBlock)]
pub struct CarrierTableFill {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// High while the modulation sine generator must evaluate `phase`
    /// (cycles 0..8191 after power-up).
    pub busy: Signal<Out, Bit>,
    /// The phase of the entry being computed, for the sine generator.
    pub phase: Signal<Out, Bits<32>>,
    /// Write the sine generator's word at `address` at this edge.
    pub write: Signal<Out, Bit>,
    /// The entry being written.
    pub address: Signal<Out, Bits<TABLE_BITS>>,
    /// The tables are complete: high from cycle `FILL_CLOCKS` on.
    pub ready: Signal<Out, Bit>,
    count: DFF<Bits<COUNT_BITS>>,
    pending: DFF<Bits<5>>,
    write_address: DFF<Bits<TABLE_BITS>>,
    counting: Signal<Local, Bit>,
    last: Constant<Bits<COUNT_BITS>>,
    entries: Constant<Bits<COUNT_BITS>>,
    centre: Constant<Bits<32>>,
    index_shift: Constant<Bits<32>>,
}

impl CarrierTableFill {
    /// The fill at power-up: count 0, nothing written.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            busy: Default::default(),
            phase: Default::default(),
            write: Default::default(),
            address: Default::default(),
            ready: Default::default(),
            count: Default::default(),
            pending: Default::default(),
            write_address: Default::default(),
            counting: Default::default(),
            last: Constant::new((FILL_CLOCKS as u64).into()),
            entries: Constant::new((TABLE_ENTRIES as u64).into()),
            centre: Constant::new((entry_phase(0) as u64).into()),
            index_shift: Constant::new((PHASE_BELOW_INDEX as u64).into()),
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
        dff_setup!(self, clock, count, pending, write_address);
        self.counting.next = self.count.q.val() != self.last.val();
        if self.counting.val() {
            self.count.d.next = self.count.q.val() + 1;
        }
        // Entries 0..8191.
        self.busy.next = self.count.q.val() < self.entries.val();
        self.phase.next =
            (bit_cast::<32, TABLE_BITS>(self.count.q.val().get_bits::<TABLE_BITS>(0))
                << self.index_shift.val())
                | self.centre.val();
        // The word of entry n leaves the sine generator 5 clocks after n.
        self.pending.d.next =
            (self.pending.q.val() << 1) | bit_cast::<5, 1>(self.busy.val().into());
        self.write.next = self.pending.q.val().get_bit(4);
        if self.pending.q.val().get_bit(4) {
            self.write_address.d.next = self.write_address.q.val() + 1;
        }
        self.address.next = self.write_address.q.val();
        self.ready.next = !self.counting.val();
    }
}

crate::impl_clocked!(CarrierTableFill);

/// Mutation hook for the negative control in `crate::rtl` (tests only).
#[cfg(test)]
impl CarrierTableFill {
    #[doc(hidden)]
    pub fn mutate_centre(&mut self) {
        // Sample each interval at its start instead of its centre.
        self.centre = Constant::new(0.into());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::primitives::convert::bits_to_u64;

    #[test]
    fn every_entry_is_asked_for_once_and_written_five_clocks_later() {
        // Golden schedule, computed here from the header's rules: entry n
        // asked for during cycle n, written during cycle n + 5, ready from
        // FILL_CLOCKS on. Checked over the whole fill and beyond.
        let mut uut = CarrierTableFill::new();
        prepare(&mut uut);
        for cycle in 0..FILL_CLOCKS + 40 {
            let busy = cycle < TABLE_ENTRIES;
            assert_eq!(uut.busy.val(), busy, "busy, cycle {cycle}");
            if busy {
                let phase = bits_to_u64(uut.phase.val()) as u32;
                assert_eq!(phase, entry_phase(cycle), "phase, cycle {cycle}");
            }
            let write = (5..TABLE_ENTRIES + 5).contains(&cycle);
            assert_eq!(uut.write.val(), write, "write, cycle {cycle}");
            if write {
                let address = bits_to_u64(uut.address.val()) as usize;
                assert_eq!(address, cycle - 5, "address, cycle {cycle}");
            }
            assert_eq!(
                uut.ready.val(),
                cycle >= FILL_CLOCKS,
                "ready, cycle {cycle}"
            );
            tick(&mut uut);
        }
    }

    #[test]
    fn entry_phases_are_interval_centres() {
        // Entry i covers phases [i 2^17, (i + 1) 2^17) of the first quadrant.
        assert_eq!(entry_phase(0), 1 << 16);
        assert_eq!(entry_phase(TABLE_ENTRIES - 1), (1 << 30) - (1 << 16));
    }
}
