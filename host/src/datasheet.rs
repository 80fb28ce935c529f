//! What the host is told about the device: a datasheet, never the device.
//!
//! In a configuration file `[datasheet]` lists what differs from `[gyro]`:
//! `[gyro]` is the simulated truth, `[datasheet]` what the host code is
//! told (a key it leaves out is `[gyro]`'s). On a real board there is no
//! truth and `[gyro]` is the datasheet itself. Process spread moves a
//! resonance by 1 to 5% (both modes mostly together: their split by up to
//! a factor of 2) and a Q by a factor of 2; the angular gain
//! lambda comes from design and enters every predicted ratio one for one,
//! so it carries its own relative uncertainty. So does the ratio of the
//! two drive channels' force gains, g2 / g1 against the design: the host
//! measures it only when a quadrature coupling or a `[drive_probe]` turn
//! makes it observable, and otherwise predicts at the design ratio, whose
//! error (channel matching, and the drift of each drive's gain over the
//! field's temperatures) only the datasheet can bound.
//!
//! ```toml
//! [datasheet]
//! f1_hz = 9.67e6                     # every key optional
//! q1 = 30000
//! angular_gain = 0.61
//! angular_gain_uncertainty = 0.01    # relative 1-sigma; required with angular_gain
//! drive_gain_ratio_uncertainty = 0.005  # relative 1-sigma of g2/g1 over the design, in the field
//! ```

use crate::device::GyroParams;
use serde::{Deserialize, Serialize};

/// A part's resonance spread about its datasheet's, relative: the 1 to 5%
/// of process spread (module doc). An identified resonance farther than
/// this from the datasheet's is said (`Identified::datasheet_departures`).
pub const F_SPREAD: f64 = 0.05;
/// A part's Q spread about its datasheet's, as a factor either way (module
/// doc). An identified Q farther than this is said, as a lost vacuum or a
/// datasheet for another part would show.
pub const Q_SPREAD: f64 = 2.0;

/// A part's mode split f2 - f1 about its datasheet's, as a factor either
/// way (module doc). Process spread moves both modes together by most of
/// [`F_SPREAD`] (the disk's size and thickness), so each f can lie within
/// it while the split is far from the datasheet's, and the split is what
/// the scale factors' ratio turns on (a split said as 40 Hz for a true 760
/// Hz, `tests/calibrate.rs`, moved neither f beyond F_SPREAD). An
/// identified split farther than this factor from the datasheet's, or of
/// the other sign, and farther from it than the modes' mean bandwidth, is
/// said (`Identified::datasheet_departures`): within a bandwidth the
/// modes' responses overlap and a split's size barely shows in them.
pub const SPLIT_SPREAD: f64 = 2.0;

/// Whether two Qs whose ratio is `ratio` lie farther apart than a part's
/// spread ([`Q_SPREAD`] either way).
///
/// ```
/// use gyrocal_host::datasheet::q_beyond_spread;
/// assert!(!q_beyond_spread(2.0) && !q_beyond_spread(0.5) && q_beyond_spread(0.49));
/// ```
pub fn q_beyond_spread(ratio: f64) -> bool {
    !(1.0 / Q_SPREAD..=Q_SPREAD).contains(&ratio)
}

/// Largest relative 1-sigma of the angular gain.
pub const MAX_ANGULAR_GAIN_UNCERTAINTY: f64 = 0.5;
/// Largest relative 1-sigma of the drive-gain ratio.
pub const MAX_DRIVE_GAIN_RATIO_UNCERTAINTY: f64 = 0.5;

/// The `[datasheet]` section: each key overrides `[gyro]`'s for the host.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Datasheet {
    /// Mode 1's resonance (Hz).
    pub f1_hz: Option<f64>,
    /// Mode 2's resonance (Hz).
    pub f2_hz: Option<f64>,
    /// Mode 1's quality factor.
    pub q1: Option<f64>,
    /// Mode 2's quality factor.
    pub q2: Option<f64>,
    /// Angular gain lambda.
    pub angular_gain: Option<f64>,
    /// Relative 1-sigma of lambda (0 when `angular_gain` is `[gyro]`'s).
    pub angular_gain_uncertainty: Option<f64>,
    /// Quadrature coupling (deg/s).
    pub quadrature_dps: Option<f64>,
    /// Damping coupling (deg/s).
    pub damping_coupling_dps: Option<f64>,
    /// Relative 1-sigma of the drive-gain ratio g2 / g1 against the design
    /// over the field's conditions (default 0: the design ratio exact).
    pub drive_gain_ratio_uncertainty: Option<f64>,
}

/// A `[datasheet]` key out of range: one line naming it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("[datasheet] {key} = {value}: {allowed}")]
pub struct DatasheetError {
    /// The key.
    pub key: &'static str,
    /// Its value.
    pub value: f64,
    /// What is allowed.
    pub allowed: String,
}

/// The datasheet as the host uses it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Nominal {
    /// The device as the datasheet gives it.
    pub gyro: GyroParams,
    /// Relative 1-sigma of its angular gain.
    pub angular_gain_uncertainty: f64,
    /// Relative 1-sigma of the drive-gain ratio against the design.
    pub drive_gain_ratio_uncertainty: f64,
}

impl Datasheet {
    /// The datasheet over `gyro` (the keys it leaves out), checked.
    ///
    /// ```
    /// use gyrocal_host::{GyroParams, datasheet::Datasheet};
    /// let gyro = GyroParams { f1_hz: 1e5, f2_hz: 1.001e5, q1: 1e3, q2: 1e3, angular_gain: 0.8,
    ///     quadrature_dps: 0.0, damping_coupling_dps: 0.0 };
    /// let ds = Datasheet { f1_hz: Some(1.02e5), ..Default::default() };
    /// let n = ds.over(&gyro).unwrap();
    /// assert_eq!((n.gyro.f1_hz, n.gyro.f2_hz, n.angular_gain_uncertainty), (1.02e5, 1.001e5, 0.0));
    /// let bad = Datasheet { angular_gain: Some(0.7), ..Default::default() };
    /// assert!(bad.over(&gyro).unwrap_err().to_string().contains("angular_gain_uncertainty"));
    /// let wide = Datasheet { drive_gain_ratio_uncertainty: Some(0.7), ..Default::default() };
    /// assert!(wide.over(&gyro).unwrap_err().to_string().contains("drive_gain_ratio_uncertainty = 0.7"));
    /// ```
    pub fn over(&self, gyro: &GyroParams) -> Result<Nominal, DatasheetError> {
        let pick = |v: Option<f64>, d: f64| v.unwrap_or(d);
        let g = GyroParams {
            f1_hz: pick(self.f1_hz, gyro.f1_hz),
            f2_hz: pick(self.f2_hz, gyro.f2_hz),
            q1: pick(self.q1, gyro.q1),
            q2: pick(self.q2, gyro.q2),
            angular_gain: pick(self.angular_gain, gyro.angular_gain),
            quadrature_dps: pick(self.quadrature_dps, gyro.quadrature_dps),
            damping_coupling_dps: pick(self.damping_coupling_dps, gyro.damping_coupling_dps),
        };
        let positive = "must be a positive number";
        let check = |key: &'static str, value: f64, ok: bool, allowed: &str| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(DatasheetError {
                    key,
                    value,
                    allowed: allowed.into(),
                })
            }
        };
        check("f1_hz", g.f1_hz, g.f1_hz > 0.0, positive)?;
        check("f2_hz", g.f2_hz, g.f2_hz > 0.0, positive)?;
        check("q1", g.q1, g.q1 > 0.0, positive)?;
        check("q2", g.q2, g.q2 > 0.0, positive)?;
        check(
            "angular_gain",
            g.angular_gain,
            g.angular_gain != 0.0,
            "must be a non-zero number",
        )?;
        check("quadrature_dps", g.quadrature_dps, true, "must be a number")?;
        check(
            "damping_coupling_dps",
            g.damping_coupling_dps,
            true,
            "must be a number",
        )?;
        let u = match (self.angular_gain, self.angular_gain_uncertainty) {
            (_, Some(u)) => u,
            (None, None) => 0.0,
            (Some(a), None) => {
                return Err(DatasheetError {
                    key: "angular_gain",
                    value: a,
                    allowed: "give angular_gain_uncertainty too (its relative 1-sigma): a designed lambda is never exact, and it enters the ratio one for one".into(),
                });
            }
        };
        check(
            "angular_gain_uncertainty",
            u,
            (0.0..=MAX_ANGULAR_GAIN_UNCERTAINTY).contains(&u),
            &format!("allowed 0..={MAX_ANGULAR_GAIN_UNCERTAINTY} (relative 1-sigma)"),
        )?;
        let r = self.drive_gain_ratio_uncertainty.unwrap_or(0.0);
        check(
            "drive_gain_ratio_uncertainty",
            r,
            (0.0..=MAX_DRIVE_GAIN_RATIO_UNCERTAINTY).contains(&r),
            &format!("allowed 0..={MAX_DRIVE_GAIN_RATIO_UNCERTAINTY} (relative 1-sigma)"),
        )?;
        Ok(Nominal {
            gyro: g,
            angular_gain_uncertainty: u,
            drive_gain_ratio_uncertainty: r,
        })
    }
}
