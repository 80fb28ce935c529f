//! `gyrocal run` on devices with mode couplings lands on the extended exact
//! theory: the model gyroscope carries the quadrature (and damping)
//! coupling in its matrices, the theory in its phasor solves, and the two
//! must agree through the whole datapath (hold, envelope lead, converters,
//! filters) within the bounds `gyrocal run` is held to everywhere
//! (`tests/any_device.rs`): |measured - exact| <= 3 sigma of the run's own
//! uncertainty, and within 0.1% of the exact ratio (2e-3 absolute below
//! |ratio| 0.5).
//!
//! The same runs show that the comparison sees the coupling: the exact
//! ratio without it (same points, same fit) lies more than 10 sigma of
//! the run away on the output it moves most, so a model or a theory that
//! dropped the coupling would fail. Each test prints the ratio shift the
//! coupling causes, fitted over its points and small-signal (the figures
//! docs/your-device.md points to).

use gyrocal_sim::config;
use gyrocal_sim::engine::EngineKind;
use gyrocal_sim::experiment::{self, Experiment, Mode};
use gyrocal_sim::fit::linear_fit;
use gyrocal_sim::report::{Report, run};
use gyrocal_sim::theory::sf_ratio;

/// The exact theory's fitted ratios of `exp` at its planned points.
fn exact_ratio(exp: &Experiment) -> [f64; 2] {
    let plan = experiment::plan(exp).expect("plan");
    let slope = |mode: Mode, k: usize| {
        let points: Vec<_> = plan.points.iter().filter(|p| p.mode == mode).collect();
        let x: Vec<f64> = points.iter().map(|p| p.rate_dps).collect();
        let y: Vec<f64> = points.iter().map(|p| plan.theory_z(exp, p)[k]).collect();
        linear_fit(&x, &y).0
    };
    std::array::from_fn(|k| slope(Mode::Readout, k) / slope(Mode::Calibration, k))
}

/// Runs `text` on the model engine and checks it against the theory, with
/// and without the coupling (module header).
fn check(name: &str, text: &str) {
    let exp = config::parse(name, text).unwrap_or_else(|e| panic!("{name}: {e}"));
    let r: Report = run(&exp, EngineKind::Model, &|_| {}).unwrap();
    for w in &r.warnings {
        eprintln!("{name}: warning: {w}");
    }
    let mut uncoupled = exp.clone();
    uncoupled.gyro.quadrature_dps = 0.0;
    uncoupled.gyro.damping_coupling_dps = 0.0;
    let without = exact_ratio(&uncoupled);
    let plan = experiment::plan(&uncoupled).expect("plan");
    let small_without = sf_ratio(&plan.theory_device(&uncoupled));
    let small = r.theory.small_signal.ratio;
    eprintln!(
        "{name}: {} rounds, {} clocks in {:.1} s; small-signal ratios {small:.6?}, \
         without the coupling {small_without:.6?}: moved by {:+.3}%, {:+.3}%",
        r.timing.rounds,
        r.timing.cycles,
        r.timing.wall_s,
        100.0 * (small[0] / small_without[0] - 1.0),
        100.0 * (small[1] / small_without[1] - 1.0)
    );
    let mut sigmas_from_uncoupled = 0.0f64;
    for (k, &w) in without.iter().enumerate() {
        let (m, x, s) = (
            r.scale_factors.ratio[k],
            r.theory.ratio[k],
            r.scale_factors.ratio_uncertainty[k],
        );
        eprintln!(
            "{name}, output {}: ratio {m:.6} +- {s:.1e}, exact {x:.6} (error {:+.4}%, {:+.2} sigma); \
             exact without the coupling {:.6}: the coupling moves it by {:+.3}%",
            k + 1,
            100.0 * (m / x - 1.0),
            (m - x) / s,
            w,
            100.0 * (x / w - 1.0)
        );
        assert!(
            (m - x).abs() <= 3.0 * s,
            "{name}, output {}: {m} vs {x}, sigma {s}",
            k + 1
        );
        let bound = if x.abs() >= 0.5 { 1e-3 * x.abs() } else { 2e-3 };
        assert!(
            (m - x).abs() <= bound,
            "{name}, output {}: {m} vs {x}",
            k + 1
        );
        sigmas_from_uncoupled = sigmas_from_uncoupled.max((m - w).abs() / s);
    }
    assert!(
        sigmas_from_uncoupled > 10.0,
        "{name}: the run cannot tell the coupling ({sigmas_from_uncoupled:.1} sigma)"
    );
}

/// The kHz consumer device of `any_device.rs` (25.1 / 25.8 kHz, Q 3000,
/// excited at mode 1, 1.2345 MHz clock) with the `[gyro]` line `coupling`.
fn consumer(coupling: &str) -> String {
    format!(
        "[gyro]\nf1_hz = 25.1e3\nf2_hz = 25.8e3\nq1 = 3000\nq2 = 3000\nangular_gain = 0.8\n\
         {coupling}\n[drive]\ncarrier_hz = 25.1e3\nclock_hz = 1.2345e6\n\
         [experiment]\nreadout_rates_dps = [50, 100, 150, 200]\ncal_freqs_hz = [2, 4, 6]\n"
    )
}

#[test]
fn consumer_device_with_300_dps_of_quadrature() {
    check(
        "consumer_quadrature.toml",
        &consumer("quadrature_dps = 300"),
    );
}

#[test]
fn consumer_device_with_100_dps_of_damping_coupling() {
    // Through mode 1's resonance the damping coupling gives output 2 a
    // calibration offset that varies with f_cal, which turns that output's
    // fitted ratio around.
    check(
        "consumer_damping.toml",
        &consumer("damping_coupling_dps = 100"),
    );
}

#[test]
fn high_q_2_mhz_device_with_quadrature_and_damping_coupling() {
    // A nearly matched 2 MHz device (modes 4 Hz apart inside a 20 Hz
    // bandwidth, Q 1e5 / 9e4, excited at mode 1) on an 8.3123 MHz clock, with
    // 300 deg/s of quadrature and 100 deg/s of damping coupling.
    check(
        "high_q_couplings.toml",
        "[gyro]\nf1_hz = 2.0e6\nf2_hz = 2.000004e6\nq1 = 1e5\nq2 = 9e4\nangular_gain = 0.7\n\
         quadrature_dps = 300\ndamping_coupling_dps = 100\n\
         [drive]\ncarrier_hz = 2.0e6\nclock_hz = 8.3123e6\n\
         [experiment]\nreadout_rates_dps = [5, 10, 15, 20]\ncal_freqs_hz = [2, 3, 4]\n",
    );
}
