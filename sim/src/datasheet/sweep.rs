//! Scale factor, nonlinearity and asymmetry from a rate sweep over +-full
//! scale (IEEE Std 952-1997 section 8.1.4 style).
//!
//! `SWEEP_POINTS` rates evenly spaced from `-FS` to `+FS`, each on a fresh
//! board at the factory temperature (in lanes, `Bench::readings`), settled and averaged
//! over one first window, with the file's Brownian and ADC noise (the rate
//! noises are not applied: they are what the Allan deviation measures).
//!
//! - Scale factor `SF` (z LSB per deg/s): the least-squares line's slope.
//! - Nonlinearity (ppm of full scale): the largest |residual| from that
//!   line over `|SF| FS`, the output's one-sided full-scale span.
//! - Asymmetry (ppm): `(SF+ - SF-) / ((SF+ + SF-) / 2)`, `SF+` and `SF-`
//!   the slopes of the points at `>= 0` and `<= 0`.
//!
//! The readout's own curvature (its quadratic term on a detuned output)
//! shows in both; so does the window's noise (`window_s`).

use super::Error;
use super::bench::Bench;
use crate::fit::linear_fit;
use serde::Serialize;

/// Rates in a sweep, zero included (`-FS, -0.9 FS, ..., FS`).
pub const SWEEP_POINTS: usize = 21;

/// The sweep and what it gives, per output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sweep {
    /// Full scale (deg/s).
    pub full_scale_dps: f64,
    /// The rates (deg/s).
    pub rates_dps: Vec<f64>,
    /// z at each rate (z LSB).
    pub z_lsb: Vec<[f64; 2]>,
    /// Window of each reading (s).
    pub window_s: f64,
    /// Best-fit slope (z LSB per deg/s).
    pub sf_lsb_per_dps: [f64; 2],
    /// Its intercept (z LSB).
    pub intercept_lsb: [f64; 2],
    /// Residuals from the line (ppm of full scale).
    pub residual_ppm: Vec<[f64; 2]>,
    /// Largest |residual| (ppm of full scale).
    pub nonlinearity_ppm: [f64; 2],
    /// Slopes over the positive and the negative half.
    pub sf_halves_lsb_per_dps: [[f64; 2]; 2],
    /// `(SF+ - SF-) / mean` (ppm).
    pub asymmetry_ppm: [f64; 2],
}

/// Slopes and intercepts of `z` on `rates`, per output.
fn lines(rates: &[f64], z: &[[f64; 2]]) -> [(f64, f64); 2] {
    std::array::from_fn(|k| {
        let y: Vec<f64> = z.iter().map(|v| v[k]).collect();
        linear_fit(rates, &y)
    })
}

/// Run the sweep at `full_scale_dps`.
pub fn run(bench: &Bench, full_scale_dps: f64) -> Result<Sweep, Error> {
    let half = (SWEEP_POINTS / 2) as f64;
    let rates: Vec<f64> = (0..SWEEP_POINTS)
        .map(|i| full_scale_dps * (i as f64 - half) / half)
        .collect();
    let z = bench.readings_in_parallel(&bench.at0, &rates)?;
    let fit = lines(&rates, &z);
    let sf = fit.map(|l| l.0);
    let residual_ppm: Vec<[f64; 2]> = rates
        .iter()
        .zip(&z)
        .map(|(r, v)| {
            std::array::from_fn(|k| {
                (v[k] - fit[k].1 - fit[k].0 * r) / (sf[k].abs() * full_scale_dps) * 1e6
            })
        })
        .collect();
    let nonlinearity_ppm =
        std::array::from_fn(|k| residual_ppm.iter().map(|v| v[k].abs()).fold(0.0, f64::max));
    let mid = SWEEP_POINTS / 2;
    let pos = lines(&rates[mid..], &z[mid..]);
    let neg = lines(&rates[..=mid], &z[..=mid]);
    let halves = [pos.map(|l| l.0), neg.map(|l| l.0)];
    let asymmetry_ppm = std::array::from_fn(|k| {
        (halves[0][k] - halves[1][k]) / ((halves[0][k] + halves[1][k]) / 2.0) * 1e6
    });
    Ok(Sweep {
        full_scale_dps,
        rates_dps: rates,
        z_lsb: z,
        window_s: bench.window_clocks() / bench.knowns.clock_hz,
        sf_lsb_per_dps: sf,
        intercept_lsb: fit.map(|l| l.1),
        residual_ppm,
        nonlinearity_ppm,
        sf_halves_lsb_per_dps: halves,
        asymmetry_ppm,
    })
}
