//! `SettingRegister`: one read-write word of the AXI4-Lite register map.
//!
//! ```text
//!  write, write_index, write_data, write_mask ──► field <= (field & !mask | data & mask) & field_mask
//!  read_index ──► read_hit, read_word = field zero- or sign-extended to 32 bits
//!                 value = field (to the datapath port)
//! ```
//!
//! Built from one `register_map::Register`: word index, field width,
//! signedness and power-up value are `Constant`s. The field is a register
//! with that power-up value (Verilog `initial`), also restored while
//! `reset` is high. Latency: a write is visible on `value` one clock after
//! the edge that samples `write`; `read_word` is combinational from the
//! field.

use super::register_map::{Access, DATA_BITS, Register, WORD_INDEX_BITS};
use rust_hdl::prelude::*;

/// One read-write bus register.
#[derive(LogicBlock)]
pub struct SettingRegister {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Synchronous reset to the power-up value (active high).
    pub reset: Signal<In, Bit>,
    /// A bus write happens at this edge.
    pub write: Signal<In, Bit>,
    /// Word index (byte address / 4) of the write.
    pub write_index: Signal<In, Bits<WORD_INDEX_BITS>>,
    /// Write data.
    pub write_data: Signal<In, Bits<DATA_BITS>>,
    /// Bytes the write strobes select, as a bit mask.
    pub write_mask: Signal<In, Bits<DATA_BITS>>,
    /// Word index of the read being decoded.
    pub read_index: Signal<In, Bits<WORD_INDEX_BITS>>,
    /// The field, zero-extended: what the datapath port sees.
    pub value: Signal<Out, Bits<DATA_BITS>>,
    /// `write` addresses this register.
    pub write_hit: Signal<Out, Bit>,
    /// `read_index` addresses this register.
    pub read_hit: Signal<Out, Bit>,
    /// The word a read returns: the field zero- or sign-extended.
    pub read_word: Signal<Out, Bits<DATA_BITS>>,
    field: DFFWithInit<Bits<DATA_BITS>>,
    index: Constant<Bits<WORD_INDEX_BITS>>,
    field_mask: Constant<Bits<DATA_BITS>>,
    sign_bit: Constant<Bits<DATA_BITS>>,
    extension: Constant<Bits<DATA_BITS>>,
    power_up: Constant<Bits<DATA_BITS>>,
}

impl SettingRegister {
    /// The register described by `reg`, which must be read-write.
    pub fn new(reg: &Register) -> Self {
        assert_eq!(
            reg.access,
            Access::ReadWrite,
            "{} is not a setting",
            reg.name
        );
        let power_up = u64::from(reg.power_up & reg.mask());
        let extension = if reg.sign_bit() != 0 { !reg.mask() } else { 0 };
        Self {
            clock: Default::default(),
            reset: Default::default(),
            write: Default::default(),
            write_index: Default::default(),
            write_data: Default::default(),
            write_mask: Default::default(),
            read_index: Default::default(),
            value: Default::default(),
            write_hit: Default::default(),
            read_hit: Default::default(),
            read_word: Default::default(),
            field: DFFWithInit::new(power_up.into()),
            index: Constant::new(u64::from(reg.word_index()).into()),
            field_mask: Constant::new(u64::from(reg.mask()).into()),
            sign_bit: Constant::new(u64::from(reg.sign_bit()).into()),
            extension: Constant::new(u64::from(extension).into()),
            power_up: Constant::new(power_up.into()),
        }
    }
}

impl Logic for SettingRegister {
    #[hdl_gen]
    fn update(&mut self) {
        self.field.clock.next = self.clock.val();
        self.write_hit.next = self.write.val() & (self.write_index.val() == self.index.val());
        self.field.d.next = self.field.q.val();
        if self.write_hit.val() {
            self.field.d.next = ((self.field.q.val() & (!self.write_mask.val()))
                | (self.write_data.val() & self.write_mask.val()))
                & self.field_mask.val();
        }
        if self.reset.val() {
            self.field.d.next = self.power_up.val();
        }
        self.value.next = self.field.q.val();
        self.read_hit.next = self.read_index.val() == self.index.val();
        self.read_word.next = self.field.q.val();
        if (self.field.q.val() & self.sign_bit.val()).any() {
            self.read_word.next = self.field.q.val() | self.extension.val();
        }
    }
}
