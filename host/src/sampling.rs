//! Reading z over time: successive samples, their means, and the means of
//! exact windows, with time taken from SAMPLE_COUNT.
//!
//! Sample i of a collection is at time `(count_i - count_0) R` clocks
//! after the first one, whatever the transport. The in-process simulator
//! hands over every sample, and a window's mean interpolates between them
//! (`crate::average`). A board that lets samples go by while the host
//! reads (a slow wire: free-running Etherbone missed 31 of 32) leaves gaps
//! that the times show; interpolating across a gap longer than the ripple
//! it should average is wrong (+188% on a staircase, measured,
//! docs/real-board.md). With gaps each part is fitted instead
//! ([`fitted_part_means`]): a constant plus harmonics of the part's
//! length, by least squares over the whole window's samples; over a whole
//! period the harmonics average to zero, so the constant is the mean. The
//! staircase's parts are whole ripple periods, so the ripple is what the
//! harmonics take up.

use crate::average::window_mean;
use crate::board::{Board, ZSample};
use crate::error::Error;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

/// Most harmonics of a part's length fitted beside the mean when samples
/// are missing ([`fitted_part_means`]): the calibration ripple is at
/// 2 f_cal and its shape keeps harmonics up to the filter's cut-off (a few
/// to tens of them); as many are fitted as the samples allow, up to this.
pub const GAP_MAX_HARMONICS: usize = 32;
/// Samples a window needs, with gaps, per unknown of its fit: twice as
/// many samples as unknowns keeps the fit's noise within sqrt(2) of a
/// mean's.
pub const GAP_SAMPLES_PER_UNKNOWN: usize = 2;
/// Fewest harmonics a window with gaps must be fitted with to give a mean.
pub const GAP_MIN_HARMONICS: usize = 4;
/// Largest condition number (largest over smallest singular value) of a
/// gap fit's design: the missing samples can leave high harmonics nearly
/// unseen, and a fit that takes them anyway turns noise into wild
/// coefficients (measured: a staircase off by 1e5 with every part's
/// residual near 0, so that the spread looked small). Harmonics are
/// dropped from the top until the design is this well conditioned; with
/// it, the noise on the constant is at most this times a mean's.
pub const GAP_MAX_CONDITION: f64 = 10.0;

/// Samples read after waiting `clocks`: `n` of them, each newer than the
/// last.
pub fn collect(board: &mut dyn Board, clocks: u64, n: u64) -> Result<Vec<ZSample>, Error> {
    board.wait_clocks(clocks)?;
    let mut last = board.read_z()?.count;
    let mut samples = Vec::with_capacity(n as usize);
    for _ in 0..n {
        let s = board.next_sample(last)?;
        last = s.count;
        samples.push(s);
    }
    Ok(samples)
}

/// Mean of both outputs over `samples`.
pub fn mean(samples: &[ZSample]) -> [f64; 2] {
    let n = samples.len() as f64;
    std::array::from_fn(|k| samples.iter().map(|s| s.z[k]).sum::<f64>() / n)
}

/// Mean of both outputs over part means (the window's mean when the parts
/// are equal).
pub fn mean_of_parts(parts: &[[f64; 2]]) -> [f64; 2] {
    std::array::from_fn(|k| parts.iter().map(|p| p[k]).sum::<f64>() / parts.len() as f64)
}

/// Wait `clocks`, then average `n` successive z samples.
pub fn average_z(board: &mut dyn Board, clocks: u64, n: u64) -> Result<[f64; 2], Error> {
    Ok(mean(&collect(board, clocks, n)?))
}

/// What a window's z does, which decides how missing samples are bridged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Signal {
    /// Steady but for noise and slow drift (readout, identification):
    /// interpolated across gaps.
    Steady,
    /// A ripple whose period is the part length (the calibration staircase):
    /// interpolated when no sample is missing, fitted across gaps
    /// ([`fitted_part_means`]).
    Periodic,
}

/// Collect z from now until `t0 + length` clocks after the first new
/// sample is covered, and return the mean of each of `parts` equal parts
/// of the window `[t0, t0 + length)` (clocks after that first sample),
/// interpolated between samples (`window_mean`), or for a
/// [`Signal::Periodic`] window with gaps fitted: their mean is the
/// window's.
pub fn part_means(
    board: &mut dyn Board,
    decimation: u32,
    t0: f64,
    length: f64,
    parts: usize,
    signal: Signal,
) -> Result<Vec<[f64; 2]>, Error> {
    let r = f64::from(decimation);
    let now = board.read_z()?.count;
    let first = board.next_sample(now)?;
    let (mut t, mut z) = (vec![0.0], [vec![first.z[0]], vec![first.z[1]]]);
    let mut last = first.count;
    while *t.last().unwrap_or(&0.0) < t0 + length {
        let s = board.next_sample(last)?;
        last = s.count;
        t.push(f64::from(s.count.wrapping_sub(first.count)) * r);
        z[0].push(s.z[0]);
        z[1].push(s.z[1]);
    }
    let part = length / parts as f64;
    if signal == Signal::Periodic && t.windows(2).any(|w| w[1] - w[0] > r) {
        return fitted_part_means(&t, &z, t0, part, parts);
    }
    Ok((0..parts)
        .map(|p| {
            let a = t0 + p as f64 * part;
            std::array::from_fn(|k| window_mean(&t, &z[k], a, a + part))
        })
        .collect())
}

/// The part means of `[t0, t0 + parts x part)` from samples `(t, z)` with
/// gaps (module header): one least-squares fit over the whole window of a
/// constant plus as many harmonics of `part` as the samples allow (at most
/// `GAP_MAX_HARMONICS`, at least `GAP_MIN_HARMONICS`, and no more than keep
/// the design's condition number within `GAP_MAX_CONDITION`); each part's mean is
/// the constant plus its samples' mean residual, so the parts' spread is
/// the noise the fit leaves. Exact for any signal periodic in `part` with
/// no higher harmonics, whatever samples are missing; an error, in one
/// line, when the window has too few samples or a part has none.
///
/// ```
/// use gyrocal_host::sampling::fitted_part_means;
/// // A constant 3 with a ripple, sampled at irregular times over 2 periods.
/// let t: Vec<f64> = (0..80).map(|i| (i * i % 97) as f64 + 3.0 * i as f64).collect();
/// let ripple = |t: f64| 3.0 + 2.0 * (std::f64::consts::TAU * t / 120.0).cos();
/// let z: [Vec<f64>; 2] = [t.iter().map(|&t| ripple(t)).collect(), vec![1.0; 80]];
/// let m = fitted_part_means(&t, &z, 0.0, 120.0, 2).unwrap();
/// assert!(m.iter().all(|m| (m[0] - 3.0).abs() < 1e-9 && (m[1] - 1.0).abs() < 1e-9));
/// ```
pub fn fitted_part_means(
    t: &[f64],
    z: &[Vec<f64>; 2],
    t0: f64,
    part: f64,
    parts: usize,
) -> Result<Vec<[f64; 2]>, Error> {
    let end = t0 + part * parts as f64;
    let inside: Vec<usize> = (0..t.len())
        .filter(|&i| (t0..end).contains(&t[i]))
        .collect();
    let n = inside.len();
    let harmonics = ((n / GAP_SAMPLES_PER_UNKNOWN).saturating_sub(1) / 2).min(GAP_MAX_HARMONICS);
    let error = |reason: String| Error::Measurement {
        what: "a window with missing samples",
        reason,
    };
    if harmonics < GAP_MIN_HARMONICS {
        return Err(error(format!(
            "{n} samples from {t0:.0} to {end:.0} clocks, fewer than the {} its fit needs: the board lets samples go by between reads (pace it, or read a stream)",
            GAP_SAMPLES_PER_UNKNOWN * (1 + 2 * GAP_MIN_HARMONICS)
        )));
    }
    let design = |h: usize| {
        DMatrix::from_fn(n, 1 + 2 * h, |i, c| {
            let phase = TAU * (t[inside[i]] - t0) / part;
            match c {
                0 => 1.0,
                c if c % 2 == 1 => (phase * c.div_ceil(2) as f64).cos(),
                c => (phase * (c / 2) as f64).sin(),
            }
        })
    };
    let conditioned = (GAP_MIN_HARMONICS..=harmonics).rev().find_map(|h| {
        let x = design(h);
        let svd = x.clone().svd(true, true);
        let (hi, lo) = (svd.singular_values.max(), svd.singular_values.min());
        (lo > 0.0 && hi / lo <= GAP_MAX_CONDITION).then_some((x, svd))
    });
    let Some((x, svd)) = conditioned else {
        return Err(error(format!(
            "{n} samples from {t0:.0} to {end:.0} clocks leave even {GAP_MIN_HARMONICS} harmonics of the ripple unresolved (condition number above {GAP_MAX_CONDITION}): the board lets samples go by between reads (pace it, or read a stream)"
        )));
    };
    let mut means = vec![[0.0; 2]; parts];
    for k in 0..2 {
        let y = DVector::from_iterator(n, inside.iter().map(|&i| z[k][i]));
        let fit = svd.solve(&y, 0.0).map_err(|e| error(e.to_string()))?;
        let residual = &y - &x * &fit;
        for (p, mean) in means.iter_mut().enumerate() {
            let a = t0 + p as f64 * part;
            let mine: Vec<f64> = (0..n)
                .filter(|&i| (a..a + part).contains(&t[inside[i]]))
                .map(|i| residual[i])
                .collect();
            if mine.is_empty() {
                return Err(error(format!(
                    "no sample from {a:.0} to {:.0} clocks: the board lets samples go by between reads (pace it, or read a stream)",
                    a + part
                )));
            }
            mean[k] = fit[0] + mine.iter().sum::<f64>() / mine.len() as f64;
        }
    }
    Ok(means)
}

/// The mean over `[t0, t0 + length)` clocks after the next sample.
pub fn window_z(
    board: &mut dyn Board,
    decimation: u32,
    t0: f64,
    length: f64,
) -> Result<[f64; 2], Error> {
    Ok(part_means(board, decimation, t0, length, 1, Signal::Steady)?[0])
}
