//! `SampleFifo`: the z-sample FIFO in front of the AXI4-Stream master.
//!
//! ```text
//!  push, push_data ──► memory[write_ptr]      (block RAM, FIFO_DEPTH x SAMPLE_BITS)
//!                      memory[read_ptr] ──► [q] ──► out_data ──► tdata
//!                                                   out_valid ──► tvalid;  tready: pop
//!  push while count == FIFO_DEPTH ──► dropped, `dropped` high for that clock
//! ```
//!
//! A first-word-fall-through FIFO of FIFO_DEPTH samples: the samples wait in
//! a `WordRam` (six iCE40 `SB_RAM40_4K`, 16 bits wide each) and the oldest
//! one is offered from the output register `out_data`, which cannot change
//! while `tvalid && !tready`. `count` is every sample held: in the RAM, in
//! flight from it, and in the output register.
//!
//! Each clock the FIFO issues a read of the oldest stored word when the RAM
//! holds one, no read is in flight, and the output register is empty or
//! being popped (`issue`); the word arrives in the RAM's read register one
//! edge later (`fetching`) and enters `out_data` at the next. So a sample
//! pushed into an empty FIFO is offered 3 clocks later, and a busy stream
//! moves one sample per 2 clocks: the datapath makes one per R >= 166
//! clocks. A push on a full FIFO is dropped even when a pop happens in the
//! same clock (the simple rule the bit-true model copies). `reset` empties
//! the FIFO and clears `out_data`; the RAM's words are never read before
//! they are written again.
//!
//! The read address of a clock that issues no read is `read_ptr - 1`, so a
//! write never meets a read of its own word (the RAM's `no_rw_check`): the
//! written word is `read_ptr + stored`, which equals `read_ptr - 1` only with
//! all FIFO_DEPTH - 1 stored and the output full, when nothing is accepted.
//!
//! Resources (Yosys 0.23 `synth_ice40`, this block): 6 `SB_RAM40_4K`, the
//! 96-bit output register, pointers and counters; the 4-deep register FIFO
//! it replaces kept 384 flip-flops and a 96-bit 4-to-1 multiplexer.

use crate::primitives::WordRam;
use rust_hdl::prelude::*;
use std::collections::VecDeque;

/// Samples the FIFO holds (block RAM words; the output register holds the
/// oldest of them).
pub use gyrocal_regs::datapath::FIFO_DEPTH;
/// Bits of a read or write pointer (FIFO_DEPTH = 2^POINTER_BITS).
pub const POINTER_BITS: usize = 8;
/// Bits of the fill count (0..=FIFO_DEPTH).
pub const COUNT_BITS: usize = POINTER_BITS + 1;
/// Width of one sample word (`tdata`): z1, z2 and a 16-bit sequence number.
pub const SAMPLE_BITS: usize = 96;
/// Clocks from a push into an empty FIFO to `tvalid`: write, read, output
/// register.
pub const PUSH_TO_VALID: usize = 3;

const _: () = assert!(FIFO_DEPTH == 1 << POINTER_BITS);

/// A FIFO_DEPTH-deep block-RAM FIFO with an AXI4-Stream style output.
#[derive(LogicBlock)]
pub struct SampleFifo {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset: empty, output register cleared (active high).
    pub reset: Signal<In, Bit>,
    /// Offer `push_data` at this edge.
    pub push: Signal<In, Bit>,
    /// The sample to push.
    pub push_data: Signal<In, Bits<SAMPLE_BITS>>,
    /// Consumer ready (AXI4-Stream `tready`).
    pub tready: Signal<In, Bit>,
    /// A sample is offered (AXI4-Stream `tvalid`).
    pub tvalid: Signal<Out, Bit>,
    /// The oldest sample (AXI4-Stream `tdata`).
    pub tdata: Signal<Out, Bits<SAMPLE_BITS>>,
    /// High during a clock whose push is dropped (FIFO full).
    pub dropped: Signal<Out, Bit>,
    memory: WordRam<SAMPLE_BITS, POINTER_BITS>,
    write_ptr: DFF<Bits<POINTER_BITS>>,
    read_ptr: DFF<Bits<POINTER_BITS>>,
    count: DFF<Bits<COUNT_BITS>>,
    fetching: DFF<Bit>,
    out_valid: DFF<Bit>,
    out_data: DFF<Bits<SAMPLE_BITS>>,
    full_count: Constant<Bits<COUNT_BITS>>,
    full: Signal<Local, Bit>,
    accept: Signal<Local, Bit>,
    pop: Signal<Local, Bit>,
    busy: Signal<Local, Bit>,
    stored: Signal<Local, Bit>,
    issue: Signal<Local, Bit>,
}

impl SampleFifo {
    /// An empty FIFO.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            reset: Default::default(),
            push: Default::default(),
            push_data: Default::default(),
            tready: Default::default(),
            tvalid: Default::default(),
            tdata: Default::default(),
            dropped: Default::default(),
            memory: WordRam::new(),
            write_ptr: Default::default(),
            read_ptr: Default::default(),
            count: Default::default(),
            fetching: Default::default(),
            out_valid: Default::default(),
            out_data: Default::default(),
            full_count: Constant::new((FIFO_DEPTH as u64).into()),
            full: Default::default(),
            accept: Default::default(),
            pop: Default::default(),
            busy: Default::default(),
            stored: Default::default(),
            issue: Default::default(),
        }
    }
}

impl Default for SampleFifo {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for SampleFifo {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, write_ptr, read_ptr, count, fetching, out_valid, out_data
        );
        self.memory.clock.next = self.clock.val();
        self.full.next = self.count.q.val() == self.full_count.val();
        self.accept.next = self.push.val() & (!self.full.val());
        self.dropped.next = self.push.val() & self.full.val();
        self.pop.next = self.out_valid.q.val() & self.tready.val();
        // At most one of out_valid and fetching is set (a read is issued
        // only into an empty or emptying output register), so the RAM holds
        // count - busy words.
        self.busy.next = self.out_valid.q.val() | self.fetching.q.val();
        self.stored.next =
            (self.count.q.val() > 1) | ((self.count.q.val() == 1) & (!self.busy.val()));
        self.issue.next = self.stored.val()
            & (!self.fetching.q.val())
            & ((!self.out_valid.q.val()) | self.pop.val());
        // The RAM: write the pushed sample, read the oldest stored word.
        self.memory.write_enable.next = self.accept.val();
        self.memory.write_address.next = self.write_ptr.q.val();
        self.memory.write_data.next = signed_cast(self.push_data.val());
        self.memory.read_address.next = self.read_ptr.q.val() - 1;
        if self.issue.val() {
            self.memory.read_address.next = self.read_ptr.q.val();
            self.read_ptr.d.next = self.read_ptr.q.val() + 1;
        }
        if self.accept.val() {
            self.write_ptr.d.next = self.write_ptr.q.val() + 1;
        }
        self.fetching.d.next = self.issue.val();
        // The output register: emptied by a pop, filled by a fetched word.
        if self.pop.val() {
            self.out_valid.d.next = false;
        }
        if self.fetching.q.val() {
            self.out_valid.d.next = true;
            self.out_data.d.next = unsigned_cast(self.memory.q.val());
        }
        if self.accept.val() & (!self.pop.val()) {
            self.count.d.next = self.count.q.val() + 1;
        }
        if self.pop.val() & (!self.accept.val()) {
            self.count.d.next = self.count.q.val() - 1;
        }
        if self.reset.val() {
            self.write_ptr.d.next = 0.into();
            self.read_ptr.d.next = 0.into();
            self.count.d.next = 0.into();
            self.fetching.d.next = false;
            self.out_valid.d.next = false;
            self.out_data.d.next = 0.into();
        }
        self.tvalid.next = self.out_valid.q.val();
        self.tdata.next = self.out_data.q.val();
    }
}

crate::impl_clocked!(SampleFifo);

/// Bit-true model of `SampleFifo`: the words stored in its RAM, the RAM's
/// read register, and the output register. The
/// hardware's fill count is every sample held: `held()`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Fifo {
    stored: VecDeque<u128>,
    fetching: bool,
    read_word: u128,
    out_valid: bool,
    out_data: u128,
}

impl Fifo {
    /// `(tvalid, tdata)` during the current cycle.
    pub fn output(&self) -> (bool, u128) {
        (self.out_valid, self.out_data)
    }

    /// Samples held: in the RAM, in flight from it, in the output register.
    fn held(&self) -> usize {
        self.stored.len() + usize::from(self.fetching) + usize::from(self.out_valid)
    }

    /// One edge; returns true when the push was dropped.
    pub fn step(&mut self, push: Option<u128>, tready: bool) -> bool {
        let full = self.held() == FIFO_DEPTH;
        let pop = self.out_valid && tready;
        let issue = !self.stored.is_empty() && !self.fetching && (!self.out_valid || pop);
        if self.fetching {
            self.out_valid = true;
            self.out_data = self.read_word;
        } else if pop {
            self.out_valid = false;
        }
        self.fetching = issue;
        if issue {
            self.read_word = self.stored.pop_front().expect("issue needs a stored word");
        }
        match push {
            Some(sample) if !full => self.stored.push_back(sample),
            _ => {}
        }
        push.is_some() && full
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, settle, tick};
    use crate::primitives::convert::{bits_to_i128, u128_to_bits};
    use proptest::prelude::*;

    /// One clock's inputs: push (with its word), tready, reset.
    type Cycle = (Option<u128>, bool, bool);

    /// Drive the block and the bit-true model alike; compare `tvalid`,
    /// `tdata` and `dropped` every clock. Returns (drops, pops) seen.
    fn compare(cycles: &[Cycle]) -> (usize, usize) {
        let mut uut = SampleFifo::new();
        prepare(&mut uut);
        let mut model = Fifo::default();
        let (mut drops, mut pops) = (0, 0);
        for (n, &(push, tready, reset)) in cycles.iter().enumerate() {
            uut.push.next = push.is_some();
            uut.push_data.next = u128_to_bits(push.unwrap_or(0));
            uut.tready.next = tready;
            uut.reset.next = reset;
            // Combinational outputs of this cycle, before the edge.
            settle(&mut uut);
            let hw = (uut.tvalid.val(), bits_to_i128(uut.tdata.val()) as u128);
            assert_eq!(hw, model.output(), "cycle {n}");
            let dropped = model.step(push, tready);
            assert_eq!(uut.dropped.val(), dropped, "dropped, cycle {n}");
            drops += dropped as usize;
            pops += (hw.0 && tready) as usize;
            if reset {
                model = Fifo::default();
            }
            tick(&mut uut);
        }
        (drops, pops)
    }

    /// Pushes with probability `push_rate`, tready with `ready_rate`, in
    /// segments; the words count up so a lost or repeated one shows.
    fn traffic() -> impl Strategy<Value = Vec<Cycle>> {
        prop::collection::vec((0.0..1.0f64, 0.0..1.0f64, 10usize..700), 3..8).prop_flat_map(
            |segments| {
                let total: usize = segments.iter().map(|s| s.2).sum();
                prop::collection::vec((0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64), total).prop_map(
                    move |draws| {
                        let mut out = Vec::with_capacity(draws.len());
                        let mut word = 1u128;
                        let mut k = 0;
                        for &(push_rate, ready_rate, len) in &segments {
                            for &(p, r, x) in &draws[k..k + len] {
                                let push = (p < push_rate).then(|| {
                                    word += 1;
                                    word * 0x1_0000_0001_0000_0001
                                });
                                out.push((push, r < ready_rate, x < 0.002));
                            }
                            k += len;
                        }
                        out
                    },
                )
            },
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(12))]
        #[test]
        fn rtl_matches_model_on_random_traffic(cycles in traffic()) {
            compare(&cycles);
        }
    }

    #[test]
    fn a_long_stall_fills_the_fifo_and_drops_the_rest() {
        // Push every clock with the consumer stalled: FIFO_DEPTH samples are
        // held and the rest dropped; then drain them all, in order.
        let extra = 40;
        let mut cycles: Vec<Cycle> = (0..FIFO_DEPTH + extra)
            .map(|k| (Some(k as u128 + 1), false, false))
            .collect();
        cycles.extend((0..3 * FIFO_DEPTH).map(|_| (None, true, false)));
        let (drops, pops) = compare(&cycles);
        assert_eq!(drops, extra);
        assert_eq!(pops, FIFO_DEPTH);
    }
}
