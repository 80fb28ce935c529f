//! Equivalent degrees of freedom of the overlapping Allan variance, and
//! its chi-square confidence interval (IEEE Std 1139-2008; C. A.
//! Greenhall, W. J. Riley, "Uncertainty of stability variances based on
//! finite differences", 35th PTTI, 2003; NIST SP 1065 section 5.3).
//!
//! # Greenhall's algorithm, for rate noise
//!
//! A rate series of `n` samples is an angle series of `N = n + 1` points.
//! For a power-law rate noise `S(f) ~ f^alpha` (white `alpha = 0`,
//! flicker -1, random walk -2: "FM" noises in the time-and-frequency
//! literature, where the rate is the frequency), the Allan variance at `m`
//! samples is a mean of `M = N - 2m` second differences whose
//! normalized autocovariance at lag `t` (in units of `m`) is `sz(t) /
//! sz(0)`, with (Greenhall's eqs. 7-9, `d = 2`, filter factor `F = m`)
//!
//! ```text
//! sw(t) = |t|^3 (alpha 0), t^4 ln|t| (-1), |t|^5 (-2)
//! sx(t) = F^2 (2 sw(t) - sw(t - 1/F) - sw(t + 1/F))    (F = inf: sw of alpha + 2)
//! sz(t) = 6 sx(t) - 4 sx(t-1) - 4 sx(t+1) + sx(t-2) + sx(t+2)
//! 1/edf = [1 + (1 - J/M) rho(J/m)^2 + 2 sum_{j<J} (1 - j/M) rho(j/m)^2] / M
//! ```
//!
//! with `J = min(M, 3m)` and Greenhall's cases for `J > 100` (his table 2
//! asymptote when `M / m > 3`, else 100 terms at a stretched stride).
//! [`edf`] follows those cases as `allantools.edf_greenhall(alpha, d=2,
//! m, N, overlapping=True)` does (`tests/datasheet_cli.rs` compares them).
//!
//! # Mixtures
//!
//! A rate noise that is a sum of independent power laws (white below,
//! flicker in the middle, random walk at the long taus) has the sum of
//! their autocovariances, each weighted by its share of the Allan variance
//! at that tau: `rho = sum_k w_k sz_k / sz_k(0)`. [`edf_mixture`] puts that
//! `rho` into the same sum, which is Greenhall's derivation unchanged (it
//! only uses the second differences' autocovariance); where the pure types
//! would take the table asymptote the mixture sums the `J = 3m` terms
//! directly (the asymptote's source, with `F = inf`).

use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// `erf(1 / sqrt 2)`: the probability of a one-sigma interval, the
/// confidence of every interval the datasheet reports (as allantools'
/// default).
pub const ONE_SIGMA: f64 = 0.682_689_492_137_085_9;

/// Greenhall's `J_max`.
const J_MAX: f64 = 100.0;

/// A power law of the rate noise's spectrum, `S(f) ~ f^alpha`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum RateNoiseType {
    /// White rate noise, `alpha = 0` (angle random walk).
    White,
    /// Flicker rate noise, `alpha = -1` (bias instability).
    Flicker,
    /// Random-walk rate noise, `alpha = -2` (rate random walk).
    RandomWalk,
}

impl RateNoiseType {
    /// The three, in the order of the weights of [`edf_mixture`].
    pub const ALL: [RateNoiseType; 3] = [Self::White, Self::Flicker, Self::RandomWalk];

    /// `alpha`.
    pub fn alpha(self) -> i32 {
        match self {
            Self::White => 0,
            Self::Flicker => -1,
            Self::RandomWalk => -2,
        }
    }

    /// Greenhall's table 2, `d = 2`: `(a0, a1)`.
    fn table2(self) -> (f64, f64) {
        match self {
            Self::White => (2.0 / 3.0, 1.0 / 3.0),
            Self::Flicker => (0.852, 0.375),
            Self::RandomWalk => (1.079, 0.368),
        }
    }
}

/// Greenhall's `sw(t)` for `alpha` in -2..=2.
fn sw(t: f64, alpha: i32) -> f64 {
    let log = |p: i32| {
        if t == 0.0 {
            0.0
        } else {
            t.powi(p) * t.abs().ln()
        }
    };
    match alpha {
        2 => -t.abs(),
        1 => log(2),
        0 => t.abs().powi(3),
        -1 => log(4),
        _ => t.abs().powi(5),
    }
}

/// `sx(t)`; `f = None` is `F = inf`.
fn sx(t: f64, f: Option<f64>, alpha: i32) -> f64 {
    match f {
        None => sw(t, alpha + 2),
        Some(f) => f * f * (2.0 * sw(t, alpha) - sw(t - 1.0 / f, alpha) - sw(t + 1.0 / f, alpha)),
    }
}

/// `sz(t)` for the Allan variance (`d = 2`).
fn sz(t: f64, f: Option<f64>, alpha: i32) -> f64 {
    6.0 * sx(t, f, alpha) - 4.0 * sx(t - 1.0, f, alpha) - 4.0 * sx(t + 1.0, f, alpha)
        + sx(t - 2.0, f, alpha)
        + sx(t + 2.0, f, alpha)
}

/// The mixture's normalized autocovariance at lag `t`.
fn rho(t: f64, f: Option<f64>, weights: &[f64; 3]) -> f64 {
    RateNoiseType::ALL
        .iter()
        .zip(weights)
        .filter(|(_, w)| **w > 0.0)
        .map(|(k, w)| w * sz(t, f, k.alpha()) / sz(0.0, f, k.alpha()))
        .sum()
}

/// Greenhall's basic sum over `rho^2`, divided by `m_count`.
fn inverse_edf(j: f64, m_count: f64, stride: f64, f: Option<f64>, weights: &[f64; 3]) -> f64 {
    let r = |t: f64| rho(t, f, weights);
    let mut sum = 1.0 + (1.0 - j / m_count) * r(j / stride).powi(2);
    for i in 1..j as u64 {
        let i = i as f64;
        sum += 2.0 * (1.0 - i / m_count) * r(i / stride).powi(2);
    }
    sum / m_count
}

/// Equivalent degrees of freedom of the overlapping Allan variance at `m`
/// samples from `n` rate samples, for a mixture of the three rate noises
/// with the Allan-variance shares `weights` (white, flicker, random walk;
/// summing to 1). `None` when `2m > n` or the weights are not shares.
pub fn edf_mixture(n: usize, m: usize, weights: [f64; 3]) -> Option<f64> {
    let total: f64 = weights.iter().sum();
    let bad_weight = weights.iter().any(|w| w.is_nan() || *w < 0.0);
    if m == 0 || n < 2 * m || bad_weight || total <= 0.0 {
        return None;
    }
    let weights = weights.map(|w| w / total);
    let (big_n, mf) = ((n + 1) as f64, m as f64);
    let m_count = big_n - 2.0 * mf;
    let j = m_count.min(3.0 * mf);
    let r = m_count / mf;
    let pure = weights.iter().position(|w| *w == 1.0);
    let inv = if j <= J_MAX {
        let f = (3.0 * mf <= J_MAX).then_some(mf);
        inverse_edf(j, m_count, mf, f, &weights)
    } else if r > 3.0 {
        match pure {
            Some(k) => {
                let (a0, a1) = RateNoiseType::ALL[k].table2();
                (a0 - a1 / r) / r
            }
            None => inverse_edf(j, m_count, mf, None, &weights),
        }
    } else {
        inverse_edf(J_MAX, J_MAX, J_MAX / r, None, &weights)
    };
    Some(1.0 / inv)
}

/// [`edf_mixture`] for one pure noise type.
pub fn edf(n: usize, m: usize, kind: RateNoiseType) -> Option<f64> {
    let mut w = [0.0; 3];
    w[RateNoiseType::ALL.iter().position(|k| *k == kind)?] = 1.0;
    edf_mixture(n, m, w)
}

/// The two-sided `confidence` interval of a deviation `dev` estimated
/// with `edf` degrees of freedom: `dev sqrt(edf / chi2(1 - p))` to `dev
/// sqrt(edf / chi2(p))`, `p = (1 - confidence) / 2` (NIST SP 1065 eq. 45).
/// `None` for a non-positive edf or a confidence outside (0, 1).
pub fn interval(dev: f64, edf: f64, confidence: f64) -> Option<(f64, f64)> {
    if !(edf > 0.0 && confidence > 0.0 && confidence < 1.0) {
        return None;
    }
    let chi = ChiSquared::new(edf).ok()?;
    let p = (1.0 - confidence) / 2.0;
    let (hi, lo) = (chi.inverse_cdf(1.0 - p), chi.inverse_cdf(p));
    Some((dev * (edf / hi).sqrt(), dev * (edf / lo).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::{random_walk_rate_edf, white_rate_edf};

    #[test]
    fn pure_types_agree_with_the_simple_formulas() {
        // Greenhall's edf and the Howe-Allan-Barnes formulas (NIST SP
        // 1065 table 5) are two approximations of one quantity; from m =
        // 16 on (m << N) they agree within 10 % for white and random walk
        // (at m = 1 they differ by 17 % and 24 %, as allantools' do).
        for m in [16usize, 64, 256] {
            let n = 20_000;
            let g = edf(n, m, RateNoiseType::White).unwrap();
            let s = white_rate_edf(n, m);
            assert!((g / s - 1.0).abs() < 0.1, "white m {m}: {g} vs {s}");
            let g = edf(n, m, RateNoiseType::RandomWalk).unwrap();
            let s = random_walk_rate_edf(n, m);
            assert!((g / s - 1.0).abs() < 0.1, "walk m {m}: {g} vs {s}");
        }
    }

    #[test]
    fn a_mixture_is_bounded_by_its_parts_and_the_sum_meets_the_table() {
        let n = 10_000;
        // rho_mix^2 <= (rho_w^2 + rho_k^2) / 2 (convexity): the mixture's
        // 1 / edf is at most the mean of its parts' (direct sums, J <= 100).
        for m in [1usize, 2, 8, 20, 33] {
            let w = edf(n, m, RateNoiseType::White).unwrap();
            let k = edf(n, m, RateNoiseType::RandomWalk).unwrap();
            let mix = edf_mixture(n, m, [0.5, 0.0, 0.5]).unwrap();
            assert!(
                1.0 / mix <= (1.0 / w + 1.0 / k) / 2.0 * (1.0 + 1e-12),
                "m {m}"
            );
        }
        // The direct sum (F = inf, J = 3m) against Greenhall's table-2
        // asymptote for pure flicker where the table applies (J > 100,
        // M / m > 3): they differ by the table's three digits and its
        // O(1 / r^2) remainder.
        for m in [50usize, 200, 1000] {
            let big_m = (n + 1 - 2 * m) as f64;
            let table = edf(n, m, RateNoiseType::Flicker).unwrap();
            let direct = 1.0 / inverse_edf(3.0 * m as f64, big_m, m as f64, None, &[0.0, 1.0, 0.0]);
            assert!(
                (table / direct - 1.0).abs() < 0.02,
                "m {m}: {table} {direct}"
            );
        }
        assert!(edf_mixture(10, 6, [1.0, 0.0, 0.0]).is_none());
        assert!(edf_mixture(10, 1, [0.0, 0.0, 0.0]).is_none());
    }

    #[test]
    fn the_interval_has_its_chi_square_quantiles() {
        // edf 2: chi2 with 2 dof is exponential, quantile -2 ln(1 - q).
        let p = (1.0 - ONE_SIGMA) / 2.0;
        let (lo, hi) = interval(1.0, 2.0, ONE_SIGMA).unwrap();
        let q_hi = -2.0 * (p).ln();
        let q_lo = -2.0 * (1.0 - p).ln();
        assert!((lo - (2.0 / q_hi).sqrt()).abs() < 1e-9, "{lo}");
        assert!((hi - (2.0 / q_lo).sqrt()).abs() < 1e-9, "{hi}");
        // Many degrees of freedom: +-1 / sqrt(2 edf) about the value.
        let (lo, hi) = interval(1.0, 20_000.0, ONE_SIGMA).unwrap();
        assert!((1.0 - lo - 0.005).abs() < 1e-4 && (hi - 1.0 - 0.005).abs() < 1e-4);
        assert!(interval(1.0, 0.0, ONE_SIGMA).is_none());
    }
}
