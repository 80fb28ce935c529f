//! Thermomechanical (Brownian) force noise of the two gyroscope modes,
//! seeded, and its exact discretization for the clock-stepped model.
//!
//! # The force
//!
//! Each mode is a damped resonator of mass `m`, angular frequency `wk` and
//! quality factor `Qk` at temperature `T`. The fluctuation-dissipation
//! theorem gives it a white random force per unit mass with the one-sided
//! power spectral density
//!
//! ```text
//! S_a,k = 4 k_B T wk / (Qk m)        ((m/s^2)^2 / Hz)
//! ```
//!
//! i.e. a two-sided intensity `q_k = S_a,k / 2`: `E[a(t) a(t')] = q_k
//! delta(t - t')`. The forces of the two modes are independent. In
//! equilibrium each mode then holds `k_B T / 2` of potential energy:
//! `E[xk^2] = k_B T / (m wk^2)` and `E[vk^2] = k_B T / m` (equipartition;
//! the Coriolis coupling does no work and leaves this unchanged).
//!
//! # Discretization
//!
//! The model steps once per clock `T_c = 1 / f_clk`. Holding one white
//! force sample per clock (zero-order hold, like the DAC) with variance
//! `sigma^2` makes a piecewise-constant force whose one-sided PSD is
//! `2 sigma^2 T_c sinc^2(f T_c)`. Matching `S_a` at low frequency gives
//!
//! ```text
//! sigma^2 = S_a f_clk / 2                       (zoh_force_variance)
//! ```
//!
//! but at the mode, `f = fk`, that force carries only `S_a sinc^2(fk /
//! f_clk)`: 0.884 S_a at the paper's 9.64 MHz on a 50 MHz clock, 11.6 % too
//! little displacement variance. So the model does not hold the noise; it
//! adds the exact increment of the continuous process over one clock,
//!
//! ```text
//! s[n+1] = Phi s[n] + Gamma f[n] + w[n],   w[n] ~ N(0, Qd)
//! Qd = integral_0^T_c exp(A t) G q G^T exp(A^T t) dt
//! ```
//!
//! computed with Van Loan's matrix exponential (C. F. Van Loan, "Computing
//! integrals involving the matrix exponential", IEEE TAC 23(3), 1978):
//! `exp([[-A, G q G^T], [0, A^T]] T_c) = [[., F12], [0, F22]]`, `Qd = F22^T
//! F12`. The sampled states then have exactly the statistics of the
//! continuous resonator at every clock edge, at any Q and any `f / f_clk`.
//! `w[n] = L z[n]` with `L` the Cholesky factor of `Qd` and `z[n]` four
//! independent standard normals (ziggurat, `rand_distr`) from a seeded
//! xoshiro256++ generator: the same seed gives the same run on every
//! machine.

use crate::error::ModelError;
use nalgebra::SMatrix;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::SeedableRng;
use serde::{Deserialize, Serialize};

/// Boltzmann constant (J/K), exact in the 2019 SI.
pub const BOLTZMANN_J_PER_K: f64 = 1.380_649e-23;

/// Default mass (kg): the order of the paper's device, a 600 um silicon
/// disk (2.6e-8 kg if 40 um thick), of which a wine-glass mode moves a
/// fraction. An assumption, not a measured figure: give your device's.
pub const DEFAULT_MASS_KG: f64 = 1.0e-8;

/// Highest temperature accepted (K): far above any silicon device's
/// operating range, low enough to catch a value typed in the wrong unit.
pub const MAX_TEMPERATURE_K: f64 = 1000.0;

/// The Brownian noise source of the gyroscope. The default (0 K) is the
/// noiseless model, step for step the model without noise.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ThermalNoise {
    /// Effective (modal) mass of each mode (kg), > 0.
    pub mass_kg: f64,
    /// Temperature of the resonator (K), in [0, MAX_TEMPERATURE_K]; 0: no noise.
    pub temperature_k: f64,
    /// Seed of the noise generator.
    pub seed: u64,
}

impl Default for ThermalNoise {
    fn default() -> Self {
        Self {
            mass_kg: DEFAULT_MASS_KG,
            temperature_k: 0.0,
            seed: 1,
        }
    }
}

impl ThermalNoise {
    /// Checks the fields; the error is one line naming the field.
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(self.mass_kg.is_finite() && self.mass_kg > 0.0) {
            return Err(ModelError::parameter(
                "mass_kg",
                self.mass_kg,
                "must be finite and > 0 kg",
            ));
        }
        let t = self.temperature_k;
        if !(t.is_finite() && (0.0..=MAX_TEMPERATURE_K).contains(&t)) {
            return Err(ModelError::parameter(
                "temperature_k",
                t,
                format!("allowed 0..={MAX_TEMPERATURE_K} K"),
            ));
        }
        Ok(())
    }

    /// True when the noise is on (temperature above 0 K).
    pub fn is_on(&self) -> bool {
        self.temperature_k > 0.0
    }

    /// One-sided force PSD per unit mass `4 k_B T w / (Q m)` of a mode at
    /// `f_hz` with quality factor `q` ((m/s^2)^2/Hz).
    pub fn force_psd(&self, f_hz: f64, q: f64) -> f64 {
        4.0 * BOLTZMANN_J_PER_K * self.temperature_k * std::f64::consts::TAU * f_hz
            / (q * self.mass_kg)
    }

    /// Equilibrium displacement variance `k_B T / (m w^2)` of a mode at
    /// `f_hz` (m^2).
    pub fn displacement_variance(&self, f_hz: f64) -> f64 {
        let w = std::f64::consts::TAU * f_hz;
        BOLTZMANN_J_PER_K * self.temperature_k / (self.mass_kg * w * w)
    }

    /// One-sided displacement PSD (m^2/Hz) at `f_hz` of a mode at `f_mode_hz`
    /// with quality factor `q`, driven by its Brownian force alone:
    /// `S_a / ((wk^2 - w^2)^2 + (w wk / Qk)^2)`. Its integral over all
    /// frequencies is [`ThermalNoise::displacement_variance`]; what a
    /// demodulator at the carrier sees of the noise is this PSD (times the
    /// pick-off gain squared) around the carrier.
    pub fn displacement_psd(&self, f_mode_hz: f64, q: f64, f_hz: f64) -> f64 {
        let wk = std::f64::consts::TAU * f_mode_hz;
        let w = std::f64::consts::TAU * f_hz;
        let detuning = wk * wk - w * w;
        self.force_psd(f_mode_hz, q) / (detuning * detuning + (w * wk / q).powi(2))
    }

    /// Equilibrium velocity variance `k_B T / m` ((m/s)^2).
    pub fn velocity_variance(&self) -> f64 {
        BOLTZMANN_J_PER_K * self.temperature_k / self.mass_kg
    }
}

/// Variance per clock of a force held for one clock whose low-frequency
/// one-sided PSD is `psd` ((m/s^2)^2/Hz): `psd f_clk / 2` (module header).
/// What a zero-order-held noise source would use; the model does not.
pub fn zoh_force_variance(psd: f64, clock_hz: f64) -> f64 {
    psd * clock_hz / 2.0
}

/// 4x4 matrices of the scaled gyroscope state.
pub(crate) type Mat4 = SMatrix<f64, 4, 4>;

/// `Qd = integral_0^1 exp(M s) N exp(M^T s) ds` for a state matrix `m`
/// and a noise intensity `n`, both already multiplied by the step (Van
/// Loan's method; module header).
pub(crate) fn discrete_covariance(m: &Mat4, n: &Mat4) -> Mat4 {
    let mut big = SMatrix::<f64, 8, 8>::zeros();
    big.fixed_view_mut::<4, 4>(0, 0).copy_from(&(-m));
    big.fixed_view_mut::<4, 4>(0, 4).copy_from(n);
    big.fixed_view_mut::<4, 4>(4, 4).copy_from(&m.transpose());
    let e = big.exp();
    let f12 = e.fixed_view::<4, 4>(0, 4);
    let f22 = e.fixed_view::<4, 4>(4, 4);
    let qd = f22.transpose() * f12;
    // Symmetric in exact arithmetic; average away the rounding.
    (qd + qd.transpose()) * 0.5
}

/// The per-clock state increment: a lower-triangular factor of its
/// covariance and the seeded generator.
#[derive(Clone, Debug)]
pub(crate) struct StateNoise {
    factor: [[f64; 4]; 4],
    rng: Xoshiro256PlusPlus,
}

impl StateNoise {
    /// Noise with covariance `qd` (positive definite), seeded.
    pub(crate) fn new(qd: &Mat4, seed: u64) -> Result<Self, ModelError> {
        let mut noise = Self {
            factor: [[0.0; 4]; 4],
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
        };
        noise.set_covariance(qd)?;
        Ok(noise)
    }

    /// Replaces the covariance (the generator runs on).
    pub(crate) fn set_covariance(&mut self, qd: &Mat4) -> Result<(), ModelError> {
        let l = qd
            .cholesky()
            .ok_or(ModelError::CovarianceNotPositiveDefinite)?
            .l();
        for i in 0..4 {
            for j in 0..4 {
                self.factor[i][j] = l[(i, j)];
            }
        }
        Ok(())
    }

    /// One increment `L z`.
    #[inline]
    pub(crate) fn sample(&mut self) -> [f64; 4] {
        let mut z = [0.0; 4];
        for v in &mut z {
            *v = StandardNormal.sample(&mut self.rng);
        }
        let l = &self.factor;
        [
            l[0][0] * z[0],
            l[1][0] * z[0] + l[1][1] * z[1],
            (l[2][0] * z[0] + l[2][1] * z[1]) + l[2][2] * z[2],
            (l[3][0] * z[0] + l[3][1] * z[1]) + (l[3][2] * z[2] + l[3][3] * z[3]),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psd_and_variances_follow_the_formulas() {
        let n = ThermalNoise {
            mass_kg: 2.0e-9,
            temperature_k: 300.0,
            seed: 0,
        };
        let kt = BOLTZMANN_J_PER_K * 300.0;
        let w = std::f64::consts::TAU * 1.0e6;
        let rel = |a: f64, b: f64| (a / b - 1.0).abs();
        assert!(rel(n.force_psd(1.0e6, 1000.0), 4.0 * kt * w / (1000.0 * 2.0e-9)) < 1e-15);
        assert!(rel(n.displacement_variance(1.0e6), kt / (2.0e-9 * w * w)) < 1e-15);
        // S_a / (2 B w^2) with B = w / Q is the same variance (the
        // resonator's noise bandwidth): the PSD and equipartition agree.
        let from_psd = n.force_psd(1.0e6, 1000.0) / 4.0 / (w / 1000.0) / (w * w);
        assert!(rel(from_psd, n.displacement_variance(1.0e6)) < 1e-12);
        assert_eq!(zoh_force_variance(2.0, 10.0), 10.0);
    }

    #[test]
    fn displacement_psd_integrates_to_equipartition() {
        // Trapezoid over 0..20 f0 in steps of f0 / (50 Q), a fiftieth of
        // the half-power bandwidth: the rule's error on a Lorentzian of
        // that width is below 1e-4, the tail beyond 20 f0 below 1e-5.
        let n = ThermalNoise {
            mass_kg: 1.0e-9,
            temperature_k: 300.0,
            seed: 0,
        };
        let (f0, q) = (1.0e5, 200.0);
        let df = f0 / (50.0 * q);
        let steps = (20.0 * f0 / df) as usize;
        let sum: f64 = (0..=steps)
            .map(|i| {
                let w = if i == 0 || i == steps { 0.5 } else { 1.0 };
                w * n.displacement_psd(f0, q, i as f64 * df)
            })
            .sum();
        let ratio = sum * df / n.displacement_variance(f0);
        assert!((ratio - 1.0).abs() < 2e-4, "{ratio}");
    }

    #[test]
    fn van_loan_matches_the_integrator_closed_form() {
        // A double integrator x' = v, v' = noise of intensity q over a step
        // h: Qd = q [[h^3/3, h^2/2], [h^2/2, h]] (closed form).
        let h = 0.7;
        let q = 2.5;
        let mut m = Mat4::zeros();
        m[(0, 1)] = h;
        m[(2, 3)] = h;
        let mut n = Mat4::zeros();
        n[(1, 1)] = q * h;
        n[(3, 3)] = q * h;
        let qd = discrete_covariance(&m, &n);
        let want = [h.powi(3) / 3.0, h * h / 2.0, h];
        for base in [0, 2] {
            let got = [
                qd[(base, base)],
                qd[(base, base + 1)],
                qd[(base + 1, base + 1)],
            ];
            for k in 0..3 {
                assert!((got[k] / (q * want[k]) - 1.0).abs() < 1e-13, "{got:?}");
            }
        }
        assert_eq!(qd[(0, 2)], 0.0);
    }

    #[test]
    fn samples_have_the_asked_covariance_and_repeat_with_the_seed() {
        let mut qd = Mat4::identity();
        qd[(1, 0)] = 0.5;
        qd[(0, 1)] = 0.5;
        qd[(3, 3)] = 4.0;
        let draw = |seed| {
            let mut s = StateNoise::new(&qd, seed).unwrap();
            (0..40_000).map(|_| s.sample()).collect::<Vec<_>>()
        };
        let a = draw(7);
        assert_eq!(a, draw(7));
        assert_ne!(a[0], draw(8)[0]);
        let n = a.len() as f64;
        let cov = |i: usize, j: usize| a.iter().map(|w| w[i] * w[j]).sum::<f64>() / n;
        // Each second moment of N = 40,000 draws has a standard error of
        // sqrt((s_ii s_jj + s_ij^2) / N) <= sqrt(2 * 16 / N) = 0.028 for
        // these entries; 5 standard errors is 0.14 at worst.
        for (i, j, want, se) in [
            (0, 0, 1.0, (2.0 / n).sqrt()),
            (0, 1, 0.5, (1.25 / n).sqrt()),
            (3, 3, 4.0, (32.0 / n).sqrt()),
            (2, 3, 0.0, (4.0 / n).sqrt()),
        ] {
            assert!(
                (cov(i, j) - want).abs() < 5.0 * se,
                "cov({i},{j}) = {}",
                cov(i, j)
            );
        }
    }

    #[test]
    fn bad_fields_are_named() {
        let bad = ThermalNoise {
            mass_kg: 0.0,
            ..ThermalNoise::default()
        };
        let e = bad.validate().unwrap_err();
        assert_eq!(e.to_string(), "mass_kg = 0: must be finite and > 0 kg");
        let bad = ThermalNoise {
            temperature_k: -1.0,
            ..ThermalNoise::default()
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.starts_with("temperature_k = -1: allowed 0..="), "{e}");
        assert!(ThermalNoise::default().validate().is_ok());
        assert!(!ThermalNoise::default().is_on());
    }
}
