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

/// What a clipped window of the calibration staircase says: ADC `adc` (1
/// or 2) clipped on `clocks` (the count saturates at `u16::MAX`) of the
/// window's `window_clocks`, where the identified response put its peak
/// at `peak` of full scale. Either the device answers more than
/// identified or the converter's own noise reaches over the room the
/// drives left; one count cannot tell them apart, so the line names both,
/// with the share and the room that weigh between them.
///
/// ```
/// let line = gyrocal_host::clip::cycle_detail(2, 420, 1e6, 0.95);
/// assert!(line.starts_with("0.04% of the window's clocks; the identified response puts ADC 2's peak at 95% of full scale"));
/// assert!(line.contains("the converter's own noise reaches over the 5% left"));
/// ```
pub fn cycle_detail(adc: usize, clocks: u32, window_clocks: f64, peak: f64) -> String {
    let at_least = if clocks >= u32::from(u16::MAX) {
        "at least "
    } else {
        ""
    };
    format!(
        "{at_least}{:.2}% of the window's clocks; the identified response puts ADC {adc}'s peak at {:.0}% of full scale: either the device answers more than identified (lower [drive] amplitude1/amplitude2, or check the ADC gain) or the converter's own noise reaches over the {:.0}% left (check its noise)",
        100.0 * f64::from(clocks) / window_clocks,
        100.0 * peak,
        100.0 * (1.0 - peak).max(0.0)
    )
}

/// The error of a window during which an ADC clipped, if one did: `what`
/// the measurement, `detail` what the host had done and what to change.
pub fn check<B: Board + ?Sized>(
    board: &mut B,
    what: &'static str,
    detail: &str,
) -> Result<(), Error> {
    check_with(board, what, |_, _| detail.into())
}

/// [`check`] with the detail made from the converter that clipped (1 or
/// 2) and its count.
pub fn check_with<B: Board + ?Sized>(
    board: &mut B,
    what: &'static str,
    detail: impl FnOnce(usize, u32) -> String,
) -> Result<(), Error> {
    let c = counts(board)?;
    match c.iter().position(|&n| n > 0) {
        None => Ok(()),
        Some(k) => Err(Error::Clipped {
            what,
            adc: k + 1,
            clocks: c[k],
            detail: detail(k + 1, c[k]),
        }),
    }
}
