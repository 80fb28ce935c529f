//! The drive-gain ratio the couplings' windows give, and the couplings
//! and the rate read again at it.
//!
//! The windows read each output's stiffness K and damping term D with the
//! design drive-gain ratio (`crate::coupling`): for a true ratio r times
//! the design's, output 1 reads them times r (its cross term is drive
//! 2's) and output 2 over r, and a rate C enters the two D with opposite
//! signs:
//!
//! ```text
//! K_1 = K r,   D_1 = (d - C) r,   K_2 = K / r,   D_2 = (d + C) / r
//! ```
//!
//! The cycle reads the means K' and m = (D_1 + D_2) / 2 and the half
//! difference h = (D_2 - D_1) / 2 (the coupling's figures and the rate,
//! [`crate::coupling::Coupling`]). With a = (r + 1/r) / 2 and b = (r - 1/r)
//! / 2 (a^2 - b^2 = 1), exactly:
//!
//! ```text
//! K = K' / a,   d = a m + b h,   C = a h + b m
//! ```
//!
//! So a damping coupling reads as a rate -b d when the drive gains part: on
//! the coupled device (`tests/data/field_coupled.toml`) with -200 deg/s of
//! damping coupling at 60 deg C, where the drives part by 2.1%, the rate
//! read -4.2 deg/s at rest, the cycle predicted the calibration at it and
//! output 2 came out 1.95% off (`tests/field_coupling.rs`). Where the
//! coupling makes the ratio observable at rest (`AT_REST_RATIO_SIGMA`) the
//! figures are read again at the measured r; elsewhere r is the design's,
//! and the rate's sigma carries |m| times the datasheet's
//! `drive_gain_ratio_uncertainty`, what a drive gain that drifted within
//! it leaves (r's sigma likewise where it is measured).
//!
//! Only a coupling makes the ratio observable here: where the rate's
//! Coriolis term is the larger of the cross responses' two, the ratio is
//! the design's, as at rest without a coupling. The windows' estimate
//! while turning did not hold its sigma: on a 27.2 / 28.1 kHz device
//! without coupling (Q 2057 / 893) at -18.4 deg/s it read 1.0020 +- 0.0007
//! where the device's is 1, over five noise seeds 1.3 to 9.3 of its sigmas
//! off, and it put the device's output 2 at -3.4 sigma (with the design
//! ratio: -0.4). The measurement made for a turning device is
//! `[drive_probe]` (`crate::drive_ratio`).
//!
//! The ratio's estimate itself moves with the rate where there is a
//! damping coupling (`drive_ratio::turning_factor`, which reads the rate
//! off the identification), so the two are iterated until the ratio
//! settles (`drive_ratio::settled`, which the probe's rounds share). At
//! rest the rate is not seen and is predicted at 0, so the ratio does not
//! move and one round settles it: on `tests/data/field_coupled.toml` at
//! each temperature eight rounds read the same ratio to the last digit.

use super::{AT_REST_RATIO_SIGMA, Operating};
use crate::coupling::TurningLine;
use crate::drive_ratio::{self, CrossWindows, DriveRatio};
use crate::identify::{CouplingFigure, Estimate, Identified};
use crate::knowns::Knowns;

/// `read` (the couplings and the rate as the windows read them, at the
/// design ratio) at the drive-gain ratio the same windows give, and that
/// ratio where it is observable at rest (module header). `spur_lines`:
/// the table core's lines in the windows (`coupling::spur_lines`), in the
/// ratio's sigma.
///
/// Returns the figures as the windows read them, too: a ratio measured
/// later (`[drive_probe]`) reads them again at its own
/// (`selfcal::apply_drive_ratio`).
pub(super) fn ratio_at_rest(
    windows: &CrossWindows,
    knowns: &Knowns,
    op: &Operating,
    read: Identified,
    spur_lines: Option<&[TurningLine]>,
) -> (Identified, Option<DriveRatio>, Figures) {
    let figures = Figures::of(&read);
    let lambda = knowns.angular_gain_uncertainty;
    let mut id = read;
    let first = drive_ratio::from_windows(windows, knowns, op, &id, spur_lines);
    let settled = drive_ratio::settled(
        first,
        |ratio| {
            let (kappa, c) = drive_ratio::cross_terms(&id, op.carrier_hz);
            if ratio.relative.uncertainty >= AT_REST_RATIO_SIGMA || c.norm() > kappa.norm() {
                return Err(Unobservable);
            }
            figures.at_ratio(ratio.relative, lambda).put(&mut id);
            Ok(drive_ratio::from_windows(
                windows, knowns, op, &id, spur_lines,
            ))
        },
        |_, _| Unobservable,
    );
    match settled {
        Ok(ratio) => {
            figures.at_ratio(ratio.relative, lambda).put(&mut id);
            (id, Some(ratio), figures)
        }
        Err(Unobservable) => {
            let design = Estimate {
                value: 1.0,
                uncertainty: knowns.drive_gain_ratio_uncertainty,
            };
            figures.at_ratio(design, lambda).put(&mut id);
            (id, None, figures)
        }
    }
}

/// The ratio is not observable at rest: its sigma beyond
/// `AT_REST_RATIO_SIGMA`, the rate's Coriolis term the larger of the
/// cross responses' two (module header), or its rounds, with a rate seen
/// near a damping coupling's, do not settle (`drive_ratio::settled`).
struct Unobservable;

/// What the couplings' windows read: the two couplings and the rate
/// (`Identified`'s `quadrature_dps`, `damping_coupling_dps` and
/// `cycle_rate_dps`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    quadrature: Option<CouplingFigure>,
    damping: Option<CouplingFigure>,
    rate: Option<Estimate>,
}

impl Figures {
    fn of(id: &Identified) -> Self {
        Self {
            quadrature: id.quadrature_dps,
            damping: id.damping_coupling_dps,
            rate: id.cycle_rate_dps,
        }
    }

    pub(super) fn put(self, id: &mut Identified) {
        id.quadrature_dps = self.quadrature;
        id.damping_coupling_dps = self.damping;
        id.cycle_rate_dps = self.rate;
    }

    /// These readings at the ratio `r` (relative to the design) with its
    /// sigma (module header): K / a, d = a m + b h, C = a h + b m, each
    /// sigma scaled by a, and r's sigma carried into d and C by their
    /// slopes there (h and m at r = 1). `lambda`: the datasheet's
    /// relative 1-sigma of lambda, for the couplings' figures.
    pub(super) fn at_ratio(self, r: Estimate, lambda: f64) -> Self {
        let (a, b) = (
            (r.value + 1.0 / r.value) / 2.0,
            (r.value - 1.0 / r.value) / 2.0,
        );
        let m = self.damping.map_or(0.0, |c| c.value);
        let h = self.rate.map_or(0.0, |e| e.value);
        let figure = |value: f64, uncertainty: f64| {
            CouplingFigure::new(Estimate { value, uncertainty }, lambda)
        };
        Self {
            quadrature: self.quadrature.map(|k| {
                let k = k.measured();
                figure(k.value / a, k.uncertainty / a)
            }),
            damping: self.damping.map(|d| {
                let sigma = (a * d.measurement_uncertainty).hypot(h * r.uncertainty);
                figure(a * m + b * h, sigma)
            }),
            rate: self.rate.map(|c| drive_ratio::at_ratio(c, m, r)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The module header's readings of chosen K, d, C at a ratio r, read
    /// back at r exactly; at r = 1 the values do not move, and r's sigma
    /// goes into d's by |h| and into the rate's by |m|.
    #[test]
    fn the_readings_at_a_ratio_are_inverted_exactly() {
        let (k, d, c, r) = (250.0, -200.0, 3.0, 1.021);
        let (k1, d1, k2, d2) = (k * r, (d - c) * r, k / r, (d + c) / r);
        let sigma = 0.01;
        let figure = |value: f64| {
            Some(CouplingFigure::new(
                Estimate {
                    value,
                    uncertainty: sigma,
                },
                0.0,
            ))
        };
        let (m, h) = ((d1 + d2) / 2.0, (d2 - d1) / 2.0);
        let read = Figures {
            quadrature: figure((k1 + k2) / 2.0),
            damping: figure(m),
            rate: Some(Estimate {
                value: h,
                uncertainty: sigma,
            }),
        };
        let exact = Estimate {
            value: r,
            uncertainty: 0.0,
        };
        let back = read.at_ratio(exact, 0.0);
        let value = |f: Option<CouplingFigure>| f.unwrap().value;
        let close = |got: f64, want: f64| (got - want).abs() <= 1e-12 * want.abs();
        assert!(close(value(back.quadrature), k), "{back:?}");
        assert!(close(value(back.damping), d), "{back:?}");
        assert!(close(back.rate.unwrap().value, c), "{back:?}");
        let design = Estimate {
            value: 1.0,
            uncertainty: 0.02,
        };
        let same = read.at_ratio(design, 0.0);
        assert_eq!(same.quadrature, read.quadrature);
        assert_eq!(value(same.damping), m);
        assert_eq!(same.damping.unwrap().uncertainty, sigma.hypot(h * 0.02));
        let rate = same.rate.unwrap();
        assert_eq!(rate.value, h);
        assert_eq!(rate.uncertainty, sigma.hypot(m * 0.02));
    }
}
