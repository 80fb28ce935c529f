//! `gyrocal field` refuses bad scenario files in one line, with exit
//! status 2, before writing anything.

mod common;

use common::gyrocal;
use std::ffi::OsStr;

const GOOD: &str = "[gyro]\nf1_hz = 25.1e3\nf2_hz = 25.8e3\nq1 = 3000\nq2 = 3000\nangular_gain = 0.8\n\
[drive]\ncarrier_hz = 25.1e3\nclock_hz = 1.2345e6\n\
[experiment]\nreadout_rates_dps = [50, 100]\ncal_freqs_hz = [2, 4]\n";

/// `gyrocal field --config CONFIG --json`, which must succeed: its report.
fn field_json(config: &OsStr) -> serde_json::Value {
    let run = gyrocal(&[
        OsStr::new("field"),
        OsStr::new("--config"),
        config,
        OsStr::new("--json"),
    ]);
    assert!(run.status.success(), "{}", common::stderr(&run));
    serde_json::from_slice(&run.stdout).unwrap()
}

/// How many of a report's `warnings` start with `line`.
fn warnings_starting(report: &serde_json::Value, line: &str) -> usize {
    report["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| w.as_str().unwrap().starts_with(line))
        .count()
}

#[test]
fn bad_scenario_files_are_refused_in_one_line() {
    let drift = "[drift]\ntemperatures_c = [25, 35]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n";
    let cases = [
        (GOOD.to_string(), "drift"),
        (
            format!("{GOOD}{drift}tcf3_ppm_per_k = 1\n"),
            "tcf3_ppm_per_k",
        ),
        (
            format!("{GOOD}{drift}front_end_phase_deg = 1e9\n"),
            "front_end_phase",
        ),
        (GOOD.replace("q1 = 3000", "q1 = -3") + drift, "q1"),
        (
            format!("{GOOD}{drift}")
                .replace("temperatures_c = [25, 35]", "temperatures_c = [25, 400]"),
            "temperatures_c",
        ),
        (
            format!("{GOOD}{drift}[profile]\nduration_s = 1\nrate_points = [[0.5, 1]]\n"),
            "rate_points",
        ),
        (
            format!("{GOOD}{drift}[profile]\nduration_s = -1\nrate_points = [[0, 1]]\n"),
            "duration_s",
        ),
        (
            format!("{GOOD}{drift}[profile]\nduration_s = 1\nrate_points = [[0, 1, 2]]\n"),
            "rate_points",
        ),
        (
            format!("{GOOD}{drift}drive_gain_ppm_per_k = [1, 2, 3]\n"),
            "length 2",
        ),
        (
            format!("{GOOD}{drift}[drive_probe]\nrate_dps = 0\n"),
            "rate_dps",
        ),
        (
            format!("{GOOD}{drift}[drive_probe]\nrate_dps = 100\nseconds = 1\n"),
            "seconds",
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (i, (text, key)) in cases.iter().enumerate() {
        let config = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&config, text).unwrap();
        let out = dir.path().join(format!("out{i}"));
        let run = gyrocal(&[
            OsStr::new("field"),
            OsStr::new("--config"),
            config.as_os_str(),
            OsStr::new("--out"),
            out.as_os_str(),
        ]);
        let stderr = common::stderr(&run);
        assert_eq!(run.status.code(), Some(2), "{key}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(stderr.contains(key), "{key}: {stderr}");
        assert!(run.stdout.is_empty());
        assert!(!out.exists(), "{key}: wrote {}", out.display());
    }
}

/// A step the host cannot calibrate (at 45 deg C the modes have drifted
/// 20% below the datasheet, beyond the +-5% scan) is reported, in the JSON
/// and in one closing line with exit status 1, while the step that
/// finished (25 deg C) stands, written whole with its figures.
#[test]
fn a_failed_step_is_reported_and_the_finished_steps_stand() {
    let drift =
        "[drift]\ntemperatures_c = [25, 45]\ntcf1_ppm_per_k = -10000\ntcf2_ppm_per_k = -10000\n";
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("drifting_out.toml");
    std::fs::write(&config, format!("{GOOD}{drift}")).unwrap();
    let out = dir.path().join("out");
    let run = gyrocal(&[
        OsStr::new("field"),
        OsStr::new("--config"),
        config.as_os_str(),
        OsStr::new("--json"),
        OsStr::new("--out"),
        out.as_os_str(),
    ]);
    let stderr = common::stderr(&run);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    let last = stderr.trim_end().lines().last().unwrap();
    assert!(
        last.contains("1 of 2 steps failed") && last.contains("45 deg C"),
        "{last}"
    );
    let text = String::from_utf8(run.stdout).unwrap();
    assert_eq!(
        text.trim().lines().count(),
        1,
        "one JSON object on one line"
    );
    let report: serde_json::Value = serde_json::from_str(&text).unwrap();
    let steps = report["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 1, "{report}");
    assert_eq!(steps[0]["temperature_c"], 25.0);
    assert!(
        steps[0]["sf_selfcal_per_dps"][0]
            .as_f64()
            .unwrap()
            .is_finite()
    );
    let failed = report["failed"].as_array().unwrap();
    assert_eq!(failed.len(), 1, "{report}");
    assert_eq!(failed[0]["temperature_c"], 45.0);
    assert_eq!(failed[0]["stage"], "self-calibration cycle");
    assert!(
        failed[0]["error"]
            .as_str()
            .unwrap()
            .contains("no resonance found"),
        "{failed:?}"
    );
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("field.json")).unwrap()).unwrap();
    assert_eq!(written, report);
}

/// A drive-gain ratio the cycle cannot measure (no coupling, no
/// `[drive_probe]`) is the design's: the summary says, in one line, that
/// its error is not in the sigma unless `[datasheet]
/// drive_gain_ratio_uncertainty` bounds it, and with that key it is silent;
/// the written report carries the same line in its `warnings`.
#[test]
fn an_unbudgeted_design_drive_ratio_is_said() {
    let drift = "[drift]\ntemperatures_c = [25]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n";
    let dir = tempfile::tempdir().unwrap();
    let note =
        "gives no drive_gain_ratio_uncertainty: a drive gain that drifted is not in the sigma";
    for (datasheet, said) in [
        ("", true),
        ("[datasheet]\ndrive_gain_ratio_uncertainty = 0.005\n", false),
    ] {
        let config = dir.path().join("design_ratio.toml");
        std::fs::write(&config, format!("{GOOD}{drift}{datasheet}")).unwrap();
        let out = dir.path().join(if said { "said" } else { "silent" });
        let run = gyrocal(&[
            OsStr::new("field"),
            OsStr::new("--config"),
            config.as_os_str(),
            OsStr::new("--out"),
            out.as_os_str(),
        ]);
        assert!(run.status.success(), "{}", common::stderr(&run));
        let text = String::from_utf8(run.stdout).unwrap();
        assert_eq!(text.contains(note), said, "{datasheet}: {text}");
        let written: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("field.json")).unwrap())
                .unwrap();
        let warned = written["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains(note));
        assert_eq!(warned, said, "{datasheet}: {written}");
    }
}

/// A profile that leaves the rates the scale factors were fitted over (the
/// rate table's 50 and 100 deg/s, and the null at 0) is said in one line,
/// in the summary and the JSON's `warnings`: beyond them the profile's
/// error holds the readout's departure from its fitted line, which no
/// sigma bounds.
#[test]
fn a_profile_beyond_the_rate_table_is_said() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("beyond.toml");
    let text = format!(
        "{GOOD}[drift]\ntemperatures_c = [25]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n\
         [profile]\nduration_s = 0.6\nrate_points = [[0, 0], [0.2, 0], [0.2, 300], [0.6, 300]]\n"
    );
    std::fs::write(&config, text).unwrap();
    let line = "warning: [profile] reaches 300 deg/s, outside the 0 to 100 deg/s";
    let run = gyrocal(&[
        OsStr::new("field"),
        OsStr::new("--config"),
        config.as_os_str(),
    ]);
    assert!(run.status.success(), "{}", common::stderr(&run));
    let text = String::from_utf8(run.stdout).unwrap();
    assert_eq!(
        text.lines().filter(|l| l.starts_with(line)).count(),
        1,
        "{text}"
    );
    let report = field_json(config.as_os_str());
    assert!(
        warnings_starting(&report, line) > 0,
        "{}",
        report["warnings"]
    );
}

/// A profile that drives the sense ADC past its range (100,000 deg/s on a
/// table of 50 and 100) is said in one line naming the step, the ADC and
/// its records, in the summary and the JSON; those records and the
/// settle_s after them are not settled, so the RMS errors leave them out,
/// and the records before the step stay in.
#[test]
fn a_profile_that_clips_an_adc_is_said_and_left_out_of_the_rms() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("clips.toml");
    let text = format!(
        "{GOOD}[drift]\ntemperatures_c = [25]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n\
         [profile]\nduration_s = 0.6\nrate_points = [[0, 0], [0.2, 0], [0.2, 100000], [0.6, 100000]]\n\
         settle_s = 0.05\n"
    );
    std::fs::write(&config, text).unwrap();
    let line = "warning: an ADC clipped under [profile] at 25 deg C (ADC 2 in ";
    let report = field_json(config.as_os_str());
    assert_eq!(
        warnings_starting(&report, line),
        1,
        "{}",
        report["warnings"]
    );
    let trace = &report["steps"][0]["profile"];
    let clipped = &trace["clipped"];
    let records = clipped["records"].as_u64().unwrap() as usize;
    let adc2 = clipped["selfcal"][1].as_u64().unwrap() as usize;
    // After the step at 0.2 s every record of the 0.4 s clips: two thirds.
    assert!(3 * adc2 >= 2 * records - 6 && adc2 <= records, "{clipped}");
    let per_record = trace["clip_clocks"].as_array().unwrap();
    assert_eq!(per_record.len(), records);
    let counted = per_record
        .iter()
        .filter(|c| c[1].as_u64().unwrap() > 0)
        .count();
    assert_eq!(counted, adc2);
    let settled: Vec<bool> = trace["settled"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b.as_bool().unwrap())
        .collect();
    let time: Vec<f64> = trace["time_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    // settle_s after the points at 0 and 0.2 s, then clipped to the end.
    for (t, s) in time.iter().zip(&settled) {
        if *t > 0.2 || (0.06..0.19).contains(t) {
            assert_eq!(*s, *t < 0.2, "record at {t} s: settled {s}");
        }
    }
    let rms = trace["selfcal_rms_error_dps"][1].as_f64().unwrap();
    assert!(rms < 1.0, "the records at rest alone: {rms} deg/s RMS");
}

/// A device whose factory settings clip ADC 1 in the rate table at 35 deg C
/// (mode 1 drifted nearer the factory's carrier): the step's own cycle
/// stands, its baseline fields are null, nothing is counted as a failure,
/// and one line says what an uncalibrated part does there. Before
/// `ADC_CLIP` watched the table, the 35 deg C baseline error was a slope
/// of a clipped converter's readings, reported as a figure.
#[test]
fn factory_settings_that_clip_are_said_and_leave_the_baseline_null() {
    let report = field_json(OsStr::new("tests/data/field_factory_clips.toml"));
    assert_eq!(
        report["failed"].as_array().unwrap().len(),
        0,
        "{}",
        report["failed"]
    );
    let steps = report["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 2);
    assert!(steps[0]["baseline_error"].is_array());
    assert!(steps[1]["baseline_error"].is_null());
    assert!(steps[1]["selfcal_error"][0].as_f64().unwrap().abs() < 0.01);
    let line =
        "warning: the factory's settings clip an ADC at 35 deg C (rate table: ADC 1 clipped on ";
    assert_eq!(
        warnings_starting(&report, line),
        1,
        "{}",
        report["warnings"]
    );
}

/// A datasheet Q1 far below the part's (a 30th and a 150th of the
/// consumer device's 3000, a datasheet's minimum Q): the search misses the
/// mode with the datasheet's spacing and waits, tries again from the Q it
/// measured or ten times its own, and identifies Q1 within 3 sigma; the
/// scale factors then come within 3 sigma too, and the report names the
/// datasheet's Q1 in one line (`datasheet_warning`). At Q1 = 0.05 two more
/// tries do not reach it: the step fails in one line naming the key to
/// correct, with exit status 1.
#[test]
fn a_datasheet_q_far_off_is_found_or_named() {
    let drift = "[drift]\ntemperatures_c = [25]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n";
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("q_far_off.toml");
    for q1 in [100.0, 20.0, 0.05] {
        std::fs::write(&config, format!("{GOOD}{drift}[datasheet]\nq1 = {q1}\n")).unwrap();
        let run = gyrocal(&[
            OsStr::new("field"),
            OsStr::new("--config"),
            config.as_os_str(),
            OsStr::new("--json"),
        ]);
        let stderr = common::stderr(&run);
        let report: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
        if q1 > 1.0 {
            assert!(run.status.success(), "q1 = {q1}: {stderr}");
            let step = &report["steps"][0];
            let id = &step["identified"];
            let (q, sigma) = (
                id["q1"].as_f64().unwrap(),
                id["q1_uncertainty"].as_f64().unwrap(),
            );
            assert!(
                (q - 3000.0).abs() < 3.0 * sigma,
                "q1 = {q1}: {q} +- {sigma}"
            );
            for k in 0..2 {
                let e = step["selfcal_error"][k].as_f64().unwrap();
                let sigma = step["selfcal_error_uncertainty"][k].as_f64().unwrap();
                assert!(
                    e.abs() < 3.0 * sigma,
                    "q1 = {q1}, output {k}: {e} +- {sigma}"
                );
            }
            // Found, and the datasheet named (`datasheet_warning`).
            let head = format!("warning: [datasheet] q1 = {q1} is 0.0");
            assert_eq!(
                warnings_starting(&report, &head),
                1,
                "{}",
                report["warnings"]
            );
        } else {
            assert_eq!(run.status.code(), Some(1), "{stderr}");
            let error = report["failed"][0]["error"].as_str().unwrap();
            assert!(
                error.starts_with("identification of mode 1: ") && error.contains("[datasheet] q1"),
                "q1 = {q1}: {error}"
            );
            assert!(!error.contains('\n'));
        }
    }
}

/// A datasheet lambda 10% below the part's, claimed within 1%: the
/// self-calibrated scale factors are off by many of their sigmas, and the
/// report says so in one line naming each error and the input to check;
/// the quadrature coupling (30 deg/s), read in deg/s through that lambda,
/// is off too, and a second line names it. With the datasheet's lambda
/// right, the same run says nothing of either.
#[test]
fn an_error_its_sigma_does_not_cover_is_said() {
    let drift = "[drift]\ntemperatures_c = [25]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n";
    let gyro = GOOD.replacen(
        "angular_gain = 0.8\n",
        "angular_gain = 0.8\nquadrature_dps = 30\n",
        1,
    );
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("lambda_off.toml");
    let line = "warning: 2 of 2 errors lie beyond 3 of their reported sigmas";
    let quadrature = "warning: 1 of 5 identified parameters lie beyond 3 of their reported sigmas, \
                      which do not cover them: at 25 deg C quadrature (+";
    for (lambda, said) in [(0.72, true), (0.8, false)] {
        let datasheet = format!(
            "[datasheet]\nangular_gain = {lambda}\nangular_gain_uncertainty = 0.01\n\
             drive_gain_ratio_uncertainty = 0.005\n"
        );
        std::fs::write(&config, format!("{gyro}{drift}{datasheet}")).unwrap();
        let report = field_json(config.as_os_str());
        assert_eq!(
            warnings_starting(&report, line),
            usize::from(said),
            "lambda {lambda}: {}",
            report["warnings"]
        );
        assert_eq!(
            warnings_starting(&report, quadrature),
            usize::from(said),
            "lambda {lambda}: {}",
            report["warnings"]
        );
        // Its f and Q are the part's: nothing said of them.
        assert_eq!(
            warnings_starting(&report, "warning: [datasheet]"),
            0,
            "{}",
            report["warnings"]
        );
        if said {
            let text = report["warnings"].to_string();
            assert!(
                text.contains("at 25 deg C output 1 (-")
                    && text.contains("[datasheet] angular_gain"),
                "{text}"
            );
        }
    }
}

/// A step whose cycle fails after identification keeps what it
/// identified: the report's `failed` entry carries it, and the table
/// prints it under the failure. The vehicle is an ADC whose own noise
/// (3000 LSB RMS, a tenth of full scale) leaves the calibration drives no
/// headroom: the staircase clips, the identification before it stands,
/// within 3 of its sigmas of the device (f1 25.1 kHz, Q1 3000 at the
/// factory temperature).
#[test]
fn a_step_that_fails_after_identification_keeps_it() {
    let drift = "[drift]\ntemperatures_c = [25]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -30\n";
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("noisy.toml");
    std::fs::write(
        &config,
        format!("{GOOD}{drift}[frontend]\nnoise_lsb = 3000\n"),
    )
    .unwrap();
    let args = |json: bool| {
        let mut a = vec![
            OsStr::new("field"),
            OsStr::new("--config"),
            config.as_os_str(),
        ];
        if json {
            a.push(OsStr::new("--json"));
        }
        gyrocal(&a)
    };
    let run = args(true);
    assert_eq!(run.status.code(), Some(1), "{}", common::stderr(&run));
    let report: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    let failed = &report["failed"][0];
    assert_eq!(failed["stage"], "self-calibration cycle");
    // The line names both causes a count cannot tell apart, with the
    // predicted peak and the room it left, in one line.
    let error = failed["error"].as_str().unwrap();
    assert!(error.starts_with("calibration staircase: ADC"), "{failed}");
    assert!(
        error.contains("of the window's clocks; the identified response puts ADC")
            && error.contains("the device answers more than identified")
            && error.contains("the converter's own noise reaches over the"),
        "{error}"
    );
    assert!(!error.contains('\n'), "{error}");
    // Its board's clocks are the run's, though no step finished.
    assert!(
        report["clocks"].as_f64().unwrap() > 1e6,
        "{}",
        report["clocks"]
    );
    let id = &failed["identified"];
    for (key, truth) in [
        ("f1_hz", 25.1e3),
        ("f2_hz", 25.8e3),
        ("q1", 3000.0),
        ("q2", 3000.0),
    ] {
        let v = id[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key} in {failed}"));
        let sigma = id[&format!("{key}_uncertainty")].as_f64().unwrap();
        assert!((v - truth).abs() <= 3.0 * sigma, "{key}: {v} +- {sigma}");
    }
    // The couplings come after identification: not measured.
    assert!(id["quadrature_dps"].is_null(), "{id}");
    let table = String::from_utf8(args(false).stdout).unwrap();
    assert!(
        table.contains("   25.00  identified before it failed: f1 25"),
        "{table}"
    );
}
