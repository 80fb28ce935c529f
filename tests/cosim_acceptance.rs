//! Co-simulation against the exact theory: the calibration scale factor
//! predicts the readout scale factor.
//!
//! Tolerance 0.1% on every ratio, from the issue; what eats into it was
//! measured while planning (design.md) and is reported by each test: the
//! 16-bit ADC's deterministic quantization error (the rate signal is a
//! fraction of an LSB on a detuned output), about 0.01-0.04% with 50 ms
//! windows; each point settled to 1e-4 of the signal it measures; the
//! whole-period window average, below 1e-6 (`average.rs`).

use gyrocal_sim::engine::EngineKind;
use gyrocal_sim::experiment::{self, BATCHES, Experiment};
use gyrocal_sim::fit::coverage_factor;
use gyrocal_sim::gyro::GyroParams;
use gyrocal_sim::report::Report;

/// A scaled copy of the paper's device: the same split in bandwidths
/// (1.43 B) and the same rates and calibration frequencies relative to the
/// bandwidth, at 1 MHz on a 10 MHz clock (non-round carrier, as design.md
/// requires of test devices).
fn scaled_paper(carrier_offset_hz: f64) -> Experiment {
    let mut e = Experiment::paper();
    let f1 = 1.0123e6;
    let q = 5000.0;
    let bandwidth = f1 / q;
    e.gyro = GyroParams {
        f1_hz: f1,
        f2_hz: f1 + 1.426 * bandwidth,
        q1: q,
        q2: q,
        angular_gain: 0.6,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
    };
    e.drive.carrier_hz = f1 + carrier_offset_hz;
    e.drive.clock_hz = 10e6;
    e.filter.decimation = Some(250);
    e.points.readout_rates_dps = vec![1.0, 5.0, 10.0, 15.0, 20.0];
    let scale = bandwidth / (9.64e6 / 55e3);
    e.points.cal_freqs_hz = (10..=15).map(|f| f as f64 * scale).collect();
    // Averaging windows of 0.1 s rather than 0.05 s: on the
    // resonant output the readout signal is a small in-phase part of a
    // full-scale quadrature signal, and the 16-bit ADC's quantization
    // residue averaged over 0.05 s left +0.094% in its readout scale
    // factor when excited at mode 2 (measured with the ideal quantizer,
    // before dither became the default: 0.031% at 0.1 s, 0.029% at 0.2 s,
    // so 0.1 s is past the knee).
    e.points.min_window_s = Some(0.1);
    e
}

fn run(e: &Experiment) -> Report {
    gyrocal_sim::report::run(e, EngineKind::Model, &|_| {}).unwrap()
}

fn assert_ratios_match_theory(r: &Report, what: &str) {
    for k in 0..2 {
        eprintln!(
            "{what}, output {}: ratio {:.6} exact {:.6} error {:+.4}%",
            k + 1,
            r.scale_factors.ratio[k],
            r.theory.ratio[k],
            100.0 * r.ratio_error[k]
        );
    }
    for k in 0..2 {
        assert!(
            r.ratio_error[k].abs() < 1e-3,
            "{what}, output {}: {:+.4}%",
            k + 1,
            100.0 * r.ratio_error[k]
        );
    }
}

#[test]
fn matched_modes_give_minus_two_lambda() {
    // Q 1000 (bandwidth 1 kHz) and f_cal 2..6 Hz keep 2 Om / B below 0.012
    // and the rates' 2 lam Omz Q / w0 below 0.002, so the closed-form
    // fitted ratio sits within 2e-4 of -2 lambda (checked first: the test
    // would otherwise measure the curvature of f(x) = x / (1 + x^2), not
    // the co-simulation). The datapath's own calibration theory adds its
    // envelope lead (-Om T / 2, theory.rs), 3.5e-4 here; the simulated
    // ratio must land within 0.1% of -2 lambda all the same.
    let mut e = Experiment::paper();
    e.gyro = GyroParams {
        f1_hz: 1.0123e6,
        f2_hz: 1.0123e6,
        q1: 1000.0,
        q2: 1000.0,
        angular_gain: 0.8,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
    };
    e.drive.carrier_hz = 1.0123e6;
    e.drive.clock_hz = 10e6;
    e.filter.decimation = Some(250);
    e.points.readout_rates_dps = vec![100.0, 200.0, 300.0, 400.0];
    e.points.cal_freqs_hz = vec![2.0, 4.0, 6.0];
    let r = run(&e);
    let target = -2.0 * 0.8;
    let plan = experiment::plan(&e).unwrap();
    let mut dev = plan.theory_device(&e);
    dev.f1_force *= plan.hold_gain.sqrt();
    dev.f2_force *= plan.hold_gain.sqrt();
    let closed_form = gyrocal_sim::fit::fitted_scale_factors(
        &dev,
        &e.points.readout_rates_dps,
        &e.points.cal_freqs_hz,
    );
    for k in 0..2 {
        assert!(
            (closed_form.ratio[k] / target - 1.0).abs() < 2e-4,
            "closed form {}",
            closed_form.ratio[k]
        );
        let error = r.scale_factors.ratio[k] / target - 1.0;
        eprintln!(
            "matched, output {}: ratio {:.6} vs -2 lambda: {:+.4}%",
            k + 1,
            r.scale_factors.ratio[k],
            100.0 * error
        );
        assert!(
            error.abs() < 1e-3,
            "output {}: {:+.4}%",
            k + 1,
            100.0 * error
        );
    }
}

#[test]
fn mismatched_modes_excited_at_mode_1() {
    let r = run(&scaled_paper(0.0));
    assert_eq!(r.detuned_output, Some(1));
    assert_ratios_match_theory(&r, "excited at mode 1");
}

#[test]
fn mismatched_modes_excited_at_mode_2() {
    let e = scaled_paper(0.0);
    let split = e.gyro.f2_hz - e.gyro.f1_hz;
    let r = run(&scaled_paper(split));
    assert_eq!(r.detuned_output, Some(0));
    assert_ratios_match_theory(&r, "excited at mode 2");
}

#[test]
fn mismatched_modes_excited_midway() {
    let e = scaled_paper(0.0);
    let split = e.gyro.f2_hz - e.gyro.f1_hz;
    let r = run(&scaled_paper(split / 2.0));
    assert_ratios_match_theory(&r, "excited midway");
}

#[test]
fn unequal_q_and_negative_split() {
    // The fifth reference case's shape: mode 2 below mode 1, Q 30,000 and
    // 25,000, lambda 0.5, scaled to 1 MHz.
    let mut e = scaled_paper(0.0);
    e.gyro = GyroParams {
        f1_hz: 1.0123e6,
        f2_hz: 1.0123e6 - 27.0,
        q1: 10_000.0,
        q2: 8_300.0,
        angular_gain: 0.5,
        quadrature_dps: 0.0,
        damping_coupling_dps: 0.0,
    };
    e.drive.carrier_hz = e.gyro.f1_hz;
    e.points.cal_freqs_hz = vec![1.0, 1.7, 2.4];
    assert_ratios_match_theory(&run(&e), "split -27 Hz, unequal Q");
}

#[test]
fn the_papers_device_at_full_scale() {
    // `gyrocal reproduce`'s experiment: 9.64 MHz, Q 55,000, 250 Hz split,
    // 50 MHz clock, 1..20 deg/s, 10..15 Hz, dithered converters: 2.45e8 clocks.
    let r = run(&Experiment::paper());
    assert_eq!(r.detuned_output, Some(1));
    // The exact fitted ratio at the paper's points is about 1.534 and the
    // small-signal one 1.536 (design.md; 1.5338 and 1.5363 in the
    // reference cases for the nominal carrier).
    assert!(
        (r.theory.ratio[1] - 1.534).abs() < 1e-3,
        "{}",
        r.theory.ratio[1]
    );
    assert!((r.theory.small_signal.ratio[1] - 1.5365).abs() < 1e-3);
    assert_ratios_match_theory(&r, "paper's device");
    // Issue 7: `reproduce`'s run lands within 1e-4 of the exact theory on
    // the detuned output. The plan's precision (0.15 s windows, dithered
    // converters): a 1-sigma uncertainty near 3e-5 of the ratio; over
    // dither seeds 1..16 the error spread by 3.05e-5 around +1.0e-5 +- 0.8e-5
    // (no bias at that level), so an unbiased run lands within 1e-4 with
    // probability 0.999. This run's dither is fixed (seed 1): the assertion
    // is a regression guard; a bias of a few 1e-5 introduced later (a
    // latency the theory does not know, a rounding) would push it out.
    // The honesty of sigma is tests/uncertainty_is_honest.rs. The guard is
    // on the bare batch spread: the reported sigma is that spread times the
    // coverage factor of its 7 degrees of freedom (1.51) plus systematic
    // terms (`gyrocal_sim::budget`), 4.85e-5 x 1.51 on this run.
    let error = r.ratio_error[1];
    let spread = r.uncertainty_budget.ratio[1].statistical
        / coverage_factor(BATCHES - 1)
        / r.scale_factors.ratio[1].abs();
    eprintln!("paper's device: detuned ratio error {error:+.2e}, batch spread {spread:.2e}");
    assert!(spread < 5e-5, "batch spread {spread:.2e}");
    assert!(error.abs() < 1e-4, "detuned ratio error {error:+.2e}");
}

#[test]
fn alignment_follows_the_converter_latencies() {
    // The references are lined up from the model's own latencies
    // (ref_delay = L_dac + L_adc, ref_phase = carrier_step / 2); the ratio,
    // which a 1-degree phase error moves by several percent on the detuned
    // output, must stay on the theory for any latencies.
    for (dac, adc) in [(0, 0), (1, 7), (12, 20)] {
        let mut e = scaled_paper(0.0);
        e.frontend.dac_latency = dac;
        e.frontend.adc_latency = adc;
        assert_ratios_match_theory(&run(&e), &format!("L_dac {dac}, L_adc {adc}"));
    }
}

#[test]
fn a_reference_one_clock_late_is_visible() {
    // Negative control for the alignment: the same experiment with every
    // reference delayed one clock too long (36 degrees at this carrier)
    // must miss the theory by far more than the 0.1% tolerance.
    let e = scaled_paper(0.0);
    let mut plan = experiment::plan(&e).unwrap();
    for p in &mut plan.points {
        p.regs.ref_delay += 1;
    }
    let points = experiment::run_points(&e, &plan, EngineKind::Model, &|_| {})
        .unwrap()
        .points;
    let sim = experiment::measured_scale_factors(&points);
    let exact = experiment::exact_scale_factors(&points);
    let error = sim.ratio[1] / exact.ratio[1] - 1.0;
    eprintln!("one clock late: detuned ratio error {:+.2}%", 100.0 * error);
    assert!(error.abs() > 0.05, "{error}");
}
