//! `gyrocal allan` as a user meets it: a short run prints its readings
//! and writes JSON, CSV and figures; bad input is one line, exit status 2,
//! and nothing written.

mod common;

use common::{gyrocal, json_object, stderr};
use std::path::Path;

const SMALL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/allan_small.toml");

#[test]
fn a_short_run_prints_json_and_writes_its_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("allan");
    let o = gyrocal(&[
        "allan",
        "--config",
        SMALL,
        "--seconds",
        "8",
        "--rate-dps",
        "-20",
        "--json",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let v = json_object(o);
    assert_eq!(v["run"]["rate_dps"].as_f64(), Some(-20.0));
    for k in 0..2 {
        let predicted = v["prediction"]["outputs"][k]["arw_deg_per_sqrt_h"]
            .as_f64()
            .unwrap();
        let reading = &v["run"]["outputs"][k]["arw_at_1s"];
        let measured = reading["deg_per_sqrt_h"].as_f64().unwrap();
        // 8 s: edf about 12, relative sigma about 20 %; a factor of 2 is
        // only a sanity check here (tests/allan_noise.rs has the 10 %).
        assert!(
            measured > 0.5 * predicted && measured < 2.0 * predicted,
            "output {k}: {measured} vs {predicted}"
        );
        let points = v["run"]["outputs"][k]["analysis"]["points"]
            .as_array()
            .unwrap();
        assert_eq!(
            points.len(),
            v["predicted_adev_dps"][k].as_array().unwrap().len()
        );
    }
    for name in [
        "allan.json",
        "allan.csv",
        "allan_output1.png",
        "allan_output1.svg",
        "allan_output2.png",
        "allan_output2.svg",
    ] {
        let path = out.join(name);
        assert!(
            std::fs::metadata(&path)
                .map(|m| m.len() > 0)
                .unwrap_or(false),
            "{} missing",
            path.display()
        );
    }
    let csv = std::fs::read_to_string(out.join("allan.csv")).unwrap();
    assert!(csv.starts_with("tau_s,adev1_dps,adev2_dps,predicted_adev1_dps"));
    assert!(csv.lines().count() > 10, "{csv}");
}

/// `args` (after `allan --config FILE`) fail with exit 2 and a one-line
/// error starting with `start`, and leave `--out` unwritten.
fn refused(config: &Path, args: &[&str], start: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let mut all = vec![
        "allan",
        "--config",
        config.to_str().unwrap(),
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    let o = gyrocal(&all);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
    assert!(err.starts_with(start), "{args:?}: {err}");
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
    assert!(o.stdout.is_empty());
}

#[test]
fn bad_input_is_one_line_exit_2_and_nothing_written() {
    let small = Path::new(SMALL);
    refused(
        small,
        &["--seconds", "1"],
        "error: --seconds 1: allowed 2 to",
    );
    refused(
        small,
        &["--seconds", "nan"],
        "error: --seconds NaN: allowed",
    );
    refused(
        small,
        &["--rate-dps", "1e6"],
        "error: --rate-dps 1000000: allowed",
    );
    refused(
        Path::new("/no/such/file.toml"),
        &[],
        "error: --config /no/such/file.toml: cannot read the file",
    );
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(SMALL).unwrap();
    for (from, to, start) in [
        (
            "mass_kg = 1e-6",
            "mass_kg = 0",
            "error: [noise] mass_kg = 0: must be",
        ),
        (
            "temperature_k = 300",
            "temperature_k = -4",
            "error: [noise] temperature_k = -4: allowed 0..=1000 K",
        ),
        ("seed = 7", "seed = 7\nkelvin = 3", "error: "),
    ] {
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, text.replace(from, to)).unwrap();
        refused(&path, &[], start);
    }
    // --out naming a file, not a folder.
    let file = dir.path().join("plain");
    std::fs::write(&file, "x").unwrap();
    let o = gyrocal(&[
        "allan",
        "--config",
        SMALL,
        "--quiet",
        "--out",
        file.join("sub").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("is not a folder"), "{}", stderr(&o));
}
