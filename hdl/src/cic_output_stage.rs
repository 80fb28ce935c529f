//! The CIC's output stage: y = round(b / 2^shift), rounded half up, low
//! 40 bits, from the 80-bit comb word b in three clocks and no adder wider
//! than 41 bits.
//!
//! ```text
//!  acc[80] ─► 2b[104] ─► >> (shift & 0b111000) ─► coarse[48] ─► >> (shift & 0b000111) ─► fine[41] ─► (fine + 1) >> 1 ─► rounded[40]
//!                         (register)                            (register)                         (combinational)
//! ```
//!
//! floor(b / 2^s + 1/2) = floor((floor(2b / 2^s) + 1) / 2) (for real t,
//! floor((floor(t) + 1) / 2) = floor((t + 1) / 2)). So the stage shifts
//! the doubled comb word right by s, keeping `HALF_BITS` = 41 bits (the
//! output and one bit below it), adds 1 and drops that bit. The doubled
//! word is b sign-extended to `DOUBLED_BITS` = 41 + 63 = 104 bits, so
//! every shift the 6-bit setting can hold reads bits that exist and the
//! shifts can be logical. `OUTPUT_STAGES` = 3 clocks, so that no clock
//! carries more than one carry chain or three mux levels:
//! 1. coarse: (2b >> (shift & 0b111000)), low `COARSE_BITS` = 41 + 7 bits
//!    (the fine step moves at most 7 bits);
//! 2. fine: (coarse >> (shift & 0b000111)), low 41 bits;
//! 3. round: (fine + 1) >> 1, low 40 bits (a 41-bit increment).
//!
//! The registers run every clock on whatever `acc` holds: `rounded` is the
//! output of the word `acc` held two clocks before, and
//! `crate::cic_decimator`'s schedule reads it at the clocks where that was
//! a comb output. Power-up: both registers 0.

use crate::cic_widths::{
    COARSE_BITS, COARSE_SHIFT_MASK, DOUBLED_BITS, FINE_SHIFT_MASK, HALF_BITS, OUTPUT_BITS,
    REGISTER_BITS, SHIFT_BITS,
};
use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// The coarse, fine and rounding steps of the CIC's output.
#[derive(LogicBlock)]
pub struct CicOutputStage {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// The comb word b (the decimator's accumulator).
    pub acc: Signal<In, Signed<REGISTER_BITS>>,
    /// The output shift s, 0..=40, held over a sample.
    pub shift: Signal<In, Bits<SHIFT_BITS>>,
    /// round(b / 2^s) of the `acc` of two clocks before, low 40 bits.
    pub rounded: Signal<Out, Signed<OUTPUT_BITS>>,
    extended: Signal<Local, Signed<DOUBLED_BITS>>,
    doubled: Signal<Local, Bits<DOUBLED_BITS>>,
    coarse_shift: Signal<Local, Bits<SHIFT_BITS>>,
    coarse_shifted: Signal<Local, Bits<DOUBLED_BITS>>,
    coarse: DFF<Bits<COARSE_BITS>>,
    fine_shift: Signal<Local, Bits<SHIFT_BITS>>,
    fine_shifted: Signal<Local, Bits<COARSE_BITS>>,
    fine: DFF<Bits<HALF_BITS>>,
    rounded_half: Signal<Local, Bits<HALF_BITS>>,
    one: Constant<Bits<HALF_BITS>>,
    coarse_shift_mask: Constant<Bits<SHIFT_BITS>>,
    fine_shift_mask: Constant<Bits<SHIFT_BITS>>,
}

impl CicOutputStage {
    /// The stage at power-up: both registers 0.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            acc: Default::default(),
            shift: Default::default(),
            rounded: Default::default(),
            extended: Default::default(),
            doubled: Default::default(),
            coarse_shift: Default::default(),
            coarse_shifted: Default::default(),
            coarse: Default::default(),
            fine_shift: Default::default(),
            fine_shifted: Default::default(),
            fine: Default::default(),
            rounded_half: Default::default(),
            one: Constant::new(1.into()),
            coarse_shift_mask: Constant::new(COARSE_SHIFT_MASK.into()),
            fine_shift_mask: Constant::new(FINE_SHIFT_MASK.into()),
        }
    }
}

impl Default for CicOutputStage {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for CicOutputStage {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, coarse, fine);
        self.extended.next = signed_bit_cast_exact::<DOUBLED_BITS, REGISTER_BITS>(self.acc.val());
        self.doubled.next = unsigned_cast(self.extended.val()) << 1;
        self.coarse_shift.next = self.shift.val() & self.coarse_shift_mask.val();
        self.coarse_shifted.next = self.doubled.val() >> self.coarse_shift.val();
        self.coarse.d.next = self.coarse_shifted.val().get_bits::<COARSE_BITS>(0);
        self.fine_shift.next = self.shift.val() & self.fine_shift_mask.val();
        self.fine_shifted.next = self.coarse.q.val() >> self.fine_shift.val();
        self.fine.d.next = self.fine_shifted.val().get_bits::<HALF_BITS>(0);
        self.rounded_half.next = (self.fine.q.val() + self.one.val()) >> 1;
        self.rounded.next = signed_cast(self.rounded_half.val().get_bits::<OUTPUT_BITS>(0));
    }
}

crate::impl_clocked!(CicOutputStage);
