//! Brownian force noise of the gyroscope model (`GyroModel::with_thermal_noise`),
//! measured from the simulated states only:
//! - equipartition: the free, noisy resonator holds E[xk^2] = k_B T / (m wk^2)
//!   and E[vk^2] = k_B T / m, at rest and under a Coriolis coupling as large
//!   as the damping, with no correlation between the modes;
//! - with a quadrature and a damping coupling, the Boltzmann distribution
//!   of the coupled stiffness: E[x x^T] = k_B T / m K^-1, E[v v^T] =
//!   k_B T / m I (the damping coupling's force noise is correlated as its
//!   damping matrix is, or the velocities would not stay independent);
//! - the same check catches a plain zero-order-held force of variance
//!   S_a f_clk / 2, which falls short by sinc^2(fk / f_clk) (noise.rs);
//! - off (0 K) is the noiseless model exactly; a seed repeats a run.
//!
//! The paper's frequency plan (9.64 MHz on a 50 MHz clock, 5.2 samples per
//! cycle, where the hold matters most) with Q lowered to 500-1000 so that a
//! run spans thousands of decay times.
//!
//! # Bounds
//!
//! A sample variance over a duration D of a Gaussian process with
//! autocorrelation rho(tau) has relative variance (2 / D) integral rho^2.
//! For a resonator of damping B = w / Q, rho = exp(-B |tau| / 2) cos(w tau),
//! so integral rho^2 = 1 / B and the relative standard error is
//! sqrt(2 / (B D)) (sampling at 5.2 points per cycle, off any rational
//! ratio, averages the cos^2 to 1/2 as the integral does). Each check allows
//! 5 standard errors (a false alarm once in 1.7 million runs; the seeds are
//! fixed anyway). The runs start at rest and discard 20 / B of burn-in: the
//! variance approaches its end value as 1 - exp(-B t), 2e-9 short after it.

use gyrocal_sim::gyro::{GyroModel, GyroParams};
use gyrocal_sim::noise::{ThermalNoise, zoh_force_variance};
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::SeedableRng;
use std::f64::consts::{PI, TAU};

const CLOCK_HZ: f64 = 50.0e6;

fn device() -> GyroParams {
    GyroParams {
        f1_hz: 9.64e6,
        f2_hz: 9.64025e6,
        q1: 500.0,
        q2: 1000.0,
        angular_gain: 0.6,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
    }
}

fn thermal(seed: u64) -> ThermalNoise {
    ThermalNoise {
        mass_kg: 1.0e-9,
        temperature_k: 300.0,
        seed,
    }
}

/// Damping B = w / Q of mode `k` (1/s).
fn damping(p: &GyroParams, k: usize) -> f64 {
    let (f, q) = if k == 0 {
        (p.f1_hz, p.q1)
    } else {
        (p.f2_hz, p.q2)
    };
    TAU * f / q
}

/// Mean of the products s_i s_j of the state `[x1, v1, x2, v2]` over
/// `clocks` steps after the burn-in; `force` gives the forces of a clock.
fn second_moments(
    g: &mut GyroModel,
    clocks: u64,
    mut force: impl FnMut() -> (f64, f64),
) -> [[f64; 4]; 4] {
    // 10 amplitude time constants: the variances settle as exp(-2 t / tau).
    let burn_in = (10.0 * g.params().slowest_time_constant_s() * g.clock_hz()) as u64;
    for _ in 0..burn_in {
        let (f1, f2) = force();
        g.step(f1, f2);
    }
    let mut m = [[0.0; 4]; 4];
    for _ in 0..clocks {
        let (f1, f2) = force();
        g.step(f1, f2);
        let s = g.state();
        for i in 0..4 {
            for j in 0..4 {
                m[i][j] += s[i] * s[j];
            }
        }
    }
    m.map(|row| row.map(|v| v / clocks as f64))
}

/// Relative standard error of a variance measured over `clocks` on a mode
/// of damping `b`.
fn relative_error(b: f64, clocks: u64) -> f64 {
    (2.0 / (b * clocks as f64 / CLOCK_HZ)).sqrt()
}

/// Checks E[x^2] and E[v^2] of both modes against `scale` times
/// equipartition; returns the measured ratios to equipartition.
fn check_equipartition(m: &[[f64; 4]; 4], clocks: u64, scale: [f64; 2]) -> [f64; 4] {
    let p = device();
    let n = thermal(0);
    let mut ratios = [0.0; 4];
    for k in 0..2 {
        let f = if k == 0 { p.f1_hz } else { p.f2_hz };
        let bound = 5.0 * relative_error(damping(&p, k), clocks);
        let x = m[2 * k][2 * k] / n.displacement_variance(f);
        let v = m[2 * k + 1][2 * k + 1] / n.velocity_variance();
        println!(
            "mode {}: E[x^2] / (kT/(m w^2)) = {x:.4}, E[v^2] / (kT/m) = {v:.4}, \
             expected {:.4} +- {bound:.4}",
            k + 1,
            scale[k]
        );
        for (what, got) in [("x", x), ("v", v)] {
            assert!(
                (got / scale[k] - 1.0).abs() < bound,
                "mode {}: {what} variance ratio {got} against {} (bound {bound})",
                k + 1,
                scale[k]
            );
        }
        ratios[2 * k] = x;
        ratios[2 * k + 1] = v;
    }
    ratios
}

/// The modes are independent: |E[xi xj]| / sqrt(E[xi^2] E[xj^2]) of the two
/// modes' positions and velocities within 5 standard errors (the correlation
/// estimate of independent narrow-band processes has the standard error of
/// the slower one, sqrt(2 / (B D)) at most).
fn check_modes_uncorrelated(m: &[[f64; 4]; 4], clocks: u64) {
    let p = device();
    let bound = 5.0 * relative_error(damping(&p, 0).min(damping(&p, 1)), clocks);
    for (i, j) in [(0, 2), (0, 3), (1, 2), (1, 3)] {
        let rho = m[i][j] / (m[i][i] * m[j][j]).sqrt();
        assert!(
            rho.abs() < bound,
            "state {i} against {j}: correlation {rho}"
        );
    }
}

#[test]
fn free_noisy_resonator_obeys_equipartition() {
    let clocks = 20_000_000;
    let mut g = GyroModel::new(&device(), CLOCK_HZ)
        .unwrap()
        .with_thermal_noise(&thermal(11))
        .unwrap();
    let m = second_moments(&mut g, clocks, || (0.0, 0.0));
    check_equipartition(&m, clocks, [1.0, 1.0]);
    check_modes_uncorrelated(&m, clocks);
}

#[test]
fn equipartition_holds_under_rotation() {
    // Coriolis coupling 2 lambda Omz = 1.2e5 1/s, the size of mode 1's
    // damping: the modes exchange energy within a decay time. The
    // gyroscopic force does no work, so the equilibrium is the same.
    let clocks = 10_000_000;
    let mut g = GyroModel::new(&device(), CLOCK_HZ)
        .unwrap()
        .with_thermal_noise(&thermal(12))
        .unwrap();
    g.set_rate(1.0e5);
    let m = second_moments(&mut g, clocks, || (0.0, 0.0));
    check_equipartition(&m, clocks, [1.0, 1.0]);
}

#[test]
fn couplings_keep_the_boltzmann_distribution() {
    // A 1 kHz pair of modes 10 Hz apart inside their 100 Hz bandwidth
    // (Q 10 / 12, so the damping coupling mixes them fully), on a 20 kHz
    // clock, with the quadrature at k = 0.3 w1 w2 (positions correlated by
    // -0.3) and the damping coupling at d = 0.6 sqrt(B1 B2). The slowest
    // mixed mode decays at b_min / 2, b_min = (B1 + B2)/2 - sqrt(((B1 -
    // B2)/2)^2 + d^2) = 218 1/s, so each second moment has the relative
    // standard error sqrt(2 / (b_min D)) at most; 5 of them are allowed on
    // every variance ratio and correlation. Without the correlation of the
    // two forces' noise (measured once, the cross term zeroed) E[x1^2] came
    // out 86% high.
    let clock = 20e3;
    let base = GyroParams {
        f1_hz: 1000.0,
        f2_hz: 1010.0,
        q1: 10.0,
        q2: 12.0,
        angular_gain: 0.7,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
    };
    let (w1, w2) = (TAU * base.f1_hz, TAU * base.f2_hz);
    let (b1, b2) = (damping(&base, 0), damping(&base, 1));
    let k = 0.3 * w1 * w2;
    let d = 0.6 * (b1 * b2).sqrt();
    let two_lambda = 2.0 * base.angular_gain;
    let p = GyroParams {
        quadrature_dps: (k / (two_lambda * w1)).to_degrees(),
        damping_coupling_dps: (d / two_lambda).to_degrees(),
        ..base
    };
    let b_min = 0.5 * (b1 + b2) - (0.25 * (b1 - b2).powi(2) + d * d).sqrt();
    let clocks = 4_000_000;
    let bound = 5.0 * (2.0 / (b_min * clocks as f64 / clock)).sqrt();
    let n = thermal(14);
    let mut g = GyroModel::new(&p, clock)
        .unwrap()
        .with_thermal_noise(&n)
        .unwrap();
    let m = second_moments(&mut g, clocks, || (0.0, 0.0));
    // K^-1 = [[w2^2, -k], [-k, w1^2]] / (w1^2 w2^2 - k^2).
    let det = (w1 * w2).powi(2) - k * k;
    let kt = n.velocity_variance();
    let expected_x = [kt * w2 * w2 / det, kt * w1 * w1 / det];
    let checks = [
        ("E[x1^2]", m[0][0] / expected_x[0] - 1.0),
        ("E[x2^2]", m[2][2] / expected_x[1] - 1.0),
        ("E[v1^2]", m[1][1] / kt - 1.0),
        ("E[v2^2]", m[3][3] / kt - 1.0),
        (
            "rho(x1, x2)",
            m[0][2] / (m[0][0] * m[2][2]).sqrt() + k / (w1 * w2),
        ),
        ("rho(v1, v2)", m[1][3] / (m[1][1] * m[3][3]).sqrt()),
        ("rho(x1, v1)", m[0][1] / (m[0][0] * m[1][1]).sqrt()),
        ("rho(x1, v2)", m[0][3] / (m[0][0] * m[3][3]).sqrt()),
        ("rho(x2, v1)", m[2][1] / (m[2][2] * m[1][1]).sqrt()),
        ("rho(x2, v2)", m[2][3] / (m[2][2] * m[3][3]).sqrt()),
    ];
    for (what, error) in checks {
        println!("{what}: off by {error:+.4} (bound {bound:.4})");
        assert!(
            error.abs() < bound,
            "{what}: off by {error} (bound {bound})"
        );
    }
}

#[test]
fn a_held_force_of_the_low_frequency_density_falls_short_by_sinc_squared() {
    // What the exact increment is there for: the same resonator, noiseless,
    // driven by a force held per clock with variance S_a f_clk / 2, settles
    // at sinc^2(f / f_clk) of equipartition (0.884 here), which the
    // equipartition check would refuse.
    let clocks = 20_000_000;
    let p = device();
    let n = thermal(0);
    let sd = [p.f1_hz, p.f2_hz].map(|f| {
        let q = if f == p.f1_hz { p.q1 } else { p.q2 };
        zoh_force_variance(n.force_psd(f, q), CLOCK_HZ).sqrt()
    });
    let sinc2 = [p.f1_hz, p.f2_hz].map(|f| {
        let a = PI * f / CLOCK_HZ;
        (a.sin() / a).powi(2)
    });
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(13);
    let mut normal = move || -> f64 { StandardNormal.sample(&mut rng) };
    let mut g = GyroModel::new(&p, CLOCK_HZ).unwrap();
    let m = second_moments(&mut g, clocks, || (sd[0] * normal(), sd[1] * normal()));
    let ratios = check_equipartition(&m, clocks, sinc2);
    for k in 0..2 {
        let bound = 5.0 * relative_error(damping(&p, k), clocks);
        assert!(
            1.0 - ratios[2 * k] > bound,
            "mode {}: the held force would pass as equipartition",
            k + 1
        );
    }
}

#[test]
fn zero_kelvin_is_the_noiseless_model_and_a_seed_repeats() {
    let p = device();
    let run = |noise: Option<ThermalNoise>| {
        let mut g = GyroModel::new(&p, CLOCK_HZ).unwrap();
        if let Some(n) = noise {
            g = g.with_thermal_noise(&n).unwrap();
        }
        let mut out = Vec::new();
        for n in 0..3000 {
            if n == 1000 {
                g.set_rate(2.0);
            }
            g.step((n as f64 * 1.3).cos(), (n as f64 * 1.3).sin());
            out.push(g.state());
        }
        out
    };
    let off = ThermalNoise {
        temperature_k: 0.0,
        ..thermal(3)
    };
    assert_eq!(run(None), run(Some(off)));
    assert_eq!(run(Some(thermal(3))), run(Some(thermal(3))));
    assert_ne!(run(Some(thermal(3))), run(Some(thermal(4))));
    assert_ne!(run(None), run(Some(thermal(3))));
}

#[test]
fn bad_noise_settings_are_refused_in_one_line() {
    let g = || GyroModel::new(&device(), CLOCK_HZ).unwrap();
    for (field, n) in [
        (
            "mass_kg",
            ThermalNoise {
                mass_kg: -1.0,
                ..thermal(1)
            },
        ),
        (
            "temperature_k",
            ThermalNoise {
                temperature_k: f64::NAN,
                ..thermal(1)
            },
        ),
    ] {
        let err = g().with_thermal_noise(&n).unwrap_err().to_string();
        assert!(err.starts_with(field) && !err.contains('\n'), "{err}");
    }
}
