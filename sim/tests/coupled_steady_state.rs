//! The exact theory with mode couplings (quadrature stiffness k, damping
//! coupling d) against an independent numerical integration of the
//! continuous equations, and its small-signal scale factors against
//! numerical derivatives of its own steady state.
//!
//! The integration: classical Runge-Kutta (RK4) of
//!
//! ```text
//! x1'' = f1 - B1 x1' + 2 lam Omz x2' - w1^2 x1 - d x2' - k x2
//! x2'' = f2 - B2 x2' - 2 lam Omz x1' - w2^2 x2 - d x1' - k x1
//! ```
//!
//! with the forces evaluated exactly at every stage (no hold), from rest,
//! on a low-frequency, low-Q device where a fine step is cheap: modes
//! 1000 / 1037 Hz, Q 40 / 60, lambda 0.7, carrier 1020 Hz, couplings and
//! rates strong enough (k and 2 lam Omz wb near 1e6 s^-2, against
//! w1 B1 = 1e6 and w2^2 - w1^2 = 3e6) that every term of the theory
//! changes z by tens of percent. After 1 s (more than 35 time constants
//! of the slowest hybrid mode, 26 ms: transient below 1e-15) the outputs
//! are averaged over whole periods of every tone in the products (the
//! carrier in readout; 1 / f_cal in calibration, with f_cal dividing the
//! carrier), on the integration grid: that mean is exact for the
//! trigonometric polynomials the sampled steady state is.
//!
//! Tolerance from the integrator's own error: RK4's global error is
//! C h^4, so runs at N and 2N steps per carrier period give the error of
//! the finer one as (z_N - z_2N) / 15 (Richardson). Each z at 2N must sit
//! within twice that estimate (plus a rounding floor of 1e-12 of the
//! output's scale) of the theory, and the coarse error must be 16 times the
//! fine one (10 to 22: the error really is RK4's h^4, so the theory is the
//! limit the integration converges to). At N = 250 the estimate is about
//! 1e-8 of z: a wrong sign or a missing term of the coupling would be off
//! by 1e-1.

use gyrocal_sim::theory::*;
use std::f64::consts::TAU;

/// The low-Q device of the module header with couplings `[Omq, Omd]` (deg/s).
fn device(couplings_dps: [f64; 2]) -> Device {
    Device {
        f1_hz: 1000.0,
        f2_hz: 1037.0,
        q1: 40.0,
        q2: 60.0,
        angular_gain: 0.7,
        quadrature_dps: couplings_dps[0],
        damping_coupling_dps: couplings_dps[1],
        carrier_hz: 1020.0,
        f1_force: 0.8,
        f2_force: 0.6,
    }
}

/// The couplings of the three cases: quadrature alone (k = 1.0e6 s^-2),
/// damping coupling alone (d = 50 s^-1, 0.38 of its stability limit), both.
const CASES: [[f64; 2]; 3] = [[6500.0, 0.0], [0.0, 2046.0], [6500.0, 2046.0]];

/// Readout at a rate (rad/s), or calibration at a modulation frequency
/// (Hz) with the datapath's envelope lead of the references (rad) and
/// sideband gains of the drives; in both the responses lag their
/// references by `lag` (rad), i.e. the references' carrier leads.
#[derive(Clone, Copy, Debug)]
enum Point {
    Readout {
        omz: f64,
        lag: f64,
    },
    Calibration {
        f_cal: f64,
        lead: f64,
        gains: [f64; 2],
        lag: f64,
    },
}

/// Drives `[f1, f2]` and the two outputs' references at time `t`
/// (readout: each output its own drive; calibration: the other's).
fn signals(dev: &Device, point: Point, t: f64) -> ([f64; 2], [f64; 2]) {
    let wb = TAU * dev.carrier_hz;
    let (fa, fb) = (dev.f1_force, dev.f2_force);
    match point {
        Point::Readout { lag, .. } => (
            [fa * (wb * t).cos(), fb * (wb * t).sin()],
            [fa * (wb * t + lag).cos(), fb * (wb * t + lag).sin()],
        ),
        Point::Calibration {
            f_cal,
            lead,
            gains: [g0, g1],
            lag,
        } => {
            let om = TAU * f_cal;
            let (lo, hi) = (((wb - om) * t).cos(), ((wb + om) * t).cos());
            (
                [
                    fa / 2.0 * (g0 * lo + g1 * hi),
                    fb / 2.0 * (g0 * lo - g1 * hi),
                ],
                [
                    fb * (wb * t + lag).sin() * (om * t + lead).sin(),
                    fa * (wb * t + lag).cos() * (om * t + lead).cos(),
                ],
            )
        }
    }
}

/// RK4 from rest: `steps_per_period` steps per carrier period, 1 s of
/// settling, then the mean of each output over `window` s.
fn integrate(dev: &Device, point: Point, steps_per_period: u32, window: f64) -> [f64; 2] {
    let g = dev.gyro_params();
    let (w1, w2) = (TAU * dev.f1_hz, TAU * dev.f2_hz);
    let (b1, b2) = (w1 / dev.q1, w2 / dev.q2);
    let (k, d) = (g.quadrature_stiffness(), g.damping_coupling());
    let omz = match point {
        Point::Readout { omz, .. } => omz,
        Point::Calibration { .. } => 0.0,
    };
    let c = 2.0 * dev.angular_gain * omz;
    let rhs = |t: f64, y: [f64; 4]| {
        let (f, _) = signals(dev, point, t);
        [
            y[1],
            f[0] - b1 * y[1] + c * y[3] - w1 * w1 * y[0] - d * y[3] - k * y[2],
            y[3],
            f[1] - b2 * y[3] - c * y[1] - w2 * w2 * y[2] - d * y[1] - k * y[0],
        ]
    };
    let h = 1.0 / (dev.carrier_hz * f64::from(steps_per_period));
    let settle = (1.0 / h).round() as u64;
    let count = (window / h).round() as u64;
    let mut y = [0.0; 4];
    let mut sum = [0.0; 2];
    let add = |y: [f64; 4], a: [f64; 4], s: f64| std::array::from_fn(|i| y[i] + s * a[i]);
    for n in 0..settle + count {
        let t = n as f64 * h;
        if n >= settle {
            let (_, r) = signals(dev, point, t);
            sum[0] += y[0] * r[0];
            sum[1] += y[2] * r[1];
        }
        let k1 = rhs(t, y);
        let k2 = rhs(t + h / 2.0, add(y, k1, h / 2.0));
        let k3 = rhs(t + h / 2.0, add(y, k2, h / 2.0));
        let k4 = rhs(t + h, add(y, k3, h));
        y = std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]));
    }
    sum.map(|s| s / count as f64)
}

/// The theory's z at a point: the closed form where there is no lead,
/// gain or lag, the datapath's function otherwise.
fn theory(dev: &Device, point: Point) -> [f64; 2] {
    match point {
        Point::Readout { omz, lag: 0.0 } => readout_z(dev, omz),
        Point::Readout { omz, lag } => readout_z_lagged(dev, omz, lag),
        Point::Calibration {
            f_cal,
            lead: 0.0,
            gains: [1.0, 1.0],
            lag: 0.0,
        } => calibration_z(dev, f_cal),
        Point::Calibration {
            f_cal,
            lead,
            gains,
            lag,
        } => calibration_z_lagged(dev, f_cal, lead, gains, lag),
    }
}

/// Integrates at N and 2N and checks the theory against the finer run
/// with the Richardson tolerance of the module header; then checks that
/// the couplings move z by at least 1000 times that tolerance (the check
/// can see them).
fn check(dev: &Device, point: Point, window: f64, scale: [f64; 2]) {
    let n = 250;
    let coarse = integrate(dev, point, n, window);
    let fine = integrate(dev, point, 2 * n, window);
    let exact = theory(dev, point);
    let uncoupled = theory(&device([0.0, 0.0]), point);
    for m in 0..2 {
        let estimate = (coarse[m] - fine[m]).abs() / 15.0;
        let floor = 1e-12 * scale[m];
        let error = (fine[m] - exact[m]).abs();
        let order = (coarse[m] - exact[m]).abs() / error;
        let tolerance = 2.0 * estimate + floor;
        let moved = (exact[m] - uncoupled[m]).abs();
        println!(
            "{point:?} couplings {:?} output {}: z {:.6e}, theory {:.6e}, error {:.1e} of scale, \
             RK4 estimate {:.1e}, coarse/fine error {order:.1}, moved by the couplings {:.1e}",
            [dev.quadrature_dps, dev.damping_coupling_dps],
            m + 1,
            fine[m],
            exact[m],
            error / scale[m],
            estimate / scale[m],
            moved / scale[m]
        );
        assert!(
            error <= tolerance,
            "{point:?} output {}: error {error:e} above the RK4 estimate {estimate:e}",
            m + 1
        );
        if error > 100.0 * floor {
            assert!((10.0..22.0).contains(&order), "not RK4's h^4: {order}");
        }
        assert!(
            moved > 1e3 * tolerance,
            "the couplings barely move z: {moved:e}"
        );
    }
}

#[test]
fn readout_with_couplings_matches_the_integrated_equations() {
    for couplings in CASES {
        let dev = device(couplings);
        // The scale of each output: its drive times the largest phasor.
        let x = readout_peak_displacement(&dev, 0.0);
        let scale = [dev.f1_force * x[0], dev.f2_force * x[1]];
        for (omz, lag) in [(0.0, 0.0), (90.0, 0.0), (-60.0, 0.0), (90.0, 0.3)] {
            // 51 carrier periods.
            check(
                &dev,
                Point::Readout { omz, lag },
                51.0 / dev.carrier_hz,
                scale,
            );
        }
    }
}

#[test]
fn calibration_with_couplings_matches_the_integrated_equations() {
    for couplings in CASES {
        let dev = device(couplings);
        // The closed form, and the datapath's function with a lead, unequal
        // sideband gains and a lag, all large enough to move z by percent.
        let points = [
            (20.0, 0.0, [1.0, 1.0], 0.0),
            (51.0, 0.0, [1.0, 1.0], 0.0),
            (20.0, 0.2, [0.9, 1.1], -0.4),
        ];
        for (f_cal, lead, gains, lag) in points {
            let x = calibration_peak_displacement(&dev, f_cal);
            let scale = [dev.f2_force * x[0], dev.f1_force * x[1]];
            let point = Point::Calibration {
                f_cal,
                lead,
                gains,
                lag,
            };
            // One period of f_cal: 1020 / f_cal carrier periods.
            check(&dev, point, 1.0 / f_cal, scale);
        }
    }
}

/// Central difference `(g(h) - g(-h))/2h` refined once by Richardson (h, h/2):
/// truncation O(h^4).
fn derivative(g: impl Fn(f64) -> f64, h: f64) -> f64 {
    let d = |h: f64| (g(h) - g(-h)) / (2.0 * h);
    (4.0 * d(h / 2.0) - d(h)) / 3.0
}

#[test]
fn small_signal_scale_factors_with_couplings_are_the_derivatives() {
    // The analytic SF_read = lam wb F1 F2 Re(1/det) and SF_cal = F1 F2/4
    // Re(-Hkk') (theory's module header) against numerical derivatives of
    // the steady state at 0. Step h = B/1000, B = min(B1, B2): the
    // responses vary on the scale B/2 and B/(2 lam), so the Richardson
    // truncation is ~(2h/B)^4 ~ 2e-11; rounding: z carries an offset
    // (the couplings' among them) up to ~1e3 x (SF h) on these devices, so
    // the difference loses ~1e-16 x 1e3 / 1e-3 = 1e-10. Tolerance 2e-9.
    // Devices: the low-Q one of the RK4 checks with each coupling, the
    // consumer device (25.1 / 25.8 kHz, Q 3000) with 300 deg/s of
    // quadrature, and a 2 MHz high-Q one with 100 deg/s and 50 deg/s of
    // damping coupling.
    let consumer = Device {
        f1_hz: 25.1e3,
        f2_hz: 25.8e3,
        q1: 3000.0,
        q2: 3000.0,
        angular_gain: 0.8,
        quadrature_dps: 300.0,
        damping_coupling_dps: 0.0,
        carrier_hz: 25.1e3,
        f1_force: 0.8,
        f2_force: 0.6,
    };
    let high_q = Device {
        f1_hz: 2.0e6,
        f2_hz: 2.000004e6,
        q1: 1e5,
        q2: 9e4,
        angular_gain: 0.7,
        quadrature_dps: 100.0,
        damping_coupling_dps: 50.0,
        carrier_hz: 2.0e6,
        f1_force: 0.3,
        f2_force: 0.4,
    };
    let devices = CASES.map(device).into_iter().chain([consumer, high_q]);
    for d in devices {
        let b = (TAU * d.f1_hz / d.q1).min(TAU * d.f2_hz / d.q2);
        let h = b / 1000.0;
        let (sr, sc) = (sf_read_per_rad_s(&d), sf_cal_per_rad_s(&d));
        for k in 0..2 {
            let read = derivative(|o| readout_z(&d, o)[k], h);
            let cal = derivative(|o| calibration_z(&d, o / TAU)[k], h);
            println!(
                "{:?} output {}: SF_read {:.3e} (numerical {:+.1e}), SF_cal {:.3e} ({:+.1e})",
                [d.quadrature_dps, d.damping_coupling_dps],
                k + 1,
                sr[k],
                sr[k] / read - 1.0,
                sc[k],
                sc[k] / cal - 1.0
            );
            assert!((sr[k] / read - 1.0).abs() < 2e-9, "{d:?}");
            assert!((sc[k] / cal - 1.0).abs() < 2e-9, "{d:?}");
        }
    }
}
