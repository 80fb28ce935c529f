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

use crate::theory::{Device, calibration_z, readout_z};

/// Least-squares line `y = slope x + intercept`; returns `(slope, intercept)`.
///
/// Centered two-pass sums, so a large common offset in `y` or `x` costs no accuracy.
///
/// # Panics
/// If the lengths differ, there are fewer than 2 points, or all `x` are equal.
pub fn linear_fit(x: &[f64], y: &[f64]) -> (f64, f64) {
    assert_eq!(x.len(), y.len(), "linear_fit: x and y lengths differ");
    assert!(x.len() >= 2, "linear_fit: needs at least 2 points");
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for (&xi, &yi) in x.iter().zip(y) {
        let dx = xi - mx;
        sxx += dx * dx;
        sxy += dx * (yi - my);
    }
    assert!(sxx > 0.0, "linear_fit: all x are equal");
    let slope = sxy / sxx;
    (slope, my - slope * mx)
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
