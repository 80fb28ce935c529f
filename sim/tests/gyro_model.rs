//! Tests of the clock-stepped gyroscope model (`gyrocal_sim::gyro`), measured
//! from the simulated samples only, never by reading the matrices:
//! - free decay of each mode alone: frequency and Q from zero crossings and the
//!   decay envelope, and the samples against the closed-form solution;
//! - driven steady state with rotation against the exact continuous-time phasor
//!   solution, with the zero-order hold accounted for (sinc gain, T/2 delay)
//!   and, in a tighter check, its aliased images;
//! - parameter validation and state handling.
//!
//! Scaled-down devices (~1 MHz modes, 10-40 MHz clocks, Q 1000-5000), plus one
//! free decay at the paper's scale (9.64 MHz, Q 55,000, 50 MHz clock).

use gyrocal_sim::fit::linear_fit;
use gyrocal_sim::gyro::{GyroModel, GyroParams};
use nalgebra::Complex;
use std::f64::consts::{PI, TAU};

type C64 = Complex<f64>;

fn params(f1_hz: f64, f2_hz: f64, q1: f64, q2: f64, angular_gain: f64) -> GyroParams {
    GyroParams {
        f1_hz,
        f2_hz,
        q1,
        q2,
        angular_gain,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
    }
}

/// Frequency [Hz] and Q of one mode measured from its free-decay samples `x`
/// (taken every `t` seconds).
///
/// - Decay rate sigma: for samples of a damped sinusoid x[n] = A r^n cos(th n + p),
///   E[n] = x[n]^2 - x[n-1] x[n+1] = A^2 r^(2n) sin^2(th) exactly, so a
///   least-squares line through ln E[n] has slope 2 ln r = -2 sigma t.
/// - Damped frequency wd: zero crossings located by linear interpolation;
///   wd = pi (crossings - 1) / (last - first).
/// - Then w = sqrt(wd^2 + sigma^2) (the poles of s^2 + (w/Q) s + w^2 have modulus
///   w) and Q = w / (2 sigma).
fn measure_decay(x: &[f64], t: f64) -> (f64, f64) {
    let n: Vec<f64> = (1..x.len() - 1).map(|i| i as f64).collect();
    let ln_e: Vec<f64> = (1..x.len() - 1)
        .map(|i| {
            let e = x[i] * x[i] - x[i - 1] * x[i + 1];
            assert!(e > 0.0 && e.is_normal(), "envelope underflow at {i}");
            e.ln()
        })
        .collect();
    let (slope, _) = linear_fit(&n, &ln_e);
    let sigma = -slope / (2.0 * t);
    let mut crossings = Vec::new();
    for i in 0..x.len() - 1 {
        if (x[i] > 0.0) != (x[i + 1] > 0.0) {
            crossings.push(i as f64 + x[i] / (x[i] - x[i + 1]));
        }
    }
    let count = crossings.len() as f64;
    let span = crossings[crossings.len() - 1] - crossings[0];
    let wd = PI * (count - 1.0) / (span * t);
    let w = (wd * wd + sigma * sigma).sqrt();
    (w / TAU, w / (2.0 * sigma))
}

/// Runs a free decay of mode `mode` (0 or 1) from x = 1, v = 0, Omz = 0, no
/// force, for `steps` clocks; returns (samples of that mode, max |other mode|).
fn free_decay(p: &GyroParams, clock_hz: f64, mode: usize, steps: usize) -> (Vec<f64>, f64) {
    let mut g = GyroModel::new(p, clock_hz).expect("valid parameters");
    let mut s = [0.0; 4];
    s[2 * mode] = 1.0;
    g.set_state(s);
    let mut x = Vec::with_capacity(steps + 1);
    let mut other = 0.0f64;
    for i in 0..=steps {
        if i > 0 {
            g.step(0.0, 0.0);
        }
        let (own, oth) = if mode == 0 {
            (g.x1(), g.x2())
        } else {
            (g.x2(), g.x1())
        };
        x.push(own);
        other = other.max(oth.abs());
    }
    (x, other)
}

#[test]
fn free_decay_gives_set_frequency_and_q() {
    // Tolerance 1e-6 relative on f and Q (the requirement). What limits the
    // measurement: the linear interpolation of each zero crossing is off by at
    // most ~(w T)^2 T / 8 (the second derivative over the bracket is at most
    // ~w^2 |x'| T near a zero), i.e. 0.05 T at 10 samples/cycle and 0.18 T at
    // the paper's 5.2 samples/cycle. Only the first and last crossings matter,
    // so wd is off by <= 2 x that / span: <= 2e-7 with the spans below
    // (5e5 and 2e6 clocks). The envelope fit is exact up to rounding (ln E has
    // ~1e-16 absolute error per sample over a slope of ~1e-4 per sample).
    // Q inherits the same relative error as w. The other mode must stay at
    // rest: with Omz = 0 the modes are decoupled, so anything above rounding
    // (1e-15 of the driven mode's amplitude) would be a coupling bug.
    let cases = [
        // (params, clock, mode, steps)
        (
            params(1.0123e6, 0.9871e6, 1000.0, 5000.0, 0.7),
            10.0e6,
            0,
            500_000,
        ),
        (
            params(1.0123e6, 0.9871e6, 1000.0, 5000.0, 0.7),
            10.0e6,
            1,
            500_000,
        ),
        (
            params(9.64e6, 9.64025e6, 55_000.0, 55_000.0, 0.6),
            50.0e6,
            0,
            2_000_000,
        ),
        (
            params(9.64e6, 9.64025e6, 55_000.0, 55_000.0, 0.6),
            50.0e6,
            1,
            2_000_000,
        ),
    ];
    for (p, clock, mode, steps) in cases {
        let (x, other) = free_decay(&p, clock, mode, steps);
        let (f_set, q_set) = if mode == 0 {
            (p.f1_hz, p.q1)
        } else {
            (p.f2_hz, p.q2)
        };
        let (f, q) = measure_decay(&x, 1.0 / clock);
        let (ef, eq) = (f / f_set - 1.0, q / q_set - 1.0);
        println!(
            "mode {} of {:?} at {clock} Hz: f {f:.6} Hz (rel {ef:.1e}), Q {q:.4} (rel {eq:.1e})",
            mode + 1,
            p
        );
        assert!(ef.abs() < 1e-6, "frequency off by {ef:e}");
        assert!(eq.abs() < 1e-6, "Q off by {eq:e}");
        assert!(other <= 1e-15, "undriven mode moved: {other:e}");
    }
}

#[test]
fn free_decay_samples_match_closed_form() {
    // x(t) = e^(-sigma t) (cos wd t + (sigma/wd) sin wd t) for x(0) = 1, v(0) = 0.
    // Error relative to the envelope e^(-sigma t). Expected error: the exactly
    // discretized model only accumulates rounding, ~1e-16 in the per-step
    // rotation and decay over 2e5 steps (~2e-11), and evaluating cos(wd t) at
    // wd t ~ 1.3e6 rad costs ~1.3e6 x 1.1e-16 = 1.4e-10. Tolerance 1e-9; an
    // Euler or RK4 step at 10 samples/cycle would be off by order 1 here.
    let p = params(1.0123e6, 0.9871e6, 1000.0, 5000.0, 0.7);
    let clock = 10.0e6;
    for mode in 0..2 {
        let (f, q) = if mode == 0 {
            (p.f1_hz, p.q1)
        } else {
            (p.f2_hz, p.q2)
        };
        let w = TAU * f;
        let sigma = w / (2.0 * q);
        let wd = (w * w - sigma * sigma).sqrt();
        let (x, _) = free_decay(&p, clock, mode, 200_000);
        let mut worst = 0.0f64;
        for (n, xs) in x.iter().enumerate() {
            let t = n as f64 / clock;
            let env = (-sigma * t).exp();
            let exact = env * ((wd * t).cos() + sigma / wd * (wd * t).sin());
            worst = worst.max((xs - exact).abs() / env);
        }
        println!(
            "mode {}: max |sim - closed form| / envelope = {worst:.2e}",
            mode + 1
        );
        assert!(worst < 1e-9, "mode {}: {worst:e}", mode + 1);
    }
}

/// Continuous-time response `X` of (x1, x2) to forces `F e^(j w t)`:
/// `[[w1^2 - w^2 + j w B1, k + j w (d - 2 lam Omz)], [k + j w (d + 2 lam Omz),
/// w2^2 - w^2 + j w B2]] X = F`, with the couplings k = 2 lam w1 Omq and
/// d = 2 lam Omd written out here from their definitions.
fn phasor(p: &GyroParams, omz: f64, w: f64, f: [C64; 2]) -> [C64; 2] {
    let (w1, w2) = (TAU * p.f1_hz, TAU * p.f2_hz);
    let j = C64::i();
    let lam2 = 2.0 * p.angular_gain;
    let k = lam2 * w1 * p.quadrature_dps * PI / 180.0;
    let dc = lam2 * p.damping_coupling_dps * PI / 180.0;
    let a = C64::new(w1 * w1 - w * w, w * w1 / p.q1);
    let d = C64::new(w2 * w2 - w * w, w * w2 / p.q2);
    let b = k + j * w * (dc - lam2 * omz);
    let c = k + j * w * (dc + lam2 * omz);
    let det = a * d - b * c;
    [(d * f[0] - b * f[1]) / det, (a * f[1] - c * f[0]) / det]
}

/// Fourier coefficient at `w` of a zero-order-held complex exponential:
/// sinc(w T/2) e^(-j w T/2).
fn zoh(w: f64, t: f64) -> C64 {
    let u = w * t / 2.0;
    let sinc = if u == 0.0 { 1.0 } else { u.sin() / u };
    C64::from_polar(sinc, -u)
}

/// Sampled steady state of the held drive `F e^(j w n T)`:
/// `sum_k X(w + k ws) zoh(w + k ws)` over the images |k| <= `kmax` (every image
/// aliases back to e^(j w n T) at the sample instants). Returns (fundamental
/// only, with images, sum over k != 0 of |image term| per mode).
fn sampled_phasor(
    p: &GyroParams,
    omz: f64,
    w: f64,
    t: f64,
    f: [C64; 2],
    kmax: i64,
) -> ([C64; 2], [C64; 2], [f64; 2]) {
    let ws = TAU / t;
    let term = |k: i64| {
        let wk = w + k as f64 * ws;
        let g = zoh(wk, t);
        phasor(p, omz, wk, [f[0] * g, f[1] * g])
    };
    let fund = term(0);
    let mut full = fund;
    let mut images = [0.0; 2];
    for k in (-kmax..=kmax).filter(|&k| k != 0) {
        let x = term(k);
        for m in 0..2 {
            full[m] += x[m];
            images[m] += x[m].norm();
        }
    }
    (fund, full, images)
}

/// The coupled device of the driven checks: 1000 rad/s (57,296 deg/s) of
/// quadrature, k = 8.9e9 s^-2 against w1 B1 = 2.0e10 s^-2, and 600 rad/s
/// (34,377 deg/s) of damping coupling, d = 840 s^-1 against
/// sqrt(B1 B2) = 2598 s^-1: each moves the response by tens of percent.
fn coupled(p: &GyroParams) -> GyroParams {
    GyroParams {
        quadrature_dps: 1000f64.to_degrees(),
        damping_coupling_dps: 600f64.to_degrees(),
        ..p.clone()
    }
}

#[test]
fn driven_steady_state_with_rotation_matches_phasor_solution() {
    let p = params(1.0123e6, 1.0131e6, 2000.0, 3000.0, 0.7);
    driven_steady_state(&p, [0.0, 2500.0, -1800.0, 0.0]);
}

#[test]
fn driven_steady_state_with_couplings_matches_phasor_solution() {
    let uncoupled = params(1.0123e6, 1.0131e6, 2000.0, 3000.0, 0.7);
    let p = coupled(&uncoupled);
    // The couplings are visible: they move each mode's response at rest.
    let w = TAU * 1.0127e6;
    let force = [C64::new(1.0, 0.0), C64::new(0.0, -0.8)];
    let (a, b) = (phasor(&p, 0.0, w, force), phasor(&uncoupled, 0.0, w, force));
    for m in 0..2 {
        let change = (a[m] - b[m]).norm() / b[m].norm();
        assert!(
            change > 0.1,
            "mode {}: couplings barely visible: {change}",
            m + 1
        );
    }
    // Other rates: at +2500 and +1800 rad/s the couplings and the rotation
    // shrink one mode's response, and the images, which do not shrink
    // alike, reach 1.9e-7 and 1.5e-7 of it, too close to the 1e-6 of check
    // 1; at -2500 and +1000 they stay below 8.2e-8.
    driven_steady_state(&p, [0.0, -2500.0, 1000.0, 0.0]);
}

/// Drives `p` at each of `rates` (rad/s) in turn and checks the steady
/// state against the phasor solution.
fn driven_steady_state(p: &GyroParams, rates: [f64; 4]) {
    // Device: modes 1.0123 / 1.0131 MHz, Q 2000 / 3000 (bandwidths 506 / 338 Hz),
    // lam = 0.7, drive F1 cos(w n T), F2 sin(w n T) at 1.0127 MHz (between the
    // modes), held for each clock of 40 MHz. Rates 0, +2500, -1800, 0 rad/s in
    // turn (amplified: 2 lam Omz ~ B, so the coupling changes the response by
    // tens of percent; the last 0 exercises the cached matrices).
    //
    // Settling: the slowest pole decays at ~B2/2 = 1061 1/s (tau = 0.94 ms =
    // 37,700 clocks); 1.2e6 clocks per rate is 32 tau, residue e^-32 ~ 1e-14.
    //
    // Check 1 (the requirement): fundamental only, i.e. the continuous phasor
    // solution with force F sinc(w T/2) e^(-j w T/2), within 1e-6 of each mode's
    // amplitude. The neglected aliased images (held drive at w + k ws, all
    // sampled back onto w) are computed below and required to be < 1e-7 (they
    // are ~3e-8 / 8e-8 for the two modes at this 40x oversampling; at 10 MHz
    // they would be 2e-6 / 5e-6, which is why the clock is 40 MHz).
    //
    // Check 2 (exactness): with the images summed (|k| <= 4000; the terms fall
    // as 1/k^3, so the rest is < 1e-13 relative), within 1e-9. Expected error:
    // rounding of Phi/Gamma (~1e-16, amplified by ~1/(B T) ~ 1e4 near resonance)
    // and of the state recursion over ~tau fclk steps: ~1e-11. The drive phase is
    // computed exactly from an integer (fd/fclk = 10127/400000).
    //
    // The same holds with the couplings of `coupled` (the model's matrices
    // must then carry them at every rate, 0 included). The damping coupling
    // slows the slower hybrid mode to a decay rate of (B1 + B2)/4 -
    // sqrt(((B1 - B2)/4)^2 + (d/2)^2) = 829 1/s (tau 48,000 clocks): 1.2e6
    // clocks are 25 tau, residue 1.4e-11, still far below 1e-9.
    let clock = 40.0e6;
    let t = 1.0 / clock;
    let (num, den) = (10_127u64, 400_000u64);
    let w = TAU * clock * num as f64 / den as f64;
    let (f1, f2) = (1.0, 0.8);
    // f1 = F1 cos = Re(F1 e^(jwt)), f2 = F2 sin = Re(-j F2 e^(jwt)).
    let force = [C64::new(f1, 0.0), C64::new(0.0, -f2)];
    let phase = |n: u64| TAU * ((num * n) % den) as f64 / den as f64;

    let mut g = GyroModel::new(p, clock).expect("valid parameters");
    let settle = 1_200_000u64;
    let window = 40_000u64;
    let mut n = 0u64;
    let mut at_rest: Option<[C64; 2]> = None;
    for omz in rates {
        g.set_rate(omz);
        assert_eq!(g.rate(), omz);
        let (fund, full, images) = sampled_phasor(p, omz, w, t, force, 4000);
        let amp = [full[0].norm(), full[1].norm()];
        for m in 0..2 {
            assert!(
                images[m] / amp[m] < 1e-7,
                "images too large for the fundamental-only check: {:e}",
                images[m] / amp[m]
            );
        }
        match at_rest {
            None => at_rest = Some(full),
            Some(x0) if omz != 0.0 => {
                let change = (full[1] - x0[1]).norm() / x0[1].norm();
                assert!(change > 0.1, "rotation barely visible: {change}");
            }
            Some(_) => {}
        }
        let mut worst_fund = [0.0f64; 2];
        let mut worst_full = [0.0f64; 2];
        let end = n + settle;
        while n < end {
            let ph = phase(n);
            g.step(f1 * ph.cos(), f2 * ph.sin());
            n += 1;
            if end - n < window {
                // Sample n is the state at t = nT.
                let e = C64::from_polar(1.0, phase(n));
                let x = [g.x1(), g.x2()];
                for m in 0..2 {
                    let ef = (x[m] - (fund[m] * e).re).abs() / amp[m];
                    let ea = (x[m] - (full[m] * e).re).abs() / amp[m];
                    worst_fund[m] = worst_fund[m].max(ef);
                    worst_full[m] = worst_full[m].max(ea);
                }
            }
        }
        println!(
            "Omz {omz:7}: |X| = {:.3e}, {:.3e} m; images {:.1e}, {:.1e}; \
             error vs fundamental {:.1e}, {:.1e}; vs fundamental+images {:.1e}, {:.1e}",
            amp[0],
            amp[1],
            images[0] / amp[0],
            images[1] / amp[1],
            worst_fund[0],
            worst_fund[1],
            worst_full[0],
            worst_full[1]
        );
        for m in 0..2 {
            assert!(worst_fund[m] < 1e-6, "mode {}: {:e}", m + 1, worst_fund[m]);
            assert!(worst_full[m] < 1e-9, "mode {}: {:e}", m + 1, worst_full[m]);
        }
    }
}

#[test]
fn new_validates_every_field() {
    let good = params(1.0e6, 1.001e6, 1000.0, 2000.0, 0.6);
    assert!(GyroModel::new(&good, 10.0e6).is_ok());
    let bad: Vec<(&str, GyroParams, f64)> = vec![
        ("clock_hz", good.clone(), 0.0),
        ("clock_hz", good.clone(), f64::NAN),
        (
            "f1_hz",
            GyroParams {
                f1_hz: -1.0,
                ..good.clone()
            },
            10.0e6,
        ),
        (
            "f1_hz",
            GyroParams {
                f1_hz: 5.0e6,
                ..good.clone()
            },
            10.0e6,
        ),
        (
            "f2_hz",
            GyroParams {
                f2_hz: f64::INFINITY,
                ..good.clone()
            },
            10.0e6,
        ),
        (
            "f2_hz",
            GyroParams {
                f2_hz: 6.0e6,
                ..good.clone()
            },
            10.0e6,
        ),
        (
            "q1",
            GyroParams {
                q1: 0.0,
                ..good.clone()
            },
            10.0e6,
        ),
        (
            "q2",
            GyroParams {
                q2: f64::NAN,
                ..good.clone()
            },
            10.0e6,
        ),
        (
            "angular_gain",
            GyroParams {
                angular_gain: f64::NAN,
                ..good.clone()
            },
            10.0e6,
        ),
        (
            "quadrature_dps",
            GyroParams {
                quadrature_dps: f64::NAN,
                ..good.clone()
            },
            10.0e6,
        ),
        (
            "quadrature_dps",
            GyroParams {
                quadrature_dps: -2e5,
                ..good.clone()
            },
            10.0e6,
        ),
        (
            // A 1 kHz device: w2 / (2 lambda) = 5236 rad/s = 3.0e5 deg/s is
            // above the cap, so unstable needs lambda 3: 1047 rad/s.
            "quadrature_dps",
            GyroParams {
                quadrature_dps: 1047.3f64.to_degrees(),
                ..params(1.0e3, 1.0e3, 10.0, 10.0, 3.0)
            },
            10.0e3,
        ),
        (
            // Q 1e5: sqrt(B1 B2) / (2 lambda) = 52.36 rad/s = 3000 deg/s.
            "damping_coupling_dps",
            GyroParams {
                damping_coupling_dps: 3002.0,
                ..params(1.0e6, 1.0e6, 1e5, 1e5, 0.6)
            },
            10.0e6,
        ),
    ];
    // Just inside the stability limits: accepted.
    let inside = [
        GyroParams {
            quadrature_dps: 1047.1f64.to_degrees(),
            ..params(1.0e3, 1.0e3, 10.0, 10.0, 3.0)
        },
        GyroParams {
            damping_coupling_dps: -2999.0,
            ..params(1.0e6, 1.0e6, 1e5, 1e5, 0.6)
        },
    ];
    for (p, clock) in inside.iter().zip([10.0e3, 10.0e6]) {
        assert!(GyroModel::new(p, clock).is_ok(), "{p:?}");
    }
    for (field, p, clock) in bad {
        let err = GyroModel::new(&p, clock).expect_err(field).to_string();
        assert!(err.starts_with(field), "{field}: message {err:?}");
        assert!(!err.contains('\n'), "one line: {err:?}");
    }
}

#[test]
fn state_round_trip_reset_and_rate_cache() {
    let p = params(1.0e6, 1.001e6, 1000.0, 2000.0, 0.6);
    let mut g = GyroModel::new(&p, 10.0e6).expect("valid");
    let s = [1e-9, -3e-3, 2e-9, 4e-3];
    g.set_state(s);
    let back = g.state();
    for i in 0..4 {
        assert!((back[i] - s[i]).abs() <= 1e-15 * s[i].abs(), "{back:?}");
    }
    assert_eq!((g.x1(), g.x2()), (s[0], s[2]));
    // Rate 0 -> r -> 0 must give exactly the trajectory of a model that never
    // rotated (cached Omz = 0 matrices are the ones built at construction).
    let mut h = GyroModel::new(&p, 10.0e6).expect("valid");
    h.set_state(s);
    g.set_rate(123.0);
    g.set_rate(0.0);
    for _ in 0..1000 {
        g.step(0.5, -0.25);
        h.step(0.5, -0.25);
    }
    assert_eq!(g.state(), h.state());
    g.reset();
    assert_eq!(g.state(), [0.0; 4]);
    assert_eq!(g.rate(), 0.0);
}

/// `len` forces for the block tests, each clock's from the count `k` of
/// clocks so far (moved on by `len`): two incommensurate sinusoids, so
/// that no two clocks' forces repeat.
fn block_forces(k: &mut f64, len: usize) -> Vec<(f64, f64)> {
    (0..len)
        .map(|_| {
            *k += 1.0;
            ((0.37 * *k).sin() * 1e3, (0.11 * *k).cos() * 1e3)
        })
        .collect()
}

/// The device the block tests step (`steps`, `steps_abreast`) at rate
/// `omz`, with thermal noise of seed `noise_seed` when given.
fn stepped_model(omz: f64, noise_seed: Option<u64>) -> GyroModel {
    let p = params(1.0e6, 1.0003e6, 3000.0, 2500.0, 0.8);
    let mut g = GyroModel::new(&p, 10.0e6).expect("valid");
    if let Some(seed) = noise_seed {
        let noise = gyrocal_sim::noise::ThermalNoise {
            mass_kg: 1.0e-9,
            temperature_k: 300.0,
            seed,
        };
        g = g.with_thermal_noise(&noise).expect("valid noise");
    }
    g.set_rate(omz);
    g
}

/// `steps` is `step` clock by clock, bit for bit: the state it senses at
/// each edge and the state after the run, over runs of odd and even
/// length (the pairs of `step` run across them), coupled and not, with
/// thermal noise and without (each its own loop in `steps`), the rate and
/// the state changed between runs (which start a new pair in both).
#[test]
fn steps_are_the_steps_clock_by_clock() {
    for (omz, thermal) in [(0.0, false), (2.0, false), (0.0, true), (2.0, true)] {
        let mut a = stepped_model(omz, thermal.then_some(9));
        let mut b = a.clone();
        let mut k = 0.0f64;
        for (i, len) in [1usize, 2, 3, 256, 7, 1, 1, 100, 5].into_iter().enumerate() {
            let forces = block_forces(&mut k, len);
            let mut seen = vec![[0.0; 4]; len];
            a.steps(&forces, &mut seen, |_, s| s);
            for (n, &(f1, f2)) in forces.iter().enumerate() {
                let at = format!("rate {omz}, thermal {thermal}, run {i}, clock {n}");
                assert_eq!(seen[n], b.state(), "{at}");
                b.step(f1, f2);
            }
            let at = format!("rate {omz}, thermal {thermal}, after run {i}");
            assert_eq!(a.state(), b.state(), "{at}");
            match i {
                3 => {
                    a.set_rate(omz + 1.0);
                    b.set_rate(omz + 1.0);
                }
                5 => {
                    let s = a.state();
                    a.set_state(s);
                    b.set_state(s);
                }
                _ => {}
            }
        }
        assert!(
            a.state().iter().any(|&x| x != 0.0),
            "the runs moved the state"
        );
    }
}

/// Two models stepped abreast (`GyroModel::steps_abreast`) are each one
/// stepped alone, bit for bit: coupled, uncoupled and one of each (which
/// run one after the other), with thermal noise on one (likewise), over
/// runs of odd and even length so that both start pairs and halves, and
/// with the rate changed between runs on one model only (its pair starts
/// again where the other's runs on: halves not aligned, one after the
/// other).
#[test]
fn steps_abreast_are_each_ones_own_steps() {
    let cases = [
        (0.5, -1.5, false),
        (0.0, 0.0, false),
        (0.0, 2.0, false),
        (1.0, 0.7, true),
    ];
    for (rate_a, rate_b, thermal) in cases {
        let (mut a, mut b) = (
            stepped_model(rate_a, None),
            stepped_model(rate_b, thermal.then_some(5)),
        );
        let (mut alone_a, mut alone_b) = (a.clone(), b.clone());
        let mut k = 0.0f64;
        for (i, len) in [1usize, 2, 3, 256, 7, 1, 100, 5, 4].into_iter().enumerate() {
            let forces = block_forces(&mut k, len);
            let (mut seen_a, mut seen_b) = (vec![[0.0; 4]; len], vec![[0.0; 4]; len]);
            GyroModel::steps_abreast(
                &mut a,
                &mut b,
                &forces,
                (&mut seen_a, &mut seen_b),
                |_, s| s,
                |_, s| s,
            );
            let (mut want_a, mut want_b) = (vec![[0.0; 4]; len], vec![[0.0; 4]; len]);
            alone_a.steps(&forces, &mut want_a, |_, s| s);
            alone_b.steps(&forces, &mut want_b, |_, s| s);
            let at = format!("rates {rate_a}, {rate_b}, thermal {thermal}, run {i}");
            assert_eq!(seen_a, want_a, "{at}: a's edges");
            assert_eq!(seen_b, want_b, "{at}: b's edges");
            assert_eq!(a.state(), alone_a.state(), "{at}: a after");
            assert_eq!(b.state(), alone_b.state(), "{at}: b after");
            if i == 4 {
                a.set_rate(rate_a + 0.25);
                alone_a.set_rate(rate_a + 0.25);
            }
        }
        assert!(a.state().iter().chain(&b.state()).all(|&x| x != 0.0));
    }
}

/// A change of rate or state between the two clocks of a pair starts a
/// new pair: the model then goes on as a fresh one set to that state and
/// rate, where the old pair's Phi^2 would carry the clock before the
/// change across it (a relative error of the change itself: 2 lam Omz T =
/// 8e-7 here for the rate).
#[test]
fn a_change_between_a_pairs_clocks_starts_a_new_pair() {
    let p = params(1.0e6, 1.0003e6, 3000.0, 2500.0, 0.8);
    let force = |n: usize| ((0.3 * n as f64).sin() * 1e3, 5e2);
    let fresh = |rate: f64, state: [f64; 4]| {
        let mut g = GyroModel::new(&p, 10.0e6).expect("valid");
        g.set_rate(rate);
        g.set_state(state);
        g
    };
    let run = |g: &mut GyroModel| {
        for n in 0..101 {
            let (f1, f2) = force(n);
            g.step(f1, f2);
        }
        g.state()
    };
    // A state set after a pair's first clock: bit for bit.
    let mut a = GyroModel::new(&p, 10.0e6).expect("valid");
    a.step(1e3, -2e3);
    let x = [1e-9, -2e-4, 3e-9, 1e-4];
    a.set_state(x);
    assert_eq!(run(&mut a), run(&mut fresh(0.0, x)));
    // A rate set after a pair's first clock: from the state then (which
    // set_state takes back to within an ulp of the scaled velocities).
    let mut c = fresh(0.0, x);
    c.step(1e3, -2e3);
    let s = c.state();
    c.set_rate(5.0);
    let (c, d) = (run(&mut c), run(&mut fresh(5.0, s)));
    let norm = d.iter().map(|v| v * v).sum::<f64>().sqrt();
    for i in 0..4 {
        assert!((c[i] - d[i]).abs() <= 1e-12 * norm, "{c:?} vs {d:?}");
    }
}
