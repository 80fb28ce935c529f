//! Over-range: the `ADC_CLIP` counts (clocks on which each ADC read a rail
//! code since the last read of the word). A measurement restarts them when
//! it starts and reads them when it ends; any count means the converter
//! clipped during it, and its figure is refused rather than reported.

use crate::board::Board;
use crate::error::Error;
use gyrocal_regs::map::ADC_CLIP;

/// Clipped clocks of ADC 1 and ADC 2 since the last read (and restart).
pub fn counts(board: &mut dyn Board) -> Result<[u32; 2], Error> {
    let word = board.read_register(ADC_CLIP.offset)?;
    Ok([word & 0xffff, word >> 16])
}

/// Restart the counts: the window that follows is watched.
pub fn restart(board: &mut dyn Board) -> Result<(), Error> {
    counts(board).map(|_| ())
}

/// The error of a window during which an ADC clipped, if one did.
pub fn check(board: &mut dyn Board, what: &'static str) -> Result<(), Error> {
    let c = counts(board)?;
    match c.iter().position(|&n| n > 0) {
        None => Ok(()),
        Some(k) => Err(Error::Clipped {
            what,
            adc: k + 1,
            clocks: c[k],
            detail: "the drive amplitude was chosen from the identified response; the device or the front end differs from it (lower [drive] amplitude1/amplitude2, or check the ADC gain)".into(),
        }),
    }
}
