//! The IIR's digit store: the digit RAM and what the program writes into
//! it (a finished column digit, a result's top digit, or a digit of a
//! captured input), and the output staging register that z1 and z2 are
//! published from.
//!
//! ```text
//!  x1, x2 [40] ─► [x1_held, x2_held] ─► input digit (x_select) ─┐
//!  column[15] (the accumulator's low bits) ─► digit, top digit ────────────────┼─ emit ─► RAM[128 x 16] ─► [q] (operand a)
//!                             └──────────── emit 3 ─► stage[90] ─┴─ publish ─► [z1, z2, z_valid]
//! ```
//!
//! `emit` (`crate::iir_program::Emit`): 1 writes the accumulator's low 15
//! bits as an unsigned digit, 2 the same sign-extended (a result's top
//! digit), 4 a digit of the input `x_select` names (0..2 channel 1's, 3..5
//! channel 2's; the top one 10 bits, signed), and 3 shifts the digit into
//! the top of the staging register; `publish` copies the staged digits
//! 0..2 to z1 and 3..5 to z2 and pulses z_valid. The inputs are captured
//! at `capture` (a strobe in idle). Every output is a register (the RAM
//! reads into one). Power-up: all 0.

use crate::iir_program::{DIGIT_BITS, OPERAND_BITS, RAM_ADDRESS_BITS};
use crate::iir_widths::SAMPLE_BITS;
use crate::primitives::DigitRam;
use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// Width of the output staging register: two samples of three digits.
const STAGE_BITS: usize = 6 * DIGIT_BITS;

/// The digit RAM, its writes, the captured inputs and the staged outputs.
#[derive(LogicBlock)]
pub struct IirDigits {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Input sample of channel 1.
    pub x1: Signal<In, Signed<SAMPLE_BITS>>,
    /// Input sample of channel 2.
    pub x2: Signal<In, Signed<SAMPLE_BITS>>,
    /// Capture x1 and x2 (a strobe while the program is idle).
    pub capture: Signal<In, Bit>,
    /// The RAM address read this clock.
    pub read_address: Signal<In, Bits<RAM_ADDRESS_BITS>>,
    /// The RAM address written this clock.
    pub write_address: Signal<In, Bits<RAM_ADDRESS_BITS>>,
    /// What this clock writes (`Emit`).
    pub emit: Signal<In, Bits<3>>,
    /// Which input digit `emit` 4 writes (0..5).
    pub x_select: Signal<In, Bits<3>>,
    /// The column accumulator's low 15 bits: the finished digit.
    pub column: Signal<In, Signed<DIGIT_BITS>>,
    /// Publish the staged outputs.
    pub publish: Signal<In, Bit>,
    /// The RAM word read the clock before.
    pub q: Signal<Out, Signed<OPERAND_BITS>>,
    /// Filtered output of channel 1.
    pub z1: Signal<Out, Signed<SAMPLE_BITS>>,
    /// Filtered output of channel 2.
    pub z2: Signal<Out, Signed<SAMPLE_BITS>>,
    /// One-clock pulse marking new `z1`, `z2`.
    pub z_valid: Signal<Out, Bit>,
    ram: DigitRam<RAM_ADDRESS_BITS>,
    x1_held: DFF<Signed<SAMPLE_BITS>>,
    x2_held: DFF<Signed<SAMPLE_BITS>>,
    stage: DFF<Bits<STAGE_BITS>>,
    z1_out: DFF<Signed<SAMPLE_BITS>>,
    z2_out: DFF<Signed<SAMPLE_BITS>>,
    z_valid_out: DFF<Bit>,
    digit_bits: Signal<Local, Bits<15>>,
    column_digit: Signal<Local, Signed<OPERAND_BITS>>,
    column_top: Signal<Local, Signed<15>>,
    column_top_digit: Signal<Local, Signed<OPERAND_BITS>>,
    x_low: Signal<Local, Signed<30>>,
    x_bits: Signal<Local, Bits<30>>,
    x_top: Signal<Local, Signed<10>>,
    input_digit: Signal<Local, Signed<OPERAND_BITS>>,
    x_top_digit: Signal<Local, Signed<OPERAND_BITS>>,
}

impl IirDigits {
    /// An empty store: RAM, inputs and outputs 0.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            x1: Default::default(),
            x2: Default::default(),
            capture: Default::default(),
            read_address: Default::default(),
            write_address: Default::default(),
            emit: Default::default(),
            x_select: Default::default(),
            column: Default::default(),
            publish: Default::default(),
            q: Default::default(),
            z1: Default::default(),
            z2: Default::default(),
            z_valid: Default::default(),
            ram: DigitRam::new(),
            x1_held: Default::default(),
            x2_held: Default::default(),
            stage: Default::default(),
            z1_out: Default::default(),
            z2_out: Default::default(),
            z_valid_out: Default::default(),
            digit_bits: Default::default(),
            column_digit: Default::default(),
            column_top: Default::default(),
            column_top_digit: Default::default(),
            x_low: Default::default(),
            x_bits: Default::default(),
            x_top: Default::default(),
            input_digit: Default::default(),
            x_top_digit: Default::default(),
        }
    }
}

impl Default for IirDigits {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for IirDigits {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            x1_held,
            x2_held,
            stage,
            z1_out,
            z2_out,
            z_valid_out
        );
        self.ram.clock.next = self.clock.val();
        self.ram.read_address.next = self.read_address.val();
        self.ram.write_address.next = self.write_address.val();
        self.q.next = self.ram.q.val();
        if self.capture.val() {
            self.x1_held.d.next = self.x1.val();
            self.x2_held.d.next = self.x2.val();
        }
        // The finished column digit, unsigned or as a top digit.
        self.column_top.next = self.column.val();
        self.digit_bits.next = unsigned_cast(self.column_top.val());
        self.column_digit.next = signed_cast(bit_cast::<OPERAND_BITS, 15>(self.digit_bits.val()));
        self.column_top_digit.next =
            signed_bit_cast_exact::<OPERAND_BITS, 15>(self.column_top.val());
        // An input digit: 15, 15 and 10 bits of x1 (0..2) or x2 (3..5).
        self.x_low.next = self.x1_held.q.val().get_bits::<30>(0);
        self.x_top.next = self.x1_held.q.val().get_bits::<10>(30);
        if self.x_select.val() >= 3 {
            self.x_low.next = self.x2_held.q.val().get_bits::<30>(0);
            self.x_top.next = self.x2_held.q.val().get_bits::<10>(30);
        }
        self.x_bits.next = unsigned_cast(self.x_low.val());
        self.x_top_digit.next = signed_bit_cast_exact::<OPERAND_BITS, 10>(self.x_top.val());
        self.input_digit.next = self.x_top_digit.val();
        if (self.x_select.val() == 0) | (self.x_select.val() == 3) {
            self.input_digit.next = signed_cast(bit_cast::<OPERAND_BITS, 15>(
                self.x_bits.val().get_bits::<15>(0),
            ));
        }
        if (self.x_select.val() == 1) | (self.x_select.val() == 4) {
            self.input_digit.next = signed_cast(bit_cast::<OPERAND_BITS, 15>(
                self.x_bits.val().get_bits::<15>(15),
            ));
        }
        // The emission.
        self.ram.write_enable.next = false;
        self.ram.write_data.next = self.column_digit.val();
        if self.emit.val() == 1 {
            self.ram.write_enable.next = true;
        }
        if self.emit.val() == 2 {
            self.ram.write_enable.next = true;
            self.ram.write_data.next = self.column_top_digit.val();
        }
        if self.emit.val() == 4 {
            self.ram.write_enable.next = true;
            self.ram.write_data.next = self.input_digit.val();
        }
        if self.emit.val() == 3 {
            // 75 = STAGE_BITS - 15: the new digit enters at the top.
            self.stage.d.next = (self.stage.q.val() >> 15)
                | (bit_cast::<STAGE_BITS, 15>(self.digit_bits.val()) << 75);
        }
        // Publish: z1 = staged digits 0..2, z2 = 3..5 (45 = 3 x 15).
        self.z_valid_out.d.next = self.publish.val();
        if self.publish.val() {
            self.z1_out.d.next = signed_cast(self.stage.q.val().get_bits::<SAMPLE_BITS>(0));
            self.z2_out.d.next = signed_cast(self.stage.q.val().get_bits::<SAMPLE_BITS>(45));
        }
        self.z1.next = self.z1_out.q.val();
        self.z2.next = self.z2_out.q.val();
        self.z_valid.next = self.z_valid_out.q.val();
    }
}

crate::impl_clocked!(IirDigits);
