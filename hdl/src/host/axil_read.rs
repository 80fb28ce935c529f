//! `AxilRead`: the AXI4-Lite read channels (AR, R) of the bus top, as one
//! block (after verilog-axi's `axil_reg_if_rd`).
//!
//! ```text
//!  s_axil_ar* ──► AR holding register (ar_held, ar_index) ──► read, index
//!                                                               │
//!  s_axil_r*  ◄── R register (r_valid, r_data, r_resp) ◄── word, accepted
//!                                                 (the register file's answer)
//! ```
//!
//! Widths: address `ADDRESS_BITS` (byte address, bits 1..0 ignored), data
//! 32 bits, response 2 bits (0 OKAY, 2 SLVERR).
//!
//! AR is taken into its holding register when it is empty (`arready` =
//! AR holding empty). `read` is high for the one clock at which an
//! address is held and no R is pending: the register file decodes `index`
//! (during every clock, from the register) and answers `word` and
//! `accepted`; at that edge R is raised with the word and OKAY, or with
//! SLVERR for an unmapped word, and held, data fixed, until `rready`.
//! Latency: R two clocks after AR. `arready`, `rvalid`, `read` and `index`
//! are registers' outputs, never combinational functions of a valid.
//! `reset` (active high, synchronous) empties the holding register and
//! drops R.

use super::register_map::{ADDRESS_BITS, DATA_BITS, WORD_INDEX_BITS};
use super::{OKAY, RESP_BITS, SLVERR};
use rust_hdl::prelude::*;

/// The read half of an AXI4-Lite register slave.
#[derive(LogicBlock)]
pub struct AxilRead {
    /// The bus clock (rising edge).
    pub clock: Signal<In, Clock>,
    /// Synchronous reset of the channel state (active high).
    pub reset: Signal<In, Bit>,
    /// AXI4-Lite read address valid.
    pub s_axil_arvalid: Signal<In, Bit>,
    /// AXI4-Lite read address ready: the AR holding register is empty.
    pub s_axil_arready: Signal<Out, Bit>,
    /// AXI4-Lite read byte address (bits 1..0 ignored).
    pub s_axil_araddr: Signal<In, Bits<ADDRESS_BITS>>,
    /// AXI4-Lite read data valid.
    pub s_axil_rvalid: Signal<Out, Bit>,
    /// AXI4-Lite read data ready.
    pub s_axil_rready: Signal<In, Bit>,
    /// AXI4-Lite read data.
    pub s_axil_rdata: Signal<Out, Bits<DATA_BITS>>,
    /// AXI4-Lite read response: 0 OKAY, 2 SLVERR.
    pub s_axil_rresp: Signal<Out, Bits<RESP_BITS>>,
    /// The read happens at this edge (one clock per AR).
    pub read: Signal<Out, Bit>,
    /// Word index (byte address / 4) of the held address.
    pub index: Signal<Out, Bits<WORD_INDEX_BITS>>,
    /// The word at `index`, from the register file.
    pub word: Signal<In, Bits<DATA_BITS>>,
    /// `index` is a mapped word (else R answers SLVERR).
    pub accepted: Signal<In, Bit>,
    ar_held: DFF<Bit>,
    ar_index: DFF<Bits<WORD_INDEX_BITS>>,
    r_valid: DFF<Bit>,
    r_data: DFF<Bits<DATA_BITS>>,
    r_resp: DFF<Bits<RESP_BITS>>,
    slverr: Constant<Bits<RESP_BITS>>,
}

impl AxilRead {
    /// The channels at power-up: nothing held, no response.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            reset: Default::default(),
            s_axil_arvalid: Default::default(),
            s_axil_arready: Default::default(),
            s_axil_araddr: Default::default(),
            s_axil_rvalid: Default::default(),
            s_axil_rready: Default::default(),
            s_axil_rdata: Default::default(),
            s_axil_rresp: Default::default(),
            read: Default::default(),
            index: Default::default(),
            word: Default::default(),
            accepted: Default::default(),
            ar_held: Default::default(),
            ar_index: Default::default(),
            r_valid: Default::default(),
            r_data: Default::default(),
            r_resp: Default::default(),
            slverr: Constant::new(u64::from(SLVERR).into()),
        }
    }
}

impl Default for AxilRead {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for AxilRead {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, ar_held, ar_index, r_valid, r_data, r_resp);
        self.s_axil_arready.next = !self.ar_held.q.val();
        self.s_axil_rvalid.next = self.r_valid.q.val();
        self.s_axil_rdata.next = self.r_data.q.val();
        self.s_axil_rresp.next = self.r_resp.q.val();
        if self.s_axil_arvalid.val() & (!self.ar_held.q.val()) {
            self.ar_held.d.next = true;
            self.ar_index.d.next = self.s_axil_araddr.val().get_bits::<WORD_INDEX_BITS>(2);
        }
        self.read.next = self.ar_held.q.val() & (!self.r_valid.q.val());
        self.index.next = self.ar_index.q.val();
        if self.read.val() {
            self.ar_held.d.next = false;
            self.r_valid.d.next = true;
            self.r_data.d.next = self.word.val();
            self.r_resp.d.next = 0.into();
            if !self.accepted.val() {
                self.r_resp.d.next = self.slverr.val();
            }
        }
        if self.r_valid.q.val() & self.s_axil_rready.val() {
            self.r_valid.d.next = false;
        }
        if self.reset.val() {
            self.ar_held.d.next = false;
            self.ar_index.d.next = 0.into();
            self.r_valid.d.next = false;
            self.r_data.d.next = 0.into();
            self.r_resp.d.next = 0.into();
        }
    }
}

crate::impl_clocked!(AxilRead);

/// Bit-true model of `AxilRead`: its registers, an edge at a time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReadChannels {
    ar_held: bool,
    ar_index: u32,
    r_valid: bool,
    r_data: u32,
    r_resp: u8,
}

impl ReadChannels {
    /// `arready` during the current cycle.
    pub fn ready(&self) -> bool {
        !self.ar_held
    }

    /// `(rvalid, rdata, rresp)` during the current cycle.
    pub fn response(&self) -> (bool, u32, u8) {
        (self.r_valid, self.r_data, self.r_resp)
    }

    /// The word index read at the coming edge, if any (the `read` port).
    pub fn read(&self) -> Option<u32> {
        (self.ar_held && !self.r_valid).then_some(self.ar_index)
    }

    /// One edge with this cycle's AR (`araddr` when `arvalid`), `rready`,
    /// and the register file's answer to `read()`: the word, or `None`
    /// for an unmapped index (read only when there is a read).
    pub fn step(&mut self, ar: Option<u8>, rready: bool, answer: Option<u32>) {
        let now = *self;
        if let (Some(address), false) = (ar, now.ar_held) {
            self.ar_held = true;
            self.ar_index = u32::from(address) >> 2;
        }
        if now.read().is_some() {
            self.ar_held = false;
            self.r_valid = true;
            self.r_data = answer.unwrap_or(0);
            self.r_resp = if answer.is_some() { OKAY } else { SLVERR };
        }
        if now.r_valid && rready {
            self.r_valid = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::test_util::Rng;

    /// The block against its model on random traffic: valids, readies
    /// and the register file's answers at random, resets now and then;
    /// every output every clock, the index on the clocks that read.
    #[test]
    fn the_channels_match_their_model() {
        let mut uut = AxilRead::new();
        prepare(&mut uut);
        let mut model = ReadChannels::default();
        let mut rng = Rng::new(22);
        let mut reads = 0;
        for cycle in 0..50_000 {
            let r = rng.next_u64();
            let ar = (r & 3 == 0).then_some((r >> 8) as u8);
            let (rready, mapped, reset) = (r >> 2 & 1 == 1, r >> 3 & 1 == 1, r >> 56 == 0);
            let word = (r >> 16) as u32;
            uut.s_axil_arvalid.next = ar.is_some();
            uut.s_axil_araddr.next = u64::from(ar.unwrap_or(0)).into();
            uut.s_axil_rready.next = rready;
            uut.word.next = u64::from(if mapped { word } else { 0 }).into();
            uut.accepted.next = mapped;
            uut.reset.next = reset;
            let (rvalid, rdata, rresp) = model.response();
            assert_eq!(uut.s_axil_arready.val(), model.ready(), "cycle {cycle}");
            assert_eq!(uut.s_axil_rvalid.val(), rvalid, "cycle {cycle}");
            assert_eq!(
                uut.s_axil_rdata.val().index() as u32,
                rdata,
                "cycle {cycle}"
            );
            assert_eq!(uut.s_axil_rresp.val().index() as u8, rresp, "cycle {cycle}");
            let read = model.read();
            assert_eq!(uut.read.val(), read.is_some(), "cycle {cycle}");
            if let Some(index) = read {
                assert_eq!(uut.index.val().index() as u32, index, "cycle {cycle}");
                reads += 1;
            }
            tick(&mut uut);
            model.step(ar, rready, mapped.then_some(word));
            if reset {
                model = ReadChannels::default();
            }
        }
        assert!(reads > 5000, "{reads} reads");
    }
}
