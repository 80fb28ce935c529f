//! Finding a mode from a guess: the narrow-band coarse search, and the
//! scan it falls back on (module header of `super`).

use super::fit::{narrow_band, scan_fit};
use super::probe::Prober;
use super::{C64, MAX_MOVES, SCAN_POINTS, SCAN_SPAN};
use crate::error::Error;

/// A bandwidth the coarse search accepts, against the datasheet's: Q is
/// within a factor of 20 of it (process spread is a factor of 2).
const BANDWIDTH_RANGE: f64 = 20.0;

/// Highest carrier the search probes, as a fraction of the clock (the
/// plan's limit is below clock / 2).
const MAX_CARRIER_RATIO: f64 = 0.45;

/// The coarse search from `start` with datasheet bandwidth `bw`: the
/// centre of three carriers moves to the narrow-band estimate of fk, their
/// spacing to a quarter of the move (at least one bandwidth), until the
/// move is below a quarter bandwidth. `Ok(None)` when it cannot converge
/// there: no finite positive bandwidth, a bandwidth `BANDWIDTH_RANGE` away
/// from the datasheet's, a carrier outside (0, 0.45 clock), or
/// `MAX_MOVES` moves. Returns (fk, bk).
pub(super) fn coarse(probe: &mut Prober, start: f64, bw: f64) -> Result<Option<(f64, f64)>, Error> {
    let top = MAX_CARRIER_RATIO * probe.clock_hz();
    let mut centre = start;
    let mut spacing = bw;
    for _ in 0..MAX_MOVES {
        if centre - spacing <= 0.0 || centre + spacing >= top {
            return Ok(None);
        }
        let mut pts: Vec<(f64, C64)> = vec![];
        for s in [-1.0, 0.0, 1.0] {
            pts.push(probe.measure(centre + s * spacing)?);
        }
        let Some((fk, bk, peak)) = narrow_band(&pts) else {
            return Ok(None);
        };
        if !(bw / BANDWIDTH_RANGE..=bw * BANDWIDTH_RANGE).contains(&bk) {
            return Ok(None);
        }
        probe.set_amplitude_for_peak(peak);
        let moved = fk - centre;
        centre = fk;
        if moved.abs() < bk / 4.0 && spacing <= 2.0 * bk.max(bw) {
            return Ok(Some((centre, bk)));
        }
        spacing = (moved.abs() / 4.0).max(bk.min(bw));
    }
    Ok(None)
}

/// The scan: `SCAN_POINTS` carriers evenly over +-`SCAN_SPAN` of `guess`
/// (within (0, 0.45 clock)), and the exact form's fit over all of them
/// (`fit::scan_fit`); returns its fk.
pub(super) fn scan(probe: &mut Prober, guess: f64) -> Result<f64, Error> {
    let top = MAX_CARRIER_RATIO * probe.clock_hz();
    let (lo, hi) = (
        (guess * (1.0 - SCAN_SPAN)).max(0.0),
        (guess * (1.0 + SCAN_SPAN)).min(top),
    );
    let mut pts = vec![];
    for i in 0..SCAN_POINTS {
        let f = lo + (hi - lo) * i as f64 / (SCAN_POINTS - 1) as f64;
        if f > 0.0 {
            pts.push(probe.measure(f)?);
        }
    }
    let largest = pts
        .iter()
        .max_by(|a, b| a.1.norm().total_cmp(&b.1.norm()))
        .map_or(guess, |p| p.0);
    match scan_fit(&pts) {
        Some((fk, _)) if fk > lo - (hi - lo) && fk < hi + (hi - lo) => Ok(fk),
        _ => Err(Error::Identification {
            mode: probe.mode(),
            reason: format!(
                "no resonance found from {lo:.1} to {hi:.1} Hz (+-{}% of {guess} Hz; the largest response was at {largest:.1} Hz): check the datasheet's frequency",
                100.0 * SCAN_SPAN
            ),
        }),
    }
}
