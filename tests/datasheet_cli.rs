//! `gyrocal datasheet` as a user meets it, checked against allantools.
//!
//! A 300 s run of `tests/data/datasheet_small.toml` (its flicker and
//! random-walk rate noises on, three `[drift]` temperatures) writes
//! datasheet.json, rate.csv and the figures; `scripts/noise/check_adev.py`
//! (in the pinned venv of `scripts/noise/install-venv.sh`) runs allantools
//! on rate.csv, and at every tau of the datasheet:
//!
//! - allantools' `oadev` agrees with the datasheet's deviation to
//!   `ADEV_AGREEMENT` relative. Both are the same sum in double precision,
//!   from the same 17-significant-digit CSV values; they differ in
//!   summation order and in that the datasheet removes the mean rate
//!   before integrating the angle (allantools does not): each second
//!   difference of the angle then carries a rounding of a few ulps of the
//!   angle's size, `|theta| <= n tau0 max|rate|`, against a difference of
//!   size `tau sigma`. With `max|rate|` a few deg/s, `n tau0` = 300 s and
//!   `tau sigma` >= 1e-4 deg at the shortest tau, that is below 1e3 x 1e-16
//!   / 1e-4 = 1e-9 relative; in practice 1e-13 (printed).
//! - Its interval with the datasheet's edf (scipy's chi-square quantiles)
//!   agrees with the datasheet's (statrs') to `CI_AGREEMENT`: both invert
//!   the regularized incomplete gamma to near double precision.
//! - `allantools.edf_greenhall` for each pure rate-noise type agrees with
//!   `gyrocal_sim::edf::edf` (the same algorithm, the same table) to
//!   `CI_AGREEMENT`.
//!
//! When the venv cannot be made (no python3 with venv, no registry), the
//! allantools half is skipped with a message on stderr, and the files are
//! still checked; under CI (`CI` set) that is a failure instead.

mod common;

use common::{gyrocal, json_object, stderr};
use gyrocal_sim::edf::{self, RateNoiseType};
use std::path::Path;
use std::process::Command;

const SMALL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/datasheet_small.toml"
);
const INSTALL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/noise/install-venv.sh");
const CHECK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/noise/check_adev.py");

/// Relative agreement of the deviations (module header).
const ADEV_AGREEMENT: f64 = 1e-9;
/// Relative agreement of the intervals and edfs (module header).
const CI_AGREEMENT: f64 = 1e-7;

/// The venv's python, or None (with the reason on stderr).
fn venv_python() -> Option<String> {
    let o = Command::new("bash").arg(INSTALL).output().ok()?;
    if !o.status.success() {
        eprintln!(
            "skipping the allantools comparison: {INSTALL} failed: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        return None;
    }
    String::from_utf8(o.stdout)
        .ok()?
        .lines()
        .last()
        .map(str::to_owned)
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// Compare every line of check_adev.py's output.
fn allantools_agrees(python: &str, out: &Path, n: usize) {
    let o = Command::new(python).arg(CHECK).arg(out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (mut worst, mut lines) = (0.0f64, 0);
    for line in String::from_utf8(o.stdout).unwrap().lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        let f = |key: &str| v[key].as_f64().unwrap();
        assert!(rel(f("allantools_tau_s"), f("tau_s")) < 1e-12, "{line}");
        let d = rel(f("ours"), f("allantools"));
        worst = worst.max(d);
        assert!(d < ADEV_AGREEMENT, "{line}");
        for i in 0..2 {
            let (a, b) = (
                v["ci_ours"][i].as_f64().unwrap(),
                v["ci_allantools"][i].as_f64().unwrap(),
            );
            assert!(rel(a, b) < CI_AGREEMENT, "{line}");
        }
        let m = v["m"].as_u64().unwrap() as usize;
        for (i, kind) in RateNoiseType::ALL.iter().enumerate() {
            let ours = edf::edf(n, m, *kind).unwrap();
            let theirs = v["edf_greenhall"][i].as_f64().unwrap();
            assert!(
                rel(ours, theirs) < CI_AGREEMENT,
                "{kind:?} m {m}: {ours} vs {theirs}"
            );
        }
        lines += 1;
    }
    assert!(lines >= 2 * 10, "{lines} taus compared");
    eprintln!("allantools: {lines} taus, worst relative difference of the deviation {worst:.2e}");
}

#[test]
fn the_datasheet_writes_its_files_and_allantools_agrees() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sheet");
    let o = gyrocal(&[
        "datasheet",
        "--config",
        SMALL,
        "--seconds",
        "300",
        "--json",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let v = json_object(o);
    let outputs = v["outputs"].as_array().unwrap();
    assert_eq!(outputs.len(), 2);
    for o in outputs {
        for key in [
            "sf_lsb_per_dps",
            "sf_nonlinearity_ppm",
            "sf_asymmetry_ppm",
            "bandwidth_hz",
            "bias_instability_deg_per_h",
            "bias_instability_tau_s",
            "arw_deg_per_sqrt_h",
        ] {
            assert!(
                o[key].as_f64().is_some_and(f64::is_finite),
                "{key}: {}",
                o[key]
            );
        }
        assert!(o.get("rrw_deg_per_h_per_sqrt_h").is_some());
        assert!(
            o["sf_tc_ppm_per_k"].as_f64().is_some()
                && o["bias_tc_deg_per_h_per_k"].as_f64().is_some()
        );
        let adev = &o["adev"];
        let n = adev["tau_s"].as_array().unwrap().len();
        for key in ["sigma_deg_per_h", "ci_low", "ci_high"] {
            assert_eq!(adev[key].as_array().unwrap().len(), n, "{key}");
        }
    }
    let written = std::fs::read_to_string(out.join("datasheet.json")).unwrap();
    let from_file: serde_json::Value = serde_json::from_str(&written).unwrap();
    assert_eq!(from_file, v, "datasheet.json is the --json object");
    for name in [
        "rate.csv",
        "datasheet_adev.png",
        "datasheet_adev.svg",
        "datasheet_nonlinearity.png",
        "datasheet_temperature.svg",
    ] {
        let len = std::fs::metadata(out.join(name))
            .map(|m| m.len())
            .unwrap_or(0);
        assert!(len > 0, "{name} missing");
    }
    let csv = std::fs::read_to_string(out.join("rate.csv")).unwrap();
    assert!(csv.starts_with("time_s,rate1_dps,rate2_dps\n"));
    let n = csv.lines().count() - 1;
    let fs = v["series"]["sample_rate_hz"].as_f64().unwrap();
    assert_eq!(n, (300.0 * fs).round() as usize);
    match venv_python() {
        Some(python) => allantools_agrees(&python, &out, n),
        None if std::env::var_os("CI").is_some() => {
            panic!("CI is set and the allantools venv could not be made (stderr above)")
        }
        None => eprintln!("allantools comparison skipped"),
    }
}

#[test]
fn bad_input_is_one_line_exit_2_and_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(SMALL).unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        text.replace(
            "rrw_deg_per_h_per_sqrt_h = 15000",
            "rrw_deg_per_h_per_sqrt_h = -1",
        ),
    )
    .unwrap();
    for (config, args, start) in [
        (
            SMALL,
            vec!["--seconds", "1"],
            "error: --seconds 1: allowed 2 to",
        ),
        (
            SMALL,
            vec!["--full-scale-dps", "0"],
            "error: --full-scale-dps 0: allowed",
        ),
        (bad.to_str().unwrap(), vec![], "error: "),
        (
            "/no/such/file.toml",
            vec![],
            "error: --config /no/such/file.toml: cannot read the file",
        ),
    ] {
        let out = dir.path().join("never");
        let mut all = vec![
            "datasheet",
            "--config",
            config,
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ];
        all.extend(args.iter().copied());
        let o = gyrocal(&all);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.starts_with(start), "{err}");
        assert!(!out.exists());
    }
    let err = stderr(&gyrocal(&[
        "datasheet",
        "--config",
        bad.to_str().unwrap(),
        "--quiet",
    ]));
    assert!(
        err.contains("[noise] rrw_deg_per_h_per_sqrt_h = -1"),
        "{err}"
    );
}
