//! The command line as a user meets it: outputs, errors, waveforms.

mod common;

use common::{gyrocal, json_object, stderr};
use std::path::Path;

const SMALL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/small_device.toml");

#[test]
fn run_json_holds_the_scale_factors_and_the_theory() {
    let o = gyrocal(&["run", "--config", SMALL, "--json", "--quiet"]);
    let v = json_object(o);
    for key in ["sf_read_per_dps", "sf_cal_per_dps", "ratio"] {
        for obj in [&v, &v["theory"]] {
            let pair = obj[key]
                .as_array()
                .unwrap_or_else(|| panic!("{key} missing"));
            assert_eq!(pair.len(), 2);
            assert!(pair.iter().all(|x| x.as_f64().unwrap().is_finite()));
        }
    }
    for key in [
        "sf_read_uncertainty",
        "sf_cal_uncertainty",
        "ratio_uncertainty",
    ] {
        let pair = v[key].as_array().unwrap_or_else(|| panic!("{key} missing"));
        assert_eq!(pair.len(), 2);
        assert!(pair.iter().all(|x| {
            let x = x.as_f64().unwrap();
            x.is_finite() && x > 0.0
        }));
    }
    assert!(v["warnings"].is_array());
    // Paper's sign convention: readout negative for positive rates,
    // calibration positive at the resonant output.
    assert!(v["sf_read_per_dps"][0].as_f64().unwrap() < 0.0);
    assert!(v["sf_cal_per_dps"][0].as_f64().unwrap() > 0.0);
    let error = v["ratio_error"][0].as_f64().unwrap();
    assert!(error.abs() < 1e-3, "ratio error {error}");
    assert_budget_adds_up(&v);
}

/// The budget by source of each figure adds up, root sum of squares, to
/// the total 1-sigma reported under the figure's own key.
fn assert_budget_adds_up(v: &serde_json::Value) {
    for (figure, key) in [
        ("sf_read_per_dps", "sf_read_uncertainty"),
        ("sf_cal_per_dps", "sf_cal_uncertainty"),
        ("ratio", "ratio_uncertainty"),
    ] {
        for k in 0..2 {
            let terms = &v["uncertainty_budget"][figure][k];
            let term = |name: &str| terms[name].as_f64().unwrap_or_else(|| panic!("{name}"));
            let rss = ["statistical", "settling", "images"]
                .map(|t| term(t).powi(2))
                .iter()
                .sum::<f64>()
                .sqrt();
            let total = v[key][k].as_f64().unwrap();
            assert_eq!(term("total"), total, "{figure} {k}");
            assert!((rss / total - 1.0).abs() < 1e-12, "{figure} {k}");
        }
    }
}

/// Write `text` to a config file in `dir`, run it with `--out`, and check
/// the failure: status 2, one line on stderr naming `needle`, no panic,
/// and no output folder created.
fn check_rejected(dir: &Path, text: &str, needle: &str) {
    let config = dir.join("bad.toml");
    std::fs::write(&config, text).unwrap();
    let out = dir.join("out");
    let o = gyrocal(&[
        "run",
        "--config",
        config.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{text:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{text:?}: {err}");
    assert!(
        err.starts_with("error: ") && err.contains(needle),
        "{text:?}: {err}"
    );
    assert!(!err.contains("panicked"));
    assert!(!out.exists(), "{text:?} wrote {}", out.display());
}

#[test]
fn bad_configurations_fail_with_one_line_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(SMALL).unwrap();
    let cases = [
        (
            base.replace("q1 = 5000", "q1 = 5000\nquality = 3"),
            "unknown field `quality`",
        ),
        (base.replace("q1 = 5000", "q1 = nan"), "[gyro] q1 = NaN"),
        (base.replace("q2 = 5000", "q2 = -2"), "[gyro] q2 = -2"),
        (
            base.replace("carrier_hz = 1.0123e6", "carrier_hz = 5e6"),
            "[drive] carrier_hz = 5000000",
        ),
        (
            base.replace("[100, 200, 300, 400]", "[]"),
            "[experiment] readout_rates_dps is empty",
        ),
        (
            base.replace("[2, 4, 6]", "[]"),
            "[experiment] cal_freqs_hz is empty",
        ),
        (base.replace("[gyro]", "[gyro"), "line 3"),
        ("[gyro]\nf1_hz = \"fast\"\n".to_string(), "invalid type"),
        ("[nonsense]\n".to_string(), "unknown field `nonsense`"),
    ];
    for (text, needle) in cases {
        check_rejected(dir.path(), &text, needle);
    }
}

#[test]
fn bad_options_fail_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.toml");
    let file = dir.path().join("a_file");
    std::fs::write(&file, "").unwrap();
    let under_file = file.join("out").display().to_string();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["reproduce".into(), "--out".into(), under_file.clone()],
            "cannot create the folder",
        ),
        (
            vec![
                "run".into(),
                "--config".into(),
                missing.display().to_string(),
            ],
            "cannot read the file",
        ),
        (
            vec![
                "run".into(),
                "--config".into(),
                SMALL.into(),
                "--engine".into(),
                "spice".into(),
            ],
            "--engine \"spice\"",
        ),
        (
            vec![
                "run".into(),
                "--config".into(),
                SMALL.into(),
                "--vcd".into(),
                "w.vcd".into(),
                "--vcd-cycles".into(),
                "9:3".into(),
            ],
            "--vcd-cycles",
        ),
        (
            vec![
                "run".into(),
                "--config".into(),
                SMALL.into(),
                "--vcd".into(),
                "w.vcd".into(),
                "--vcd-signals".into(),
                "z9".into(),
            ],
            "unknown signal \"z9\"",
        ),
        (
            vec![
                "run".into(),
                "--config".into(),
                SMALL.into(),
                "--vcd".into(),
                "w.vcd".into(),
                "--vcd-point".into(),
                "7".into(),
            ],
            "--vcd-point 7",
        ),
        (
            vec![
                "run".into(),
                "--config".into(),
                SMALL.into(),
                "--vcd".into(),
                file.join("w.vcd").display().to_string(),
            ],
            "is not a folder",
        ),
    ];
    for (args, needle) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = gyrocal(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.lines().count() == 1 && err.contains(needle),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn vcd_dump_reads_back_with_the_expected_signals_and_timing() {
    use vcd::{Command as V, Value};
    // The README's command: `--out out/ --vcd out/wave.vcd` with no out/ yet.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let path = out.join("wave.vcd");
    let o = gyrocal(&[
        "run",
        "--config",
        SMALL,
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--vcd",
        path.to_str().unwrap(),
        "--vcd-point",
        "4",
        "--vcd-cycles",
        "9000:11000",
        "--vcd-signals",
        "ports,w1,cic1,x1_pm",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("results.json").exists());
    let mut parser = vcd::Parser::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
    let header = parser.parse_header().unwrap();
    let id = |name: &str| {
        header
            .find_var(&["gyro_interface", name])
            .unwrap_or_else(|| panic!("{name}"))
            .code
    };
    let names = [
        "clock", "adc1", "adc2", "dac1", "dac2", "z1", "z2", "z_valid", "select", "w1", "cic1",
        "x1_pm",
    ];
    let ids: Vec<_> = names.iter().map(|n| id(n)).collect();
    assert!(
        header.find_var(&["gyro_interface", "ref1"]).is_none(),
        "unselected signal dumped"
    );
    let (clock, dac1, z_valid, select, x1) = (ids[0], ids[3], ids[7], ids[8], ids[11]);
    let (mut time, mut rising, mut strobes, mut last_strobe) = (0u64, 0u64, vec![], 0u64);
    let mut max_dac = 0i64;
    let mut x_values = 0;
    for cmd in parser {
        match cmd.unwrap() {
            V::Timestamp(t) => time = t,
            V::ChangeVector(i, v) if i == clock => {
                rising += (v.into_iter().next() == Some(Value::V1)) as u64
            }
            V::ChangeVector(i, v) if i == dac1 => {
                let bits: Vec<Value> = v.into_iter().collect();
                assert_eq!(bits.len(), 16);
                let raw = bits
                    .iter()
                    .fold(0i64, |a, b| 2 * a + (*b == Value::V1) as i64);
                max_dac = max_dac.max(if raw >= 1 << 15 { (1 << 16) - raw } else { raw });
            }
            V::ChangeVector(i, v) if i == z_valid && v.into_iter().next() == Some(Value::V1) => {
                strobes.push(time - last_strobe);
                last_strobe = time;
            }
            V::ChangeVector(i, v) if i == select => assert_eq!(
                v.into_iter().next(),
                Some(Value::V1),
                "point 4 is calibration"
            ),
            V::ChangeReal(i, x) if i == x1 => {
                assert!(x.is_finite());
                x_values += 1;
            }
            _ => {}
        }
    }
    // 2000 clocks of 100 ns at 10 MHz, after the drives start (cycle 8232);
    // z every R = 250 clocks.
    assert_eq!(time, 10999 * 100_000);
    assert_eq!(rising, 2000, "rising clock edges");
    assert!(
        strobes.len() >= 7 && strobes[1..].iter().all(|&d| d == 250 * 100_000),
        "{strobes:?}"
    );
    assert!(max_dac > 20_000 && max_dac <= 32767, "dac1 peak {max_dac}");
    assert!(x_values > 1000);
}

/// `GYROCAL_ISA` naming no instruction set stops any command in one line,
/// exit 2, before it runs; naming each one this processor runs gives the
/// same figures, word for word (the runs compiled for it change speed
/// only).
#[test]
fn the_instruction_set_is_checked_and_changes_no_figure() {
    use gyrocal_hdl::model::isa::Isa;
    let with_isa = |isa: &str, args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_gyrocal"))
            .env("GYROCAL_ISA", isa)
            .args(args)
            .output()
            .unwrap()
    };
    let run = ["run", "--config", SMALL, "--json", "--quiet"];
    let o = with_isa("sse9", &run);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(o.stdout.is_empty());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: GYROCAL_ISA = \"sse9\": not an instruction set; allowed portable"),
        "{err}"
    );
    // Everything but the wall times.
    let figures = |isa: &Isa| {
        let mut v = json_object(with_isa(isa.name(), &run));
        v.as_object_mut().unwrap().remove("timing");
        v
    };
    let isas = Isa::supported_all();
    let first = figures(&isas[0]);
    for isa in &isas[1..] {
        assert_eq!(figures(isa), first, "{isa} against {}", isas[0]);
    }
}
