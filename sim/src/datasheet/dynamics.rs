//! Bandwidth and turn-on time of the rate output.
//!
//! # Bandwidth (-3 dB, from a rate step)
//!
//! Two boards from power-up with the same seeds, settled at rest; then one
//! steps to `step_dps` (a tenth of full scale: small against the readout's
//! curvature, large against its noise). Their z difference cancels the
//! noise (the same draws; only the Brownian covariance's tiny dependence
//! on the rate and the quantization differ) and leaves the step response
//! `s_i`, normalized to its final value (the mean of its last quarter).
//! The frequency response is the transform of its increments, `H(f) =
//! sum_i (s_i - s_{i-1}) exp(-j 2 pi f i / f_z)`; the bandwidth is the
//! lowest `f` where `|H(f)| = |H(0)| / sqrt 2`: a grid of
//! `BANDWIDTH_GRID` log-spaced frequencies up to `f_z / 2`, then
//! bisection. Null when `|H|` stays above that to `f_z / 2`.
//!
//! # Turn-on time
//!
//! From power-up (clock 0: the core first fills its carrier tables, then
//! the host programs it) to the first z sample after which every sample of
//! the record stays within `TURN_ON_FRACTION` (1 %) of full scale (`|SF| FS`)
//! of the final value (the mean of the record's last tenth), at rest, with
//! the Brownian and ADC noise off (the settling is the dynamics'; with
//! noise the band would measure the noise). The record is
//! `TURN_ON_RECORD` settling times long; null if the output is still
//! outside the band in its last tenth.

use super::Error;
use super::bench::{Bench, run};
use crate::field::board::Board;
use serde::Serialize;
use std::f64::consts::{FRAC_1_SQRT_2, TAU};

/// The step over full scale.
pub const STEP_OVER_FULL_SCALE: f64 = 0.1;
/// Frequencies of the bandwidth's first search.
const BANDWIDTH_GRID: usize = 400;
/// The turn-on band, a fraction of full scale (1 %). With the noise off
/// the converters still quantize: on `tests/data/datasheet_small.toml`'s
/// resonant output that residue is about 0.1 % of full scale from sample
/// to sample, so a 0.1 % band would time the quantization, not the
/// settling.
pub const TURN_ON_FRACTION: f64 = 1e-2;
/// The turn-on record in settling times (`Bench::settle_clocks`).
const TURN_ON_RECORD: u64 = 3;

/// The rate output's dynamics, per output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Dynamics {
    /// The rate step (deg/s).
    pub step_dps: f64,
    /// The normalized step response, per z sample after the step.
    pub step_response: Vec<[f64; 2]>,
    /// -3 dB bandwidth (Hz).
    pub bandwidth_hz: [Option<f64>; 2],
    /// Turn-on time (s).
    pub turn_on_s: [Option<f64>; 2],
}

/// `|H(f)|` of the step response `s` at `f / f_z = x`.
fn magnitude(s: &[f64], x: f64) -> f64 {
    let (mut re, mut im, mut last) = (0.0, 0.0, 0.0);
    for (i, v) in s.iter().enumerate() {
        let (sin, cos) = (TAU * x * i as f64).sin_cos();
        re += (v - last) * cos;
        im -= (v - last) * sin;
        last = *v;
    }
    re.hypot(im)
}

/// The -3 dB point of a normalized step response sampled at `fz` (Hz).
fn minus_3db(s: &[f64], fz: f64) -> Option<f64> {
    let target = magnitude(s, 0.0) * FRAC_1_SQRT_2;
    let lo = 1.0 / s.len() as f64;
    let x_at = |i: usize| lo * (0.5 / lo).powf(i as f64 / (BANDWIDTH_GRID - 1) as f64);
    let i = (0..BANDWIDTH_GRID).find(|&i| magnitude(s, x_at(i)) <= target)?;
    let (mut a, mut b) = (if i == 0 { 0.0 } else { x_at(i - 1) }, x_at(i));
    for _ in 0..50 {
        let m = 0.5 * (a + b);
        if magnitude(s, m) <= target {
            b = m
        } else {
            a = m
        }
    }
    Some(0.5 * (a + b) * fz)
}

/// A normalized step response per z sample, and the bandwidths (Hz).
type StepResult = (Vec<[f64; 2]>, [Option<f64>; 2]);

/// The step response of both outputs (normalized) and the bandwidths.
fn step(bench: &Bench, step_dps: f64) -> Result<StepResult, Error> {
    let mut still = bench.board(&bench.at0, 0.0, false)?;
    let mut moved = bench.board(&bench.at0, 0.0, false)?;
    for b in [&mut still, &mut moved] {
        b.wait_clocks(bench.settle_clocks()).map_err(run)?;
    }
    moved.set_rate(step_dps.to_radians());
    let n = bench.settle_clocks() / u64::from(bench.knowns.filter.decimation) + 1;
    let (mut last_a, mut last_b) = (
        still.read_z().map_err(run)?.count,
        moved.read_z().map_err(run)?.count,
    );
    let mut d = Vec::with_capacity(n as usize);
    for _ in 0..n {
        let (a, b) = (
            still.next_sample(last_a).map_err(run)?,
            moved.next_sample(last_b).map_err(run)?,
        );
        (last_a, last_b) = (a.count, b.count);
        d.push([b.z[0] - a.z[0], b.z[1] - a.z[1]]);
    }
    let tail = &d[d.len() * 3 / 4..];
    let fin: [f64; 2] =
        std::array::from_fn(|k| tail.iter().map(|v| v[k]).sum::<f64>() / tail.len() as f64);
    let s: Vec<[f64; 2]> = d.iter().map(|v| [v[0] / fin[0], v[1] / fin[1]]).collect();
    let fz = bench.z_rate_hz();
    let bw = std::array::from_fn(|k| {
        let col: Vec<f64> = s.iter().map(|v| v[k]).collect();
        minus_3db(&col, fz)
    });
    Ok((s, bw))
}

/// The turn-on time of both outputs, from a quiet board at rest; `band`
/// is `TURN_ON_FRACTION |SF| FS` per output (z LSB).
fn turn_on(bench: &Bench, band: [f64; 2]) -> Result<[Option<f64>; 2], Error> {
    let mut board = bench.board(&bench.at0, 0.0, true)?;
    let r = u64::from(bench.knowns.filter.decimation);
    let n = TURN_ON_RECORD * bench.settle_clocks() / r + 1;
    let mut last = board.read_z().map_err(run)?.count;
    let mut rec = Vec::with_capacity(n as usize);
    for _ in 0..n {
        let s = board.next_sample(last).map_err(run)?;
        last = s.count;
        rec.push((board.cycle() as f64 / bench.knowns.clock_hz, s.z));
    }
    let tail = &rec[rec.len() * 9 / 10..];
    Ok(std::array::from_fn(|k| {
        let fin = tail.iter().map(|v| v.1[k]).sum::<f64>() / tail.len() as f64;
        let outside = rec.iter().rposition(|v| (v.1[k] - fin).abs() > band[k]);
        match outside {
            None => Some(rec[0].0),
            Some(i) if i + 1 < rec.len() * 9 / 10 => Some(rec[i + 1].0),
            Some(_) => None,
        }
    }))
}

/// Bandwidth and turn-on time at full scale `full_scale_dps`, with the
/// sweep's scale factors `sf` (z LSB per deg/s).
pub fn run_dynamics(bench: &Bench, full_scale_dps: f64, sf: [f64; 2]) -> Result<Dynamics, Error> {
    let step_dps = STEP_OVER_FULL_SCALE * full_scale_dps;
    let (stepped, turn_on_s) = rayon::join(
        || step(bench, step_dps),
        || {
            turn_on(
                bench,
                sf.map(|s| TURN_ON_FRACTION * s.abs() * full_scale_dps),
            )
        },
    );
    let (step_response, bandwidth_hz) = stepped?;
    Ok(Dynamics {
        step_dps,
        step_response,
        bandwidth_hz,
        turn_on_s: turn_on_s?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_first_order_step_has_its_corner() {
        // s_i = 1 - exp(-(i + 1) dt / T) at fz = 1 kHz, T = 1 / (2 pi 10
        // Hz): a one-pole low-pass sampled finely, -3 dB at 10 Hz within
        // the sampling's O((f / fz)^2) and the record's end.
        let (fz, fc) = (1000.0, 10.0);
        let s: Vec<f64> = (0..4000)
            .map(|i| 1.0 - (-(i as f64 + 1.0) / fz * TAU * fc).exp())
            .collect();
        let got = minus_3db(&s, fz).unwrap();
        assert!((got / fc - 1.0).abs() < 0.01, "{got}");
        assert!(minus_3db(&[1.0; 100], fz).is_none());
    }
}
