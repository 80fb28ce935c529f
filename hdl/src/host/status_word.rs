//! `StatusWord`: one read-only word of the AXI4-Lite register map.
//!
//! ```text
//!  live ──► read_word = (live & field_mask) zero- or sign-extended
//!  read_index ──► read_hit
//! ```
//!
//! Built from one `register_map::Register` (word index, width, signedness
//! as `Constant`s). Purely combinational: the value comes from the bus top
//! (identification constants, counters, the z snapshot).

use super::register_map::{Access, DATA_BITS, Register, WORD_INDEX_BITS};
use rust_hdl::prelude::*;

/// One read-only bus word.
#[derive(LogicBlock)]
pub struct StatusWord {
    /// The status value; bits above the field width are ignored.
    pub live: Signal<In, Bits<DATA_BITS>>,
    /// Word index of the read being decoded.
    pub read_index: Signal<In, Bits<WORD_INDEX_BITS>>,
    /// `read_index` addresses this word.
    pub read_hit: Signal<Out, Bit>,
    /// The word a read returns.
    pub read_word: Signal<Out, Bits<DATA_BITS>>,
    index: Constant<Bits<WORD_INDEX_BITS>>,
    field_mask: Constant<Bits<DATA_BITS>>,
    sign_bit: Constant<Bits<DATA_BITS>>,
    extension: Constant<Bits<DATA_BITS>>,
    field: Signal<Local, Bits<DATA_BITS>>,
}

impl StatusWord {
    /// The word described by `reg`, which must be read-only.
    pub fn new(reg: &Register) -> Self {
        assert_eq!(
            reg.access,
            Access::ReadOnly,
            "{} is not a status word",
            reg.name
        );
        let extension = if reg.sign_bit() != 0 { !reg.mask() } else { 0 };
        Self {
            live: Default::default(),
            read_index: Default::default(),
            read_hit: Default::default(),
            read_word: Default::default(),
            index: Constant::new(u64::from(reg.word_index()).into()),
            field_mask: Constant::new(u64::from(reg.mask()).into()),
            sign_bit: Constant::new(u64::from(reg.sign_bit()).into()),
            extension: Constant::new(u64::from(extension).into()),
            field: Default::default(),
        }
    }
}

impl Logic for StatusWord {
    #[hdl_gen]
    fn update(&mut self) {
        self.field.next = self.live.val() & self.field_mask.val();
        self.read_hit.next = self.read_index.val() == self.index.val();
        self.read_word.next = self.field.val();
        if (self.field.val() & self.sign_bit.val()).any() {
            self.read_word.next = self.field.val() | self.extension.val();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::axi_top::STATUS;
    use super::*;
    use crate::drive::settle;

    /// Every status word of the map returns its field alone, sign-extended
    /// when signed, whatever the bits above it carry, and hits on its own
    /// index only (the bus top feeds some words fields narrower than 32
    /// bits: the z snapshots' high bytes).
    #[test]
    fn a_read_returns_the_field_alone_sign_extended() {
        for reg in STATUS.iter() {
            let mut uut = StatusWord::new(reg);
            uut.connect_all();
            check_all(&uut).expect("connection checks");
            for live in [
                0u32,
                1,
                0x7f,
                0x80,
                0xff,
                0x1ff,
                0xffff,
                0x8000_0000,
                u32::MAX,
            ] {
                for index in [reg.word_index(), reg.word_index() ^ 1] {
                    uut.live.next = u64::from(live).into();
                    uut.read_index.next = u64::from(index).into();
                    settle(&mut uut);
                    assert_eq!(
                        uut.read_word.val().index() as u32,
                        reg.extend(live),
                        "{} live {live:#x}",
                        reg.name
                    );
                    assert_eq!(
                        uut.read_hit.val(),
                        index == reg.word_index(),
                        "{}",
                        reg.name
                    );
                }
            }
        }
    }
}
