//! The mechanical parameters of a two-mode gyroscope: what a datasheet
//! gives, what identification measures, and what the simulator's truth is.
//!
//! Paper eqs (1)/(3), generalized to mismatched modes:
//!
//! ```text
//! x1'' + B1 x1' - 2 lam Omz x2' + w1^2 x1 = f1(t)
//! x2'' + B2 x2' + 2 lam Omz x1' + w2^2 x2 = f2(t)        Bk = wk / Qk,  wk = 2 pi fk
//! ```

use serde::{Deserialize, Serialize};

/// Physical parameters of the two-mode gyroscope (the `[gyro]` section of
/// a configuration file: every key required).
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
}
