//! The IIR's sequencer: the program counter, the micro-program ROM and the
//! word register after it, the sample counter and the RAM addresses of the
//! word it runs.
//!
//! ```text
//!  x_valid ─► pc[8] ─► ROM[256 x 30] ─► [word_reg] ─┬─► factor, op, emit, x_select, flags
//!  (idle)      0, 1..=last, 0                        └─► slot rotation (base) ─► read_address, write_address [7]
//! ```
//!
//! `pc` idles at 0; `x_valid` there starts the program (pc = 1) and steps
//! `base`, the sample counter modulo 3; each clock after it the counter
//! moves on, back to 0 after the last word (`crate::iir_program::PROGRAM`).
//! The ROM word is registered once more in the fabric: a block RAM's
//! clock-to-output is too slow to feed the coefficient multiplexer. So the
//! word a clock runs is the one pc addressed two clocks before.
//!
//! Slot rotation (`crate::iir_program::physical_address`): the address
//! fields' bits 3:2 name a slot; a rotating slot r < 3 becomes (r + base)
//! mod 3, slot 3 stays, so a new sample overwrites the one three back and no
//! state word is copied. Every output depends on this block's registers
//! only. Power-up: pc, base and the word register 0 (the idle word).

use crate::iir_program::{PC_BITS, PROGRAM, RAM_ADDRESS_BITS, WORD_BITS};
use crate::primitives::MicrocodeRom;
use rust_hdl::prelude::*;

/// Program counter, micro-program ROM, word register and slot rotation.
#[derive(LogicBlock)]
pub struct IirSequencer {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Pulse marking new input samples: starts the program when idle.
    pub x_valid: Signal<In, Bit>,
    /// High while the program counter is 0 (a strobe now starts it).
    pub idle: Signal<Out, Bit>,
    /// The running word's operand-a flag: sign-extend a state's top digit.
    pub wrap_top: Signal<Out, Bit>,
    /// Its accumulator-start flag: start from 2^29 (a rounding) instead of 0.
    pub round_start: Signal<Out, Bit>,
    /// Its publish flag: the staged outputs go out (the program's last word).
    pub publish: Signal<Out, Bit>,
    /// Its coefficient-digit field (`Factor::encode`).
    pub factor: Signal<Out, Bits<5>>,
    /// Its accumulator operation (`AccumulatorOp`).
    pub op: Signal<Out, Bits<2>>,
    /// Its emission (`Emit`).
    pub emit: Signal<Out, Bits<3>>,
    /// Its input-digit select (channel and digit, 0..5).
    pub x_select: Signal<Out, Bits<3>>,
    /// The digit RAM address it reads, slots rotated.
    pub read_address: Signal<Out, Bits<RAM_ADDRESS_BITS>>,
    /// The digit RAM address it writes, slots rotated.
    pub write_address: Signal<Out, Bits<RAM_ADDRESS_BITS>>,
    rom: MicrocodeRom<WORD_BITS, PC_BITS>,
    pc: DFF<Bits<PC_BITS>>,
    word_reg: DFF<Bits<WORD_BITS>>,
    base: DFF<Bits<2>>,
    read_field: Signal<Local, Bits<RAM_ADDRESS_BITS>>,
    write_field: Signal<Local, Bits<RAM_ADDRESS_BITS>>,
    read_sum: Signal<Local, Bits<3>>,
    read_wrapped: Signal<Local, Bits<3>>,
    read_slot: Signal<Local, Bits<2>>,
    write_sum: Signal<Local, Bits<3>>,
    write_wrapped: Signal<Local, Bits<3>>,
    write_slot: Signal<Local, Bits<2>>,
    last_pc: Constant<Bits<PC_BITS>>,
    slot_mask: Constant<Bits<RAM_ADDRESS_BITS>>,
}

impl IirSequencer {
    /// An idle sequencer holding `PROGRAM`.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            x_valid: Default::default(),
            idle: Default::default(),
            wrap_top: Default::default(),
            round_start: Default::default(),
            publish: Default::default(),
            factor: Default::default(),
            op: Default::default(),
            emit: Default::default(),
            x_select: Default::default(),
            read_address: Default::default(),
            write_address: Default::default(),
            rom: MicrocodeRom::new(PROGRAM.image()),
            pc: Default::default(),
            word_reg: Default::default(),
            base: Default::default(),
            read_field: Default::default(),
            write_field: Default::default(),
            read_sum: Default::default(),
            read_wrapped: Default::default(),
            read_slot: Default::default(),
            write_sum: Default::default(),
            write_wrapped: Default::default(),
            write_slot: Default::default(),
            last_pc: Constant::new(((PROGRAM.words.len() - 1) as u64).into()),
            slot_mask: Constant::new(0b111_0011u64.into()),
        }
    }
}

impl Default for IirSequencer {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for IirSequencer {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, pc, word_reg, base);
        self.rom.clock.next = self.clock.val();
        // Program counter: idle at 0 until a strobe, then 1..=last, then 0.
        self.rom.address.next = self.pc.q.val();
        self.idle.next = self.pc.q.val() == 0;
        if self.pc.q.val() == 0 {
            if self.x_valid.val() {
                self.pc.d.next = 1.into();
                // base counts samples modulo 3 (the slot rotation).
                if self.base.q.val() == 0 {
                    self.base.d.next = 1.into();
                }
                if self.base.q.val() == 1 {
                    self.base.d.next = 2.into();
                }
                if self.base.q.val() == 2 {
                    self.base.d.next = 0.into();
                }
            }
        } else {
            self.pc.d.next = self.pc.q.val() + 1;
            if self.pc.q.val() == self.last_pc.val() {
                self.pc.d.next = 0.into();
            }
        }
        // Fields of the word (`MicroWord::encode`).
        self.word_reg.d.next = self.rom.q.val();
        self.wrap_top.next = self.word_reg.q.val().get_bit(7);
        self.round_start.next = self.word_reg.q.val().get_bit(15);
        self.publish.next = self.word_reg.q.val().get_bit(29);
        self.read_field.next = self.word_reg.q.val().get_bits::<RAM_ADDRESS_BITS>(0);
        self.factor.next = self.word_reg.q.val().get_bits::<5>(8);
        self.op.next = self.word_reg.q.val().get_bits::<2>(13);
        self.emit.next = self.word_reg.q.val().get_bits::<3>(16);
        self.write_field.next = self.word_reg.q.val().get_bits::<RAM_ADDRESS_BITS>(19);
        self.x_select.next = self.word_reg.q.val().get_bits::<3>(26);
        // Slot rotation: slot r < 3 becomes (r + base) mod 3; slot 3 stays.
        self.read_sum.next = bit_cast::<3, 2>(self.read_field.val().get_bits::<2>(2))
            + bit_cast::<3, 2>(self.base.q.val());
        self.read_wrapped.next = self.read_sum.val() - 3;
        self.read_slot.next = self.read_sum.val().get_bits::<2>(0);
        if self.read_sum.val() >= 3 {
            self.read_slot.next = self.read_wrapped.val().get_bits::<2>(0);
        }
        if self.read_field.val().get_bits::<2>(2) == 3 {
            self.read_slot.next = 3.into();
        }
        self.write_sum.next = bit_cast::<3, 2>(self.write_field.val().get_bits::<2>(2))
            + bit_cast::<3, 2>(self.base.q.val());
        self.write_wrapped.next = self.write_sum.val() - 3;
        self.write_slot.next = self.write_sum.val().get_bits::<2>(0);
        if self.write_sum.val() >= 3 {
            self.write_slot.next = self.write_wrapped.val().get_bits::<2>(0);
        }
        if self.write_field.val().get_bits::<2>(2) == 3 {
            self.write_slot.next = 3.into();
        }
        self.read_address.next = (self.read_field.val() & self.slot_mask.val())
            | (bit_cast::<RAM_ADDRESS_BITS, 2>(self.read_slot.val()) << 2);
        self.write_address.next = (self.write_field.val() & self.slot_mask.val())
            | (bit_cast::<RAM_ADDRESS_BITS, 2>(self.write_slot.val()) << 2);
    }
}

crate::impl_clocked!(IirSequencer);
