//! Overlapping Allan deviation of a rate series, with the angle random walk
//! and the bias instability read from it (IEEE Std 952-1997, annex C;
//! IEEE Std 1554-2005).
//!
//! # Estimator
//!
//! From `n` rate samples `r_k` (deg/s) at `fs` (Hz), `tau0 = 1 / fs`, the
//! angle `theta_j = tau0 sum_{k<j} (r_k - mean r)` at `N = n + 1` points
//! (a constant rate leaves the deviation unchanged; removing it first keeps
//! the differences below exact). At a cluster of `m` samples, `tau = m
//! tau0`:
//!
//! ```text
//! sigma^2(tau) = sum_{j=0}^{N-2m-1} (theta_{j+2m} - 2 theta_{j+m} + theta_j)^2
//!                / (2 tau^2 (N - 2m))
//! ```
//!
//! evaluated at octave-spaced clusters `m = 1, 2, 4, ...` while `2m <= n`.
//!
//! # Reading it
//!
//! - Angle random walk `N`: white rate noise gives `sigma(tau) = N /
//!   sqrt(tau)`, a -1/2 slope; `N` is that line read at `tau = 1 s`. It is
//!   fitted with its slope fixed at -1/2 (the mean of `ln(sigma sqrt(tau))`)
//!   over the points within a factor `ARW_WINDOW` of 1 s, and the free
//!   slope over the same points is reported to show whether the line is
//!   there. deg/sqrt(s) x 60 = deg/sqrt(h).
//! - Bias instability `B`: flicker rate noise gives a flat floor `sigma =
//!   B sqrt(2 ln 2 / pi) = 0.664 B`; `B = min sigma / 0.664`. On octave
//!   taus the minimum of a smooth curve is missed by at most 3 % (white
//!   plus random walk: `sigma^2` at `sqrt 2` off its minimum is `(sqrt 2 +
//!   1/sqrt 2) / 2 = 1.06` times the minimum). deg/s x 3600 = deg/h.
//!
//! # Confidence
//!
//! `sigma^2` estimates scatter like `chi^2_edf / edf`: the relative
//! standard deviation of `sigma` is about `1 / sqrt(2 edf)`. The equivalent
//! degrees of freedom depend on the noise type (D. A. Howe, D. W. Allan,
//! J. A. Barnes, "Properties of signal sources and measurement methods",
//! 35th AFCS, 1981; W. J. Riley, NIST SP 1065, table 5):
//! [`white_rate_edf`] (white rate noise, the angle random walk) and
//! [`random_walk_rate_edf`].

use crate::error::AllanError;
use serde::Serialize;

/// `sigma` of flicker rate noise over its coefficient, `sqrt(2 ln 2 / pi)`
/// (IEEE 952): the bias instability is `min sigma / BIAS_INSTABILITY_FACTOR`.
pub const BIAS_INSTABILITY_FACTOR: f64 = 0.664;

/// The angle random walk is fitted over `tau` in `[1 / ARW_WINDOW,
/// ARW_WINDOW]` seconds: two octaves either side of 1 s.
pub const ARW_WINDOW: f64 = 4.0;

/// One point of the Allan deviation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AllanPoint {
    /// Cluster time `m tau0` (s).
    pub tau_s: f64,
    /// Samples per cluster `m`.
    pub cluster: usize,
    /// Overlapping Allan deviation (units of the rate, deg/s).
    pub adev: f64,
}

/// The angle random walk and how well a -1/2 line fits.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AngleRandomWalk {
    /// `N`: the -1/2 line at `tau = 1 s` (deg/sqrt(h)).
    pub deg_per_sqrt_h: f64,
    /// Free least-squares slope of `ln sigma` on `ln tau` over the same
    /// points (-0.5 for white rate noise; NaN from a single point).
    pub fitted_slope: f64,
    /// Shortest and longest `tau` used (s).
    pub tau_range_s: (f64, f64),
}

/// The bias instability and where it was read.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BiasInstability {
    /// `min sigma / 0.664` (deg/h).
    pub deg_per_h: f64,
    /// `tau` of the minimum (s).
    pub tau_s: f64,
}

/// The Allan deviation of a rate series and what it says.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AllanAnalysis {
    /// Sample rate of the series (Hz).
    pub sample_rate_hz: f64,
    /// Octave-spaced points.
    pub points: Vec<AllanPoint>,
    /// Angle random walk (None when no point lies within the window near 1 s).
    pub angle_random_walk: Option<AngleRandomWalk>,
    /// Bias instability.
    pub bias_instability: BiasInstability,
}

/// Octave-spaced clusters `1, 2, 4, ...` for `n` samples (`2m <= n`).
pub fn octave_clusters(n: usize) -> Vec<usize> {
    std::iter::successors(Some(1usize), |m| m.checked_mul(2))
        .take_while(|m| 2 * m <= n)
        .collect()
}

fn check_series(rate: &[f64], sample_rate_hz: f64) -> Result<(), AllanError> {
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return Err(AllanError::SampleRate(sample_rate_hz));
    }
    if rate.len() < 2 {
        return Err(AllanError::TooFewSamples(rate.len()));
    }
    if let Some(index) = rate.iter().position(|v| !v.is_finite()) {
        let value = rate[index];
        return Err(AllanError::NotFinite { index, value });
    }
    Ok(())
}

/// Overlapping Allan deviation of `rate` sampled at `sample_rate_hz`, at the
/// clusters `clusters` (each in `1..=n/2`; module header).
pub fn overlapping_adev(
    rate: &[f64],
    sample_rate_hz: f64,
    clusters: &[usize],
) -> Result<Vec<AllanPoint>, AllanError> {
    check_series(rate, sample_rate_hz)?;
    let n = rate.len();
    if let Some(&cluster) = clusters.iter().find(|&&m| m == 0 || 2 * m > n) {
        return Err(AllanError::Cluster {
            cluster,
            samples: n,
        });
    }
    let tau0 = 1.0 / sample_rate_hz;
    let mean = rate.iter().sum::<f64>() / n as f64;
    let mut theta = Vec::with_capacity(n + 1);
    theta.push(0.0);
    let mut acc = 0.0;
    for r in rate {
        acc += (r - mean) * tau0;
        theta.push(acc);
    }
    Ok(clusters
        .iter()
        .map(|&m| {
            let terms = theta.len() - 2 * m;
            let sum: f64 = (0..terms)
                .map(|j| {
                    let d = theta[j + 2 * m] - 2.0 * theta[j + m] + theta[j];
                    d * d
                })
                .sum();
            let tau = m as f64 * tau0;
            AllanPoint {
                tau_s: tau,
                cluster: m,
                adev: (sum / (2.0 * tau * tau * terms as f64)).sqrt(),
            }
        })
        .collect())
}

/// Least-squares slope of `y` on `x`, NaN from fewer than two distinct x.
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    if sxx > 0.0 { sxy / sxx } else { f64::NAN }
}

/// The angle random walk from the points within `ARW_WINDOW` of 1 s (None
/// if there are none). Rate units deg/s.
pub fn angle_random_walk(points: &[AllanPoint]) -> Option<AngleRandomWalk> {
    let near: Vec<&AllanPoint> = points
        .iter()
        .filter(|p| p.tau_s >= 1.0 / ARW_WINDOW && p.tau_s <= ARW_WINDOW && p.adev > 0.0)
        .collect();
    if near.is_empty() {
        return None;
    }
    let ln_tau: Vec<f64> = near.iter().map(|p| p.tau_s.ln()).collect();
    let ln_adev: Vec<f64> = near.iter().map(|p| p.adev.ln()).collect();
    let ln_n = ln_adev
        .iter()
        .zip(&ln_tau)
        .map(|(s, t)| s + 0.5 * t)
        .sum::<f64>()
        / near.len() as f64;
    Some(AngleRandomWalk {
        deg_per_sqrt_h: ln_n.exp() * 60.0,
        fitted_slope: slope(&ln_tau, &ln_adev),
        tau_range_s: (near[0].tau_s, near[near.len() - 1].tau_s),
    })
}

/// The bias instability: the smallest deviation over 0.664, in deg/h.
///
/// # Panics
/// If `points` is empty.
pub fn bias_instability(points: &[AllanPoint]) -> BiasInstability {
    let min = points
        .iter()
        .min_by(|a, b| a.adev.total_cmp(&b.adev))
        .expect("bias_instability: no Allan points");
    BiasInstability {
        deg_per_h: min.adev / BIAS_INSTABILITY_FACTOR * 3600.0,
        tau_s: min.tau_s,
    }
}

/// The whole analysis of a rate series (deg/s) at `sample_rate_hz`, on
/// octave-spaced taus. Errors (one line) on a non-finite sample or rate, or
/// fewer than 2 samples.
pub fn analyze(rate_dps: &[f64], sample_rate_hz: f64) -> Result<AllanAnalysis, AllanError> {
    check_series(rate_dps, sample_rate_hz)?;
    let points = overlapping_adev(rate_dps, sample_rate_hz, &octave_clusters(rate_dps.len()))?;
    Ok(AllanAnalysis {
        sample_rate_hz,
        angle_random_walk: angle_random_walk(&points),
        bias_instability: bias_instability(&points),
        points,
    })
}

/// The angle random walk read at one cluster time (IEEE 952: `N =
/// sigma(tau = 1 s)`), with the confidence of that one reading.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ArwReading {
    /// `60 sigma(tau_m) sqrt(tau_m)` (deg/sqrt(h)): the deviation at the
    /// cluster nearest the asked tau, moved to it along the -1/2 line
    /// (`tau_m` is within half a sample of it).
    pub deg_per_sqrt_h: f64,
    /// The cluster time read (s).
    pub tau_s: f64,
    /// Samples per cluster.
    pub cluster: usize,
    /// Equivalent degrees of freedom for white rate noise
    /// ([`white_rate_edf`]).
    pub edf: f64,
    /// Relative standard deviation of the reading, `1 / sqrt(2 edf)`.
    pub relative_sigma: f64,
}

/// The angle random walk of `rate` (deg/s at `sample_rate_hz`) read at the
/// cluster nearest `tau_s`, with its degrees of freedom. Errors (one line)
/// when the series is shorter than two such clusters.
pub fn arw_at(rate: &[f64], sample_rate_hz: f64, tau_s: f64) -> Result<ArwReading, AllanError> {
    check_series(rate, sample_rate_hz)?;
    let m = (tau_s * sample_rate_hz).round().max(1.0) as usize;
    if 2 * m > rate.len() {
        return Err(AllanError::TooShortForTau {
            samples: rate.len(),
            sample_rate_hz,
            tau_s,
            needed: 2 * m,
        });
    }
    let point = overlapping_adev(rate, sample_rate_hz, &[m])?.remove(0);
    let edf = white_rate_edf(rate.len(), m);
    Ok(ArwReading {
        deg_per_sqrt_h: 60.0 * point.adev * point.tau_s.sqrt(),
        tau_s: point.tau_s,
        cluster: m,
        edf,
        relative_sigma: 1.0 / (2.0 * edf).sqrt(),
    })
}

/// Equivalent degrees of freedom of the overlapping Allan variance of white
/// rate noise from `n` rate samples at cluster `m`:
/// `(3 (N-1) / (2m) - 2 (N-2) / N) 4 m^2 / (4 m^2 + 5)`, `N = n + 1`.
pub fn white_rate_edf(n: usize, m: usize) -> f64 {
    let (big_n, m) = ((n + 1) as f64, m as f64);
    (3.0 * (big_n - 1.0) / (2.0 * m) - 2.0 * (big_n - 2.0) / big_n) * 4.0 * m * m
        / (4.0 * m * m + 5.0)
}

/// Equivalent degrees of freedom of the overlapping Allan variance of a
/// random walk of the rate: `(N-2)/m ((N-1)^2 - 3m(N-1) + 4m^2) / (N-3)^2`,
/// `N = n + 1`.
pub fn random_walk_rate_edf(n: usize, m: usize) -> f64 {
    let (big_n, m) = ((n + 1) as f64, m as f64);
    (big_n - 2.0) / m * ((big_n - 1.0).powi(2) - 3.0 * m * (big_n - 1.0) + 4.0 * m * m)
        / (big_n - 3.0).powi(2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_of_rate_and_a_constant_have_the_textbook_deviations() {
        // A constant rate: zero. A rate ramp r = a t: sigma = a tau / sqrt 2.
        let constant = vec![3.0; 64];
        let p = overlapping_adev(&constant, 10.0, &[1, 4]).unwrap();
        assert!(p.iter().all(|p| p.adev.abs() < 1e-12), "{p:?}");
        let a = 0.5;
        let ramp: Vec<f64> = (0..200).map(|k| a * k as f64 * 0.1).collect();
        for p in overlapping_adev(&ramp, 10.0, &octave_clusters(200)).unwrap() {
            let want = a * p.tau_s / 2f64.sqrt();
            assert!((p.adev / want - 1.0).abs() < 1e-9, "{p:?}");
        }
    }

    #[test]
    fn alternating_samples_match_a_hand_count() {
        // +1, -1, ...: at m = 1, theta = 0, 1, 0, 1, ... (tau0 = 1, mean 0),
        // every second difference is +-2: sigma^2 = 4 / 2 = 2. At m = 2 every
        // cluster averages to 0 (theta_{j+4} = theta_{j+2} = theta_j).
        let r: Vec<f64> = (0..100)
            .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let p = overlapping_adev(&r, 1.0, &[1, 2]).unwrap();
        assert!((p[0].adev - 2f64.sqrt()).abs() < 1e-12);
        assert!(p[1].adev.abs() < 1e-12);
    }

    #[test]
    fn clusters_and_series_are_checked() {
        assert_eq!(octave_clusters(9), vec![1, 2, 4]);
        assert_eq!(octave_clusters(1), Vec::<usize>::new());
        let e = overlapping_adev(&[1.0; 8], 1.0, &[5]).unwrap_err();
        assert_eq!(
            e,
            AllanError::Cluster {
                cluster: 5,
                samples: 8
            }
        );
        assert!(e.to_string().contains("1..=4"), "{e}");
        let e = analyze(&[1.0, f64::NAN], 1.0).unwrap_err();
        assert!(matches!(e, AllanError::NotFinite { index: 1, .. }), "{e:?}");
        assert!(e.to_string().starts_with("rate sample 1"), "{e}");
        assert_eq!(
            analyze(&[1.0, 2.0], 0.0).unwrap_err(),
            AllanError::SampleRate(0.0)
        );
        assert_eq!(
            analyze(&[1.0], 1.0).unwrap_err(),
            AllanError::TooFewSamples(1)
        );
    }

    #[test]
    fn white_noise_read_at_one_second_lands_within_its_confidence() {
        // White rate noise of two-sided density N^2 at fs: samples of
        // variance N^2 fs. 400 s at 50 Hz, read at 1 s: edf = 1.5 x 400 x
        // (4 / 4.00..) ~ 600, relative sigma ~ 2.9 %; 4 sigma allowed.
        // A fixed seed keeps the test repeatable; the seed was not chosen.
        use rand_distr::{Distribution, StandardNormal};
        use rand_xoshiro::Xoshiro256PlusPlus;
        use rand_xoshiro::rand_core::SeedableRng;
        let (n_coef, fs) = (0.02, 50.0);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let rate: Vec<f64> = (0..20_000)
            .map(|_| {
                let z: f64 = StandardNormal.sample(&mut rng);
                z * n_coef * f64::sqrt(fs)
            })
            .collect();
        let r = arw_at(&rate, fs, 1.0).unwrap();
        assert_eq!((r.cluster, r.tau_s), (50, 1.0));
        assert!((r.edf - white_rate_edf(20_000, 50)).abs() < 1e-12);
        assert!(r.relative_sigma > 0.02 && r.relative_sigma < 0.04, "{r:?}");
        let err = r.deg_per_sqrt_h / (60.0 * n_coef) - 1.0;
        assert!(err.abs() < 4.0 * r.relative_sigma, "{r:?}");
        assert!(
            arw_at(&rate[..99], fs, 1.0)
                .unwrap_err()
                .to_string()
                .contains("at least 100")
        );
    }

    #[test]
    fn readings_follow_the_units() {
        // sigma = 0.01 / sqrt(tau) deg/s exactly: N = 0.01 deg/sqrt(s) =
        // 0.6 deg/sqrt(h), slope -1/2; the minimum, at the longest tau, gives
        // B = sigma_min / 0.664 x 3600 deg/h.
        let points: Vec<AllanPoint> = [0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0]
            .iter()
            .map(|&tau: &f64| AllanPoint {
                tau_s: tau,
                cluster: 1,
                adev: 0.01 / tau.sqrt(),
            })
            .collect();
        let arw = angle_random_walk(&points).unwrap();
        assert!((arw.deg_per_sqrt_h - 0.6).abs() < 1e-12);
        assert!((arw.fitted_slope + 0.5).abs() < 1e-12);
        assert_eq!(arw.tau_range_s, (0.25, 4.0));
        let bi = bias_instability(&points);
        assert_eq!(bi.tau_s, 8.0);
        assert!((bi.deg_per_h - 0.01 / 8f64.sqrt() / 0.664 * 3600.0).abs() < 1e-12);
        assert!(angle_random_walk(&points[..1]).is_none());
    }
}
