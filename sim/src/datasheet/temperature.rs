//! Bias and scale-factor temperature coefficients over the `[drift]`
//! steps, as a user without self-calibration sees them.
//!
//! At each step `T` the device is `Drift::at(T)` on fresh boards at the
//! factory's settings (nominal carrier, aligned reference), read at rest
//! and at each `[experiment] readout_rates_dps` (in parallel): the line's
//! slope `SF(T)` and intercept `z0(T)`. With the factory's calibration
//! (`SF(T0)`, `z0(T0)` at the first step) the rate output at rest reads
//!
//! ```text
//! bias(T) = (z0(T) - z0(T0)) / SF(T0)          (deg/h)
//! sf_error(T) = SF(T) / SF(T0) - 1             (ppm)
//! ```
//!
//! and the coefficients are their least-squares slopes against `T`
//! (deg/h per K, ppm per K); null with a single temperature.

use super::Error;
use super::bench::Bench;
use crate::drift::Drift;
use crate::fit::linear_fit;
use rayon::prelude::*;
use serde::Serialize;

/// One temperature step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TemperatureStep {
    /// Temperature (deg C).
    pub temperature_c: f64,
    /// Slope at the factory's settings (z LSB per deg/s).
    pub sf_lsb_per_dps: [f64; 2],
    /// Intercept (z LSB).
    pub intercept_lsb: [f64; 2],
    /// The rate output at rest with the factory's calibration (deg/h).
    pub bias_deg_per_h: [f64; 2],
    /// `SF(T) / SF(T0) - 1` (ppm).
    pub sf_error_ppm: [f64; 2],
}

/// The steps and the coefficients.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Temperature {
    /// The rates of each table (deg/s).
    pub rates_dps: Vec<f64>,
    /// One entry per `[drift]` step, in the file's order.
    pub steps: Vec<TemperatureStep>,
    /// Bias temperature coefficient (deg/h per K), null with one temperature.
    pub bias_tc_deg_per_h_per_k: Option<[f64; 2]>,
    /// Scale-factor temperature coefficient (ppm per K), likewise.
    pub sf_tc_ppm_per_k: Option<[f64; 2]>,
}

/// Run the tables at every step of `drift`.
pub fn run(bench: &Bench, drift: &Drift) -> Result<Temperature, Error> {
    let mut rates = vec![0.0];
    rates.extend(
        bench
            .exp
            .points
            .readout_rates_dps
            .iter()
            .filter(|r| **r != 0.0),
    );
    let temps = &drift.temperatures_c;
    // Each temperature's rates in lanes (`Bench::readings`), the
    // temperatures in parallel.
    let z: Vec<Vec<[f64; 2]>> = temps
        .par_iter()
        .map(|&t| bench.readings(&drift.at(&bench.exp.gyro, t), &rates))
        .collect::<Result<_, _>>()?;
    let z: Vec<[f64; 2]> = z.into_iter().flatten().collect();
    let lines: Vec<[(f64, f64); 2]> = z
        .chunks(rates.len())
        .map(|zt| {
            std::array::from_fn(|k| {
                let y: Vec<f64> = zt.iter().map(|v| v[k]).collect();
                linear_fit(&rates, &y)
            })
        })
        .collect();
    let first = lines[0];
    let steps: Vec<TemperatureStep> = temps
        .iter()
        .zip(&lines)
        .map(|(&t, l)| TemperatureStep {
            temperature_c: t,
            sf_lsb_per_dps: l.map(|v| v.0),
            intercept_lsb: l.map(|v| v.1),
            bias_deg_per_h: std::array::from_fn(|k| (l[k].1 - first[k].1) / first[k].0 * 3600.0),
            sf_error_ppm: std::array::from_fn(|k| (l[k].0 / first[k].0 - 1.0) * 1e6),
        })
        .collect();
    let distinct = temps.iter().any(|t| *t != temps[0]);
    let slope = |f: &dyn Fn(&TemperatureStep) -> [f64; 2]| -> Option<[f64; 2]> {
        distinct.then(|| {
            std::array::from_fn(|k| {
                let y: Vec<f64> = steps.iter().map(|s| f(s)[k]).collect();
                linear_fit(temps, &y).0
            })
        })
    };
    Ok(Temperature {
        bias_tc_deg_per_h_per_k: slope(&|s| s.bias_deg_per_h),
        sf_tc_ppm_per_k: slope(&|s| s.sf_error_ppm),
        rates_dps: rates,
        steps,
    })
}
