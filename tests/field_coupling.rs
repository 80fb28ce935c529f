//! A device with a quadrature coupling its datasheet does not give (issue
//! 22 section 2): the host measures the coupling at rest in every cycle
//! (`gyrocal_host::coupling`), removes it from the identified modes and
//! predicts with it. `tests/data/field_coupled.toml`: the consumer device
//! with 250 deg/s at 25 deg C, +0.5 deg/s per K, over 5..60 deg C, its
//! drive gains parting by 600 ppm/K (up to 2% apart). At rest the coupling
//! also makes the drive-gain ratio observable (`drive_ratio::from_windows`):
//! the cycle measures and applies it.
//!
//! Asserted at every step, and why each can fail:
//! - the identified coupling within 3 of its sigma of the truth, and that
//!   sigma below 1 deg/s (a sign or unit error in the estimator puts it
//!   hundreds of deg/s off; measured: within 0.02 deg/s, sigma 0.01);
//! - the rate output's (output 2's) self-calibrated scale factor within
//!   0.1% of the rate table, and every figure within 3 of its sigma
//!   (before the modes were uncoupled, output 2 was 1.5% off at 6.6
//!   sigma: each mode's fit sees the other through the coupling, 4e-4 Hz
//!   on f1, which the detuned output feels);
//! - the coupling matters: predicted without it, output 2's ratio moves by
//!   more than 0.1% (so this device tests the correction);
//! - the drive-gain ratio measured at rest within 3 of its sigma of the
//!   truth (measured: within 1.6), and away from 25 deg C the design
//!   ratio would have left output 2 more than 0.1% off (0.6% to 2.0%).

mod common;

use gyrocal_host::selfcal::predicted_ratio;
use gyrocal_sim::field::probe::DriveProbe;
use gyrocal_sim::field::scenario::{self, Scenario};

/// The scenario of `tests/data/field_coupled.toml`.
fn coupled() -> Scenario {
    let path = "tests/data/field_coupled.toml";
    let text = std::fs::read_to_string(path).unwrap();
    scenario::parse(path, &text).unwrap()
}

#[test]
fn a_coupled_device_self_calibrates_from_5_to_60_deg_c() {
    let sc = coupled();
    let report = scenario::run(&sc, &|line| eprintln!("{line}")).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    assert_eq!(report.steps.len(), 6);
    let knowns = &report.knowns;
    for s in &report.steps {
        let id = &s.identified;
        let truth = s.truth.gyro.quadrature_dps;
        let t: Vec<f64> = (0..2)
            .map(|k| s.selfcal_error[k] / s.selfcal_error_uncertainty[k])
            .collect();
        let ratio = s
            .selfcal
            .drive_ratio
            .as_ref()
            .expect("a ratio at rest")
            .relative;
        let mut gyro = s.selfcal.identified.gyro(&knowns.nominal);
        gyro.quadrature_dps = 0.0;
        let mut measured_gains = knowns.clone();
        measured_gains.force_full_scale[1] *= ratio.value;
        let op = &s.selfcal.operating;
        let without = predicted_ratio(&measured_gains, &gyro, op, &s.selfcal.cal_hz)
            .unwrap()
            .exact;
        let moved = without[1] / s.selfcal.ratio.exact[1] - 1.0;
        eprintln!(
            "{} deg C: coupling {:.3} +- {:.3} deg/s (true {truth:.3}), self-cal error {:+.4}% / {:+.4}% (t {:+.2} / {:+.2}), output 2 without the coupling {:+.3}%",
            s.temperature_c,
            id.quadrature_dps,
            id.quadrature_dps_uncertainty,
            100.0 * s.selfcal_error[0],
            100.0 * s.selfcal_error[1],
            t[0],
            t[1],
            100.0 * moved
        );
        assert!(id.quadrature_dps_uncertainty < 1.0);
        assert!((id.quadrature_dps - truth).abs() <= 3.0 * id.quadrature_dps_uncertainty);
        assert!(s.selfcal_error[1].abs() < 1e-3);
        assert!(t.iter().all(|t| t.abs() <= 3.0), "{t:?}");
        assert!(moved.abs() > 1e-3, "{moved}");
        let design = s.selfcal.sf_design_ratio_per_dps[1] / s.sf_true_per_dps[1] - 1.0;
        eprintln!(
            "  g2/g1 over design {:.6} +- {:.1e} (truth {:.6}); at the design ratio output 2 {:+.3}%",
            ratio.value,
            ratio.uncertainty,
            s.drive_gain_ratio_true,
            100.0 * design
        );
        assert!((ratio.value - s.drive_gain_ratio_true).abs() <= 3.0 * ratio.uncertainty);
        if s.temperature_c != 25.0 {
            assert!(design.abs() > 1e-3, "{design}");
        }
    }
}

/// The coupling in deg/s is the stiffness the host measures turned with
/// the datasheet's lambda (`gyrocal_host::identify::CouplingFigure`): a
/// lambda 4% high puts the figure 4% low, 10 deg/s at 250, where the
/// measurement's sigma is some 0.016 deg/s. With the datasheet saying 4%,
/// the figure's sigma carries 4% of the value, and the error lies within 3
/// of it (measured: 240.397 +- 9.616 at 25 deg C; without that term it lay
/// 600 of the measurement's sigmas off).
/// The prediction turns the figure back with the same lambda, so lambda's
/// error does not move it: the scale factors' budget moves the coupling by
/// the measurement's sigma alone, which stays below 1 deg/s, while
/// lambda's own term (4% of the ratio, `budget::angular_gain`) covers
/// their error.
#[test]
fn a_datasheet_lambda_off_is_in_the_coupling_figures_sigma() {
    let path = "tests/data/field_coupled.toml";
    let text = std::fs::read_to_string(path).unwrap().replace(
        "[datasheet]\n",
        "[datasheet]\nangular_gain = 0.832\nangular_gain_uncertainty = 0.04\n",
    );
    let mut sc = scenario::parse(path, &text).unwrap();
    sc.drift.temperatures_c = vec![25.0, 60.0];
    let report = scenario::run(&sc, &|_| {}).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    for s in &report.steps {
        let id = &s.identified;
        let figure = s.selfcal.identified.quadrature_dps.unwrap();
        let truth = s.truth.gyro.quadrature_dps;
        eprintln!(
            "{} deg C: coupling {:.3} +- {:.3} deg/s (measurement {:.3}; true {truth:.3}), self-cal error {:+.4}% / {:+.4}% at {:.4}% / {:.4}%",
            s.temperature_c,
            id.quadrature_dps,
            id.quadrature_dps_uncertainty,
            figure.measurement_uncertainty,
            100.0 * s.selfcal_error[0],
            100.0 * s.selfcal_error[1],
            100.0 * s.selfcal_error_uncertainty[0],
            100.0 * s.selfcal_error_uncertainty[1],
        );
        assert!(
            (id.quadrature_dps - truth).abs() <= 3.0 * id.quadrature_dps_uncertainty,
            "{} deg C",
            s.temperature_c
        );
        assert!(id.quadrature_dps_uncertainty >= 0.04 * id.quadrature_dps.abs());
        assert!(figure.measurement_uncertainty < 1.0);
        common::outputs_within_three_sigma(&format!("{} deg C", s.temperature_c), s);
    }
}

/// While the coupled device turns (`[drive_probe]`, 200 deg/s), the
/// measurement's identity picks up -(k - c) / (k + c), which moves its
/// phase (about 50 deg here) but not its magnitude
/// (`drive_ratio::from_windows`): the ratio measured while turning, which
/// replaces the one at rest, is within 3 of its sigma of the truth
/// (measured: within 0.9), and the rate output stays within 0.1%.
#[test]
fn the_drive_gain_ratio_measured_while_turning_holds_with_a_coupling() {
    let mut sc = coupled();
    sc.drift.temperatures_c = vec![25.0, 5.0, 60.0];
    sc.drive_probe = Some(DriveProbe { rate_dps: 200.0 });
    let report = scenario::run(&sc, &|_| {}).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    for s in &report.steps {
        let m = s.selfcal.drive_ratio.as_ref().unwrap();
        eprintln!(
            "{} deg C: g2/g1 over design {:.6} +- {:.1e} (truth {:.6}), phase {:+.2} deg; self-cal error {:+.4}% / {:+.4}%",
            s.temperature_c,
            m.relative.value,
            m.relative.uncertainty,
            s.drive_gain_ratio_true,
            m.phase_deg.value,
            100.0 * s.selfcal_error[0],
            100.0 * s.selfcal_error[1]
        );
        assert!((m.relative.value - s.drive_gain_ratio_true).abs() <= 3.0 * m.relative.uncertainty);
        assert!(s.selfcal_error[1].abs() < 1e-3);
    }
}

/// With a damping coupling the identity's factor -(kappa - c) / (kappa +
/// c) has a magnitude other than 1, which moves with the probe's rate
/// (`drive_ratio::turning_factor`), so `[drive_probe]` reads the rate
/// from its own windows and takes the factor out (`drive_ratio::measure`).
/// Two cases: the coupled device's 250 deg/s of stiffness with -200 deg/s
/// of damping coupling probed at 200 deg/s (a factor of about 0.53), and
/// the same device with no stiffness and 4.4 deg/s of damping probed at
/// -24.5 deg/s (as a random device that read 0.972 for 1, 421 sigma off,
/// when the factor was taken at the cycle's rate, 0), each at 25 and 60
/// deg C, where the drives part by 2.1%: the ratio within 3 of its sigma
/// of the truth, every self-calibrated scale factor within 3 of its.
#[test]
fn a_drive_probe_takes_a_damping_couplings_turning_out() {
    let mut worst = 0.0;
    for (stiffness, damping, rate) in [(250.0, -200.0, 200.0), (0.0, 4.4, -24.5)] {
        let mut sc = coupled();
        sc.exp.gyro.quadrature_dps = stiffness;
        sc.exp.gyro.damping_coupling_dps = damping;
        sc.drift.temperatures_c = vec![25.0, 60.0];
        sc.drive_probe = Some(DriveProbe { rate_dps: rate });
        let report = scenario::run(&sc, &|_| {}).unwrap();
        assert!(report.failed.is_empty(), "{:?}", report.failed);
        for s in &report.steps {
            let m = s.selfcal.drive_ratio.as_ref().unwrap();
            let t = (m.relative.value - s.drive_gain_ratio_true) / m.relative.uncertainty;
            let sf_t = [0, 1].map(|k| s.selfcal_error[k] / s.selfcal_error_uncertainty[k]);
            eprintln!(
                "{stiffness} + j {damping} deg/s at {rate} deg/s, {} deg C: g2/g1 {:.6} +- {:.1e} (truth {:.6}, t {t:+.2}); self-cal t {:+.2} / {:+.2}",
                s.temperature_c,
                m.relative.value,
                m.relative.uncertainty,
                s.drive_gain_ratio_true,
                sf_t[0],
                sf_t[1]
            );
            worst = [t, sf_t[0], sf_t[1]]
                .iter()
                .fold(worst, |w: f64, t| w.max(t.abs()));
        }
    }
    assert!(worst <= 3.0, "a figure at {worst:.2} sigma");
}

/// A probe near the damping coupling's own rate. The probe's rounds (its
/// ratio, the rate read again at it, `drive_ratio::settled`) swing
/// without end there, and after 64 rounds the last ratio was taken as the
/// figure: the device with 4.4 deg/s of damping coupling probed at 5
/// deg/s read g2/g1 0.44 for 1 at 25 deg C (27 sigma), its scale factors
/// 22 and 24 of their sigmas off, and nothing was said. Nearer still the
/// rounds can settle on a second root, where the rate read at that ratio
/// is 0 and nothing is taken out: a random device with -2.30 deg/s of
/// coupling probed at -2.19 read 0.17 for 1, 38 sigma off. Now the step
/// at 25 deg C fails with one line naming the probe's rate and the
/// coupling, keeping its identification: rounds that do not settle, or
/// a root whose rate is not seen, though the probe turned. The step at
/// 60 deg C (17.5 deg/s of stiffness coupling by then) stands within 3 of
/// its sigmas.
#[test]
fn a_probe_near_the_damping_couplings_rate_fails_in_one_line() {
    for (damping, rate, says) in [
        (
            4.4,
            5.0,
            "drive-gain ratio: [drive_probe]'s rounds did not settle",
        ),
        (
            -2.3,
            -2.19,
            "drive-gain ratio: [drive_probe]'s rounds settled on g2/g1 0.1",
        ),
    ] {
        let mut sc = coupled();
        sc.exp.gyro.quadrature_dps = 0.0;
        sc.exp.gyro.damping_coupling_dps = damping;
        sc.drift.temperatures_c = vec![25.0, 60.0];
        sc.drive_probe = Some(DriveProbe { rate_dps: rate });
        let report = scenario::run(&sc, &|_| {}).unwrap();
        let [failed] = &report.failed[..] else {
            panic!("{rate} deg/s: one step fails: {:?}", report.failed);
        };
        eprintln!("{} deg C: {}", failed.temperature_c, failed.error);
        assert_eq!(failed.temperature_c, 25.0);
        assert!(failed.identified.is_some(), "the identification is kept");
        assert!(failed.error.contains(says), "{}", failed.error);
        let coupling = format!("the damping coupling, read {}", &damping.to_string()[..3]);
        assert!(failed.error.contains(&coupling), "{}", failed.error);
        assert!(!failed.error.contains('\n'));
        for s in &report.steps {
            let m = s.selfcal.drive_ratio.as_ref().unwrap();
            let t = (m.relative.value - s.drive_gain_ratio_true) / m.relative.uncertainty;
            let at = s.temperature_c;
            assert!(
                t.abs() <= 3.0,
                "{rate} deg/s at {at} deg C: g2/g1 at {t:.2} sigma"
            );
            for k in 0..2 {
                let sf_t = s.selfcal_error[k] / s.selfcal_error_uncertainty[k];
                assert!(sf_t.abs() <= 3.0, "output {}: {sf_t:.2} sigma", k + 1);
            }
        }
    }
}

/// The couplings and the rate the cycle read at rest, at the design ratio,
/// are read again at the ratio `[drive_probe]` measures
/// (`selfcal::apply_drive_ratio`): where the drives part, a damping
/// coupling reads as a rate -b d. A random device (seed 602's third of
/// `scripts/coverage/drive_probe.py`: 31.8 kHz, f2 377 Hz above, Q 6662 /
/// 822, 4.72 deg/s of damping coupling, drives parting by 953 ppm/K each
/// way, probed at 76.4 deg/s) read that rate, 0.09 deg/s, beyond 5 of its
/// sigmas at 35 deg C, the calibration was predicted at it, and output 2
/// came out +0.18%, 4.4 sigma; read again, every figure within 3 sigma.
#[test]
fn a_drive_probe_reads_the_couplings_again_at_its_ratio() {
    let text = "[gyro]\nf1_hz = 31847.569\nf2_hz = 32224.598\nq1 = 6661.5\nq2 = 822.3\n\
        angular_gain = 0.7353\nquadrature_dps = 0\ndamping_coupling_dps = 4.721\n\
        [drive]\ncarrier_hz = 31847.569\nclock_hz = 1441065.7\n\
        [experiment]\nreadout_rates_dps = [50, 150, 300]\ncal_freqs_hz = [3, 5, 8]\n\
        [drift]\ntemperatures_c = [25, 35]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n\
        drive_gain_ppm_per_k = [953.1, -953.1]\n[drive_probe]\nrate_dps = 76.415\n";
    let sc = scenario::parse("probe.toml", text).unwrap();
    let report = scenario::run(&sc, &|_| {}).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    for s in &report.steps {
        let m = s.selfcal.drive_ratio.as_ref().unwrap();
        let t = [0, 1].map(|k| s.selfcal_error[k] / s.selfcal_error_uncertainty[k]);
        eprintln!(
            "{} deg C: g2/g1 {:.6} +- {:.1e} (truth {:.6}); predicted at {} deg/s; self-cal t {:+.2} / {:+.2}",
            s.temperature_c,
            m.relative.value,
            m.relative.uncertainty,
            s.drive_gain_ratio_true,
            s.selfcal.operating.cycle_rate_dps,
            t[0],
            t[1]
        );
        assert!((m.relative.value - s.drive_gain_ratio_true).abs() <= 3.0 * m.relative.uncertainty);
        assert!(t.iter().all(|t| t.abs() <= 3.0), "{t:?}");
    }
}

/// Where the correction stops: a coupling so strong that the modes mix
/// (`coupling::MAX_MIXING`; 4,000 deg/s on this device, where the
/// self-calibration was 2.9 sigma off) is a step that fails with one line
/// naming the coupling, not a figure.
#[test]
fn a_coupling_too_strong_to_separate_is_a_one_line_failure() {
    let mut sc = coupled();
    sc.exp.gyro.quadrature_dps = 4000.0;
    sc.drift.temperatures_c = vec![25.0];
    let report = scenario::run(&sc, &|_| {}).unwrap();
    assert!(report.steps.is_empty());
    let error = &report.failed[0].error;
    eprintln!("{error}");
    assert!(error.contains("couples the modes too strongly"), "{error}");
    assert!(!error.contains('\n'));
}

/// A damping coupling (`[gyro] damping_coupling_dps`, symmetric, in phase
/// with the Coriolis force) is the imaginary part of the same estimate:
/// with -200 deg/s of it beside the 250 of stiffness, both are found
/// within 3 of their sigmas (measured: -200.018 +- 0.007 and -199.978 +-
/// 0.012) and every self-calibrated figure lies within 3 of its sigma. On
/// the device without one (the first test) the estimate is taken as none
/// (`selfcal::DAMPING_SEEN`).
#[test]
fn a_damping_coupling_is_measured_with_it() {
    let mut sc = coupled();
    sc.exp.gyro.damping_coupling_dps = -200.0;
    sc.drift.temperatures_c = vec![25.0, 60.0];
    let report = scenario::run(&sc, &|_| {}).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    for s in &report.steps {
        let id = &s.identified;
        eprintln!(
            "{} deg C: damping coupling {:.3} +- {:.3} deg/s, quadrature {:.3} +- {:.3}; self-cal error {:+.4}% / {:+.4}%",
            s.temperature_c,
            id.damping_coupling_dps,
            id.damping_coupling_dps_uncertainty,
            id.quadrature_dps,
            id.quadrature_dps_uncertainty,
            100.0 * s.selfcal_error[0],
            100.0 * s.selfcal_error[1]
        );
        let truth = &s.truth.gyro;
        assert!(
            (id.damping_coupling_dps - truth.damping_coupling_dps).abs()
                <= 3.0 * id.damping_coupling_dps_uncertainty
        );
        assert!(
            (id.quadrature_dps - truth.quadrature_dps).abs() <= 3.0 * id.quadrature_dps_uncertainty
        );
        common::outputs_within_three_sigma(&format!("{} deg C", s.temperature_c), s);
    }
}

/// The same drives parting by 600 ppm/K on the device without a coupling:
/// at rest the ratio is not observable, there is no `[drive_probe]`, and
/// the cycle predicts at the design ratio. The datasheet bounds the
/// ratio's error in the field (`drive_gain_ratio_uncertainty`, 1%: the
/// drives part by 1.2% at 5 deg C and 2.1% at 60), and that term carries
/// the error: every figure within 3 of its sigma. Without it the sigma
/// would not cover: at 60 deg C output 2 is 2.05% off against 0.35% from
/// the other terms (5.8 of them).
#[test]
fn an_unmeasured_drive_gain_ratio_is_in_the_sigma_the_datasheet_gives() {
    let path = "tests/data/field_coupled.toml";
    let text = std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with("quadrature_dps"))
        .map(|l| match l {
            "[datasheet]" => "[datasheet]\ndrive_gain_ratio_uncertainty = 0.01".to_string(),
            l if l.starts_with("temperatures_c") => "temperatures_c = [25, 5, 60]".into(),
            l => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    let sc = scenario::parse(path, &text).unwrap();
    let report = scenario::run(&sc, &|line| eprintln!("{line}")).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    let mut uncovered = 0;
    for s in &report.steps {
        assert!(s.selfcal.drive_ratio.is_none(), "no ratio is observable");
        let u = &s.selfcal.sf_selfcal_uncertainty;
        for k in 0..2 {
            let e = s.selfcal_error[k];
            let sigma = s.selfcal_error_uncertainty[k];
            let others = [u.staircase[k], u.identified[k], u.angular_gain[k]]
                .into_iter()
                .fold(s.sf_true_uncertainty[k], f64::hypot);
            eprintln!(
                "{} deg C output {}: error {:+.4}%, sigma {:.4}% ({:.4}% without the ratio's term)",
                s.temperature_c,
                k + 1,
                100.0 * e,
                100.0 * sigma,
                100.0 * others
            );
            assert!(e.abs() <= 3.0 * sigma, "{e} at sigma {sigma}");
            uncovered += usize::from(e.abs() > 3.0 * others);
        }
    }
    assert!(uncovered > 0, "the drives' drift must matter here");
}
