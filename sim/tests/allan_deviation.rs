//! The overlapping Allan deviation (`gyrocal_sim::allan`) on synthetic rate
//! series of known statistics:
//! - white rate noise of known density: every point on sigma = N / sqrt(tau),
//!   and the angle random walk read at 1 s;
//! - a random walk of the rate: every point on the exact discrete curve,
//!   slope +1/2;
//! - both together: the bias instability at the curve's minimum.
//!
//! # Bounds
//!
//! An Allan variance with `edf` equivalent degrees of freedom scatters as
//! chi^2_edf / edf: the deviation's relative standard error is
//! 1 / sqrt(2 edf) (edf from `allan::white_rate_edf` and
//! `allan::random_walk_rate_edf`, Howe, Allan and Barnes 1981). Each point is
//! held to 5 standard errors; for `edf` of 100 or more the chi-square tail
//! beyond 5 of its standard errors is below 1e-5 (the seeds are fixed
//! anyway). A quantity averaged from several points is within the largest
//! of their bounds.

use gyrocal_sim::allan::{
    self, AllanPoint, BIAS_INSTABILITY_FACTOR, octave_clusters, random_walk_rate_edf,
    white_rate_edf,
};
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::SeedableRng;

fn normals(seed: u64, n: usize) -> Vec<f64> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n).map(|_| StandardNormal.sample(&mut rng)).collect()
}

/// Relative standard error of a deviation with `edf` degrees of freedom.
fn standard_error(edf: f64) -> f64 {
    1.0 / (2.0 * edf).sqrt()
}

#[test]
fn white_rate_noise_gives_its_angle_random_walk() {
    // Samples of standard deviation s at fs: sigma^2(tau) = s^2 / m =
    // s^2 tau0 / tau, so N = s sqrt(tau0) = 0.02 deg/sqrt(s) = 1.2
    // deg/sqrt(h) (one-sided rate PSD 2 s^2 / fs = 2 N^2).
    let (fs, s, n): (f64, f64, usize) = (100.0, 0.2, 1 << 22);
    let rate: Vec<f64> = normals(1, n).iter().map(|z| 5.0 + s * z).collect();
    let arw_true = s * (1.0 / fs).sqrt();
    let a = allan::analyze(&rate, fs).unwrap();
    let mut worst_near_1s: f64 = 0.0;
    for p in &a.points {
        let want = arw_true / p.tau_s.sqrt();
        let edf = white_rate_edf(n, p.cluster);
        let bound = 5.0 * standard_error(edf);
        let err = p.adev / want - 1.0;
        println!(
            "tau {:9.2} s  adev {:.4e}  rel {err:+.4} (bound {bound:.4})",
            p.tau_s, p.adev
        );
        if edf >= 100.0 {
            assert!(err.abs() < bound, "tau {}: {err} beyond {bound}", p.tau_s);
        }
        if (0.25..=4.0).contains(&p.tau_s) {
            worst_near_1s = worst_near_1s.max(bound);
        }
    }
    let arw = a.angle_random_walk.expect("points near 1 s");
    let err = arw.deg_per_sqrt_h / (arw_true * 60.0) - 1.0;
    println!(
        "ARW {:.5} deg/sqrt(h) against {:.5}: {err:+.5} (bound {worst_near_1s:.4}), slope {:.4}",
        arw.deg_per_sqrt_h,
        arw_true * 60.0,
        arw.fitted_slope
    );
    assert!(err.abs() < worst_near_1s);
    assert_eq!(arw.tau_range_s, (0.32, 2.56));
    // The free slope over 0.32..2.56 s: each end within its bound, so the
    // slope is within (b1 + b2) / ln(2.56 / 0.32) of -1/2.
    let b = |tau: f64| 5.0 * standard_error(white_rate_edf(n, (tau * fs) as usize));
    assert!((arw.fitted_slope + 0.5).abs() < (b(0.32) + b(2.56)) / 8f64.ln());
}

/// The exact Allan variance of a discrete random walk of the rate with
/// increments of variance r^2: r^2 (2 m^2 + 1) / (6 m) (cluster means of
/// partial sums; the continuous limit is K^2 tau / 3 with K^2 = r^2 / tau0).
fn random_walk_avar(r: f64, m: usize) -> f64 {
    let m = m as f64;
    r * r * (2.0 * m * m + 1.0) / (6.0 * m)
}

#[test]
fn a_random_walk_of_the_rate_has_slope_one_half() {
    let (fs, r, n) = (10.0, 1e-3, 1 << 20);
    let mut acc = 0.0;
    let rate: Vec<f64> = normals(2, n)
        .iter()
        .map(|z| {
            acc += r * z;
            acc
        })
        .collect();
    let clusters: Vec<usize> = octave_clusters(n)
        .into_iter()
        .filter(|&m| m <= 1 << 13)
        .collect();
    let points = allan::overlapping_adev(&rate, fs, &clusters).unwrap();
    for p in &points {
        let want = random_walk_avar(r, p.cluster).sqrt();
        let bound = 5.0 * standard_error(random_walk_rate_edf(n, p.cluster));
        let err = p.adev / want - 1.0;
        println!(
            "m {:6}  adev {:.4e}  rel {err:+.4} (bound {bound:.4})",
            p.cluster, p.adev
        );
        assert!(err.abs() < bound, "m {}: {err} beyond {bound}", p.cluster);
    }
    // Slope between m = 64 and m = 8192 (where the curve is sqrt(tau / 3)
    // K within 1e-4): 1/2 within the two ends' bounds over ln(128).
    let at = |m: usize| points.iter().find(|p| p.cluster == m).unwrap();
    let (a, b) = (at(64), at(8192));
    let slope = (b.adev / a.adev).ln() / (b.tau_s / a.tau_s).ln();
    let bound = 5.0
        * (standard_error(random_walk_rate_edf(n, 64))
            + standard_error(random_walk_rate_edf(n, 8192)))
        / 128f64.ln();
    println!("slope {slope:.4} (1/2 within {bound:.4})");
    assert!((slope - 0.5).abs() < bound);
}

#[test]
fn white_noise_plus_random_walk_gives_the_bias_instability_at_the_minimum() {
    // sigma^2 = N^2 / tau + K^2 tau / 3 has its minimum 2 N K / sqrt(3) at
    // tau* = sqrt(3) N / K. The octave grid lands within sqrt(2) of tau*,
    // where sigma is at most 1.03 times the minimum (allan.rs). So
    // B 0.664 lies in [1, 1.03] x sigma_min, each end widened by the
    // statistical bound at the grid's minimum.
    let (fs, s, r, n): (f64, f64, f64, usize) = (100.0, 0.05, 2e-5, 1 << 22);
    let white = normals(3, n);
    let steps = normals(4, n);
    let mut acc = 0.0;
    let rate: Vec<f64> = white
        .iter()
        .zip(&steps)
        .map(|(w, z)| {
            acc += r * z;
            s * w + acc
        })
        .collect();
    let tau0 = 1.0 / fs;
    let arw = s * tau0.sqrt();
    let k = r / tau0.sqrt();
    let sigma_min = (2.0 * arw * k / 3f64.sqrt()).sqrt();
    let tau_star = 3f64.sqrt() * arw / k;
    let a = allan::analyze(&rate, fs).unwrap();
    let bi = &a.bias_instability;
    let found = bi.deg_per_h / 3600.0 * BIAS_INSTABILITY_FACTOR;
    let at_min: &AllanPoint = a.points.iter().find(|p| p.tau_s == bi.tau_s).unwrap();
    // The slower-converging of the two noise types bounds the scatter.
    let edf = white_rate_edf(n, at_min.cluster).min(random_walk_rate_edf(n, at_min.cluster));
    let stat = 5.0 * standard_error(edf);
    println!(
        "BI {:.4} deg/h at {} s (tau* {tau_star:.1} s): sigma {found:.4e} against min {sigma_min:.4e}, stat {stat:.3}",
        bi.deg_per_h, bi.tau_s
    );
    assert!(found > sigma_min * (1.0 - stat) && found < sigma_min * 1.03 * (1.0 + stat));
    assert!(bi.tau_s > tau_star / 2.0 && bi.tau_s < tau_star * 2.0);
}
