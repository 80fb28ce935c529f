//! The calibration ripple taken out of a window's samples before they are
//! averaged.
//!
//! A calibration output carries a ripple at 2 Om and its harmonics, up to
//! about (f_k / 2 Q_k) / f_cal times its DC value. Whole ripple periods
//! average it out, but the z samples come every R clocks, not a whole
//! fraction of a period, and the averages integrate their linear
//! interpolant (`crate::average`): over a batch of an eighth of a period
//! that leaves an error of order A (2 pi h / P)^2 / 12 of a ripple A
//! sampled every h, which moves from period to period with the sample
//! grid. At 34 samples per period (a Q 290 device at 95 kHz on a 410 kHz
//! clock, R = 166, f_cal 36 Hz) it made the spread between periods, and so
//! the calibration scale factor's reported sigma, 8 to 10 times the error
//! it described (four times as many samples per period: 1 time).
//!
//! So the ripple's first `HARMONICS` harmonics of 2 Om are fitted to the
//! window's samples by least squares (with a constant) and subtracted:
//! their exact mean over whole periods is 0, so the window's mean keeps
//! its DC value and loses the ripple's interpolation error, and the
//! batches keep only what the fit leaves (noise and the ripple's finer
//! shape, which the two-way layout of `crate::experiment` handles).
//! Harmonics the samples cannot resolve (above a quarter of their count
//! per period) are left out.

use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

/// Harmonics of the ripple fitted at most.
pub const HARMONICS: usize = 6;

/// Subtract from `z` (samples at times `t`, clocks) the ripple of period
/// `period` (clocks) fitted over the samples in [`t0`, `t1`] (a whole
/// number of periods).
pub fn remove(t: &[f64], z: &mut [f64], period: f64, t0: f64, t1: f64) {
    let inside: Vec<usize> = (0..t.len()).filter(|&i| t[i] >= t0 && t[i] <= t1).collect();
    let per_period = inside.len() as f64 * period / (t1 - t0);
    let harmonics = HARMONICS.min((per_period / 4.0).floor() as usize);
    if harmonics == 0 {
        return;
    }
    let w = TAU / period;
    let columns = 2 * harmonics + 1;
    // The constant and cos, sin of each harmonic at time x.
    let basis = |x: f64, out: &mut [f64]| {
        out[0] = 1.0;
        for h in 1..=harmonics {
            let (s, c) = (w * h as f64 * (x - t0)).sin_cos();
            out[2 * h - 1] = c;
            out[2 * h] = s;
        }
    };
    let mut a = DMatrix::zeros(inside.len(), columns);
    let mut r = vec![0.0; columns];
    for (row, &i) in inside.iter().enumerate() {
        basis(t[i], &mut r);
        for (j, v) in r.iter().enumerate() {
            a[(row, j)] = *v;
        }
    }
    let b = DVector::from_iterator(inside.len(), inside.iter().map(|&i| z[i]));
    let Some(fit) = (a.transpose() * &a)
        .cholesky()
        .map(|c| c.solve(&(a.transpose() * b)))
    else {
        return;
    };
    for (x, v) in t.iter().zip(z.iter_mut()) {
        basis(*x, &mut r);
        *v -= (1..columns).map(|j| r[j] * fit[j]).sum::<f64>();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::average::window_mean;

    #[test]
    fn a_coarsely_sampled_ripple_leaves_its_dc_and_nothing_else() {
        // DC 1, a ripple 5 times larger with two harmonics, sampled 34
        // times a period from an arbitrary phase; 3 whole periods.
        let (h, period) = (1.0, 34.37);
        let t: Vec<f64> = (0..200).map(|i| f64::from(i) * h).collect();
        let ripple = |x: f64| {
            let a = TAU * x / period;
            5.0 * (a + 0.3).cos() + 1.0 * (2.0 * a - 1.1).cos() + 0.2 * (3.0 * a).sin()
        };
        let mut z: Vec<f64> = t.iter().map(|&x| 1.0 + ripple(x)).collect();
        let (t0, t1) = (10.4, 10.4 + 3.0 * period);
        let before = window_mean(&t, &z, t0, t0 + period / 8.0);
        remove(&t, &mut z, period, t0, t1);
        let batch = window_mean(&t, &z, t0, t0 + period / 8.0);
        assert!((before - 1.0).abs() > 1.0, "the batch carried the ripple");
        assert!((batch - 1.0).abs() < 1e-9, "{batch}");
        assert!((window_mean(&t, &z, t0, t1) - 1.0).abs() < 1e-9);
    }
}
