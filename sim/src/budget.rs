//! The uncertainty budget of the figures a run reports (SF_read, SF_cal,
//! their ratio, per output): each 1-sigma term by source, and their root
//! sum of squares, the `_uncertainty` the report gives.
//!
//! - `statistical`: the spread of the batch slopes (`crate::fit`), times
//!   `fit::coverage_factor` of its degrees of freedom (7 in readout, 8 per
//!   extra ripple period in calibration), so that 3 sigma covers what a
//!   normal 3 sigma would (the bare spread with 7 degrees of freedom left
//!   2% of errors beyond 3 sigma); `experiment::measured_lines` applies it.
//! - `settling`: each point's bound on the transient's bias
//!   (`crate::settling`), weighted by |x_i - mean x| / Sxx as the slope
//!   weighs the point and added, over sqrt 3 (a bound of unknown sign,
//!   taken as uniform).
//! - `images`: the shift the DAC's images make in the sampled loop, which
//!   the exact theory leaves out (`crate::images`), computed with the same
//!   fit: the truth's own error, known in size and sign (`Theory::images`
//!   in the report gives it signed).
//!
//! Readout and calibration are independent runs, so a ratio's relative
//! terms add in quadrature (images: the shifted ratio's own difference).

use crate::experiment::{Mode, PointResult};
use crate::fit::{ScaleFactors, linear_fit};
use serde::Serialize;

/// One figure's 1-sigma uncertainty by source (the figure's units).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Terms {
    /// Batch spread at its degrees of freedom.
    pub statistical: f64,
    /// Settling transient's bias (bound over sqrt 3).
    pub settling: f64,
    /// DAC images against the exact theory (the computed shift).
    pub images: f64,
    /// Root sum of squares of the terms.
    pub total: f64,
}

impl Terms {
    fn new(statistical: f64, settling: f64, images: f64) -> Self {
        let total = (statistical * statistical + settling * settling + images * images).sqrt();
        Self {
            statistical,
            settling,
            images,
            total,
        }
    }

    /// Each term of `self` (about `a`) and of `other` (about `b`) as the
    /// uncertainty of a / b (independent), with the images term given.
    fn of_ratio(&self, a: f64, other: &Terms, b: f64, images: f64) -> Self {
        let r = (a / b).abs();
        let rel = |x: f64, y: f64| r * ((x / a).powi(2) + (y / b).powi(2)).sqrt();
        Self::new(
            rel(self.statistical, other.statistical),
            rel(self.settling, other.settling),
            images,
        )
    }
}

/// The budget of every figure, per output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Budget {
    /// Readout scale factor ((m^2/s^2) per deg/s).
    pub sf_read_per_dps: [Terms; 2],
    /// Calibration scale factor ((m^2/s^2) per deg/s of virtual rate).
    pub sf_cal_per_dps: [Terms; 2],
    /// Their ratio.
    pub ratio: [Terms; 2],
}

/// What the DAC's images add to the exact theory's figures (signed).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImageShifts {
    /// Readout scale factor.
    pub sf_read_per_dps: [f64; 2],
    /// Calibration scale factor.
    pub sf_cal_per_dps: [f64; 2],
    /// Ratio.
    pub ratio: [f64; 2],
}

/// One sweep's slope terms per output (`statistical` the slopes' batch
/// uncertainty, `crate::experiment::measured_lines`), and the theory's
/// slope and its image shift.
fn sweep_terms(
    points: &[PointResult],
    mode: Mode,
    statistical: [f64; 2],
) -> [(Terms, f64, f64); 2] {
    let sweep: Vec<&PointResult> = points.iter().filter(|p| p.mode == mode).collect();
    let x: Vec<f64> = sweep.iter().map(|p| p.rate_dps).collect();
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let sxx: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
    std::array::from_fn(|k| {
        let bound: f64 = sweep
            .iter()
            .zip(&x)
            .map(|(p, v)| (v - mean).abs() / sxx * p.settling_bound[k])
            .sum();
        let exact: Vec<f64> = sweep.iter().map(|p| p.z_theory[k]).collect();
        let shifted: Vec<f64> = sweep
            .iter()
            .map(|p| p.z_theory[k] + p.z_images[k])
            .collect();
        let slope = linear_fit(&x, &exact).0;
        let images = linear_fit(&x, &shifted).0 - slope;
        (
            Terms::new(statistical[k], bound / 3f64.sqrt(), images.abs()),
            slope,
            images,
        )
    })
}

/// The budget of a run's figures, and the images' signed shifts;
/// `measured` holds the slopes and their statistical uncertainties.
pub fn budget(points: &[PointResult], measured: &ScaleFactors) -> (Budget, ImageShifts) {
    let read = sweep_terms(points, Mode::Readout, measured.sf_read_uncertainty);
    let cal = sweep_terms(points, Mode::Calibration, measured.sf_cal_uncertainty);
    let ratio_shift: [f64; 2] = std::array::from_fn(|k| {
        let (r, c) = (&read[k], &cal[k]);
        (r.1 + r.2) / (c.1 + c.2) - r.1 / c.1
    });
    let ratio = std::array::from_fn(|k| {
        read[k].0.of_ratio(
            measured.sf_read_per_dps[k],
            &cal[k].0,
            measured.sf_cal_per_dps[k],
            ratio_shift[k].abs(),
        )
    });
    (
        Budget {
            sf_read_per_dps: read.map(|t| t.0),
            sf_cal_per_dps: cal.map(|t| t.0),
            ratio,
        },
        ImageShifts {
            sf_read_per_dps: read.map(|t| t.2),
            sf_cal_per_dps: cal.map(|t| t.2),
            ratio: ratio_shift,
        },
    )
}

/// One line per output whose ratio's systematic terms exceed its target
/// (longer windows cannot lower them): how large, and what would.
/// `carrier_per_clock` is the realized carrier over the clock.
pub fn warnings(budget: &Budget, target: [f64; 2], carrier_per_clock: f64) -> Vec<String> {
    let mut lines = vec![];
    for (k, t) in budget.ratio.iter().enumerate() {
        if t.images > target[k] {
            lines.push(format!(
                "output {}: the DAC's images, aliased back by the ADC, move the ratio by {:.2e} against the exact theory, which leaves them out (target {:.2e}; theory.images gives the shift with its sign): the carrier is {:.3} of the clock, and they fall at least as its cube (a faster clock)",
                k + 1,
                t.images,
                target[k],
                carrier_per_clock
            ));
        }
        if t.settling > target[k] {
            lines.push(format!(
                "output {}: the settling transient's bound on the ratio is {:.2e} (target {:.2e}); a lower tolerance settles longer",
                k + 1,
                t.settling,
                target[k]
            ));
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ratio_adds_its_slopes_relative_terms_and_keeps_its_own_images() {
        // a = 2 +- (0.02 stat, 0.01 settling), b = -4 +- (0.04, 0): the
        // ratio -0.5 has relative terms sqrt(1e-4 + 1e-4) and 5e-3.
        let a = Terms::new(0.02, 0.01, 0.3);
        let b = Terms::new(0.04, 0.0, 0.7);
        let r = a.of_ratio(2.0, &b, -4.0, 1e-3);
        assert!((r.statistical - 0.5 * 2e-4f64.sqrt()).abs() < 1e-12);
        assert!((r.settling - 0.5 * 5e-3).abs() < 1e-12);
        assert_eq!(r.images, 1e-3);
        let total = (r.statistical.powi(2) + r.settling.powi(2) + 1e-6).sqrt();
        assert!((r.total - total).abs() < 1e-15);
    }
}
