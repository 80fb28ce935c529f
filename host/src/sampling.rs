//! Reading z over time: successive samples, their means, and the means of
//! exact windows, with time taken from SAMPLE_COUNT.
//!
//! Sample i of a collection is at time `(count_i - count_0) R` clocks
//! after the first one, whatever the transport: a board that lets samples
//! go by while the host reads (a slow wire) leaves gaps that the times
//! show, and the window means interpolate across them (`crate::average`).
//! The in-process simulator hands over every sample.

use crate::average::window_mean;
use crate::board::{Board, ZSample};
use crate::error::Error;

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

/// Wait `clocks`, then average `n` successive z samples.
pub fn average_z(board: &mut dyn Board, clocks: u64, n: u64) -> Result<[f64; 2], Error> {
    Ok(mean(&collect(board, clocks, n)?))
}

/// Collect z from now until `t0 + length` clocks after the first new
/// sample is covered, and return the mean of each of `parts` equal parts
/// of the window `[t0, t0 + length)` (clocks after that first sample),
/// interpolated between samples (`window_mean`): their mean is the
/// window's.
pub fn part_means(
    board: &mut dyn Board,
    decimation: u32,
    t0: f64,
    length: f64,
    parts: usize,
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
    Ok((0..parts)
        .map(|p| {
            let a = t0 + p as f64 * part;
            std::array::from_fn(|k| window_mean(&t, &z[k], a, a + part))
        })
        .collect())
}

/// The mean over `[t0, t0 + length)` clocks after the next sample.
pub fn window_z(
    board: &mut dyn Board,
    decimation: u32,
    t0: f64,
    length: f64,
) -> Result<[f64; 2], Error> {
    Ok(part_means(board, decimation, t0, length, 1)?[0])
}
