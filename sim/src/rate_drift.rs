//! Rate noises that enter the gyroscope as a rotation rate (deg/s added to
//! `Omz`): white rate noise (angle random walk `N`), flicker rate noise
//! (bias instability `B`) and random-walk rate noise (rate random walk
//! `K`), IEEE Std 952-1997 annex C conventions, seeded.
//!
//! # The processes, in discrete time
//!
//! The rate is updated once every `h` seconds and held in between (the
//! caller updates the board's rate table at that cadence). Each term is
//! generated exactly in discrete time, and [`RateNoiseSource::allan_variance`]
//! is the exact Allan variance of the held sequence at `tau = m h`, which
//! is what a series averaged in blocks of `h` sees:
//!
//! - **White** (`N`, deg/sqrt(s)): independent samples of variance `N^2 /
//!   h`. Two-sided density `N^2` below `1 / (2h)`; `sigma^2 = N^2 / tau`.
//! - **Random walk** (`K`, deg/s/sqrt(s)): `r_j = r_{j-1} + K sqrt(h) w_j`,
//!   from 0 at the start; IEEE 952's `S = (K / 2 pi)^2 / f^2` (two-sided)
//!   below `1 / (2h)`. Counting each increment's weight in the difference
//!   of two adjacent `m`-means gives `sigma^2(m h) = K^2 h (2 m^2 + 1) /
//!   (6 m)`, the continuous `K^2 tau / 3` plus `K^2 h / (6 m)`.
//! - **Flicker** (`B`, deg/s): a sum of first-order Gauss-Markov processes
//!   (exact AR(1) discretizations of Ornstein-Uhlenbeck processes) with
//!   corner frequencies `f_i = FLICKER_LOW_HZ r^i`, `r = 10^(1/3)` (three
//!   per decade), up to the last corner at or below `1 / h`, each of
//!   variance `sigma_i^2 = B^2 ln(r) / pi`, started in its stationary
//!   distribution. A corner `f_i` contributes the one-sided PSD `2
//!   sigma_i^2 / (pi f_i (1 + (f / f_i)^2))`; summed over corners spread
//!   evenly in `ln f` this is `sigma_i^2 / (ln(r) f) = B^2 / (pi f)`
//!   between the corners (ripple below 1e-3 at three per decade), IEEE 952's
//!   `(B^2 / 2 pi) / f` two-sided, whose Allan deviation is the flat `sqrt(2
//!   ln 2 / pi) B = 0.664 B`. The realized deviation is flat to within 3 %
//!   from `tau = 16 h` to `tau = 1 / (50 FLICKER_LOW_HZ)` (5.5 hours; unit
//!   test below), above it at shorter taus (10 % at `4 h`, 42 % at `h`:
//!   the top corners are nearly white), below it at longer ones (the
//!   lowest corner); each AR(1) term's exact Allan
//!   variance is `2 (V(m) - V(2m))`, `V(m)` the variance of an `m`-mean.
//!
//! # Why updating once per `h` is exact enough
//!
//! The board sees a piecewise-constant rate, so the sequence above is the
//! rate the gyroscope integrates, exactly; only the gyroscope's and the
//! output filter's own low-pass (unity at DC, time constants well below
//! the shortest tau the datasheet fits) stand between it and the rate
//! series, moving `sigma(tau)` by `O(t_filter / tau)`, as they do for the
//! white noise of the converters. Flicker and random walk have their power
//! at frequencies far below `1 / h`, where holding changes nothing.
//!
//! The three generators draw from one xoshiro256++ stream seeded from
//! `[noise] seed` and jumped by 2^128 steps, so they never overlap the
//! Brownian force noise's stream of the same seed.

use crate::error::ConfigError;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::SeedableRng;
use serde::{Deserialize, Serialize};

/// Lowest flicker corner (Hz): periods of 11.6 days, far beyond any run
/// (`gyrocal datasheet --seconds` is at most `rate_noise::MAX_SECONDS`).
pub const FLICKER_LOW_HZ: f64 = 1e-6;

/// Flicker corners per decade (module header).
pub const FLICKER_CORNERS_PER_DECADE: f64 = 3.0;

/// `sqrt(2 ln 2 / pi)`: the Allan deviation of flicker rate noise over its
/// coefficient `B` (IEEE 952).
pub const FLICKER_ADEV_PER_B: f64 = 0.664_282_573_406_620_8;

/// Largest coefficient accepted (any of the three, in its unit): 1e6 is
/// far beyond any gyroscope and still far from overflow.
pub const MAX_COEFFICIENT: f64 = 1e6;

/// deg/s per deg/h.
const DPS_PER_DPH: f64 = 1.0 / 3600.0;
/// deg/sqrt(s) per deg/sqrt(h).
const PER_SQRT_H: f64 = 1.0 / 60.0;

/// The rate-noise keys of the `[noise]` section (all 0, off, by default).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RateNoise {
    /// Additional white rate noise, angle random walk `N` (deg/sqrt(h)).
    #[serde(default)]
    pub arw_deg_per_sqrt_h: f64,
    /// Flicker rate noise, bias instability `B` (deg/h).
    #[serde(default)]
    pub bias_instability_deg_per_h: f64,
    /// Random-walk rate noise, rate random walk `K` (deg/h/sqrt(h)).
    #[serde(default)]
    pub rrw_deg_per_h_per_sqrt_h: f64,
}

impl RateNoise {
    /// Checks the three keys: finite, `0..=MAX_COEFFICIENT`; one line
    /// naming the key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for (key, v) in [
            ("arw_deg_per_sqrt_h", self.arw_deg_per_sqrt_h),
            (
                "bias_instability_deg_per_h",
                self.bias_instability_deg_per_h,
            ),
            ("rrw_deg_per_h_per_sqrt_h", self.rrw_deg_per_h_per_sqrt_h),
        ] {
            if !(v.is_finite() && (0.0..=MAX_COEFFICIENT).contains(&v)) {
                let allowed = format!("allowed 0..={MAX_COEFFICIENT}");
                return Err(ConfigError::key("noise", key, v, allowed));
            }
        }
        Ok(())
    }

    /// True when any of the three is set.
    pub fn is_on(&self) -> bool {
        self.arw_deg_per_sqrt_h > 0.0
            || self.bias_instability_deg_per_h > 0.0
            || self.rrw_deg_per_h_per_sqrt_h > 0.0
    }

    /// `N` in deg/sqrt(s).
    pub fn n_dps_sqrt_s(&self) -> f64 {
        self.arw_deg_per_sqrt_h * PER_SQRT_H
    }

    /// `B` in deg/s.
    pub fn b_dps(&self) -> f64 {
        self.bias_instability_deg_per_h * DPS_PER_DPH
    }

    /// `K` in deg/s/sqrt(s).
    pub fn k_dps_per_sqrt_s(&self) -> f64 {
        self.rrw_deg_per_h_per_sqrt_h * DPS_PER_DPH * PER_SQRT_H
    }

    /// The continuous-time Allan variance `N^2 / tau + (0.664 B)^2 + K^2
    /// tau / 3` ((deg/s)^2), IEEE 952's three lines.
    pub fn ideal_allan_variance(&self, tau_s: f64) -> f64 {
        let b = FLICKER_ADEV_PER_B * self.b_dps();
        self.n_dps_sqrt_s().powi(2) / tau_s + b * b + self.k_dps_per_sqrt_s().powi(2) * tau_s / 3.0
    }
}

/// One AR(1) term of the flicker sum: `x_j = a x_{j-1} + drive w_j`.
#[derive(Clone, Debug)]
struct Markov {
    a: f64,
    drive: f64,
    x: f64,
    variance: f64,
}

/// Variance of the mean of `m` consecutive samples of a stationary AR(1)
/// sequence of variance `s2` and coefficient `a`.
fn ar1_mean_variance(s2: f64, a: f64, m: f64) -> f64 {
    let one = 1.0 - a;
    let sum = m * (1.0 + a) / one - 2.0 * a * (1.0 - a.powf(m)) / (one * one);
    s2 * sum / (m * m)
}

/// The seeded generator of the three rate noises at one update interval.
#[derive(Clone, Debug)]
pub struct RateNoiseSource {
    step_s: f64,
    white: f64,
    walk_step: f64,
    walk: f64,
    flicker: Vec<Markov>,
    rng: Xoshiro256PlusPlus,
}

impl RateNoiseSource {
    /// The generator for `noise`, updated every `step_s` seconds, from the
    /// `[noise]` `seed` (its stream jumped past the Brownian noise's).
    /// Errors (one line) on a bad key or step.
    pub fn new(noise: &RateNoise, step_s: f64, seed: u64) -> Result<Self, ConfigError> {
        noise.validate()?;
        if !(step_s.is_finite() && step_s > 0.0 && 1.0 / step_s > FLICKER_LOW_HZ) {
            return Err(ConfigError::rule(
                "noise",
                format!("rate-noise update interval {step_s} s"),
                format!("must be > 0 and below {} s", 1.0 / FLICKER_LOW_HZ),
            ));
        }
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        rng.jump();
        let b = noise.b_dps();
        let ratio = 10f64.powf(1.0 / FLICKER_CORNERS_PER_DECADE);
        let variance = b * b * ratio.ln() / std::f64::consts::PI;
        // 1e-9: a whole number of corners must not lose one to rounding.
        let corners = ((1.0 / step_s / FLICKER_LOW_HZ).ln() / ratio.ln() + 1e-9).floor() as i32 + 1;
        let mut flicker = Vec::new();
        if b > 0.0 {
            for i in 0..corners {
                let fc = FLICKER_LOW_HZ * ratio.powi(i);
                let a = (-std::f64::consts::TAU * fc * step_s).exp();
                let z: f64 = StandardNormal.sample(&mut rng);
                flicker.push(Markov {
                    a,
                    drive: (variance * (1.0 - a * a)).sqrt(),
                    x: z * variance.sqrt(),
                    variance,
                });
            }
        }
        Ok(Self {
            step_s,
            white: noise.n_dps_sqrt_s() / step_s.sqrt(),
            walk_step: noise.k_dps_per_sqrt_s() * step_s.sqrt(),
            walk: 0.0,
            flicker,
            rng,
        })
    }

    /// The update interval `h` (s).
    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    /// Number of flicker corners.
    pub fn flicker_corners(&self) -> usize {
        self.flicker.len()
    }

    /// The rate noise over the next interval (deg/s).
    pub fn next_dps(&mut self) -> f64 {
        let mut sum = 0.0;
        for g in &mut self.flicker {
            let z: f64 = StandardNormal.sample(&mut self.rng);
            g.x = g.a * g.x + g.drive * z;
            sum += g.x;
        }
        if self.walk_step > 0.0 {
            let z: f64 = StandardNormal.sample(&mut self.rng);
            self.walk += self.walk_step * z;
        }
        if self.white > 0.0 {
            let z: f64 = StandardNormal.sample(&mut self.rng);
            sum += self.white * z;
        }
        sum + self.walk
    }

    /// The exact Allan variance ((deg/s)^2) of the held sequence at `tau =
    /// m h` (module header), per term: `[white, flicker, random walk]`.
    pub fn allan_variance_terms(&self, m: f64) -> [f64; 3] {
        let white = self.white * self.white / m;
        let walk = self.walk_step * self.walk_step * (2.0 * m * m + 1.0) / (6.0 * m);
        let flicker = self
            .flicker
            .iter()
            .map(|g| {
                2.0 * (ar1_mean_variance(g.variance, g.a, m)
                    - ar1_mean_variance(g.variance, g.a, 2.0 * m))
            })
            .sum();
        [white, flicker, walk]
    }

    /// The sum of [`RateNoiseSource::allan_variance_terms`].
    pub fn allan_variance(&self, m: f64) -> f64 {
        self.allan_variance_terms(m).iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan;

    fn source(n: f64, b: f64, k: f64, h: f64) -> RateNoiseSource {
        let noise = RateNoise {
            arw_deg_per_sqrt_h: n,
            bias_instability_deg_per_h: b,
            rrw_deg_per_h_per_sqrt_h: k,
        };
        RateNoiseSource::new(&noise, h, 5).unwrap()
    }

    #[test]
    fn the_realized_flicker_is_flat_where_documented() {
        // 0.664 B within 3 % from 16 h to 1 / (50 f_low), at octaves.
        let h = 0.01;
        let s = source(0.0, 36.0, 0.0, h);
        let want = FLICKER_ADEV_PER_B * 0.01;
        let mut m = 16.0;
        while m * h <= 1.0 / (50.0 * FLICKER_LOW_HZ) {
            let got = s.allan_variance(m).sqrt();
            assert!(
                (got / want - 1.0).abs() < 0.03,
                "tau {}: {got} vs {want}",
                m * h
            );
            m *= 2.0;
        }
        assert_eq!(s.flicker_corners(), 25);
    }

    #[test]
    fn white_and_walk_follow_the_closed_forms() {
        let h = 0.05;
        let s = source(60.0, 0.0, 3600.0 * 60.0, h);
        for m in [1.0, 3.0, 100.0] {
            let [w, f, k] = s.allan_variance_terms(m);
            assert!((w * m * h / 1.0 - 1.0).abs() < 1e-12, "{w}");
            assert_eq!(f, 0.0);
            let tau = m * h;
            assert!((k / (tau / 3.0 + h / (6.0 * m)) - 1.0).abs() < 1e-12, "{k}");
        }
        let noise = RateNoise {
            arw_deg_per_sqrt_h: 60.0,
            bias_instability_deg_per_h: 0.0,
            rrw_deg_per_h_per_sqrt_h: 3600.0 * 60.0,
        };
        let ideal = noise.ideal_allan_variance(2.0);
        assert!((ideal - (0.5 + 2.0 / 3.0)).abs() < 1e-12, "{ideal}");
    }

    #[test]
    fn a_long_draw_has_the_predicted_deviation() {
        // 2^18 samples of the three terms at h = 0.01 s. At m = 16 the
        // edf of each type is above 1.6e4 (white 1.5 N / m = 24,600,
        // flicker 5 N / (4 m) = 20,480, random walk about N / m = 16,384),
        // so the deviation's relative sigma is below 1 / sqrt(2 x 16,384)
        // = 0.55 %: 2.8 % is 5 sigma. The seed was not chosen.
        let h = 0.01;
        let mut s = source(6.0, 3600.0, 3600.0 * 60.0 * 0.2, h);
        let expect = s.clone();
        let n = 1 << 18;
        let rate: Vec<f64> = (0..n).map(|_| s.next_dps()).collect();
        let p = allan::overlapping_adev(&rate, 1.0 / h, &[16]).unwrap();
        let want = expect.allan_variance(16.0).sqrt();
        assert!(
            (p[0].adev / want - 1.0).abs() < 0.028,
            "{} vs {want}",
            p[0].adev
        );
        assert_eq!(rate, {
            let mut again = expect.clone();
            (0..n).map(|_| again.next_dps()).collect::<Vec<_>>()
        });
    }

    #[test]
    fn bad_keys_are_named() {
        let bad = RateNoise {
            rrw_deg_per_h_per_sqrt_h: -1.0,
            ..RateNoise::default()
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .starts_with("[noise] rrw_deg_per_h_per_sqrt_h = -1")
        );
        assert!(!RateNoise::default().is_on());
        assert!(RateNoiseSource::new(&RateNoise::default(), 0.0, 1).is_err());
    }
}
