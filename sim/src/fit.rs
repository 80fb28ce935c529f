//! Least-squares scale factors, fitted the way the paper measures them.
//!
//! The paper fits a straight line to readout outputs at rates of 1-20 deg/s and to
//! calibration outputs at f_cal = 10-15 Hz (virtual rates `360 f_cal` deg/s).
//! [`fitted_scale_factors`] does the same on the exact steady state of
//! [`crate::theory`], with an intercept (readout outputs carry large offsets with
//! mismatched modes), so the result includes the curvature of the exact response
//! over the fitted span: compare co-simulations with these numbers, not with the
//! small-signal ones.
//!
//! Units: rates in deg/s, f_cal in Hz, z in m^2/s^2, scale factors in
//! (m^2/s^2) per deg/s, ratio dimensionless.
//!
//! Uncertainties, from the data alone. Every point's window is cut into
//! the same number of batches, and the points of a sweep share their batch
//! boundaries relative to power-up. Batch j of every point gives one line;
//! the reported slope is the slope of the points' means, which (the fit
//! being linear in y) is the mean of the batch slopes, and its 1-sigma
//! uncertainty is their standard deviation over sqrt(batches). Residues
//! common to all points of a sweep (the converters' quantization pattern is
//! nearly the same at every rate) cancel in each batch's slope as they do in
//! the final one, which a per-point uncertainty propagated as if the points
//! were independent would miss (it errs high 20-fold on the paper's
//! readout). Readout and calibration are different runs, so a ratio's
//! relative variance is the sum of its slopes' (first order).

use crate::theory::{Device, calibration_z, readout_z};
use serde::Serialize;

pub use gyrocal_host::stats::{coverage_factor, linear_fit, mean_and_standard_error};

/// A fitted line and its slope's 1-sigma uncertainty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// Slope.
    pub slope: f64,
    /// Intercept.
    pub intercept: f64,
    /// 1-sigma uncertainty of the slope (0 for exact values).
    pub slope_uncertainty: f64,
}

/// Least-squares line through points `x[i]` whose values were measured as
/// `batches[i]` (batch means, the same number for every point): the line
/// of the means, with the spread of the batch lines as its uncertainty.
///
/// ```
/// use gyrocal_sim::fit::fit_batches;
/// // y = 2x + 1, with batch residues common to both points (they cancel)
/// // plus +-0.1 on the second point.
/// let line = fit_batches(&[0.0, 1.0], &[vec![1.5, 0.5], vec![3.6, 2.4]]);
/// assert!((line.slope - 2.0).abs() < 1e-12);
/// // Batch slopes 2.1 and 1.9: sd 0.1414, over sqrt(2).
/// assert!((line.slope_uncertainty - 0.1).abs() < 1e-12);
/// ```
///
/// # Panics
/// As [`linear_fit`], or if the points have different numbers of batches
/// or fewer than 2.
pub fn fit_batches(x: &[f64], batches: &[Vec<f64>]) -> Line {
    let n = batches[0].len();
    assert!(n >= 2, "fit_batches: needs at least 2 batches");
    assert!(
        batches.iter().all(|b| b.len() == n),
        "fit_batches: unequal batches"
    );
    let means: Vec<f64> = batches
        .iter()
        .map(|b| b.iter().sum::<f64>() / n as f64)
        .collect();
    let (slope, intercept) = linear_fit(x, &means);
    let slopes: Vec<f64> = (0..n)
        .map(|j| linear_fit(x, &batches.iter().map(|b| b[j]).collect::<Vec<_>>()).0)
        .collect();
    Line {
        slope,
        intercept,
        slope_uncertainty: mean_and_standard_error(&slopes).1,
    }
}

/// 1-sigma uncertainty of `a / b` for independent `a +- sa`, `b +- sb`.
pub fn ratio_uncertainty(a: f64, sa: f64, b: f64, sb: f64) -> f64 {
    (a / b).abs() * ((sa / a).powi(2) + (sb / b).powi(2)).sqrt()
}

/// Scale factors per output with their uncertainties, in the sign
/// convention of the paper's equations, (m^2/s^2) per deg/s.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScaleFactors {
    /// Readout scale factor [output 1, output 2].
    pub sf_read_per_dps: [f64; 2],
    /// Its 1-sigma uncertainty.
    pub sf_read_uncertainty: [f64; 2],
    /// Calibration scale factor per deg/s of virtual rate.
    pub sf_cal_per_dps: [f64; 2],
    /// Its 1-sigma uncertainty.
    pub sf_cal_uncertainty: [f64; 2],
    /// sf_read / sf_cal.
    pub ratio: [f64; 2],
    /// Its 1-sigma uncertainty.
    pub ratio_uncertainty: [f64; 2],
    /// Intercepts of the readout lines.
    pub intercept_read: [f64; 2],
    /// Intercepts of the calibration lines.
    pub intercept_cal: [f64; 2],
}

impl ScaleFactors {
    /// From the readout and calibration lines of both outputs.
    pub fn from_lines(read: [Line; 2], cal: [Line; 2]) -> Self {
        Self {
            sf_read_per_dps: read.map(|l| l.slope),
            sf_read_uncertainty: read.map(|l| l.slope_uncertainty),
            sf_cal_per_dps: cal.map(|l| l.slope),
            sf_cal_uncertainty: cal.map(|l| l.slope_uncertainty),
            ratio: std::array::from_fn(|k| read[k].slope / cal[k].slope),
            ratio_uncertainty: std::array::from_fn(|k| {
                ratio_uncertainty(
                    read[k].slope,
                    read[k].slope_uncertainty,
                    cal[k].slope,
                    cal[k].slope_uncertainty,
                )
            }),
            intercept_read: read.map(|l| l.intercept),
            intercept_cal: cal.map(|l| l.intercept),
        }
    }
}

/// Scale factors fitted over lists of points, per output `[z1, z2]`.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedScaleFactors {
    /// Readout slope ((m^2/s^2)/(deg/s)).
    pub sf_read_per_dps: [f64; 2],
    /// Calibration slope per deg/s of virtual rate `360 f_cal` ((m^2/s^2)/(deg/s)).
    pub sf_cal_per_dps: [f64; 2],
    /// `sf_read / sf_cal`.
    pub ratio: [f64; 2],
}

/// Fits the exact steady state: readout at `rates_dps` (deg/s) (Omz = rate
/// pi/180 rad/s), calibration at `cal_freqs_hz` (Hz) against the virtual rate
/// `360 f_cal` deg/s. Slopes with intercept.
///
/// # Panics
/// As [`linear_fit`]: each list needs at least 2 distinct points.
pub fn fitted_scale_factors(
    dev: &Device,
    rates_dps: &[f64],
    cal_freqs_hz: &[f64],
) -> FittedScaleFactors {
    let read: Vec<[f64; 2]> = rates_dps
        .iter()
        .map(|r| readout_z(dev, r.to_radians()))
        .collect();
    let cal: Vec<[f64; 2]> = cal_freqs_hz
        .iter()
        .map(|&f| calibration_z(dev, f))
        .collect();
    let virt: Vec<f64> = cal_freqs_hz.iter().map(|f| 360.0 * f).collect();
    let mut out = FittedScaleFactors {
        sf_read_per_dps: [0.0; 2],
        sf_cal_per_dps: [0.0; 2],
        ratio: [0.0; 2],
    };
    for k in 0..2 {
        let yr: Vec<f64> = read.iter().map(|z| z[k]).collect();
        let yc: Vec<f64> = cal.iter().map(|z| z[k]).collect();
        out.sf_read_per_dps[k] = linear_fit(rates_dps, &yr).0;
        out.sf_cal_per_dps[k] = linear_fit(&virt, &yc).0;
        out.ratio[k] = out.sf_read_per_dps[k] / out.sf_cal_per_dps[k];
    }
    out
}
