//! `FineSlope`: the interpolation slope of a sub-interval, registered: stage
//! 3 of `crate::sine_pair::SinePair`.
//!
//! ```text
//!  sub[2:0] ─► slope[0..7] (constants) ─► 8:1 mux (bit 0, then 1, then 2) ─► [slope]
//! ```
//!
//! Widths: `sub` 3 bits (`fine_sine_table::INTERPOLATED_BITS`), slopes 18
//! signed (`fine_sine_table::SLOPE_BITS`, radians at 2^30,
//! `fine_sine_table::slope`). Latency: one clock, the register at the
//! output, so that the pair reads only a register of this block (no
//! combinational path through it). Resources: 18 flip-flops and an 18-bit
//! 8:1 multiplexer over constants.

use crate::fine_sine_table::{INTERPOLATED_BITS, SLOPE_BITS, SUBINTERVALS, slope};
use rust_hdl::prelude::*;

const _: () = assert!(INTERPOLATED_BITS == 3 && SUBINTERVALS == 8 && SLOPE_BITS == 18);

/// The slope of a sub-interval, one clock later.
#[derive(LogicBlock)]
pub struct FineSlope {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// The sub-interval (phase bits 16:14).
    pub sub: Signal<In, Bits<3>>,
    /// `slope[sub]` of the clock before.
    pub slope: Signal<Out, Signed<18>>,
    slope_3: DFF<Signed<18>>,
    slope_at_01: Signal<Local, Signed<18>>,
    slope_at_23: Signal<Local, Signed<18>>,
    slope_at_45: Signal<Local, Signed<18>>,
    slope_at_67: Signal<Local, Signed<18>>,
    slope_at_0123: Signal<Local, Signed<18>>,
    slope_at_4567: Signal<Local, Signed<18>>,
    slope_at_0: Constant<Signed<18>>,
    slope_at_1: Constant<Signed<18>>,
    slope_at_2: Constant<Signed<18>>,
    slope_at_3: Constant<Signed<18>>,
    slope_at_4: Constant<Signed<18>>,
    slope_at_5: Constant<Signed<18>>,
    slope_at_6: Constant<Signed<18>>,
    slope_at_7: Constant<Signed<18>>,
}

impl FineSlope {
    /// The slopes of `fine_sine_table::slope`; the register at 0.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            sub: Default::default(),
            slope: Default::default(),
            slope_3: Default::default(),
            slope_at_01: Default::default(),
            slope_at_23: Default::default(),
            slope_at_45: Default::default(),
            slope_at_67: Default::default(),
            slope_at_0123: Default::default(),
            slope_at_4567: Default::default(),
            slope_at_0: slope_constant(0),
            slope_at_1: slope_constant(1),
            slope_at_2: slope_constant(2),
            slope_at_3: slope_constant(3),
            slope_at_4: slope_constant(4),
            slope_at_5: slope_constant(5),
            slope_at_6: slope_constant(6),
            slope_at_7: slope_constant(7),
        }
    }
}

impl Default for FineSlope {
    fn default() -> Self {
        Self::new()
    }
}

/// `slope[s]` as a constant of the block.
fn slope_constant(s: usize) -> Constant<Signed<18>> {
    assert!(s < SUBINTERVALS);
    Constant::new(i64::from(slope(s)).into())
}

impl Logic for FineSlope {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, slope_3);
        self.slope_at_01.next = self.slope_at_0.val();
        self.slope_at_23.next = self.slope_at_2.val();
        self.slope_at_45.next = self.slope_at_4.val();
        self.slope_at_67.next = self.slope_at_6.val();
        if self.sub.val().get_bit(0) {
            self.slope_at_01.next = self.slope_at_1.val();
            self.slope_at_23.next = self.slope_at_3.val();
            self.slope_at_45.next = self.slope_at_5.val();
            self.slope_at_67.next = self.slope_at_7.val();
        }
        self.slope_at_0123.next = self.slope_at_01.val();
        self.slope_at_4567.next = self.slope_at_45.val();
        if self.sub.val().get_bit(1) {
            self.slope_at_0123.next = self.slope_at_23.val();
            self.slope_at_4567.next = self.slope_at_67.val();
        }
        self.slope_3.d.next = self.slope_at_0123.val();
        if self.sub.val().get_bit(2) {
            self.slope_3.d.next = self.slope_at_4567.val();
        }
        self.slope.next = self.slope_3.q.val();
    }
}

crate::impl_clocked!(FineSlope);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};

    /// Every sub-interval's slope, one clock after its index.
    #[test]
    fn each_sub_interval_gives_its_slope_a_clock_later() {
        let mut uut = FineSlope::new();
        prepare(&mut uut);
        for s in (0..SUBINTERVALS).chain((0..SUBINTERVALS).rev()) {
            uut.sub.next = (s as u64).into();
            tick(&mut uut);
            assert_eq!(uut.slope.val(), i64::from(slope(s)).into(), "sub {s}");
        }
    }
}
