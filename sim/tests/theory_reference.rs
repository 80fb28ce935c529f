//! Checks `theory` and `fit` against `data/reference-cases.json` (exact values for
//! five devices computed independently of this project, a copy of
//! `shared/reference-cases.json`), against their own limits (matched modes, the
//! paper's eqs 2/4/5/6) and against independent numerical derivatives.
//!
//! Accuracy of our side, measured once against a 50-digit (mpmath) evaluation of
//! the same formulas: z and small-signal scale factors within 1e-15 relative,
//! fitted readout slopes within 6e-13 (the fit subtracts z values that carry a
//! large offset, ~1.5e5 x the signal, rounded at 1.1e-16 of it). The reference
//! values are plain f64: its z and fitted values sit within 7e-11 of the
//! 50-digit values, so every comparison with it below is limited by the
//! reference, not by us.

use gyrocal_sim::fit::{fitted_scale_factors, linear_fit};
use gyrocal_sim::theory::*;
use serde_json::Value;
use std::f64::consts::TAU;

struct Case {
    name: String,
    dev: Device,
    rates_dps: Vec<f64>,
    cal_freqs_hz: Vec<f64>,
    readout_z: Vec<[f64; 2]>,
    cal_z: Vec<[f64; 2]>,
    ss_read: [f64; 2],
    ss_cal: [f64; 2],
    ss_ratio: [f64; 2],
    fit_read: [f64; 2],
    fit_cal: [f64; 2],
    fit_ratio: [f64; 2],
}

fn f(v: &Value) -> f64 {
    v.as_f64().expect("number")
}
fn list(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(f).collect()
}
fn pair(v: &Value) -> [f64; 2] {
    let l = list(v);
    assert_eq!(l.len(), 2);
    [l[0], l[1]]
}
fn pairs(v: &Value) -> Vec<[f64; 2]> {
    v.as_array().expect("array").iter().map(pair).collect()
}

fn cases() -> Vec<Case> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/reference-cases.json"
    );
    let text = std::fs::read_to_string(path).expect("read reference-cases.json");
    let root: Value = serde_json::from_str(&text).expect("parse reference-cases.json");
    let cases: Vec<Case> = root["devices"]
        .as_array()
        .expect("devices")
        .iter()
        .map(|d| Case {
            name: d["name"].as_str().expect("name").to_string(),
            // The reference uses F1 = F2 = 1 N/kg ("conventions").
            dev: Device {
                f1_hz: f(&d["f1_hz"]),
                f2_hz: f(&d["f2_hz"]),
                q1: f(&d["q1"]),
                q2: f(&d["q2"]),
                angular_gain: f(&d["angular_gain"]),
                quadrature_dps: 0.0,
                damping_coupling_dps: 0.0,
                carrier_hz: f(&d["carrier_hz"]),
                f1_force: 1.0,
                f2_force: 1.0,
            },
            rates_dps: list(&d["readout_rates_dps"]),
            cal_freqs_hz: list(&d["cal_freqs_hz"]),
            readout_z: pairs(&d["readout_z"]),
            cal_z: pairs(&d["cal_z"]),
            ss_read: pair(&d["small_signal"]["sf_read_per_rad_s"]),
            ss_cal: pair(&d["small_signal"]["sf_cal_per_rad_s"]),
            ss_ratio: pair(&d["small_signal"]["ratio"]),
            fit_read: pair(&d["fitted"]["sf_read_per_dps"]),
            fit_cal: pair(&d["fitted"]["sf_cal_per_dps"]),
            fit_ratio: pair(&d["fitted"]["ratio"]),
        })
        .collect();
    assert_eq!(cases.len(), 5, "expected the five reference devices");
    cases
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// Asserts `|a/b - 1| <= tol` with a readable message.
fn assert_rel(what: &str, a: f64, b: f64, tol: f64) {
    let e = rel(a, b);
    assert!(
        e <= tol,
        "{what}: got {a:e}, expected {b:e}, relative error {e:.3e} > {tol:.1e}"
    );
}

/// The paper's three devices (same gyroscope, carrier at mode 1, mode 2, midway).
fn paper_devices() -> Vec<Device> {
    cases()
        .into_iter()
        .filter(|c| c.name.starts_with("paper"))
        .map(|c| c.dev)
        .collect()
}

#[test]
fn z_at_every_reference_point() {
    // Tolerance 1e-9: the reference's own f64 rounding is <= 7e-11 relative
    // (it solves a complex system whose readout z1 is ~2e-6 of the phasor
    // magnitude, losing ~6 digits); ours is ~1e-15. 1e-9 leaves a 15x margin.
    let mut worst = 0.0f64;
    for c in cases() {
        for (r, z) in c.rates_dps.iter().zip(&c.readout_z) {
            let ours = readout_z(&c.dev, r.to_radians());
            for k in 0..2 {
                assert_rel(
                    &format!("{} readout z{} at {r} deg/s", c.name, k + 1),
                    ours[k],
                    z[k],
                    1e-9,
                );
                worst = worst.max(rel(ours[k], z[k]));
            }
        }
        for (fc, z) in c.cal_freqs_hz.iter().zip(&c.cal_z) {
            let ours = calibration_z(&c.dev, *fc);
            for k in 0..2 {
                assert_rel(
                    &format!("{} cal z{} at {fc} Hz", c.name, k + 1),
                    ours[k],
                    z[k],
                    1e-9,
                );
                worst = worst.max(rel(ours[k], z[k]));
            }
        }
    }
    println!("worst relative difference from reference z: {worst:.2e}");
}

#[test]
fn fitted_scale_factors_and_ratios() {
    // Tolerance 1e-9: the fitted slopes inherit the reference's z rounding
    // (<= 7e-11, measured against 50 digits) and ours (<= 6e-13).
    for c in cases() {
        let fit = fitted_scale_factors(&c.dev, &c.rates_dps, &c.cal_freqs_hz);
        for k in 0..2 {
            let n = format!("{} output {}", c.name, k + 1);
            assert_rel(
                &format!("{n} fitted sf_read"),
                fit.sf_read_per_dps[k],
                c.fit_read[k],
                1e-9,
            );
            assert_rel(
                &format!("{n} fitted sf_cal"),
                fit.sf_cal_per_dps[k],
                c.fit_cal[k],
                1e-9,
            );
            assert_rel(
                &format!("{n} fitted ratio"),
                fit.ratio[k],
                c.fit_ratio[k],
                1e-9,
            );
        }
    }
}

#[test]
fn paper_ratio_is_1_53() {
    // The paper's "ratio of 1.53": excitation at mode 1, calibration read at the
    // detuned mode-2 output. Exact: 1.5338 fitted over the paper's points,
    // which rounds to 1.53 (tolerance 0.005, half a unit of the last printed
    // digit), and 1.5363 small-signal, which rounds to 1.54: it matches the
    // paper only if the paper truncated (1.53 <= r < 1.54). Both exact values
    // are pinned to 1e-9 by the reference tests; this is a readable anchor.
    let c = &cases()[0];
    assert!(c.name.contains("mode 1"));
    let fit = fitted_scale_factors(&c.dev, &c.rates_dps, &c.cal_freqs_hz);
    assert!(
        (fit.ratio[1] - 1.53).abs() < 0.005,
        "fitted {}",
        fit.ratio[1]
    );
    let small = sf_ratio(&c.dev)[1];
    assert!((1.53..1.54).contains(&small), "small-signal {small}");
}

/// Central difference `(g(h) - g(-h))/2h` refined once by Richardson (h, h/2):
/// truncation O(h^4).
fn richardson(g: impl Fn(f64) -> f64, h: f64) -> f64 {
    let d = |h: f64| (g(h) - g(-h)) / (2.0 * h);
    (4.0 * d(h / 2.0) - d(h)) / 3.0
}

#[test]
fn small_signal_matches_numerical_derivatives_of_our_steady_state() {
    // Independent of the analytic derivative formulas. Step h = B/1000 with
    // B = min(B1, B2): the response varies on the scale B/(2 lam) (readout) and
    // B/2 (calibration), so the Richardson truncation error is ~(2h/B)^4 ~ 2e-11;
    // rounding: readout z carries an offset up to ~3e3 x (sf * h), so the
    // difference loses ~1e-16 * 3e3 / 1e-3 ~ 3e-10 at worst; calibration z has
    // no offset. Tolerance 2e-9.
    let mut worst = 0.0f64;
    for c in cases() {
        let d = &c.dev;
        let b = (TAU * d.f1_hz / d.q1).min(TAU * d.f2_hz / d.q2);
        let h = b / 1000.0;
        let sr = sf_read_per_rad_s(d);
        let sc = sf_cal_per_rad_s(d);
        for k in 0..2 {
            let num_r = richardson(|o| readout_z(d, o)[k], h);
            // calibration_z takes Hz: Om = 2 pi f_cal.
            let num_c = richardson(|o| calibration_z(d, o / TAU)[k], h);
            worst = worst.max(rel(sr[k], num_r)).max(rel(sc[k], num_c));
            assert_rel(
                &format!("{} sf_read{} vs numerical", c.name, k + 1),
                sr[k],
                num_r,
                2e-9,
            );
            assert_rel(
                &format!("{} sf_cal{} vs numerical", c.name, k + 1),
                sc[k],
                num_c,
                2e-9,
            );
        }
        // Exact theory: both readout outputs have the same small-signal scale factor.
        assert_eq!(sr[0], sr[1]);
    }
    println!("worst analytic vs numerical small-signal: {worst:.2e}");
}

#[test]
fn small_signal_read_matches_reference() {
    // Tolerance 1e-8. The reference small-signal readout values are numerical
    // derivatives: its two outputs differ from each other by up to 3.4e-9
    // relative (paper, mode 1), although the exact derivatives are identical
    // (both are lam wb F1 F2 Re[1/(D1 D2)]). Ours match 50-digit values to 1e-15.
    for c in cases() {
        let sr = sf_read_per_rad_s(&c.dev);
        for (k, (ours, theirs)) in sr.iter().zip(c.ss_read).enumerate() {
            assert_rel(&format!("{} sf_read{}", c.name, k + 1), *ours, theirs, 1e-8);
        }
    }
}

/// Value at y = 0 of the polynomial through (y_i, g_i) (Neville), and the
/// Lebesgue factor sum_i |l_i(0)| that multiplies errors in g_i.
fn extrapolate_to_zero(y: &[f64], g: &[f64]) -> (f64, f64) {
    let n = y.len();
    let mut p = g.to_vec();
    for m in 1..n {
        for i in 0..n - m {
            p[i] = (-y[i + m] * p[i] + y[i] * p[i + 1]) / (y[i] - y[i + m]);
        }
    }
    let lebesgue: f64 = (0..n)
        .map(|i| {
            (0..n)
                .filter(|&j| j != i)
                .map(|j| (y[j] / (y[j] - y[i])).abs())
                .product::<f64>()
        })
        .sum();
    (p[0], lebesgue)
}

#[test]
fn small_signal_cal_against_reference() {
    // (a) The reference's own cal_z points, z(Om)/Om extrapolated to Om -> 0 as
    // a polynomial in Om^2 (z is odd in Om), must give our small-signal sf_cal.
    // Error budget: the reference z rounding (<= 7e-11, bounded here by 2e-10)
    // times the Lebesgue factor of the extrapolation, plus the truncation: for
    // a resonant output z/Om ~ 1/(1 + x^2), x = 2 Om/B, whose interpolation
    // error at 0 is exactly prod_i x_i^2/(1 + x_i^2); detuned outputs have their
    // poles farther away (|dw + jB/2| >= B/2), scaled by the factor
    // (4dw^2 + B^2)/|4dw^2 - B^2| by which Re[1/(2dw + jB)^2] is smaller than its
    // modulus. The bound takes 2x that product plus the rounding term.
    //
    // (b) The reference's stated small-signal sf_cal (and so its ratio) is NOT
    // that limit: it is off by a factor common to both outputs of a device,
    // 2.2e-5, 1.7e-5, 3.0e-5, -1.3e-6, 1.9e-5 for the five devices, while (a)
    // holds to <= 7e-7. For the matched device it gives ratio -1.6000021,
    // where the exact small-signal ratio is -2 lam identically (see the
    // matched test). It is consistent with a finite difference in f64 whose
    // tone frequencies wb +- h (~6e7 rad/s, ulp 7.5e-9) were rounded: that
    // quantizes the effective step by ~ulp/h ~ 1e-5 for h ~ 1e-4 rad/s, the
    // same step that explains the 3e-9 noise in its readout values. So (b) is
    // only checked to 5e-5, as a guard against gross errors.
    let mut worst_a = 0.0f64;
    for c in cases() {
        let d = &c.dev;
        let sc = sf_cal_per_rad_s(d);
        let sr = sf_read_per_rad_s(d);
        let om: Vec<f64> = c.cal_freqs_hz.iter().map(|fc| TAU * fc).collect();
        let y: Vec<f64> = om.iter().map(|o| o * o).collect();
        for k in 0..2 {
            let (fk, qk) = if k == 0 {
                (d.f1_hz, d.q1)
            } else {
                (d.f2_hz, d.q2)
            };
            let bk = TAU * fk / qk;
            let dw = TAU * (fk - d.carrier_hz);
            let weight = (4.0 * dw * dw + bk * bk) / (4.0 * dw * dw - bk * bk).abs();
            let trunc: f64 = om
                .iter()
                .map(|o| {
                    let x2 = (2.0 * o / bk).powi(2);
                    x2 / (1.0 + x2)
                })
                .product();
            let g: Vec<f64> = c.cal_z.iter().zip(&om).map(|(z, o)| z[k] / o).collect();
            let (g0, lebesgue) = extrapolate_to_zero(&y, &g);
            let tol = 2.0 * weight * trunc + lebesgue * 2e-10;
            let e = rel(sc[k], g0);
            worst_a = worst_a.max(e);
            assert!(
                e <= tol,
                "{} output {}: sf_cal {:e} vs reference cal_z extrapolated to 0 {:e}: {e:.2e} > {tol:.2e}",
                c.name,
                k + 1,
                sc[k],
                g0
            );
            assert_rel(
                &format!("{} sf_cal{} vs stated reference", c.name, k + 1),
                sc[k],
                c.ss_cal[k],
                5e-5,
            );
            assert_rel(
                &format!("{} ratio{} vs stated reference", c.name, k + 1),
                sr[k] / sc[k],
                c.ss_ratio[k],
                5e-5,
            );
        }
    }
    println!("worst sf_cal vs extrapolated reference cal_z: {worst_a:.2e}");
}

#[test]
fn matched_modes_follow_eqs_2_and_4_and_ratio_is_minus_2_lambda() {
    // Matched modes excited at resonance (D1 = D2 = j wb B):
    // - readout: z1 = z2 = -F1 F2 c / (2 ((wb B)^2 + c^2)), c = 2 lam Omz wb, which
    //   IS eq (2) identically (any F1, F2, any rate): tolerance 1e-13, rounding
    //   of a few dozen operations (~1e-15 each would give ~1e-14).
    // - small signal: SF_read = -lam F1 F2/(wb B^2), SF_cal = F1 F2/(2 wb B^2), so
    //   the ratio is -2 lam exactly, no Om/w0 term at all in the Om -> 0 limit:
    //   tolerance 1e-13 (rounding only).
    // - calibration at finite Om: exact = eq (4) x (1 - e^4/(w^2 K)) /
    //   ((1 - delta)^2 + eta) with e = Om, K = 4 e^2 + B^2,
    //   delta = e^2 (e^2 + B^2)/(w^2 K) <= (e/w)^2, eta <= (e/w)^2/4, so
    //   |exact/eq4 - 1| <= 3 (Om/w0)^2 (+ rounding 1e-13).
    let reference_matched = cases()
        .into_iter()
        .find(|c| c.name.starts_with("matched"))
        .expect("matched case")
        .dev;
    let unequal_forces = Device {
        f1_hz: 1.8e6,
        f2_hz: 1.8e6,
        q1: 20_000.0,
        q2: 20_000.0,
        angular_gain: 0.37,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
        carrier_hz: 1.8e6,
        f1_force: 0.7,
        f2_force: 1.9,
    };
    for d in [reference_matched, unequal_forces] {
        let lam = d.angular_gain;
        let ratio = sf_ratio(&d);
        for r in ratio {
            assert_rel("matched small-signal ratio", r, -2.0 * lam, 1e-13);
        }
        let w0 = TAU * d.carrier_hz;
        let b = w0 / d.q1;
        // Rates from deep linear to well past the peak of f(x) (x = 2 lam Omz/B up to 5).
        for x in [1e-4, 0.01, 0.3, 1.0, 5.0, -0.7] {
            let omz = x * b / (2.0 * lam);
            let z = readout_z(&d, omz);
            let e2 = eq2_readout_z(&d, omz);
            assert_rel("z1 vs eq (2)", z[0], e2, 1e-13);
            assert_rel("z2 vs eq (2)", z[1], e2, 1e-13);
            assert!(z[0] * omz < 0.0, "readout is negative for positive rate");
        }
        for f_cal in [0.01, 1.0, 10.0, 100.0, 1000.0] {
            let om = TAU * f_cal;
            let z = calibration_z(&d, f_cal);
            let e4 = eq4_calibration_z(&d, f_cal);
            let tol = 3.0 * (om / w0).powi(2) + 1e-13;
            assert_rel("cal z1 vs eq (4)", z[0], e4, tol);
            assert_rel("cal z2 vs eq (4)", z[1], e4, tol);
            assert!(z[0] > 0.0, "calibration is positive");
        }
    }
}

#[test]
fn eqs_5_and_6_within_1e_4_at_paper_scale() {
    // Eqs (5)/(6) replace wk^2 - wb^2 by 2 wb dwk and Bk = wk/Q by wb/Q, and drop
    // the j B/(2 wb) term of the derivative: relative perturbations of order
    // dw/wb <= 2.6e-5 (250 Hz at 9.64 MHz) and 1/(2Q) = 9e-6, entering squared
    // denominators (x2) and amplified near the zero of (B^2 - 4dw^2) by
    // (4dw^2 + B^2)/|4dw^2 - B^2| (2.9 midway): first order ~ 2 x 2.9 x 1.3e-5
    // = 7.5e-5 at worst. Measured worst 5.9e-5 (eq 6, midway). The 1e-4 is the
    // design claim being checked.
    let mut worst = 0.0f64;
    for d in paper_devices() {
        let sr = sf_read_per_rad_s(&d);
        let sc = sf_cal_per_rad_s(&d);
        let e5 = eq5_sf_read_per_rad_s(&d);
        let e6 = eq6_sf_cal_per_rad_s(&d);
        for k in 0..2 {
            assert_rel("eq (5) vs exact SF_read", e5, sr[k], 1e-4);
            assert_rel("eq (6) vs exact SF_cal", e6[k], sc[k], 1e-4);
            worst = worst.max(rel(e5, sr[k])).max(rel(e6[k], sc[k]));
            // Sign convention: eqs (5)/(6) as printed carry the same signs as the
            // exact values (negative readout near resonance, positive
            // calibration at the resonant output); they are not magnitudes.
            assert_eq!(e5.signum(), sr[k].signum());
            assert_eq!(e6[k].signum(), sc[k].signum());
        }
    }
    println!("paper scale: worst |eq/exact - 1| = {worst:.2e}");
}

#[test]
fn eqs_5_and_6_off_by_percent_at_20_khz() {
    // The paper's split (250 Hz) and Q at a 20 kHz carrier: the narrow-band
    // error of eq (6) at the detuned output is, to first order for 2dw >> B,
    // dw/wb (Re D2 = 2 wb dw (1 + dw/(2 wb)) squared): 250/20000 = 1.25%. We
    // require more than 1% and first-order agreement within 10% of itself
    // (second-order terms are (dw/wb)^2 ~ 1.6e-4 relative, and B/(2dw) ~ 1e-3).
    let d = Device {
        f1_hz: 20_000.0,
        f2_hz: 20_250.0,
        q1: 55_000.0,
        q2: 55_000.0,
        angular_gain: 0.6,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
        carrier_hz: 20_000.0,
        f1_force: 1.0,
        f2_force: 1.0,
    };
    let exact_ratio = sf_ratio(&d)[1];
    let eq_ratio = eq5_sf_read_per_rad_s(&d) / eq6_sf_cal_per_rad_s(&d)[1];
    let e6_err = eq6_sf_cal_per_rad_s(&d)[1] / sf_cal_per_rad_s(&d)[1] - 1.0;
    let ratio_err = eq_ratio / exact_ratio - 1.0;
    println!(
        "20 kHz: exact ratio {exact_ratio:.5}, eqs (5)/(6) {eq_ratio:.5} ({:+.2}%), eq (6) error {:+.2}%",
        100.0 * ratio_err,
        100.0 * e6_err
    );
    let first_order = (d.f2_hz - d.carrier_hz) / d.carrier_hz;
    assert!(e6_err.abs() > 1e-2 && ratio_err.abs() > 1e-2);
    assert!((e6_err.abs() - first_order).abs() < 0.1 * first_order);
}

#[test]
fn linear_fit_recovers_a_line_with_offset() {
    // Exact line with a large offset (like a readout output). The y values are
    // rounded at ~2e-28 absolute (1.1e-16 of the offset), against a slope x
    // spread of ~1e-16: slope error ~1e-11 at most, checked at 1e-9; the
    // intercept is the offset itself, to a few ulp (1e-14).
    let x: Vec<f64> = (1..=20).map(f64::from).collect();
    let y: Vec<f64> = x.iter().map(|x| 2.34e-12 - 1.56e-17 * x).collect();
    let (s, i) = linear_fit(&x, &y);
    assert_rel("slope", s, -1.56e-17, 1e-9);
    assert_rel("intercept", i, 2.34e-12, 1e-14);
    // Least squares, not interpolation: symmetric residuals cancel.
    let (s, i) = linear_fit(&[0.0, 1.0, 2.0], &[0.0, 2.0, 0.0]);
    assert!((s - 0.0).abs() < 1e-15 && (i - 2.0 / 3.0).abs() < 1e-15);
}
