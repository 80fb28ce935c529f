//! Bit-true model of `crate::quarter_wave::QuarterWave`'s arithmetic: the
//! quadrant, the mirrored index and the sign around one table read, shared
//! by the models of the ROM sine (`super::sine`) and the carriers' RAM sine
//! (`super::carrier_nco`).

use crate::quarter_wave::{PHASE_BELOW_INDEX, TABLE_ENTRIES};

/// `32767 sin` of a 32-bit phase plus `advance` quarter turns, with
/// `word(index)` the table's first-quadrant word for the 13-bit interval
/// index (mirrored in odd quadrants, as `QuarterWave` addresses its table).
#[inline(always)]
pub fn lookup(phase: u32, advance: u8, word: impl FnOnce(usize) -> i16) -> i16 {
    let q = ((phase >> 30) + u32::from(advance)) & 3;
    let i = (phase >> PHASE_BELOW_INDEX) as usize & (TABLE_ENTRIES - 1);
    let v = word(if q & 1 == 0 { i } else { TABLE_ENTRIES - 1 - i });
    if q >= 2 { -v } else { v }
}
