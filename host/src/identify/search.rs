//! Finding a mode from a guess: the narrow-band coarse search, and the
//! scan it falls back on (module header of `super`).

use super::fit::{narrow_band, scan_fit};
use super::probe::Prober;
use super::{C64, MAX_MOVES, SCAN_POINTS, SCAN_SPAN};
use crate::error::Error;
use crate::theory::hold_gain;

/// A bandwidth the coarse search accepts, against the one of the Q it
/// starts from: Q is within a factor of 20 of it (process spread is a
/// factor of 2). A datasheet Q too low reaches less than that: the
/// carriers start a bandwidth apart and wait its time constant, too wide
/// and too short for the part. Then `Unsettled::retry_q` gives the Q a
/// second search starts from (`super::identify_mode`). Measured on the
/// consumer device (Q 3000, `tests/field_cli.rs`'s): one search alone
/// identified a datasheet Q1 from 350 to 60,000; with the second tries,
/// from 0.3 to 200,000 (the highest tried). At Q1 = 0.05 two more tries
/// do not reach it, and the step fails in one line that names
/// `[datasheet] q`.
const BANDWIDTH_RANGE: f64 = 20.0;

/// Highest carrier the search probes, as a fraction of the clock (the
/// plan's limit is below clock / 2).
const MAX_CARRIER_RATIO: f64 = 0.45;

/// Why the coarse search stopped without settling on a resonance.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub(super) enum Unsettled {
    /// A carrier it would probe lies outside (0, 0.45 clock).
    #[error(
        "a carrier it would probe, {spacing:.1} Hz from {centre:.1} Hz, lies outside 0 to \
         {top:.1} Hz (the spacing starts at the bandwidth of Q{mode} = {}: if the part's Q \
         is far from it, correct [datasheet] q{mode})",
        shown_q(*q)
    )]
    Carrier {
        mode: usize,
        centre: f64,
        spacing: f64,
        top: f64,
        q: f64,
    },
    /// Three points gave no finite, positive bandwidth. Their spacing
    /// starts at the datasheet's bandwidth: a Q far too low spreads them
    /// over the whole resonance and beyond.
    #[error(
        "three points {spacing:.4} Hz apart around {centre:.1} Hz gave no finite, positive \
         bandwidth (the spacing starts at the bandwidth of Q{mode} = {}: if the part's Q \
         is far from it, correct [datasheet] q{mode})",
        shown_q(*q)
    )]
    NoEstimate {
        mode: usize,
        centre: f64,
        spacing: f64,
        q: f64,
    },
    /// The resonance found is `BANDWIDTH_RANGE` or more from the
    /// datasheet's bandwidth: most likely the datasheet's Q is wrong.
    #[error(
        "the resonance near {fk:.1} Hz measured {found:.4} Hz wide, more than {BANDWIDTH_RANGE}x \
         from the {expected:.4} Hz of Q{mode} = {} (a Q that far off also \
         misleads the measurement, through the carriers' spacing and the time waited at each): \
         correct [datasheet] q{mode}",
        shown_q(*q)
    )]
    Bandwidth {
        mode: usize,
        fk: f64,
        found: f64,
        expected: f64,
        q: f64,
    },
    /// `MAX_MOVES` moves without settling.
    #[error("{MAX_MOVES} moves did not settle")]
    Moves,
}

/// A Q as a message shows it: whole above 10, three decimals below.
pub(super) fn shown_q(q: f64) -> String {
    if q >= 10.0 {
        format!("{q:.0}")
    } else {
        format!("{q:.3}")
    }
}

impl Unsettled {
    /// The Q a second search starts from when a wrong Q (the one it
    /// started from, `q`) explains this miss: the one measured, when the bandwidth was out of range; ten
    /// times `q` when three points a bandwidth apart gave none (they
    /// spanned the resonance and beyond) or would leave the clock's range.
    pub(super) fn retry_q(&self) -> Option<f64> {
        match *self {
            Unsettled::Bandwidth { fk, found, .. } => Some(fk / found),
            Unsettled::NoEstimate { q, .. } | Unsettled::Carrier { q, .. } => {
                Some(RETRY_Q_FACTOR * q)
            }
            Unsettled::Moves => None,
        }
    }
}

/// How much higher than the datasheet's a second search takes Q when the
/// first could estimate no bandwidth (`Unsettled::retry_q`).
const RETRY_Q_FACTOR: f64 = 10.0;

/// The coarse search from `start` with datasheet bandwidth `bw`: the
/// centre of three carriers moves to the narrow-band estimate of fk, their
/// spacing to a quarter of the move (at least one bandwidth), until the
/// move is below a quarter bandwidth. `Ok(Err(why))` when it cannot
/// converge there: no finite positive bandwidth, a bandwidth
/// `BANDWIDTH_RANGE` away from the datasheet's, a carrier outside (0, 0.45
/// clock), or `MAX_MOVES` moves. Returns (fk, bk).
pub(super) fn coarse(
    probe: &mut Prober,
    start: f64,
    bw: f64,
) -> Result<Result<(f64, f64), Unsettled>, Error> {
    let top = MAX_CARRIER_RATIO * probe.clock_hz();
    let mut centre = start;
    let mut spacing = bw;
    for _ in 0..MAX_MOVES {
        if centre - spacing <= 0.0 || centre + spacing >= top {
            return Ok(Err(Unsettled::Carrier {
                mode: probe.mode(),
                centre,
                spacing,
                top,
                q: probe.q_guess(),
            }));
        }
        let mut pts: Vec<(f64, C64)> = vec![];
        for s in [-1.0, 0.0, 1.0] {
            pts.push(probe.measure(centre + s * spacing)?);
        }
        let Some((fk, bk, peak)) = narrow_band(&pts) else {
            return Ok(Err(Unsettled::NoEstimate {
                mode: probe.mode(),
                centre,
                spacing,
                q: probe.q_guess(),
            }));
        };
        if !(bw / BANDWIDTH_RANGE..=bw * BANDWIDTH_RANGE).contains(&bk) {
            return Ok(Err(Unsettled::Bandwidth {
                mode: probe.mode(),
                fk,
                found: bk,
                expected: bw,
                q: probe.q_guess(),
            }));
        }
        probe.set_amplitude_for_peak(peak);
        let moved = fk - centre;
        centre = fk;
        if moved.abs() < bk / 4.0 && spacing <= 2.0 * bk.max(bw) {
            return Ok(Ok((centre, bk)));
        }
        spacing = (moved.abs() / 4.0).max(bk.min(bw));
    }
    Ok(Err(Unsettled::Moves))
}

/// The scan: `SCAN_POINTS` carriers evenly over +-`SCAN_SPAN` of `guess`
/// (within (0, 0.45 clock)) and the exact form's fit over all of them
/// (`fit::scan_fit`), then scans that zoom in: each spans +-`ZOOM_SPACINGS`
/// of the previous scan's spacing around its estimate, until the spacing
/// is within `ZOOM_UNTIL` datasheet bandwidths `bw`. Returns the last fk.
///
/// Why zoom: the first scan's points lie hundreds of bandwidths from the
/// resonance (a 5% scan of a Q 55,000 mode is 2,700 bandwidths wide), where
/// the response is small and any departure from the exact form (the front
/// end's frequency-dependent phase across 10% of the carrier; the drive
/// hold's gain is divided out) moves fk by a fraction of the spacing: measured on the
/// paper device with a datasheet 1.5% low, 30 kHz off a 47.5 kHz spacing.
/// Each zoom divides that error with the span; the estimate stays inside
/// the next scan as long as it is within `ZOOM_SPACINGS` spacings.
pub(super) fn scan(probe: &mut Prober, guess: f64, bw: f64) -> Result<f64, Error> {
    let top = MAX_CARRIER_RATIO * probe.clock_hz();
    let (mut lo, mut hi) = (
        (guess * (1.0 - SCAN_SPAN)).max(0.0),
        (guess * (1.0 + SCAN_SPAN)).min(top),
    );
    loop {
        let fk = scan_once(probe, lo, hi, guess)?;
        let spacing = (hi - lo) / (SCAN_POINTS - 1) as f64;
        if spacing <= ZOOM_UNTIL * bw {
            return Ok(fk);
        }
        let half = ZOOM_SPACINGS * spacing;
        (lo, hi) = ((fk - half).max(0.0), (fk + half).min(top));
    }
}

/// Half-width of a zoomed scan in the previous scan's spacings (a zoom
/// divides the span by (SCAN_POINTS - 1) / (2 ZOOM_SPACINGS) = 3.3).
const ZOOM_SPACINGS: f64 = 3.0;
/// The scans stop when their spacing is within this many datasheet
/// bandwidths: the coarse search starts from there.
const ZOOM_UNTIL: f64 = 2.0;

/// One scan of `SCAN_POINTS` carriers over [lo, hi] and its fit.
fn scan_once(probe: &mut Prober, lo: f64, hi: f64, guess: f64) -> Result<f64, Error> {
    let mut pts = vec![];
    for i in 0..SCAN_POINTS {
        let f = lo + (hi - lo) * i as f64 / (SCAN_POINTS - 1) as f64;
        if f > 0.0 {
            // The exact form leaves out the hold's gain, which falls by
            // several percent across a wide scan (`theory::hold_gain`).
            let (f, y) = probe.measure(f)?;
            pts.push((f, y / hold_gain(f, probe.clock_hz())));
        }
    }
    let largest = pts
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.1.norm().total_cmp(&b.1.1.norm()));
    // A response that only grows towards one end of the scan points past
    // it: a resonance's skirt falls on both sides of its peak.
    let (at, beyond) = match largest {
        Some((0, p)) => (p.0, ", its low end: the resonance is likely below"),
        Some((i, p)) if i + 1 == pts.len() => {
            (p.0, ", its high end: the resonance is likely above")
        }
        Some((_, p)) => (p.0, ""),
        None => (guess, ""),
    };
    match scan_fit(&pts) {
        Some((fk, _)) if fk > lo - (hi - lo) && fk < hi + (hi - lo) => Ok(fk),
        _ => Err(Error::Identification {
            mode: probe.mode(),
            reason: format!(
                "no resonance found from {lo:.1} to {hi:.1} Hz (scanning from the datasheet's {guess:.1} Hz, +-{}%; the largest response was at {at:.1} Hz{beyond}): check the datasheet's frequency",
                100.0 * SCAN_SPAN
            ),
        }),
    }
}
