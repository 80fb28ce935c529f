//! `SampleFifo`: the z-sample FIFO in front of the AXI4-Stream master.
//!
//! ```text
//!  push, push_data ──► slots[write_ptr] ──► slots[read_ptr] ──► tdata, tvalid (count != 0)
//!                                                        tready: pop when tvalid && tready
//!  push while count == FIFO_DEPTH ──► dropped, `dropped` high for that clock
//! ```
//!
//! FIFO_DEPTH registers of SAMPLE_BITS, a circular buffer. `tdata` is the
//! oldest slot, combinational from registers only, so it cannot change
//! while `tvalid && !tready` (nothing pops and the read pointer holds). A
//! push on a full FIFO is dropped even when a pop happens in the same
//! clock (the simple rule the bit-true model copies). Latency: a pushed
//! sample is offered on the next clock. `reset` empties the FIFO and
//! clears the slots.

use rust_hdl::prelude::*;

/// Samples the FIFO holds.
pub const FIFO_DEPTH: usize = 4;
/// Bits of a read or write pointer (FIFO_DEPTH = 2^POINTER_BITS).
pub const POINTER_BITS: usize = 2;
/// Bits of the fill count (0..=FIFO_DEPTH).
pub const COUNT_BITS: usize = POINTER_BITS + 1;
/// Width of one sample word (`tdata`): z1, z2 and a 16-bit sequence number.
pub const SAMPLE_BITS: usize = 96;

const _: () = assert!(FIFO_DEPTH == 1 << POINTER_BITS);

/// A FIFO_DEPTH-deep register FIFO with an AXI4-Stream style output.
#[derive(LogicBlock)]
pub struct SampleFifo {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset: empty, slots cleared (active high).
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
    slots: [DFF<Bits<SAMPLE_BITS>>; FIFO_DEPTH],
    write_ptr: DFF<Bits<POINTER_BITS>>,
    read_ptr: DFF<Bits<POINTER_BITS>>,
    count: DFF<Bits<COUNT_BITS>>,
    full_count: Constant<Bits<COUNT_BITS>>,
    full: Signal<Local, Bit>,
    accept: Signal<Local, Bit>,
    pop: Signal<Local, Bit>,
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
            slots: Default::default(),
            write_ptr: Default::default(),
            read_ptr: Default::default(),
            count: Default::default(),
            full_count: Constant::new((FIFO_DEPTH as u64).into()),
            full: Default::default(),
            accept: Default::default(),
            pop: Default::default(),
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
        dff_setup!(self, clock, write_ptr, read_ptr, count);
        for i in 0..FIFO_DEPTH {
            self.slots[i].clock.next = self.clock.val();
            self.slots[i].d.next = self.slots[i].q.val();
        }
        self.full.next = self.count.q.val() == self.full_count.val();
        self.tvalid.next = self.count.q.val().any();
        self.pop.next = self.count.q.val().any() & self.tready.val();
        self.accept.next = self.push.val() & (!self.full.val());
        self.dropped.next = self.push.val() & self.full.val();
        self.tdata.next = self.slots[0].q.val();
        for i in 0..FIFO_DEPTH {
            if self.read_ptr.q.val().index() == i {
                self.tdata.next = self.slots[i].q.val();
            }
            if self.accept.val() & (self.write_ptr.q.val().index() == i) {
                self.slots[i].d.next = self.push_data.val();
            }
        }
        if self.accept.val() {
            self.write_ptr.d.next = self.write_ptr.q.val() + 1;
        }
        if self.pop.val() {
            self.read_ptr.d.next = self.read_ptr.q.val() + 1;
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
            for i in 0..FIFO_DEPTH {
                self.slots[i].d.next = 0.into();
            }
        }
    }
}
