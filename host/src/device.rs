//! The mechanical parameters of a two-mode gyroscope: what a datasheet
//! gives, what identification measures, and what the simulator's truth is.
//!
//! Paper eqs (1)/(3), generalized to mismatched modes and mode couplings:
//!
//! ```text
//! x1'' + B1 x1' - 2 lam Omz x2' + w1^2 x1 + d x2' + k x2 = f1(t)
//! x2'' + B2 x2' + 2 lam Omz x1' + w2^2 x2 + d x1' + k x1 = f2(t)
//! Bk = wk / Qk,  wk = 2 pi fk,  k = 2 lam w1 Omq,  d = 2 lam Omd
//! ```
//!
//! `k` is the quadrature (stiffness) coupling, `Omq` = `quadrature_dps` in
//! rad/s: at mode 1's frequency its force on mode 2 is as large as the
//! Coriolis force of a rate `Omq`, 90 deg from it. `d` is the damping
//! coupling, `Omd` = `damping_coupling_dps` in rad/s: its force is as large
//! as the Coriolis force of a rate `Omd` at every frequency, in phase with
//! it, but symmetric (it acts on mode 1 with the same sign as on mode 2,
//! where Coriolis changes sign). Both default to 0 (the paper's model).

use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// Largest |quadrature_dps| and |damping_coupling_dps| (deg/s), as for a
/// rate: real devices carry tens to thousands of deg/s of quadrature.
pub const MAX_COUPLING_DPS: f64 = 1e5;

/// Physical parameters of the two-mode gyroscope (the `[gyro]` section of
/// a configuration file: the mode keys required, the couplings 0 unless
/// given).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GyroParams {
    /// Resonance frequency of mode 1 (Hz).
    pub f1_hz: f64,
    /// Resonance frequency of mode 2 (Hz).
    pub f2_hz: f64,
    /// Quality factor of mode 1 (B1 = w1/q1).
    pub q1: f64,
    /// Quality factor of mode 2 (B2 = w2/q2).
    pub q2: f64,
    /// Angular gain lambda (Coriolis coupling is 2 lambda Omz).
    pub angular_gain: f64,
    /// Quadrature (stiffness) coupling Omq (deg/s, default 0): `+ k x2` in
    /// mode 1's equation and `+ k x1` in mode 2's, `k = 2 lambda w1 Omq`
    /// (Omq in rad/s; module header).
    #[serde(default)]
    pub quadrature_dps: f64,
    /// Damping coupling Omd (deg/s, default 0): `+ d x2'` in mode 1's
    /// equation and `+ d x1'` in mode 2's, `d = 2 lambda Omd` (Omd in rad/s).
    #[serde(default)]
    pub damping_coupling_dps: f64,
}

impl GyroParams {
    /// Mode k's frequency (Hz), k = 0 or 1.
    pub fn f_hz(&self, k: usize) -> f64 {
        [self.f1_hz, self.f2_hz][k]
    }

    /// Mode k's quality factor, k = 0 or 1.
    pub fn q(&self, k: usize) -> f64 {
        [self.q1, self.q2][k]
    }

    /// Mode k's bandwidth f / Q (Hz), k = 0 or 1.
    pub fn bandwidth_hz(&self, k: usize) -> f64 {
        self.f_hz(k) / self.q(k)
    }

    /// The quadrature stiffness `k = 2 lambda w1 Omq` (1/s^2).
    pub fn quadrature_stiffness(&self) -> f64 {
        2.0 * self.angular_gain * TAU * self.f1_hz * self.quadrature_dps.to_radians()
    }

    /// The damping coupling `d = 2 lambda Omd` (1/s).
    pub fn damping_coupling(&self) -> f64 {
        2.0 * self.angular_gain * self.damping_coupling_dps.to_radians()
    }

    /// Whether the modes are coupled at rest (a coupling is not zero).
    pub fn coupled_at_rest(&self) -> bool {
        self.quadrature_stiffness() != 0.0 || self.damping_coupling() != 0.0
    }

    /// The slowest amplitude time constant of the free modes (s): `2 Qk /
    /// wk` of the slower mode; with a damping coupling `d`, `2 / b_min`
    /// with `b_min` the smallest eigenvalue of the damping matrix
    /// `[[B1, d], [d, B2]]`, `(B1 + B2)/2 - sqrt(((B1 - B2)/2)^2 + d^2)`
    /// (the modes may mix fully; a stiffness coupling or a rotation only
    /// mixes them, each mixed mode decaying between B1/2 and B2/2).
    pub fn slowest_time_constant_s(&self) -> f64 {
        let (w1, w2) = (TAU * self.f1_hz, TAU * self.f2_hz);
        let d = self.damping_coupling();
        if d == 0.0 {
            (2.0 * self.q1 / w1).max(2.0 * self.q2 / w2)
        } else {
            let (b1, b2) = (w1 / self.q1, w2 / self.q2);
            2.0 / (0.5 * (b1 + b2) - (0.25 * (b1 - b2).powi(2) + d * d).sqrt())
        }
    }

    /// The stability limits of |quadrature_dps| and |damping_coupling_dps|
    /// (deg/s, exclusive) of a passive device: a positive definite
    /// stiffness matrix, `k^2 < w1^2 w2^2`, i.e. `|Omq| < w2 / (2 |lambda|)`,
    /// and a positive definite damping matrix, `d^2 < B1 B2`, i.e.
    /// `|Omd| < sqrt(B1 B2) / (2 |lambda|)` (infinite for lambda = 0).
    pub fn coupling_limits_dps(&self) -> [f64; 2] {
        let two_lambda = 2.0 * self.angular_gain.abs();
        let (w1, w2) = (TAU * self.f1_hz, TAU * self.f2_hz);
        let damping = (w1 / self.q1 * w2 / self.q2).sqrt();
        [w2, damping].map(|limit| (limit / two_lambda).to_degrees())
    }

    /// Checks both couplings: finite, |value| <= `MAX_COUPLING_DPS` and
    /// below [`GyroParams::coupling_limits_dps`] (the other fields must be
    /// valid).
    pub fn check_couplings(&self) -> Result<(), CouplingOutOfRange> {
        let limits = self.coupling_limits_dps();
        let fields = [
            ("quadrature_dps", self.quadrature_dps),
            ("damping_coupling_dps", self.damping_coupling_dps),
        ];
        for ((field, value), limit_dps) in fields.into_iter().zip(limits) {
            if !(value.is_finite() && value.abs() <= MAX_COUPLING_DPS && value.abs() < limit_dps) {
                return Err(CouplingOutOfRange {
                    field,
                    value,
                    limit_dps,
                });
            }
        }
        Ok(())
    }
}

/// A coupling out of its range ([`GyroParams::check_couplings`]); its
/// message is one line naming the field, its value and what is allowed.
#[derive(Clone, Debug, PartialEq)]
pub struct CouplingOutOfRange {
    /// `quadrature_dps` or `damping_coupling_dps`.
    pub field: &'static str,
    /// The value (deg/s).
    pub value: f64,
    /// The stability limit (deg/s, exclusive).
    pub limit_dps: f64,
}

impl std::fmt::Display for CouplingOutOfRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (name, value, limit) = (self.field, self.value, self.limit_dps);
        let matrix = match name {
            "quadrature_dps" => "w2",
            _ => "sqrt(B1 B2)",
        };
        write!(
            f,
            "{name} = {value}: allowed |{name}| <= {MAX_COUPLING_DPS:e} deg/s and < {limit:.6e} deg/s ({matrix} / (2 |angular_gain|), beyond which a mode is unstable)"
        )
    }
}

impl std::error::Error for CouplingOutOfRange {}
