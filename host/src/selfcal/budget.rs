//! The self-calibrated scale factor's uncertainty, by source: each term
//! moves the prediction or the staircase by its own 1-sigma, through the
//! same exact theory, and the terms add in quadrature (independent
//! sources).

use super::predict::{predicted_ratio, predicted_ratio_lagged};
use super::{Operating, Ratio};
use crate::device::GyroParams;
use crate::error::Error;
use crate::identify::Identified;
use crate::knowns::Knowns;
use serde::{Deserialize, Serialize};

/// Relative 1-sigma uncertainties of the self-calibrated scale factors,
/// per output, by source, and their quadrature sum.
///
/// A drive-gain ratio the cycle could not measure (no quadrature coupling
/// at rest, no `[drive_probe]`) is the design's, with the datasheet's
/// `drive_gain_ratio_uncertainty` in `drive_ratio`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SfUncertainty {
    /// The staircase slope's noise (`staircase`), with the coverage
    /// factor of its degrees of freedom.
    pub staircase: [f64; 2],
    /// The predicted ratio's, from the identified f1, f2, Q1, Q2,
    /// mode couplings, group delay and loop phase (each moved by its
    /// uncertainty through the exact theory), and the front end's
    /// unmeasured gain slope, at the DAC's images and across the
    /// calibration's sidebands.
    pub identified: [f64; 2],
    /// The datasheet's angular gain lambda: its relative 1-sigma moved
    /// through the exact theory (the ratio scales with lambda, one for one
    /// to first order).
    pub angular_gain: [f64; 2],
    /// The drive-gain ratio's: the measured ratio's sigma, or without a
    /// measurement the datasheet's on the design ratio.
    pub drive_ratio: [f64; 2],
    /// The rate the device turned at during the cycle: the prediction,
    /// at the rate `super::predicted_rate` gives (the couplings' windows'
    /// reading where it is seen, else 0), moved by that rate's sigma. A
    /// detuned output's calibration moves with the rate (the consumer
    /// device's output 2 by 4.6% per deg/s), so on such a device this
    /// term is there at rest too.
    pub cycle_rate: [f64; 2],
    /// The FPGA clock's error, within `Knowns::clock_tolerance`
    /// (`budget::clock`): a bound, taken as uniform (its sigma is the bound
    /// over sqrt(3)).
    pub clock: [f64; 2],
    /// All of them in quadrature.
    pub total: [f64; 2],
}

impl SfUncertainty {
    /// The sources' names, in the order [`SfUncertainty::terms`] gives
    /// them: the JSON's keys.
    pub const TERMS: [&'static str; 6] = [
        "staircase",
        "identified",
        "angular_gain",
        "drive_ratio",
        "cycle_rate",
        "clock",
    ];

    /// Output `k`'s terms, named as [`SfUncertainty::TERMS`].
    ///
    /// ```
    /// use gyrocal_host::selfcal::SfUncertainty;
    /// let u = SfUncertainty { cycle_rate: [0.0, 3e-3], staircase: [1e-4, 4e-3], ..Default::default() }
    ///     .with_total();
    /// assert_eq!(u.terms(1)[4], ("cycle_rate", 3e-3));
    /// assert!((u.total[1] - 5e-3).abs() < 1e-15);
    /// ```
    pub fn terms(&self, k: usize) -> [(&'static str, f64); 6] {
        let values = [
            self.staircase[k],
            self.identified[k],
            self.angular_gain[k],
            self.drive_ratio[k],
            self.cycle_rate[k],
            self.clock[k],
        ];
        std::array::from_fn(|i| (Self::TERMS[i], values[i]))
    }

    /// The quadrature sum into `total`.
    pub fn with_total(mut self) -> Self {
        self.total = std::array::from_fn(|k| {
            self.terms(k)
                .into_iter()
                .fold(0.0, |sum: f64, (_, term)| sum.hypot(term))
        });
        self
    }
}

/// Relative change of each output's ratio, in quadrature over `moved`.
fn spread(moved: &[Ratio], ratio: &Ratio) -> [f64; 2] {
    std::array::from_fn(|k| {
        moved
            .iter()
            .map(|m| (m.exact[k] / ratio.exact[k] - 1.0).powi(2))
            .sum::<f64>()
            .sqrt()
    })
}

/// The predicted ratio's relative 1-sigma uncertainty per output from the
/// identified parameters: each of f1, Q1, f2, Q2, the two mode couplings,
/// the group delay and the loop phase (as a residual error of the
/// correction) moved by its uncertainty (independent fits), and the front
/// end moved to its first-order form (`front_slope`), the changes added
/// in quadrature.
pub(super) fn identified(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    cal_hz: &[f64],
    ratio: &Ratio,
) -> Result<[f64; 2], Error> {
    let gyro = id.gyro(&knowns.nominal);
    let [m1, m2] = &id.modes;
    let mut moved = vec![];
    for (i, sd) in [m1.f_hz, m1.q, m2.f_hz, m2.q]
        .map(|e| e.uncertainty)
        .into_iter()
        .enumerate()
    {
        let mut g = gyro.clone();
        *[&mut g.f1_hz, &mut g.q1, &mut g.f2_hz, &mut g.q2][i] += sd;
        moved.push(predicted_ratio(knowns, &g, op, cal_hz)?);
    }
    // The couplings by their measurement's sigma alone: the prediction
    // turns them back into stiffness with the lambda that made the figure.
    if let Some(q) = id.quadrature_dps {
        let mut g = gyro.clone();
        g.quadrature_dps += q.measurement_uncertainty;
        moved.push(predicted_ratio(knowns, &g, op, cal_hz)?);
    }
    if let Some(d) = id.damping_coupling_dps {
        let mut g = gyro.clone();
        g.damping_coupling_dps += d.measurement_uncertainty;
        moved.push(predicted_ratio(knowns, &g, op, cal_hz)?);
    }
    if id.group_delay_s.uncertainty.is_finite() {
        let mut o = op.clone();
        o.envelope_delay_s += id.group_delay_s.uncertainty;
        moved.push(predicted_ratio(knowns, &gyro, &o, cal_hz)?);
    }
    let lag = id.loop_phase_deg.uncertainty.to_radians();
    moved.push(predicted_ratio_lagged(
        knowns, &gyro, op, cal_hz, lag, None,
    )?);
    moved.push(front_slope(knowns, id, op, cal_hz, ratio)?);
    Ok(spread(&moved, ratio))
}

/// The front end's gain slope is not measured (`identify::FrontEnd`
/// bounds it): the prediction with the first-order form instead of the
/// delay's turn (`images::ImageFront`), with the gain slope at either end
/// of a first-order front end's bound +-sin(phi)^2 / f, the farther of the
/// two per output. The slope acts at the DAC's images and across the
/// calibration's sidebands (`predict::predicted_ratio_lagged`); there it
/// is the larger part on a detuned output. The simulator's pick-off sits
/// at the + end, so its error is about this term, whatever the lag: on
/// seed 2096 of `tests/field_coverage.rs`, output 1's mean error over 12
/// noise seeds at 4 and 8 deg of lag was 0.94 and 0.98 of it (it had been
/// -2.2 and -5.0 sigma without it).
fn front_slope(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    cal_hz: &[f64],
    ratio: &Ratio,
) -> Result<Ratio, Error> {
    let gyro = id.gyro(&knowns.nominal);
    let bound = id.loop_phase_deg.value.to_radians().sin().powi(2) / op.carrier_hz;
    let [up, down] =
        [bound, -bound].map(|a| predicted_ratio_lagged(knowns, &gyro, op, cal_hz, 0.0, Some(a)));
    let (up, down) = (up?, down?);
    let farther = |k: usize| {
        let change = |r: &Ratio| (r.exact[k] / ratio.exact[k] - 1.0).abs();
        if change(&up) >= change(&down) {
            up.exact[k]
        } else {
            down.exact[k]
        }
    };
    Ok(Ratio {
        exact: std::array::from_fn(farther),
        ..ratio.clone()
    })
}

/// A datasheet sigma `u` (relative) through the exact theory: the ratio
/// predicted with the quantity moved by `u` (`moved`), against `ratio`;
/// no term for `u` = 0.
fn datasheet_term(
    u: f64,
    ratio: &Ratio,
    moved: impl FnOnce(f64) -> Result<Ratio, Error>,
) -> Result<[f64; 2], Error> {
    if u == 0.0 {
        return Ok([0.0; 2]);
    }
    Ok(spread(&[moved(u)?], ratio))
}

/// The predicted ratio's relative 1-sigma from the datasheet's lambda
/// (`Knowns::angular_gain_uncertainty`), through the exact theory.
pub(super) fn angular_gain(
    knowns: &Knowns,
    gyro: &GyroParams,
    op: &Operating,
    cal_hz: &[f64],
    ratio: &Ratio,
) -> Result<[f64; 2], Error> {
    datasheet_term(knowns.angular_gain_uncertainty, ratio, |u| {
        let mut g = gyro.clone();
        g.angular_gain *= 1.0 + u;
        // The windows measured the Coriolis term 2 lambda Omega, read in
        // deg/s with the datasheet's lambda: it stays what they measured.
        let o = Operating {
            cycle_rate_dps: op.cycle_rate_dps / (1.0 + u),
            ..op.clone()
        };
        predicted_ratio(knowns, &g, &o, cal_hz)
    })
}

/// The predicted ratio's relative 1-sigma from the rate read during the
/// cycle (`SfUncertainty::cycle_rate`): the prediction with the rate
/// moved by its sigma (`super::predicted_rate`); no term before the rate
/// is read.
pub(super) fn cycle_rate(
    knowns: &Knowns,
    id: &Identified,
    op: &Operating,
    cal_hz: &[f64],
    ratio: &Ratio,
) -> Result<[f64; 2], Error> {
    let Some(reading) = id.cycle_rate_dps else {
        return Ok([0.0; 2]);
    };
    let o = Operating {
        cycle_rate_dps: op.cycle_rate_dps
            + super::predicted_rate(reading, knowns.rest_bound_dps).uncertainty,
        ..op.clone()
    };
    let moved = predicted_ratio(knowns, &id.gyro(&knowns.nominal), &o, cal_hz)?;
    Ok(spread(&[moved], ratio))
}

/// The predicted ratio's relative 1-sigma from the design drive-gain
/// ratio's (`Knowns::drive_gain_ratio_uncertainty`): drive 2's force gain
/// moved by it through the exact theory (`super::with_drive_ratio`).
pub(super) fn design_drive_ratio(
    knowns: &Knowns,
    gyro: &GyroParams,
    op: &Operating,
    cal_hz: &[f64],
    ratio: &Ratio,
) -> Result<[f64; 2], Error> {
    datasheet_term(knowns.drive_gain_ratio_uncertainty, ratio, |u| {
        predicted_ratio(&super::with_drive_ratio(knowns, 1.0 + u), gyro, op, cal_hz)
    })
}

/// The predicted ratio's relative 1-sigma from the FPGA clock's error
/// (`SfUncertainty::clock`), for a clock whose frequency lies within
/// `Knowns::clock_tolerance` e of what the host takes.
///
/// Everything the host measures and programs runs on that clock, so a
/// clock fast by e is invisible to it: the loop on a clock fast by e is,
/// clock for clock, the loop of a device whose frequencies, rates and
/// couplings are all 1 / (1 + e) of the real ones (its forces (1 + e)^-2,
/// which the prediction's ratio does not see). The self-calibration is
/// exact for that device, in its units: a real rate r reads as r / (1 +
/// e), so the figure is (1 + e) times the real scale factor, and its
/// readout slope is the secant over rates the host takes as the table's
/// but which are (1 + e) times them in the real device's, which moves a
/// slope that curves over the rates (a resonant output's offset turning
/// with the rate: 0.5 to 1.4 e on random devices' output 1). So the
/// figure's error is (1 + e) R(rates (1 + e)) / R(rates) - 1, with R
/// the predicted ratio; taken at both ends of the bound, the larger, over
/// sqrt(3). Measured with `[drive] clock_error_ppm` on 16 random devices
/// at +-5000 ppm: 1.5 to 2.4 e on output 1, 0.9 to 1.3 e on output 2.
pub(super) fn clock(
    knowns: &Knowns,
    gyro: &GyroParams,
    op: &Operating,
    cal_hz: &[f64],
    ratio: &Ratio,
) -> Result<[f64; 2], Error> {
    let e = knowns.clock_tolerance;
    if e == 0.0 {
        return Ok([0.0; 2]);
    }
    let mut worst = [0.0f64; 2];
    for e in [e, -e] {
        let fast = Knowns {
            rates_dps: knowns.rates_dps.iter().map(|r| r * (1.0 + e)).collect(),
            ..knowns.clone()
        };
        let moved = predicted_ratio(&fast, gyro, op, cal_hz)?;
        for (k, w) in worst.iter_mut().enumerate() {
            *w = w.max(((1.0 + e) * moved.exact[k] / ratio.exact[k] - 1.0).abs());
        }
    }
    Ok(worst.map(|w| w / 3f64.sqrt()))
}
