//! A datasheet that is off, as every real one is (issue 20 §2): the paper
//! device of `tests/data/field_paper.toml` at its factory temperature,
//! self-calibrated by a host whose `[datasheet]` differs from the device.
//!
//! - f1 1.5% low: beyond the narrow-band search's reach, so the host scans
//!   +-5% and zooms in (`identify` module header); the cycle must finish.
//! - Q half the truth: every wait before identification is half as long
//!   as the device needs (after it, the identified Q sets them).
//! - lambda 1% high, with the datasheet's 1% uncertainty on it: the
//!   self-calibrated scale factor moves by about that much, and its
//!   reported sigma must say so.
//!
//! Each must finish (no step in `failed`), identify f1 within 3 of its
//! sigmas of the truth and put the self-calibrated scale factor within 3
//! sigma of the rate table's on both outputs (the promise of a sigma; the
//! error's sigma is the self-calibration's and the rate table's own in
//! quadrature, `selfcal_error_uncertainty`), and within the project's 0.1%
//! where the datasheet's lambda is right. Cost: three single-step scenarios, in parallel (about 2 minutes
//! of CPU, most of it the scans of the first).

mod common;

use common::outputs_within_three_sigma;
use gyrocal_sim::field::probe::DriveProbe;
use gyrocal_sim::field::scenario::{self, FieldReport};

/// The paper scenario at 25 deg C alone, without its profile, with `datasheet`.
fn scenario_with(datasheet: &str) -> scenario::Scenario {
    let path = "tests/data/field_paper.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let mut sc = scenario::parse(path, &format!("{text}\n[datasheet]\n{datasheet}\n")).unwrap();
    sc.drift.temperatures_c = vec![25.0];
    sc.profile = None;
    sc
}

fn check(name: &str, report: &FieldReport, lambda_right: bool) {
    assert!(report.failed.is_empty(), "{name}: {:?}", report.failed);
    let st = &report.steps[0];
    let id = &st.identified;
    let f1 = st.truth.gyro.f1_hz;
    eprintln!(
        "{name}: f1 {:.3} +- {:.3} Hz (truth {f1}), self-cal error {:+.4}% / {:+.4}%, sigma {:.4}% / {:.4}% (with the truth's {:.4}% / {:.4}%)",
        id.f1_hz,
        id.f1_hz_uncertainty,
        100.0 * st.selfcal_error[0],
        100.0 * st.selfcal_error[1],
        100.0 * st.sf_selfcal_uncertainty[0],
        100.0 * st.sf_selfcal_uncertainty[1],
        100.0 * st.selfcal_error_uncertainty[0],
        100.0 * st.selfcal_error_uncertainty[1],
    );
    assert!(
        (id.f1_hz - f1).abs() <= 3.0 * id.f1_hz_uncertainty,
        "{name}: f1 {} +- {} against {f1}",
        id.f1_hz,
        id.f1_hz_uncertainty
    );
    outputs_within_three_sigma(name, st);
    if lambda_right {
        for (k, e) in st.selfcal_error.iter().enumerate() {
            assert!(e.abs() < 1e-3, "{name}: output {}: {e}", k + 1);
        }
    }
}

#[test]
fn a_datasheet_off_by_the_process_spread_is_found_and_its_lambda_budgeted() {
    let cases = [
        ("f1 1.5% low", "f1_hz = 9.4954e6", true),
        ("Q half the truth", "q1 = 27500\nq2 = 27500", true),
        (
            "lambda 1% high, 1% uncertain",
            "angular_gain = 0.606\nangular_gain_uncertainty = 0.01",
            false,
        ),
    ];
    let reports: Vec<FieldReport> = std::thread::scope(|s| {
        let runs: Vec<_> = cases
            .iter()
            .map(|(_, datasheet, _)| {
                s.spawn(|| scenario::run(&scenario_with(datasheet), &|_| {}).unwrap())
            })
            .collect();
        runs.into_iter().map(|r| r.join().unwrap()).collect()
    });
    for ((name, _, lambda_right), report) in cases.iter().zip(&reports) {
        check(name, report, *lambda_right);
    }
    // lambda's term is in the budget: 1% of lambda is at least 1% of the
    // ratio (`selfcal::budget`), so the sigma is at least half that.
    let st = &reports[2].steps[0];
    assert!(
        st.sf_selfcal_uncertainty.iter().all(|&s| s > 0.005),
        "{:?}",
        st.sf_selfcal_uncertainty
    );
}

/// The consumer device of `tests/data/field_consumer.toml` with Q 20,000
/// on both modes and its datasheet's 3000, without its profile: 30 of
/// the datasheet's time constants are 4.5 of the part's.
fn q_far_above_the_datasheets() -> scenario::Scenario {
    let path = "tests/data/field_consumer.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let gyro = "q1 = 3000\nq2 = 3000\n";
    assert!(text.contains(gyro), "{path}: its [gyro] Qs moved");
    let text = text.replacen(gyro, "q1 = 20000\nq2 = 20000\n", 1);
    let text = format!("{text}\n[datasheet]\nq1 = 3000\nq2 = 3000\n");
    let mut sc = scenario::parse(path, &text).unwrap();
    sc.profile = None;
    sc
}

/// The warning that names the datasheet's Q, in one line.
fn names_the_q(report: &FieldReport) {
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("[datasheet] q1 = 3000 is 0.15 times the identified")),
        "{:?}",
        report.warnings
    );
}

/// A part whose Q is far above its datasheet's
/// ([`q_far_above_the_datasheets`]) at 25 deg C. The cycle finds the Q
/// and says so in one line, and every wait after identification is the
/// identified modes'. The truth must settle on the part too: its rate
/// table had waited 30 of the datasheet's time constants and read output
/// 1 0.33% off the self-calibrated figure at 4.7 of the two sigmas (1.1%
/// on another run of the same part, whose cycle had stopped earlier);
/// `scenario::settle_clocks_at` now waits on the part. Asserted: the
/// step finishes, the warning names Q1, f1 within 3 sigma, and both
/// outputs within 3 sigma and 0.1% of the truth. About 5 s.
#[test]
fn a_q_far_above_the_datasheets_is_found_and_its_truth_settled() {
    let mut sc = q_far_above_the_datasheets();
    sc.drift.temperatures_c = vec![25.0];
    let report = scenario::run(&sc, &|_| {}).unwrap();
    names_the_q(&report);
    check("Q 20,000 against the datasheet's 3000", &report, true);
}

/// The same part probed while it turns (`[drive_probe]`, 100 deg/s) at 25
/// and 35 deg C, its drive gains drifting apart by 2% over the 10 K. The
/// probe's windows waited on the datasheet's time constants, so it read
/// the turn at 34 deg/s instead of 100 and both steps failed, the error
/// line blaming a damping coupling the part does not have; it now waits
/// on the identified modes, as the cycle does. Asserted: both steps
/// finish, each measured ratio within 3 of its sigma of the truth, each
/// output within 3 sigma of the truth. About 10 s.
#[test]
fn a_q_far_above_the_datasheets_is_probed_on_the_identified_modes() {
    let mut sc = q_far_above_the_datasheets();
    sc.drift.temperatures_c = vec![25.0, 35.0];
    sc.drift.drive_gain_ppm_per_k = [1e3, -1e3];
    sc.drive_probe = Some(DriveProbe { rate_dps: 100.0 });
    let report = scenario::run(&sc, &|_| {}).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    names_the_q(&report);
    for s in &report.steps {
        let m = s.selfcal.drive_ratio.as_ref().expect("probed");
        let t = (m.relative.value - s.drive_gain_ratio_true) / m.relative.uncertainty;
        assert!(
            t.abs() <= 3.0,
            "{} deg C: g2/g1 at {t:.2} sigma",
            s.temperature_c
        );
        outputs_within_three_sigma(&format!("{} deg C", s.temperature_c), s);
    }
}
