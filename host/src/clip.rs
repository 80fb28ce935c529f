//! Over-range: the `ADC_CLIP` counts (clocks on which each ADC read a word
//! within 1/128 of full scale, the rail codes of any converter of 8 to 16
//! bits, since the last read of the word). A measurement restarts them when
//! it starts and reads them when it ends; any count means the converter
//! clipped during it, and its figure is refused rather than reported.

use crate::board::Board;
use crate::error::Error;
use gyrocal_regs::map::ADC_CLIP;

/// Clipped clocks of ADC 1 and ADC 2 since the last read (and restart).
pub fn counts<B: Board + ?Sized>(board: &mut B) -> Result<[u32; 2], Error> {
    let word = board.read_register(ADC_CLIP.offset)?;
    Ok([word & 0xffff, word >> 16])
}

/// Restart the counts: the window that follows is watched.
pub fn restart<B: Board + ?Sized>(board: &mut B) -> Result<(), Error> {
    counts(board).map(|_| ())
}

/// What a clipped window of the cycle says: its drives came from the
/// identified response, which the device or the front end left.
pub const CYCLE_DETAIL: &str = "the drive amplitude was chosen from the identified response; the device or the front end differs from it (lower [drive] amplitude1/amplitude2, or check the ADC gain)";

/// The error of a window during which an ADC clipped, if one did: `what`
/// the measurement, `detail` what the host had done and what to change.
pub fn check<B: Board + ?Sized>(
    board: &mut B,
    what: &'static str,
    detail: &str,
) -> Result<(), Error> {
    let c = counts(board)?;
    match c.iter().position(|&n| n > 0) {
        None => Ok(()),
        Some(k) => Err(Error::Clipped {
            what,
            adc: k + 1,
            clocks: c[k],
            detail: detail.into(),
        }),
    }
}
