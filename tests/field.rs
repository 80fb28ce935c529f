//! The self-calibration cycle over temperature: the self-calibrated scale
//! factor against the rate table of the same simulation, and the
//! factory-calibrated baseline beside it.

use gyrocal_hdl::model::gyro_interface::CarrierProfile;
use gyrocal_host::selfcal;
use gyrocal_sim::drift::Drift;
use gyrocal_sim::field::probe::DriveProbe;
use gyrocal_sim::field::scenario::{self, FieldReport, Scenario};
use gyrocal_sim::noise::ThermalNoise;
use gyrocal_sim::rate_noise;

fn run(path: &str) -> FieldReport {
    let text = std::fs::read_to_string(path).unwrap();
    let sc = scenario::parse(path, &text).unwrap();
    finished(&sc)
}

/// The scenario's report, every step of which finished.
fn finished(sc: &Scenario) -> FieldReport {
    let report = scenario::run(sc, &|line| eprintln!("{line}")).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    report
}

/// The consumer device of `tests/data/field_consumer.toml` with its
/// `[drift]` replaced by `drift`.
fn run_consumer(drift: Drift) -> FieldReport {
    let path = "tests/data/field_consumer.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let mut sc = scenario::parse(path, &text).unwrap();
    sc.drift = drift;
    sc.profile = None;
    finished(&sc)
}

/// No drift but the converters' gains (ppm/K), from 25 to 35 deg C.
fn gains_only(adc: [f64; 2], drive: [f64; 2]) -> Drift {
    Drift {
        temperatures_c: vec![25.0, 35.0],
        tcf1_ppm_per_k: 0.0,
        tcf2_ppm_per_k: 0.0,
        q_ppm_per_k: 0.0,
        front_end_phase_deg: 0.0,
        front_end_phase_deg_per_k: 0.0,
        adc_gain_ppm_per_k: adc,
        drive_gain_ppm_per_k: drive,
        quadrature_dps_per_k: 0.0,
    }
}

/// Every step's self-calibrated scale factor within 0.1% of the rate
/// table's (the target).
fn assert_within_target(report: &FieldReport) {
    for s in &report.steps {
        for k in 0..2 {
            assert!(
                s.selfcal_error[k].abs() < 1e-3,
                "{} deg C output {}: {}",
                s.temperature_c,
                k + 1,
                s.selfcal_error[k]
            );
        }
    }
}

#[test]
fn consumer_and_high_q_devices_self_calibrate_over_ten_kelvin() {
    let report = run("tests/data/field_consumer.toml");
    assert_within_target(&report);
    assert_rate_output_tracks_temperature(&report);
    // The high-Q device at its extremes and T0 only: its identification
    // waits 12 of its 19 ms time constants per carrier on a 20.3 MHz clock
    // (240 M clocks a step); `gyrocal field --config
    // tests/data/field_highq.toml` runs all five steps.
    let path = "tests/data/field_highq.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let mut sc = scenario::parse(path, &text).unwrap();
    sc.drift.temperatures_c = vec![25.0, 15.0, 35.0];
    let report = finished(&sc);
    assert_within_target(&report);
}

/// The calibrated rate output under the profile. At T0 the self-calibrated
/// and the baseline outputs read the same z (their scale factors differ by
/// the self-calibration's error); what is left of their error
/// there is the device's (the readout's curvature against the line fitted
/// over the readout rates, the output's lag on a ramp), not the
/// calibration's. Elsewhere the self-calibrated output must keep that
/// error (its scale factor moves by < 0.1% and its null is measured
/// again: within 25% of T0's RMS on the rate output, the output whose
/// scale factor is largest), while the baseline's grows by orders of
/// magnitude (a fixed null on an output whose offset moves with the
/// detuning).
fn assert_rate_output_tracks_temperature(report: &FieldReport) {
    let sf = report.sf_factory_per_dps.expect("the factory calibration");
    let k = usize::from(sf[1].abs() > sf[0].abs());
    let at_t0 = report.steps[0].profile.as_ref().unwrap();
    let reference = at_t0.selfcal_rms_error_dps[k];
    for s in &report.steps[1..] {
        let trace = s.profile.as_ref().unwrap();
        let (own, base) = (
            trace.selfcal_rms_error_dps[k],
            trace.baseline_rms_error_dps.expect("a baseline")[k],
        );
        eprintln!(
            "{} deg C output {}: rate RMS error self-cal {own:.4} deg/s, baseline {base:.4e} deg/s (T0 {reference:.4})",
            s.temperature_c,
            k + 1
        );
        assert!((own / reference - 1.0).abs() < 0.25, "{own} vs {reference}");
        assert!(base > 100.0 * reference, "{base}");
    }
}

/// ADC gains and a common drive gain cancel exactly in the ratio
/// (`selfcal` module header): at 35 deg C the ADCs are up 10% and the
/// drives down 10% (the ADC stays below full scale), so every signal is
/// 0.99 of the plain run's, with the same noise seed.
///
/// The model is linear up to the converters' rounding: the gyroscope's
/// response scales with the drive gain, the ADC's input with both, and the
/// ADC adds the same noise samples in both runs. What differs is the ADC's
/// rounding error, re-drawn when the level moves. On the self-calibration
/// (the staircase's window means, 6e5 to 1e8 z LSB, and the identification
/// behind the predicted ratio) that is far below 0.01%: SF_selfcal / level
/// must move by less than 1e-4 (measured: 5e-7 and 3.4e-6).
///
/// The truth, the rate table, is another matter on output 1: its rate term
/// is 189 z LSB per deg/s on an offset of 1e8 (the resonant drive mode at
/// full scale), a change far below one ADC LSB per sample from one rate
/// to the next, where the rounding's error, with 1 LSB of dither, is some
/// 1e-4 of that slope and moves with any change of level (measured by
/// `rounding_moves_the_resonant_outputs_rate_table`: 5e-5 to 9e-4 over
/// levels 0.5 to 0.99, 6e-4 to 7e-3 without dither; output 2, whose rate
/// term is larger, 1e-4). So the
/// self-calibration error (against that truth) may move by that much; it
/// must stay within the 0.1% target.
#[test]
fn adc_and_common_drive_gains_cancel() {
    let plain = run_consumer(gains_only([0.0; 2], [0.0; 2]));
    let gains = run_consumer(gains_only([1e4, 1e4], [-1e4, -1e4]));
    assert_within_target(&gains);
    let (a, b) = (&plain.steps[1], &gains.steps[1]);
    for k in 0..2 {
        let level = b.truth.adc_gain[k] * b.truth.drive_gain[k];
        let moved = |x: [f64; 2], y: [f64; 2]| y[k] / (x[k] * level) - 1.0;
        let selfcal = moved(a.sf_selfcal_per_dps, b.sf_selfcal_per_dps);
        let cal = moved(a.selfcal.sf_cal_per_dps, b.selfcal.sf_cal_per_dps);
        let ratio = b.selfcal.ratio.exact[k] / a.selfcal.ratio.exact[k] - 1.0;
        let truth = moved(a.sf_true_per_dps, b.sf_true_per_dps);
        eprintln!(
            "output {}: level {level}, SF_selfcal / level moved {selfcal:+.2e} (SF_cal {cal:+.2e}, \
             ratio {ratio:+.2e}), rate table / level moved {truth:+.2e}",
            k + 1
        );
        assert!(selfcal.abs() < 1e-4, "{selfcal}");
        assert!(truth.abs() < 1e-3, "{truth}");
    }
}

/// The rate table's slope over the ADC level (module note above
/// `adc_and_common_drive_gains_cancel`), with the plain run's carrier and
/// zero phase correction on every run: with and without the 1 LSB dither.
/// A measurement, printed: `cargo test --release --test field --
/// --ignored --nocapture rounding`.
#[test]
#[ignore]
fn rounding_moves_the_resonant_outputs_rate_table() {
    let path = "tests/data/field_consumer.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let mut sc = scenario::parse(path, &text).unwrap();
    for noise in [1.0, 0.0] {
        sc.exp.frontend.noise_lsb = noise;
        let (fe, knowns) = scenario::build(&sc.exp).unwrap();
        let mut at = gains_only([0.0; 2], [0.0; 2]).at(&sc.exp.gyro, 25.0);
        let op = selfcal::Operating {
            carrier_hz: sc.exp.drive.carrier_hz,
            ref_lag_deg: 0.0,
            envelope_delay_s: 0.0,
            amplitude: knowns.amplitude,
            fold_shift_hz: 0.0,
            static_fold: None,
            spur_move: None,
            scaled_drives: None,
            cycle_rate_dps: 0.0,
        };
        let sf0 = scenario::rate_table(&sc.exp, &fe, &at, &knowns, &op, None)
            .unwrap()
            .0
            .sf_per_dps;
        for level in [0.99, 0.98, 0.9, 0.5] {
            at.adc_gain = [level; 2];
            let sf = scenario::rate_table(&sc.exp, &fe, &at, &knowns, &op, None)
                .unwrap()
                .0
                .sf_per_dps;
            eprintln!(
                "dither {noise} LSB, level {level}: rate table / level moved {:+.2e} / {:+.2e}",
                sf[0] / (level * sf0[0]) - 1.0,
                sf[1] / (level * sf0[1]) - 1.0
            );
        }
    }
}

/// A differential drive gain (+-1% at +-10 K) on the consumer device.
///
/// At rest it is not observable, and the cycle's prediction at the design
/// force ratio carries it as the exact theory says: one for one on the
/// linear rate term (ratio_k carries g_(1-k) / g_k), but the fitted slope
/// over rates that are not symmetric about 0 also holds the quadratic
/// term, which scales with the other drive (on this device output 2 moves
/// -1.98% for +-1%, output 1 only +0.1%). That error must match the
/// theory with the true gains to within the self-calibration's own 0.1%.
///
/// While the device turns at 200 deg/s (`[drive_probe]`), the host
/// measures g2 / g1 (`drive_ratio`) and predicts again with it:
/// - the measured ratio is within 5 of its standard errors of the truth
///   (a t with 7 degrees of freedom exceeds 5 with probability 0.0016), and
///   its phase, zero for gains that differ in size only, likewise;
/// - the corrected scale factors are within the 0.1% target at every step,
///   where the design ratio's are off by more than 1% at +-10 K.
#[test]
fn a_differential_drive_gain_is_measured_while_turning_and_corrected() {
    let path = "tests/data/field_consumer.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let mut sc = scenario::parse(path, &text).unwrap();
    sc.drift = gains_only([0.0; 2], [1e3, -1e3]);
    sc.drift.temperatures_c = vec![25.0, 35.0, 15.0];
    sc.profile = None;
    sc.drive_probe = Some(DriveProbe { rate_dps: 200.0 });
    let report = finished(&sc);
    for s in &report.steps {
        let m = s.selfcal.drive_ratio.as_ref().unwrap();
        let sigmas = (m.relative.value - s.drive_gain_ratio_true) / m.relative.uncertainty;
        let design_error: [f64; 2] = std::array::from_fn(|k| {
            s.selfcal.sf_design_ratio_per_dps[k] / s.sf_true_per_dps[k] - 1.0
        });
        eprintln!(
            "{} deg C: g2/g1 over design {:.6} +- {:.1e} (truth {:.6}, {sigmas:+.2} sigma), \
             phase {:+.4} +- {:.4} deg, cross/direct {:.3e}; self-cal error {:+.3e} / {:+.3e}, \
             at the design ratio {:+.3e} / {:+.3e}; SF uncertainty from the ratio {:.1e} / {:.1e}",
            s.temperature_c,
            m.relative.value,
            m.relative.uncertainty,
            s.drive_gain_ratio_true,
            m.phase_deg.value,
            m.phase_deg.uncertainty,
            m.cross_over_direct,
            s.selfcal_error[0],
            s.selfcal_error[1],
            design_error[0],
            design_error[1],
            s.selfcal.sf_selfcal_uncertainty.drive_ratio[0],
            s.selfcal.sf_selfcal_uncertainty.drive_ratio[1],
        );
        // The promise of every sigma: the error within 3 of them. Here at
        // most 0.82 (25 deg C); 2.5 (35 deg C) while the host took the
        // table core's drive-1 word at 1/8 amplitude as the exact product,
        // a bias of some -8e-5 of which some -3e-5 is left, not traced
        // (docs/field.md).
        assert!(sigmas.abs() < 3.0, "{sigmas}");
        assert!(m.phase_deg.value.abs() < 5.0 * m.phase_deg.uncertainty);
        // At the design ratio: the theory's error with the true gains.
        let op = &s.selfcal.operating;
        let gyro = s.selfcal.identified.gyro(&report.knowns.nominal);
        let cal_hz = &s.selfcal.cal_hz;
        let design = selfcal::predicted_ratio(&report.knowns, &gyro, op, cal_hz).unwrap();
        let mut true_gains = report.knowns.clone();
        for k in 0..2 {
            true_gains.force_full_scale[k] *= s.truth.drive_gain[k];
        }
        let truth = selfcal::predicted_ratio(&true_gains, &gyro, op, cal_hz).unwrap();
        for (k, error) in design_error.iter().enumerate() {
            let want = design.exact[k] / truth.exact[k] - 1.0;
            assert!(
                (error - want).abs() < 1e-3,
                "output {}: {error} vs {want}",
                k + 1
            );
        }
        if s.temperature_c != 25.0 {
            assert!(design_error[1].abs() > 1e-2, "{design_error:?}");
        }
    }
    assert_within_target(&report);
}

/// Issue 20 section 3's goal: at every step the calibrated rate's RMS
/// error under the profile is within twice the quietest step's, on both
/// outputs. The paper device's carrier folds in the passband at two
/// steps. At 25 deg C the operating point moves the carrier 0.81 Hz out of
/// its fold at 4.8 Hz (period 1250), which had rippled the rate by 0.46 /
/// 0.19 deg/s; it is at the floor now (0.065 / 0.020). At 30 deg C the
/// move out of the fold at 18.2 Hz (period 83) would change the scale
/// factors by 45% (`gyrocal_host::selfcal::FOLD_SF_CHANGE`), so on the
/// table core the carrier moves -1.09 Hz, to where the bound on its
/// table spurs' ripple is lowest within the allowance (the fold 109 Hz
/// away, most of its lines through the filter's skirt), and the rate is
/// at 0.049 / 0.031 deg/s: 0.75 and 1.57 times the quietest step's. It
/// was 0.158 / 0.088 with the carrier moved only until the fold beat four
/// times a window, and 0.251 / 0.140 with the carrier at 18.2 Hz. The
/// largest ratio over the five steps is 1.59 on output 1 (35 deg C
/// against 30) and 1.57 on output 2. A step whose fold lies in the band
/// still names it (`carrier_fold`).
fn assert_every_step_within_twice_the_floor(report: &FieldReport) {
    for k in 0..2 {
        let rms = |s: &scenario::FieldStep| s.profile.as_ref().unwrap().selfcal_rms_error_dps[k];
        let floor = report.steps.iter().map(rms).fold(f64::INFINITY, f64::min);
        for s in &report.steps {
            let f = s.carrier_fold;
            eprintln!(
                "{} deg C output {}: rate RMS error {:.3} deg/s ({:.2} times the floor {floor:.3}), fold {:.1} Hz (period {})",
                s.temperature_c,
                k + 1,
                rms(s),
                rms(s) / floor,
                f.offset_hz,
                f.period
            );
            assert!(rms(s) <= 2.0 * floor, "{} deg C", s.temperature_c);
            assert_eq!(f.clause().is_some(), f.in_passband);
        }
    }
}

#[test]
fn paper_device_self_calibrates_over_ten_kelvin() {
    let report = run("tests/data/field_paper.toml");
    for s in &report.steps {
        eprintln!(
            "{} deg C: self-cal error {:?} (1-sigma {:?}), baseline error {:?}",
            s.temperature_c, s.selfcal_error, s.sf_selfcal_uncertainty, s.baseline_error
        );
    }
    eprintln!("clocks {} wall {:.1} s", report.clocks, report.wall_s);
    assert_within_target(&report);
    assert_every_step_within_twice_the_floor(&report);
    // The carrier moved where that cleared its fold within the scale
    // factors' allowance (25 deg C), or where its spur bound is lowest
    // (30 deg C), and only there.
    let window = report.knowns.filter.min_window_s;
    for s in &report.steps {
        let shift = s.selfcal.operating.fold_shift_hz;
        eprintln!("{} deg C: carrier moved {shift:+.4} Hz", s.temperature_c);
        assert_eq!(
            shift != 0.0,
            s.temperature_c == 25.0 || s.temperature_c == 30.0,
            "{} deg C",
            s.temperature_c
        );
    }
    let beaten = report
        .steps
        .iter()
        .find(|s| s.temperature_c == 30.0)
        .unwrap();
    let beats = beaten.carrier_fold.offset_hz * window;
    let spur_move = beaten.selfcal.operating.spur_move.expect("a spur move");
    eprintln!("30 deg C: the fold beats {beats:.2} times a window, {spur_move:?}");
    assert!(beats >= gyrocal_regs::plan::SETTLED_FOLD_BEATS, "{beats}");
    let to = beaten
        .selfcal
        .carrier_spurs
        .as_ref()
        .expect("a bound")
        .rms_dps;
    for (k, (from, to)) in spur_move.from_dps.iter().zip(to).enumerate() {
        let gain = from / to;
        assert!(gain >= selfcal::SPUR_MOVE_GAIN, "output {}: {gain}", k + 1);
    }
    let moved = &report.steps[0];
    assert!((moved.selfcal.operating.fold_shift_hz - 0.81).abs() < 0.01);
    assert!(!moved.carrier_fold.in_passband);
    // The baseline, beside it: a fixed carrier leaves the resonance within
    // a fraction of a kelvin (290 Hz/K against an 88 Hz half-bandwidth), so
    // 5 K away its scale factor is off by more than a factor of 2.
    let far = report
        .steps
        .iter()
        .filter(|s| (s.temperature_c - 25.0).abs() >= 5.0);
    for s in far {
        assert!(
            s.baseline_error
                .expect("a baseline")
                .iter()
                .all(|e| e.abs() > 1.0),
            "{:?}",
            s.baseline_error
        );
    }
}

/// Brownian force noise on (300 K, the default 1e-8 kg modal mass) with
/// the ADC's 1 LSB, on the consumer device driven at 100 N/kg full scale
/// (so that the noise is referred to a physical drive): the noise model
/// (`rate_noise`) puts the Brownian force at 84% of the rate noise on both
/// outputs (ARW 19 and 2.1 deg/sqrt(h)), a noisy consumer part. The
/// self-calibration's error must stay within 3 of its own sigma at every
/// step, for two noise seeds (below: why not 0.1%); the seed-to-seed
/// difference of the errors, over sqrt(2), is the Brownian noise's 1-sigma
/// share of each error (printed).
#[test]
fn self_calibration_holds_with_brownian_noise() {
    let path = "tests/data/field_consumer.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let mut sc = scenario::parse(path, &text).unwrap();
    sc.profile = None;
    sc.drift.temperatures_c = vec![25.0, 15.0, 35.0];
    sc.exp.drive.force_full_scale1_n_per_kg = 100.0;
    sc.exp.drive.force_full_scale2_n_per_kg = 100.0;
    sc.exp.noise = ThermalNoise {
        mass_kg: 1e-8,
        temperature_k: 300.0,
        seed: 1,
    };
    let (_, prediction) = rate_noise::plan_and_predict(&sc.exp, 100.0).unwrap();
    for o in &prediction.outputs {
        let share = o.thermal_rate_psd / o.rate_psd;
        eprintln!(
            "predicted ARW {:.2} deg/sqrt(h), Brownian share {:.0}%",
            o.arw_deg_per_sqrt_h,
            100.0 * share
        );
        assert!(share > 0.5, "{share}");
    }
    let first = finished(&sc);
    sc.exp.noise.seed = 2;
    let second = finished(&sc);
    for s in first.steps.iter().chain(&second.steps) {
        eprintln!(
            "{} deg C: self-cal error {:+.4}% / {:+.4}%, its 1-sigma {:.4}% / {:.4}%",
            s.temperature_c,
            100.0 * s.selfcal_error[0],
            100.0 * s.selfcal_error[1],
            100.0 * s.selfcal_error_uncertainty[0],
            100.0 * s.selfcal_error_uncertainty[1]
        );
    }
    // With this much noise the self-calibration is noise-limited: the
    // error's own 1-sigma (self-cal and truth in quadrature) is 0.035% to
    // 0.048% on output 1 and 0.27% to 0.29% on output 2 (the noisy rate
    // table's), so 0.1% is 2 to 3 sigma on output 1 and below one on
    // output 2: asserting 0.1% on 12 figures fails by chance about one run
    // in ten (it did: 0.108% at 2.25 sigma). What a noisy part can promise
    // is its sigma: every error within 3 of its own 1-sigma.
    for s in first.steps.iter().chain(&second.steps) {
        for k in 0..2 {
            let (e, u) = (s.selfcal_error[k], s.selfcal_error_uncertainty[k]);
            assert!(
                e.abs() <= 3.0 * u,
                "{} deg C output {}: {e} at sigma {u}",
                s.temperature_c,
                k + 1
            );
        }
    }
    for k in 0..2 {
        let diffs: Vec<f64> = first
            .steps
            .iter()
            .zip(&second.steps)
            .map(|(a, b)| a.selfcal_error[k] - b.selfcal_error[k])
            .collect();
        let sigma = (diffs.iter().map(|d| d * d).sum::<f64>() / (2.0 * diffs.len() as f64)).sqrt();
        let worst = first
            .steps
            .iter()
            .chain(&second.steps)
            .map(|s| s.selfcal_error[k].abs())
            .fold(0.0, f64::max);
        eprintln!(
            "output {}: worst self-cal error {:.4}%, Brownian 1-sigma {:.4}% ({} steps x 2 seeds)",
            k + 1,
            100.0 * worst,
            100.0 * sigma,
            diffs.len()
        );
    }
}

/// A carrier on a short fold that beats slower than a window
/// (`gyrocal_regs::plan::STATIC_FOLD_BEATS`) is moved off it. The
/// scenario's 25 deg C carrier is 15000.000 Hz, 0.004 Hz from 1/80 of the
/// 1.2 MHz clock. Left there, the converters' and tables' errors were the
/// same in every batch: the couplings measured at rest came out
/// -1.680 +- 0.020 and +0.693 +- 0.014 deg/s against a truth of 0 (84 and
/// 50 sigma, before the couplings' coverage factor of 1.51), and the
/// self-cal errors -0.14% / -0.05%. Moved 0.031 Hz (the
/// fold then beats once a 0.4 s window; the scale factors change 5.7%,
/// within `STATIC_FOLD_SF_CHANGE`), every figure lies within 3 sigma.
#[test]
fn a_carrier_on_a_static_fold_moves_off_it() {
    let report = run("tests/data/field_static_fold.toml");
    let s = &report.steps[0];
    let op = &s.selfcal.operating;
    eprintln!(
        "carrier {} Hz, moved {:+.4} Hz, fold {:?}",
        op.carrier_hz, op.fold_shift_hz, s.carrier_fold
    );
    assert!(op.fold_shift_hz.abs() > 0.02 && op.fold_shift_hz.abs() < 0.05);
    assert_eq!(s.carrier_fold.static_fold, None);
    let id = &s.identified;
    for (name, value, sigma) in [
        (
            "quadrature",
            id.quadrature_dps,
            id.quadrature_dps_uncertainty,
        ),
        (
            "damping coupling",
            id.damping_coupling_dps,
            id.damping_coupling_dps_uncertainty,
        ),
    ] {
        eprintln!("{name}: {value:+.3} +- {sigma:.3} deg/s (truth 0)");
        assert!(value.abs() <= 3.0 * sigma, "{name} {value} +- {sigma}");
    }
    for k in 0..2 {
        let (e, u) = (s.selfcal_error[k], s.selfcal_error_uncertainty[k]);
        eprintln!("output {}: self-cal error {e:+.5} +- {u:.5}", k + 1);
        assert!(e.abs() <= 3.0 * u, "output {}: {e} +- {u}", k + 1);
    }
}

/// A step's rate RMS error in excess of a quiet step's (its floor): the
/// ripple adds in quadrature to the noise, and the noise in deg/s scales
/// as 1 / SF from one step to the other.
fn excess(report: &FieldReport, t: f64, quiet: f64, k: usize) -> f64 {
    let step = |t: f64| report.steps.iter().find(|s| s.temperature_c == t).unwrap();
    let rms = |t: f64| step(t).profile.as_ref().unwrap().selfcal_rms_error_dps[k];
    let floor = rms(quiet) * (step(quiet).sf_true_per_dps[k] / step(t).sf_true_per_dps[k]).abs();
    (rms(t).powi(2) - floor.powi(2)).max(0.0).sqrt()
}

/// The table core's spur bound at step `t` (`gyrocal_host::selfcal::spurs`,
/// over the profile's records) covers the rate's RMS excess over the
/// quiet step's on both outputs, and on the outputs `tight` it is within
/// 3 times that excess. The bound adds amplitudes where the ripple adds
/// lines of unrelated phases: the drive's and the reference's (they read
/// the table a REF_PHASE apart) and a fold's two sides kq -+ 1, so it may
/// exceed an RMS by twice with nothing missed; 3 leaves the excess's own
/// error from the noise floor's spread between steps (up to 17% on the
/// paper field).
fn assert_the_spur_bound_holds(report: &FieldReport, t: f64, quiet: f64, tight: &[usize]) {
    let step = report.steps.iter().find(|s| s.temperature_c == t).unwrap();
    let bound = step
        .profile
        .as_ref()
        .unwrap()
        .spur_bound_dps
        .expect("a bound");
    for (k, &b) in bound.iter().enumerate() {
        let e = excess(report, t, quiet, k);
        eprintln!(
            "{t} deg C output {}: excess {e:.4} deg/s, spur bound {b:.4} ({:.2} times)",
            k + 1,
            b / e
        );
        assert!(e <= b, "output {}: excess {e} over the bound {b}", k + 1);
        if tight.contains(&k) {
            assert!(b <= 3.0 * e, "output {}: bound {b} for {e}", k + 1);
        }
    }
}

/// Both cores on the paper device at 25 and 30 deg C. At 30 deg C the
/// carrier lies in the band of a fold of period 83 that the host cannot
/// leave (18.2 Hz from it). On the table core the carriers' words and
/// phase rounding, and the mixer's second rounding of F x carrier, come
/// back as a slow error of the DAC words of 0.042 LSB there; the host
/// moves that carrier to where its spur bound is lowest (the fold 109 Hz
/// away, `gyrocal_host::selfcal::SpurMove`). The fine core (the ECP5's,
/// `[drive] carrier_profile = "fine"`) rounds F times the quarter-LSB pair
/// once and feeds that error back away from the carrier (0.0055 LSB,
/// `examples/carrier_profiles.rs`, the DAC rows); it has no spur bound and
/// moves its carrier only until the fold beats four times a window (40.4
/// Hz). Issue 20's goal: both outputs' RMS within twice the floor (the
/// moved 25 deg C step). Measured: table 0.75 and 1.57 times (2.4 and 4.4
/// before the spur move), fine 1.11 and 1.44 (at 18.2 Hz 1.07 and 1.56;
/// with one rounding and no feedback 1.11 and 1.42); with the fine core's
/// pair rounded to whole LSB before the mixer (a second rounding) output
/// 2 was 3.9 times, which this test fails. On the table core the spur
/// bound must cover the excess over the floor (0 and 0.023 deg/s, bound
/// 0.111 and 0.072 over the records).
#[test]
fn both_cores_keep_the_30_deg_c_rate_within_twice_its_floor() {
    let path = "tests/data/field_paper.toml";
    let text = std::fs::read_to_string(path).unwrap();
    for profile in CarrierProfile::ALL {
        let mut sc = scenario::parse(path, &text).unwrap();
        sc.drift.temperatures_c = vec![25.0, 30.0];
        sc.exp.drive.carrier_profile = profile;
        let report = finished(&sc);
        let at = |t: f64| {
            let s = report.steps.iter().find(|s| s.temperature_c == t).unwrap();
            s.profile.as_ref().unwrap().selfcal_rms_error_dps
        };
        let (floor, hot) = (at(25.0), at(30.0));
        eprintln!("{profile}: rate RMS error 25 deg C {floor:?}, 30 deg C {hot:?} (deg/s)");
        for k in 0..2 {
            let times = hot[k] / floor[k];
            eprintln!("{profile} output {}: {times:.2} times the floor", k + 1);
            assert!(times <= 2.0, "{profile} output {}: {times:.2}", k + 1);
        }
        if profile == CarrierProfile::Table {
            assert_the_spur_bound_holds(&report, 30.0, 25.0, &[]);
        } else {
            assert!(
                report
                    .steps
                    .iter()
                    .all(|s| s.selfcal.carrier_spurs.is_none())
            );
        }
    }
}

/// The paper field at 25 and 30 deg C on a 50.005 MHz clock, on the core
/// with `profile`: its 25 deg C carrier lies 2.4 Hz from a fold of period
/// 10001, beyond the host's fold search.
fn paper_on_50_005_mhz(profile: CarrierProfile) -> FieldReport {
    let path = "tests/data/field_paper.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let mut sc = scenario::parse(path, &text).unwrap();
    sc.drift.temperatures_c = vec![25.0, 30.0];
    sc.exp.drive.carrier_profile = profile;
    sc.exp.drive.clock_hz = 50.005e6;
    finished(&sc)
}

/// The paper device on a 50.005 MHz clock, on the fine core. Its 25 deg C
/// carrier lies at 1928 / 10001 of the clock, 2.4 Hz from a fold of
/// period 10001: beyond the host's search (`plan::MAX_FOLD_PERIOD`, 4096),
/// so the step names no fold in its band (`in_passband` false). On the
/// table core, and on the fine core before its mixer fed the rounding
/// error back away from the carrier, output 1 rippled there: 0.14 and
/// 0.141 deg/s RMS, 1.6 times the 30 deg C step of the same run (0.086).
/// With the feedback there is no rounding error at the carrier for a fold
/// of any period to bring into the band (`carrier_multiplier`).
///
/// The bound: between the steps of one run the noise's RMS differs by up
/// to 1.17 times on output 1 (the paper field, fine core, five steps); a
/// ripple adds in quadrature, and the unfed core's 1.6 needs an excess of
/// 1.3 times the floor. So output 1 at 25 deg C must stay within 1.3 times
/// its 30 deg C RMS, and output 2 (noisier between steps, up to 1.56
/// times) within issue 20's twice. Measured: 0.94 and 0.81.
#[test]
fn the_fine_core_keeps_a_fold_of_period_10001_out_of_the_rate() {
    let report = paper_on_50_005_mhz(CarrierProfile::Fine);
    let step = |t: f64| report.steps.iter().find(|s| s.temperature_c == t).unwrap();
    assert!(
        !step(25.0).carrier_fold.in_passband,
        "the premise: no step names this fold, {:?}",
        step(25.0).carrier_fold
    );
    let rms = |t: f64| step(t).profile.as_ref().unwrap().selfcal_rms_error_dps;
    let (fold, quiet) = (rms(25.0), rms(30.0));
    eprintln!("rate RMS error (deg/s): 25 deg C {fold:?}, 30 deg C {quiet:?}");
    for (k, bound) in [(0, 1.3), (1, 2.0)] {
        let ratio = fold[k] / quiet[k];
        eprintln!("output {}: {ratio:.2} times the 30 deg C step", k + 1);
        assert!(ratio <= bound, "output {}: {ratio:.2} > {bound}", k + 1);
    }
}

/// The same fold on the table core, which has no room for the fine core's
/// feedback (the UP5K): the step names no fold, but its spur bound
/// (`gyrocal_host::selfcal::spurs`, harmonic by harmonic, whatever the
/// period) finds the lines 4.8 Hz from the carrier and bounds the ripple
/// they make on output 1 (measured: excess 0.11 deg/s over the 30 deg C
/// step, bound 0.29, 2.6 times). Output 2 shows no excess here (its lines
/// cancel in part), so there the bound is only asserted to cover.
#[test]
fn the_table_core_bounds_the_ripple_of_a_fold_of_period_10001() {
    let report = paper_on_50_005_mhz(CarrierProfile::Table);
    let fold = report
        .steps
        .iter()
        .find(|s| s.temperature_c == 25.0)
        .unwrap();
    assert!(!fold.carrier_fold.in_passband, "{:?}", fold.carrier_fold);
    let largest = fold.selfcal.carrier_spurs.as_ref().expect("spurs").largest[0];
    eprintln!("largest line {largest:?}");
    assert!((largest.offset_hz - 4.8).abs() < 0.1, "{largest:?}");
    assert_the_spur_bound_holds(&report, 25.0, 30.0, &[0]);
}

/// The paper device behind a front end set for a carrier 1 kHz above its
/// resonance (`tests/data/field_paper_scaled_drives.toml`: a datasheet
/// 0.01% high, the configured carrier on it): at
/// the identified resonance the configured drives would peak the ADCs
/// some 10 times over full scale, so the operating point scales them to
/// 9.2% (measured 0.0922 and 0.0919 of the configured). Each step says so
/// (`Operating::scaled_drives`), and at 30 deg C the spur move is judged
/// at the drive the carrier runs with: the bound where it was asked and
/// the cycle's own where it moved (both at the scaled drive) must show
/// the move's gain. Measured: 5.35 / 3.14 to 2.13 / 1.00 deg/s RMS (+1.09
/// Hz). Judged at the configured drive (mutant
/// `spur-bound-at-the-configured-drive`), the move went -1.09 Hz as on
/// the paper device and reported 0.77 / 0.39 where it was asked, while
/// the cycle's own bound where it moved was 1.78 / 1.33: no gain at all.
#[test]
fn a_drive_scaled_for_the_adcs_is_said_and_the_spur_move_is_judged_at_it() {
    let path = "tests/data/field_paper_scaled_drives.toml";
    let text = std::fs::read_to_string(path).unwrap();
    let report = finished(&scenario::parse(path, &text).unwrap());
    for st in &report.steps {
        let scaled = st.selfcal.operating.scaled_drives.expect("scaled drives");
        assert!(
            scaled.is_said() && scaled.table_core,
            "{}: {scaled:?}",
            st.temperature_c
        );
        assert_eq!(scaled.amplitude, st.selfcal.operating.amplitude);
    }
    let step = report
        .steps
        .iter()
        .find(|s| s.temperature_c == 30.0)
        .unwrap();
    let from = step
        .selfcal
        .operating
        .spur_move
        .expect("a spur move")
        .from_dps;
    let to = step
        .selfcal
        .carrier_spurs
        .as_ref()
        .expect("a bound")
        .rms_dps;
    eprintln!("30 deg C: spur bound {from:?} to {to:?}");
    for k in 0..2 {
        assert!(
            from[k] >= selfcal::SPUR_MOVE_GAIN * to[k],
            "output {}: {} to {}",
            k + 1,
            from[k],
            to[k]
        );
    }
}
