//! The CIC's shared comb step, acc - delay, in two 40-bit halves on
//! consecutive clocks, with the comb delays of both channels in one RAM.
//!
//! ```text
//!            low clock                                high clock
//!  acc[80] ─► lo: acc_lo - delay_lo ──► borrow       hi: (2 acc_hi) - (2 delay_hi + borrow), halved
//!            acc <- {acc_hi, difference_lo}           acc <- {difference_hi, acc_lo}
//!            delay[k] <- acc, delay_hi <- delay[k]    k <- k + 1
//! ```
//!
//! Each comb step of `crate::cic_decimator`'s schedule is a low clock then
//! a high clock (`low`, `high`): no clock carries an 80-bit carry chain
//! (with the RAM's clock-to-out in front, that chain held an iCE40 UP5K
//! to 26 MHz). The low clock subtracts the low halves, keeps the borrow
//! and the delay word's high half in registers, and writes the
//! accumulator as the new delay; the high clock subtracts the high halves
//! and the borrow as one 41-bit subtraction, halved, and moves to the next
//! delay word. The accumulator is this block's register, so the schedule
//! (`crate::cic_decimator`) reads nothing here that its own signals drive
//! combinationally: it loads a channel's integral (`load`), steps the
//! halves (`low`, `high`) and reads `acc`. The RAM is read one clock ahead
//! of each step's low clock and again during it (the old value of the word
//! it reads is the delay); the read and write addresses of one clock
//! always differ.
//!
//! Widths: the halves are `REGISTER_HALF_BITS` = 40 bits, each difference
//! `COMB_CARRY_BITS` = 41 (the borrow, or the borrow-in). The delays: 8
//! words of 80 bits (2 channels x 4 stages), addressed in step order, in a
//! `WordRam` (block RAM: five iCE40 `SB_RAM40_4K`; LUT RAM on ECP5), not in
//! flip-flops: 640 flip-flops and an 80-bit 8-to-1 read multiplexer saved.
//! Power-up: all delay words, the address and the registers 0.

use crate::cic_widths::{COMB_CARRY_BITS, DELAY_ADDRESS_BITS, REGISTER_BITS, REGISTER_HALF_BITS};
use crate::primitives::WordRam;
use rust_hdl::prelude::*;

/// The accumulator, the comb subtractor in halves and the comb delays.
#[derive(LogicBlock)]
pub struct CicComb {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// High during a comb step's low clock.
    pub low: Signal<In, Bit>,
    /// High during a comb step's high clock.
    pub high: Signal<In, Bit>,
    /// High during the schedule's loads: the accumulator takes `load_value`.
    pub load: Signal<In, Bit>,
    /// The word a load puts into the accumulator (a channel's integral).
    pub load_value: Signal<In, Signed<REGISTER_BITS>>,
    /// The accumulator: the comb word after the step's last half.
    pub acc: Signal<Out, Signed<REGISTER_BITS>>,
    accumulator: DFF<Signed<REGISTER_BITS>>,
    delays: WordRam<REGISTER_BITS, DELAY_ADDRESS_BITS>,
    delay_address: DFF<Bits<DELAY_ADDRESS_BITS>>,
    borrow: DFF<Bits<1>>,
    delay_high: DFF<Bits<REGISTER_HALF_BITS>>,
    acc_bits: Signal<Local, Bits<REGISTER_BITS>>,
    delay_bits: Signal<Local, Bits<REGISTER_BITS>>,
    acc_low: Signal<Local, Bits<REGISTER_HALF_BITS>>,
    acc_high: Signal<Local, Bits<REGISTER_HALF_BITS>>,
    delay_low: Signal<Local, Bits<REGISTER_HALF_BITS>>,
    low_difference: Signal<Local, Bits<COMB_CARRY_BITS>>,
    high_difference: Signal<Local, Bits<COMB_CARRY_BITS>>,
    next_address: Constant<Bits<DELAY_ADDRESS_BITS>>,
    half_shift: Constant<Bits<8>>,
}

impl CicComb {
    /// The comb at power-up: delays, address and registers 0.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            low: Default::default(),
            high: Default::default(),
            load: Default::default(),
            load_value: Default::default(),
            acc: Default::default(),
            accumulator: Default::default(),
            delays: WordRam::new(),
            delay_address: Default::default(),
            borrow: Default::default(),
            delay_high: Default::default(),
            acc_bits: Default::default(),
            delay_bits: Default::default(),
            acc_low: Default::default(),
            acc_high: Default::default(),
            delay_low: Default::default(),
            low_difference: Default::default(),
            high_difference: Default::default(),
            next_address: Constant::new(1.into()),
            half_shift: Constant::new((REGISTER_HALF_BITS as u64).into()),
        }
    }
}

impl Default for CicComb {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for CicComb {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, accumulator, delay_address, borrow, delay_high);
        self.delays.clock.next = self.clock.val();
        // The halves' differences (module header).
        self.acc.next = self.accumulator.q.val();
        self.acc_bits.next = unsigned_cast(self.accumulator.q.val());
        self.delay_bits.next = unsigned_cast(self.delays.q.val());
        self.acc_low.next = self.acc_bits.val().get_bits::<REGISTER_HALF_BITS>(0);
        self.acc_high.next = self.acc_bits.val().get_bits::<REGISTER_HALF_BITS>(40);
        self.delay_low.next = self.delay_bits.val().get_bits::<REGISTER_HALF_BITS>(0);
        self.low_difference.next =
            bit_cast::<COMB_CARRY_BITS, REGISTER_HALF_BITS>(self.acc_low.val())
                - bit_cast::<COMB_CARRY_BITS, REGISTER_HALF_BITS>(self.delay_low.val());
        self.high_difference.next =
            (bit_cast::<COMB_CARRY_BITS, REGISTER_HALF_BITS>(self.acc_high.val()) << 1)
                - ((bit_cast::<COMB_CARRY_BITS, REGISTER_HALF_BITS>(self.delay_high.q.val()) << 1)
                    | bit_cast::<COMB_CARRY_BITS, 1>(self.borrow.q.val()));
        // The delay word of this step, read a clock ahead of its low clock.
        self.delays.write_enable.next = self.low.val();
        self.delays.write_address.next = self.delay_address.q.val();
        self.delays.write_data.next = self.accumulator.q.val();
        self.delays.read_address.next = self.delay_address.q.val();
        if self.load.val() {
            self.accumulator.d.next = self.load_value.val();
        }
        if self.low.val() {
            self.accumulator.d.next = signed_cast(
                (bit_cast::<REGISTER_BITS, REGISTER_HALF_BITS>(self.acc_high.val())
                    << self.half_shift.val())
                    | bit_cast::<REGISTER_BITS, REGISTER_HALF_BITS>(
                        self.low_difference.val().get_bits::<REGISTER_HALF_BITS>(0),
                    ),
            );
            self.borrow.d.next = self.low_difference.val().get_bits::<1>(40);
            self.delay_high.d.next = self.delay_bits.val().get_bits::<REGISTER_HALF_BITS>(40);
            self.delays.read_address.next = self.delay_address.q.val() + self.next_address.val();
        }
        if self.high.val() {
            self.accumulator.d.next = signed_cast(
                (bit_cast::<REGISTER_BITS, REGISTER_HALF_BITS>(
                    self.high_difference.val().get_bits::<REGISTER_HALF_BITS>(1),
                ) << self.half_shift.val())
                    | bit_cast::<REGISTER_BITS, REGISTER_HALF_BITS>(self.acc_low.val()),
            );
            self.delay_address.d.next = self.delay_address.q.val() + self.next_address.val();
            self.delays.read_address.next = self.delay_address.q.val() + self.next_address.val();
        }
    }
}

crate::impl_clocked!(CicComb);
