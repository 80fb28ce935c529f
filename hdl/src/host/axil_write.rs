//! `AxilWrite`: the AXI4-Lite write channels (AW, W, B) of the bus top,
//! as one block (after verilog-axi's `axil_reg_if_wr`).
//!
//! ```text
//!  s_axil_aw* ──► AW holding register (aw_held, aw_index) ─┐
//!  s_axil_w*  ──► W holding register (w_held, w_data, w_strb)├─► write, index, data, mask
//!                                                            │        │
//!  s_axil_b*  ◄── B register (b_valid, b_resp) ◄── accepted ◄┘ (the register file's answer)
//! ```
//!
//! Widths: address `ADDRESS_BITS` (byte address, bits 1..0 ignored; the
//! word index is bits `WORD_INDEX_BITS + 1..2`), data 32 bits, 4 strobes,
//! response 2 bits (0 OKAY, 2 SLVERR).
//!
//! AW and W are each taken into a holding register when it is empty
//! (`awready` = AW holding empty, likewise `wready`), in either order or
//! together. `write` is high for the one clock at which both are held and
//! no response is pending: the register file writes `data` under `mask`
//! to word `index` at that edge and answers `accepted`; B is raised at the
//! same edge with OKAY, or SLVERR when the write was not accepted
//! (read-only or unmapped word), and held until `bready`. Latency: B two
//! clocks after the later of AW and W. Every ready and valid here is a
//! register's output, never a combinational function of a valid, and so
//! are `write`, `index`, `data` and `mask`: the register file's answer
//! can depend on them without a loop. `reset` (active high, synchronous)
//! empties both holding registers and drops B.

use super::register_map::{self, ADDRESS_BITS, DATA_BITS, WORD_INDEX_BITS};
use super::{OKAY, RESP_BITS, SLVERR};
use rust_hdl::prelude::*;

/// The write half of an AXI4-Lite register slave.
#[derive(LogicBlock)]
pub struct AxilWrite {
    /// The bus clock (rising edge).
    pub clock: Signal<In, Clock>,
    /// Synchronous reset of the channel state (active high).
    pub reset: Signal<In, Bit>,
    /// AXI4-Lite write address valid.
    pub s_axil_awvalid: Signal<In, Bit>,
    /// AXI4-Lite write address ready: the AW holding register is empty.
    pub s_axil_awready: Signal<Out, Bit>,
    /// AXI4-Lite write byte address (bits 1..0 ignored).
    pub s_axil_awaddr: Signal<In, Bits<ADDRESS_BITS>>,
    /// AXI4-Lite write data valid.
    pub s_axil_wvalid: Signal<In, Bit>,
    /// AXI4-Lite write data ready: the W holding register is empty.
    pub s_axil_wready: Signal<Out, Bit>,
    /// AXI4-Lite write data.
    pub s_axil_wdata: Signal<In, Bits<DATA_BITS>>,
    /// AXI4-Lite write strobes, one per byte.
    pub s_axil_wstrb: Signal<In, Bits<4>>,
    /// AXI4-Lite write response valid.
    pub s_axil_bvalid: Signal<Out, Bit>,
    /// AXI4-Lite write response ready.
    pub s_axil_bready: Signal<In, Bit>,
    /// AXI4-Lite write response: 0 OKAY, 2 SLVERR.
    pub s_axil_bresp: Signal<Out, Bits<RESP_BITS>>,
    /// The write happens at this edge (one clock per AW/W pair).
    pub write: Signal<Out, Bit>,
    /// Word index (byte address / 4) of the held address.
    pub index: Signal<Out, Bits<WORD_INDEX_BITS>>,
    /// The held write data.
    pub data: Signal<Out, Bits<DATA_BITS>>,
    /// The held strobes as a bit mask (0xff per selected byte).
    pub mask: Signal<Out, Bits<DATA_BITS>>,
    /// The register file took the write (else B answers SLVERR).
    pub accepted: Signal<In, Bit>,
    aw_held: DFF<Bit>,
    aw_index: DFF<Bits<WORD_INDEX_BITS>>,
    w_held: DFF<Bit>,
    w_data: DFF<Bits<DATA_BITS>>,
    w_strb: DFF<Bits<4>>,
    b_valid: DFF<Bit>,
    b_resp: DFF<Bits<RESP_BITS>>,
    slverr: Constant<Bits<RESP_BITS>>,
    byte_lane: Constant<Bits<DATA_BITS>>,
    lane0: Signal<Local, Bits<DATA_BITS>>,
    lane1: Signal<Local, Bits<DATA_BITS>>,
    lane2: Signal<Local, Bits<DATA_BITS>>,
    lane3: Signal<Local, Bits<DATA_BITS>>,
}

impl AxilWrite {
    /// The channels at power-up: nothing held, no response.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            reset: Default::default(),
            s_axil_awvalid: Default::default(),
            s_axil_awready: Default::default(),
            s_axil_awaddr: Default::default(),
            s_axil_wvalid: Default::default(),
            s_axil_wready: Default::default(),
            s_axil_wdata: Default::default(),
            s_axil_wstrb: Default::default(),
            s_axil_bvalid: Default::default(),
            s_axil_bready: Default::default(),
            s_axil_bresp: Default::default(),
            write: Default::default(),
            index: Default::default(),
            data: Default::default(),
            mask: Default::default(),
            accepted: Default::default(),
            aw_held: Default::default(),
            aw_index: Default::default(),
            w_held: Default::default(),
            w_data: Default::default(),
            w_strb: Default::default(),
            b_valid: Default::default(),
            b_resp: Default::default(),
            slverr: Constant::new(u64::from(SLVERR).into()),
            byte_lane: Constant::new(0xffu64.into()),
            lane0: Default::default(),
            lane1: Default::default(),
            lane2: Default::default(),
            lane3: Default::default(),
        }
    }
}

impl Default for AxilWrite {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for AxilWrite {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, aw_held, aw_index, w_held, w_data, w_strb, b_valid, b_resp
        );
        self.s_axil_awready.next = !self.aw_held.q.val();
        self.s_axil_wready.next = !self.w_held.q.val();
        self.s_axil_bvalid.next = self.b_valid.q.val();
        self.s_axil_bresp.next = self.b_resp.q.val();
        if self.s_axil_awvalid.val() & (!self.aw_held.q.val()) {
            self.aw_held.d.next = true;
            self.aw_index.d.next = self.s_axil_awaddr.val().get_bits::<WORD_INDEX_BITS>(2);
        }
        if self.s_axil_wvalid.val() & (!self.w_held.q.val()) {
            self.w_held.d.next = true;
            self.w_data.d.next = self.s_axil_wdata.val();
            self.w_strb.d.next = self.s_axil_wstrb.val();
        }
        self.write.next = self.aw_held.q.val() & self.w_held.q.val() & (!self.b_valid.q.val());
        self.index.next = self.aw_index.q.val();
        self.data.next = self.w_data.q.val();
        // The byte lanes the strobes select.
        self.lane0.next = 0.into();
        self.lane1.next = 0.into();
        self.lane2.next = 0.into();
        self.lane3.next = 0.into();
        if self.w_strb.q.val().get_bit(0) {
            self.lane0.next = self.byte_lane.val();
        }
        if self.w_strb.q.val().get_bit(1) {
            self.lane1.next = self.byte_lane.val() << 8;
        }
        if self.w_strb.q.val().get_bit(2) {
            self.lane2.next = self.byte_lane.val() << 16;
        }
        if self.w_strb.q.val().get_bit(3) {
            self.lane3.next = self.byte_lane.val() << 24;
        }
        self.mask.next = self.lane0.val() | self.lane1.val() | self.lane2.val() | self.lane3.val();
        if self.write.val() {
            self.aw_held.d.next = false;
            self.w_held.d.next = false;
            self.b_valid.d.next = true;
            self.b_resp.d.next = 0.into();
            if !self.accepted.val() {
                self.b_resp.d.next = self.slverr.val();
            }
        }
        if self.b_valid.q.val() & self.s_axil_bready.val() {
            self.b_valid.d.next = false;
        }
        if self.reset.val() {
            self.aw_held.d.next = false;
            self.aw_index.d.next = 0.into();
            self.w_held.d.next = false;
            self.w_data.d.next = 0.into();
            self.w_strb.d.next = 0.into();
            self.b_valid.d.next = false;
            self.b_resp.d.next = 0.into();
        }
    }
}

crate::impl_clocked!(AxilWrite);

/// A write the channels hand to the register file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Write {
    /// Word index (byte address / 4).
    pub index: u32,
    /// The data word.
    pub data: u32,
    /// The byte strobes (4 bits).
    pub strb: u8,
}

impl Write {
    /// The strobes as a bit mask, as the block's `mask` port.
    pub fn mask(&self) -> u32 {
        register_map::byte_mask(self.strb)
    }
}

/// Bit-true model of `AxilWrite`: its registers, an edge at a time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WriteChannels {
    aw_held: bool,
    aw_index: u32,
    w_held: bool,
    w_data: u32,
    w_strb: u8,
    b_valid: bool,
    b_resp: u8,
}

impl WriteChannels {
    /// `(awready, wready)` during the current cycle.
    pub fn ready(&self) -> (bool, bool) {
        (!self.aw_held, !self.w_held)
    }

    /// `(bvalid, bresp)` during the current cycle.
    pub fn response(&self) -> (bool, u8) {
        (self.b_valid, self.b_resp)
    }

    /// The write happening at the coming edge, if any (the `write` port).
    pub fn write(&self) -> Option<Write> {
        (self.aw_held && self.w_held && !self.b_valid).then_some(Write {
            index: self.aw_index,
            data: self.w_data,
            strb: self.w_strb,
        })
    }

    /// One edge with this cycle's AW (`awaddr` when `awvalid`), W
    /// (`(wdata, wstrb)` when `wvalid`), `bready`, and the register file's
    /// answer to `write()` (read only when there is one).
    pub fn step(&mut self, aw: Option<u8>, w: Option<(u32, u8)>, bready: bool, accepted: bool) {
        let now = *self;
        if let (Some(address), false) = (aw, now.aw_held) {
            self.aw_held = true;
            self.aw_index = u32::from(address) >> 2;
        }
        if let (Some((data, strb)), false) = (w, now.w_held) {
            self.w_held = true;
            self.w_data = data;
            self.w_strb = strb & 0xf;
        }
        if now.write().is_some() {
            self.aw_held = false;
            self.w_held = false;
            self.b_valid = true;
            self.b_resp = if accepted { OKAY } else { SLVERR };
        }
        if now.b_valid && bready {
            self.b_valid = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::test_util::Rng;

    /// The block against its model on random traffic: valids, readies
    /// and the register file's answer at random, resets now and then.
    /// Every output every clock; the write's index, data and mask on the
    /// clocks that write.
    #[test]
    fn the_channels_match_their_model() {
        let mut uut = AxilWrite::new();
        prepare(&mut uut);
        let mut model = WriteChannels::default();
        let mut rng = Rng::new(21);
        let mut writes = 0;
        for cycle in 0..50_000 {
            let r = rng.next_u64();
            let aw = (r & 3 == 0).then_some((r >> 8) as u8);
            let w = (r >> 2 & 3 == 0).then_some(((r >> 16) as u32, (r >> 48) as u8 & 0xf));
            let (bready, accepted, reset) = (r >> 4 & 1 == 1, r >> 5 & 1 == 1, r >> 56 == 0);
            uut.s_axil_awvalid.next = aw.is_some();
            uut.s_axil_awaddr.next = u64::from(aw.unwrap_or(0)).into();
            uut.s_axil_wvalid.next = w.is_some();
            uut.s_axil_wdata.next = u64::from(w.unwrap_or_default().0).into();
            uut.s_axil_wstrb.next = u64::from(w.unwrap_or_default().1).into();
            uut.s_axil_bready.next = bready;
            uut.accepted.next = accepted;
            uut.reset.next = reset;
            let (awready, wready) = model.ready();
            let (bvalid, bresp) = model.response();
            assert_eq!(uut.s_axil_awready.val(), awready, "cycle {cycle}");
            assert_eq!(uut.s_axil_wready.val(), wready, "cycle {cycle}");
            assert_eq!(uut.s_axil_bvalid.val(), bvalid, "cycle {cycle}");
            assert_eq!(uut.s_axil_bresp.val().index() as u8, bresp, "cycle {cycle}");
            let write = model.write();
            assert_eq!(uut.write.val(), write.is_some(), "cycle {cycle}");
            if let Some(write) = write {
                assert_eq!(uut.index.val().index() as u32, write.index, "cycle {cycle}");
                assert_eq!(uut.data.val().index() as u32, write.data, "cycle {cycle}");
                assert_eq!(uut.mask.val().index() as u32, write.mask(), "cycle {cycle}");
                writes += 1;
            }
            tick(&mut uut);
            model.step(aw, w, bready, accepted);
            if reset {
                model = WriteChannels::default();
            }
        }
        assert!(writes > 5000, "{writes} writes");
    }
}
