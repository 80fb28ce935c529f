//! The rate series the Allan deviation is computed from: one board at the
//! factory temperature, at rest, with every noise of `[noise]`: the
//! Brownian force, the ADC's, and the rate noises
//! ([`crate::rate_drift`]) applied through the board's rate table.
//!
//! z samples are averaged in blocks of `ceil(f_z / MAX_SERIES_HZ)`; the
//! rate noise is updated once per block, at the block's start, so the
//! series' sample interval is the update interval `h` (module header of
//! `rate_drift` for why that is exact enough). The board settles at the
//! first rate-noise value before the series starts. The caller turns each
//! block mean into a rate with the sweep's line, `(z - intercept) / SF`.

use super::Error;
use super::bench::{Bench, run};
use crate::field::board::Board;
use crate::rate_drift::{RateNoise, RateNoiseSource};
use serde::Serialize;

/// Highest sample rate of the series (Hz).
pub const MAX_SERIES_HZ: f64 = 100.0;

/// Clocks between progress reports.
const PROGRESS_CLOCKS: u64 = 1 << 22;

/// The block means of both outputs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Series {
    /// Sample rate of the series (Hz).
    pub sample_rate_hz: f64,
    /// z samples per series sample.
    pub block: u32,
    /// Flicker corners of the rate-noise generator (0: no flicker).
    pub flicker_corners: usize,
    /// Clocks simulated.
    pub clocks: u64,
    /// Block means (z LSB), per output.
    #[serde(skip)]
    pub z_lsb: [Vec<f64>; 2],
}

/// The series' block and sample rate for `bench`.
pub fn block(bench: &Bench) -> (u32, f64) {
    let fz = bench.z_rate_hz();
    let block = (fz / MAX_SERIES_HZ).ceil().max(1.0) as u32;
    (block, fz / f64::from(block))
}

/// Run `seconds` of series; `progress` gets clocks.
pub fn run_series(
    bench: &Bench,
    rate_noise: &RateNoise,
    seconds: f64,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Series, Error> {
    let (block, rate_hz) = block(bench);
    let mut source = RateNoiseSource::new(rate_noise, 1.0 / rate_hz, bench.exp.noise.seed)
        .map_err(|e| Error::Input(e.to_string()))?;
    let on = rate_noise.is_on();
    let first = if on { source.next_dps() } else { 0.0 };
    let mut board = bench.board(&bench.at0, first, false)?;
    board.wait_clocks(bench.settle_clocks()).map_err(run)?;
    let blocks = (seconds * rate_hz).round() as usize;
    let mut z: [Vec<f64>; 2] = std::array::from_fn(|_| Vec::with_capacity(blocks));
    let mut last = board.read_z().map_err(run)?.count;
    let mut reported = board.cycle();
    for j in 0..blocks {
        if on && j > 0 {
            board.set_rate(source.next_dps().to_radians());
        }
        let mut sum = [0.0; 2];
        for _ in 0..block {
            let s = board.next_sample(last).map_err(run)?;
            last = s.count;
            sum[0] += s.z[0];
            sum[1] += s.z[1];
        }
        for k in 0..2 {
            z[k].push(sum[k] / f64::from(block));
        }
        if board.cycle() - reported >= PROGRESS_CLOCKS {
            progress(board.cycle() - reported);
            reported = board.cycle();
        }
    }
    progress(board.cycle() - reported);
    Ok(Series {
        sample_rate_hz: rate_hz,
        block,
        flicker_corners: source.flicker_corners(),
        clocks: board.cycle(),
        z_lsb: z,
    })
}
