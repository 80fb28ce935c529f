//! `gyrocal sweep`: a production spread, whole and sharded. The shards run
//! by the repository's Slurm job-array script (with the variables Slurm
//! would set; Slurm is not installed here) and by its GNU parallel script,
//! then merged, give the unsharded report byte for byte. Bad input is
//! refused in one line with exit status 2.

mod common;

use common::{gyrocal, json_object, stderr};
use std::path::Path;
use std::process::Command;

/// The consumer device (tests/data/field_consumer.toml) with a short plan,
/// five parts of a spread that is not the example's.
const SWEEP: &str = "[gyro]\nf1_hz = 25.1e3\nf2_hz = 25.8e3\nq1 = 3000\nq2 = 3000\nangular_gain = 0.8\n\
[drive]\ncarrier_hz = 25.1e3\nclock_hz = 1.2345e6\n\
[experiment]\nreadout_rates_dps = [50, 100]\ncal_freqs_hz = [2, 4]\n\
[spread]\ndevices = 5\nseed = 11\nf1_hz = { sd = 30.0 }\nsplit_hz = { sd = 20.0 }\n\
q1 = { rel_sd = 0.08 }\nq2 = { rel_sd = 0.08 }\nquadrature_dps = { sd = 30.0 }\n";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Run an example script with `envs`; it must succeed.
fn script(path: &str, args: &[&str], envs: &[(&str, &str)]) {
    let o = Command::new("bash")
        .arg(root().join(path))
        .args(args)
        .envs(envs.iter().copied())
        .env("GYROCAL", env!("CARGO_BIN_EXE_gyrocal"))
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{path}: {}\n{}",
        String::from_utf8_lossy(&o.stdout),
        stderr(&o)
    );
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn shards_run_by_slurm_and_gnu_parallel_merge_into_the_unsharded_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("spread.toml");
    std::fs::write(&config, SWEEP).unwrap();
    let config = config.to_str().unwrap();
    let full_dir = dir.path().join("full");
    let full_out = full_dir.display().to_string();
    let o = gyrocal(&["sweep", "--config", config, "--json", "--out", &full_out]);
    let full = String::from_utf8(o.stdout.clone()).unwrap();
    let report = json_object(o);

    // What the report says, checked against itself and the physics.
    let devices = report["devices"].as_array().unwrap();
    assert_eq!(devices.len(), 5);
    let mut within = 0;
    for (i, d) in devices.iter().enumerate() {
        assert_eq!(d["index"], i);
        assert_ne!(d["device"]["f1_hz"], 25.1e3, "device {i} is drawn");
        assert!(d["failed"].as_array().unwrap().is_empty(), "{d}");
        // Every error within 3 of its reported sigmas (the field's
        // coverage test: none beyond 3 over 160 figures).
        for s in d["steps"].as_array().unwrap() {
            for k in 0..2 {
                let e = s["sf_selfcal_error"][k].as_f64().unwrap();
                let sigma = s["selfcal_error_uncertainty"][k].as_f64().unwrap();
                assert!(
                    e.abs() <= 3.0 * sigma,
                    "device {i} output {}: {e} at sigma {sigma}",
                    k + 1
                );
            }
        }
        within += usize::from(d["within_tolerance"].as_bool().unwrap());
    }
    let summary = &report["summary"];
    assert_eq!(summary["yield_both"].as_f64().unwrap(), within as f64 / 5.0);
    assert_eq!(summary["error_percentiles"].as_array().unwrap().len(), 4);
    // Each output's coverage is its steps' (error over sigma), and each
    // step's budget sums to its sigma.
    for k in 0..2 {
        let t: Vec<f64> = devices
            .iter()
            .flat_map(|d| d["steps"].as_array().unwrap())
            .map(|s| {
                let total = s["sf_selfcal_budget"]["total"][k].as_f64().unwrap();
                assert_eq!(total, s["sf_selfcal_uncertainty"][k].as_f64().unwrap());
                s["sf_selfcal_error"][k].as_f64().unwrap()
                    / s["selfcal_error_uncertainty"][k].as_f64().unwrap()
            })
            .collect();
        let c = &summary["coverage_per_output"][k];
        let rms = (t.iter().map(|t| t * t).sum::<f64>() / t.len() as f64).sqrt();
        assert!((c["rms_t"].as_f64().unwrap() - rms).abs() < 1e-12, "{c}");
        assert_eq!(
            (c["errors"].as_u64(), c["parts"].as_u64()),
            (Some(5), Some(5))
        );
        let within = t.iter().filter(|t| t.abs() <= 2.0).count() as f64 / 5.0;
        assert_eq!(c["within_2_sigma"].as_f64().unwrap(), within);
    }
    // Each identified parameter's coverage is its steps' identified value
    // against the step's truth, over its sigma.
    for (key, name) in [("f2_hz", "f2"), ("q1", "q1")] {
        let t: Vec<f64> = devices
            .iter()
            .flat_map(|d| d["steps"].as_array().unwrap())
            .map(|s| {
                let id = &s["identified"];
                (id[key].as_f64().unwrap() - s["truth"][key].as_f64().unwrap())
                    / id[format!("{key}_uncertainty")].as_f64().unwrap()
            })
            .collect();
        let c = summary["coverage_per_parameter"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["parameter"] == name)
            .unwrap_or_else(|| panic!("{name} in {summary}"));
        let rms = (t.iter().map(|t| t * t).sum::<f64>() / t.len() as f64).sqrt();
        assert!((c["rms_t"].as_f64().unwrap() - rms).abs() < 1e-12, "{c}");
        let beyond = t.iter().filter(|t| t.abs() > 3.0).count();
        assert!(beyond as u64 <= summary["parameters_beyond_3_sigma"].as_u64().unwrap());
    }
    assert!(report["shard"].is_null());
    let csv = read(&full_dir.join("sweep.csv"));
    assert_eq!(csv.lines().count(), 1 + 5, "a header and a row per device");
    assert_eq!(read(&full_dir.join("sweep.json")).trim(), full.trim());
    assert!(full_dir.join("fig_sweep.png").exists() && full_dir.join("fig_sweep.svg").exists());

    // Slurm: three array tasks, as `sbatch --array=1-3` would run them,
    // then the merge job.
    let parts = dir.path().join("slurm");
    let out = parts.to_str().unwrap();
    for i in ["1", "2", "3"] {
        script(
            "examples/sweep/slurm.sbatch",
            &[],
            &[
                ("CONFIG", config),
                ("OUT", out),
                ("SLURM_ARRAY_TASK_ID", i),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
        );
    }
    script("examples/sweep/slurm-merge.sbatch", &[], &[("OUT", out)]);
    assert_eq!(
        read(&parts.join("merged.json")),
        full,
        "Slurm shards merged"
    );
    assert!(parts.join("merged/fig_sweep.png").exists());

    // GNU parallel: two shards at once on this machine.
    let par = dir.path().join("parallel");
    script(
        "examples/sweep/parallel.sh",
        &[config, "2", par.to_str().unwrap()],
        &[],
    );
    assert_eq!(
        read(&par.join("merged.json")),
        full,
        "GNU parallel shards merged"
    );

    // Shards that do not make one sweep are refused in one line.
    let shard = |i: u32| {
        parts
            .join(format!("shard-{i}-of-3.json"))
            .display()
            .to_string()
    };
    let foreign = dir.path().join("foreign.json");
    std::fs::write(
        &foreign,
        read(Path::new(&shard(3))).replace("\"fingerprint\":\"", "\"fingerprint\":\"0"),
    )
    .unwrap();
    let refusals = [
        (vec![shard(1), shard(2)], "shard 3/3 is missing"),
        (
            vec![shard(1), shard(2), shard(2)],
            "shard 2/3 is given twice",
        ),
        (
            vec![shard(1), shard(2), foreign.display().to_string()],
            "another file",
        ),
        (
            vec![full_dir.join("sweep.json").display().to_string()],
            "not a shard",
        ),
        (vec![config.to_string()], "not a sweep report"),
    ];
    for (files, what) in refusals {
        let mut args = vec!["sweep".to_string(), "merge".into()];
        args.extend(files);
        let o = gyrocal(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(what), "{what}: {err}");
        assert!(o.stdout.is_empty());
    }
}

/// The sweep of `SWEEP`'s first two parts with `extra` sections: its
/// JSON report.
fn two_parts_json(extra: &str) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("two_parts.toml");
    std::fs::write(&config, SWEEP.replace("devices = 5", "devices = 2") + extra).unwrap();
    json_object(gyrocal(&[
        "sweep",
        "--config",
        config.to_str().unwrap(),
        "--json",
    ]))
}

/// A JSON list of strings.
fn strings(v: &serde_json::Value) -> Vec<&str> {
    let list = v.as_array().unwrap_or_else(|| panic!("not a list: {v}"));
    list.iter().map(|w| w.as_str().unwrap()).collect()
}

/// Any part of a sweep runs again alone: `gyrocal sweep part` prints it as
/// a field file, and `gyrocal field` on that file gives the figures the
/// sweep gave the part, to the bit, at every step: its device, its noise
/// (seeds below 2^63, which a TOML integer holds) and its oscillator.
#[test]
fn a_part_printed_by_sweep_part_runs_alone_to_the_sweeps_figures() {
    let drift = "[drift]\ntemperatures_c = [25, 40]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -31\n";
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("two_parts.toml");
    let text = SWEEP.replace(
        "devices = 5",
        "devices = 2\nclock_error_ppm = { sd = 50.0 }",
    );
    std::fs::write(&config, text + drift).unwrap();
    let config = config.to_str().unwrap();
    let report = json_object(gyrocal(&["sweep", "--config", config, "--json"]));
    let o = gyrocal(&["sweep", "part", "--config", config, "--index", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let part = dir.path().join("part1.toml");
    std::fs::write(&part, &o.stdout).unwrap();
    let field = json_object(gyrocal(&[
        "field",
        "--config",
        part.to_str().unwrap(),
        "--json",
    ]));
    let swept = report["devices"][1]["steps"].as_array().unwrap();
    let alone = field["steps"].as_array().unwrap();
    assert_eq!(swept.len(), 2);
    assert_eq!(alone.len(), 2);
    for (s, f) in swept.iter().zip(alone) {
        assert_eq!(s["temperature_c"], f["temperature_c"]);
        assert_eq!(s["sf_selfcal_error"], f["selfcal_error"], "{s}\n{f}");
        for key in ["sf_selfcal_uncertainty", "sf_true_per_dps"] {
            assert_eq!(s[key], f[key], "{key}");
        }
    }
    // A part the spread does not have: one line, exit status 2, no file.
    let o = gyrocal(&["sweep", "part", "--config", config, "--index", "2"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
    let err = stderr(&o);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("--index 2: the spread has parts 0 to 1"),
        "{err}"
    );
}

#[test]
fn with_a_drift_every_part_runs_every_step() {
    let report = two_parts_json(
        "[drift]\ntemperatures_c = [25, 40]\ntcf1_ppm_per_k = -30\ntcf2_ppm_per_k = -31\n",
    );
    assert_eq!(report["temperatures_c"], serde_json::json!([25.0, 40.0]));
    for d in report["devices"].as_array().unwrap() {
        let steps = d["steps"].as_array().unwrap();
        assert_eq!(steps.len(), 2, "{d}");
        // The worst step is the one with the largest |error|.
        let size = |s: &serde_json::Value| {
            (0..2)
                .map(|k| s["sf_selfcal_error"][k].as_f64().unwrap().abs())
                .fold(0.0, f64::max)
        };
        let worst = steps
            .iter()
            .max_by(|a, b| size(a).total_cmp(&size(b)))
            .unwrap();
        assert_eq!(d["worst_temperature_c"], worst["temperature_c"]);
        assert_eq!(d["sf_selfcal_error"], worst["sf_selfcal_error"]);
        // The field run's warning on the drive-gain ratio is kept, naming
        // exactly the steps where no coupling at rest measured it (the
        // file's datasheet gives no drive_gain_ratio_uncertainty).
        let design: Vec<String> = steps
            .iter()
            .filter(|s| s["identified"]["drive_gain_ratio"].is_null())
            .map(|s| s["temperature_c"].as_f64().unwrap().to_string())
            .collect();
        let lines = strings(&d["warnings"]);
        let ratio: Vec<&&str> = lines
            .iter()
            .filter(|w| w.contains("drive-gain ratio"))
            .collect();
        if design.is_empty() {
            assert!(ratio.is_empty(), "{lines:?}");
        } else {
            let head = format!(
                "warning: at {} deg C the drive-gain ratio",
                design.join(", ")
            );
            assert!(
                ratio.len() == 1 && ratio[0].starts_with(&head),
                "{lines:?}, {head}"
            );
        }
    }
    // The summary names each distinct warning once, with its parts.
    let summary = &report["summary"];
    let lines = strings(&summary["warnings"]);
    let devices = report["devices"].as_array().unwrap();
    let mut distinct: Vec<&str> = devices
        .iter()
        .flat_map(|d| strings(&d["warnings"]))
        .collect();
    distinct.sort_unstable();
    distinct.dedup();
    for w in &distinct {
        let carriers = devices
            .iter()
            .filter(|d| d["warnings"].as_array().unwrap().iter().any(|x| x == w))
            .count();
        let text = w.strip_prefix("warning: ").unwrap();
        let line = format!("warning: {carriers} of 2 parts (device ");
        assert!(
            lines
                .iter()
                .any(|l| l.starts_with(&line) && l.ends_with(text)),
            "{lines:?} lacks {line}...{text}"
        );
    }
    let beyond = summary["beyond_3_sigma"].as_u64().unwrap();
    let named = lines
        .iter()
        .filter(|l| l.contains("beyond 3 of their reported sigmas"));
    assert_eq!(named.count(), usize::from(beyond > 0), "{lines:?}");
    assert_eq!(
        lines.len(),
        distinct.len() + usize::from(beyond > 0),
        "{lines:?}"
    );
}

#[test]
fn bad_sweep_input_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            SWEEP.split("[spread]").next().unwrap().to_string(),
            "missing [spread]",
        ),
        (
            SWEEP.replace("devices = 5", "devices = 0"),
            "[spread] devices = 0",
        ),
        (
            SWEEP.replace("q1 = { rel_sd = 0.08 }", "q1 = { rel_sd = 0.8 }"),
            "q1.rel_sd = 0.8",
        ),
        (
            SWEEP.replace("q1 = { rel_sd = 0.08 }", "q1 = { sd = 3, rel_sd = 0.1 }"),
            "exactly one",
        ),
        (
            SWEEP.replace(
                "quadrature_dps = { sd = 30.0 }",
                "quadrature_dps = { rel_sd = 0.1 }",
            ),
            "give `sd`",
        ),
        (
            SWEEP.replace("seed = 11", "seed = 11\nq3 = { sd = 1 }"),
            "q3",
        ),
        (SWEEP.replace("q1 = 3000", "q1 = -3"), "q1"),
    ];
    for (i, (text, what)) in cases.iter().enumerate() {
        let config = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&config, text).unwrap();
        let o = gyrocal(&[
            "sweep",
            "--config",
            config.to_str().unwrap(),
            "--out",
            dir.path().join("out").to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "case {i}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "case {i}: {err}");
        assert!(err.contains(what), "case {i} ({what}): {err}");
        assert!(!dir.path().join("out").exists(), "nothing written");
    }
    // A shard that is not I/N with 1 <= I <= N.
    let config = dir.path().join("good.toml");
    std::fs::write(&config, SWEEP).unwrap();
    for shard in ["0/3", "4/3", "2", "x/y"] {
        let o = gyrocal(&[
            "sweep",
            "--config",
            config.to_str().unwrap(),
            "--shard",
            shard,
        ]);
        assert_eq!(o.status.code(), Some(2), "{shard}");
        assert!(stderr(&o).contains("give I/N"), "{}", stderr(&o));
    }
    // `field` runs one device: it refuses [spread], and needs [drift].
    let o = gyrocal(&["field", "--config", config.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("[spread] is read by `gyrocal sweep`"),
        "{}",
        stderr(&o)
    );
    std::fs::write(&config, SWEEP.split("[spread]").next().unwrap()).unwrap();
    let o = gyrocal(&["field", "--config", config.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("missing [drift]"), "{}", stderr(&o));
}

/// Parts whose datasheet lambda is 10% low, claimed within 1%: every
/// error lies beyond 3 sigma. The summary names them by part in its one
/// line; the parts' own field line saying the same is not carried as well.
/// The quadrature coupling, read in deg/s through that lambda, lies
/// beyond 3 too, and its line names the datasheet's lambda.
#[test]
fn uncovered_errors_are_named_once_by_part() {
    let report = two_parts_json(
        "[datasheet]\nangular_gain = 0.72\nangular_gain_uncertainty = 0.01\n\
         drive_gain_ratio_uncertainty = 0.005\n",
    );
    let warnings = strings(&report["summary"]["warnings"]);
    let parameters: Vec<&&str> = warnings
        .iter()
        .filter(|w| w.contains("identified parameters lie beyond 3"))
        .collect();
    assert_eq!(parameters.len(), 1, "{warnings:#?}");
    assert!(
        parameters[0].contains("device 0 at 25 deg C quadrature (+")
            && parameters[0].contains("device 1 at 25 deg C quadrature (+")
            && parameters[0]
                .ends_with("through [datasheet] angular_gain, within its angular_gain_uncertainty"),
        "{}",
        parameters[0]
    );
    let beyond: Vec<&&str> = warnings
        .iter()
        .filter(|w| w.contains("errors lie beyond 3"))
        .collect();
    assert_eq!(beyond.len(), 1, "{warnings:#?}");
    assert!(
        beyond[0].starts_with("warning: 4 of 4 errors lie beyond 3")
            && beyond[0].contains("device 0 at 25 deg C output 1 (-")
            && beyond[0].contains("device 1 at 25 deg C output 2 (-"),
        "{}",
        beyond[0]
    );
    assert_eq!(report["summary"]["beyond_3_sigma"], 4);
}

/// Each part's board runs its own oscillator (`[spread] clock_error_ppm`,
/// sd 250 ppm around an exact clock) within the 1000 ppm the host is told
/// (`[drive] clock_tolerance_ppm`): each part records its draw (the same
/// with the tolerance or without), its sigmas grow by the clock's term
/// (`selfcal::budget::clock`), and every figure lies within 3 of them.
#[test]
fn a_spread_of_oscillators_is_in_each_parts_sigma() {
    let run = |tolerance: f64| {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("clocks.toml");
        let text = SWEEP.replace("devices = 5", "devices = 2").replace(
            "clock_hz = 1.2345e6",
            &format!("clock_hz = 1.2345e6\nclock_tolerance_ppm = {tolerance}"),
        ) + "clock_error_ppm = { sd = 250.0 }\n";
        std::fs::write(&config, text).unwrap();
        let report = json_object(gyrocal(&[
            "sweep",
            "--config",
            config.to_str().unwrap(),
            "--json",
        ]));
        let devices = report["devices"].as_array().unwrap().clone();
        let clocks: Vec<f64> = devices
            .iter()
            .map(|d| d["clock_error_ppm"].as_f64().unwrap())
            .collect();
        let figures: Vec<(f64, f64)> = devices
            .iter()
            .flat_map(|d| d["steps"].as_array().unwrap().clone())
            .flat_map(|s| {
                (0..2)
                    .map(|k| {
                        (
                            s["sf_selfcal_error"][k].as_f64().unwrap(),
                            s["selfcal_error_uncertainty"][k].as_f64().unwrap(),
                        )
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        (clocks, figures)
    };
    let (clocks, told) = run(1000.0);
    let (same, untold) = run(0.0);
    assert_eq!(clocks, same);
    assert!(
        clocks.iter().all(|c| *c != 0.0 && c.abs() < 1000.0) && clocks[0] != clocks[1],
        "{clocks:?}"
    );
    assert_eq!(told.len(), 4);
    for ((e, sigma), (_, without)) in told.iter().zip(&untold) {
        assert!(sigma > without, "{told:?} {untold:?}");
        assert!(
            e.abs() <= 3.0 * sigma,
            "{e} at {sigma}, clocks {clocks:?} ppm"
        );
    }
}

/// Every example spread (`examples/sweep/*.toml`) is accepted: its first
/// part is drawn and printed as a field file that `gyrocal field` would
/// take (`sweep part`), so an example cannot rot unseen.
#[test]
fn every_example_spread_gives_its_parts() {
    let mut examples: Vec<_> = std::fs::read_dir(root().join("examples/sweep"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    examples.sort();
    assert!(examples.len() >= 2, "{examples:?}");
    for example in examples {
        let config = example.to_str().unwrap();
        let o = gyrocal(&["sweep", "part", "--config", config, "--index", "0"]);
        assert!(o.status.success(), "{config}: {}", stderr(&o));
        let part = String::from_utf8(o.stdout).unwrap();
        assert!(
            part.contains("[gyro]") && part.contains("[experiment]"),
            "{config}: {part}"
        );
    }
}

/// A family no sigma was tuned on (`examples/sweep/low_q_wide_split.toml`,
/// docs/sweep.md, "Two more families not tuned on"): 40 low-Q parts split
/// by 19 to 28 of their mean bandwidth, 35 of them beyond the 20 that
/// `tests/supported_ranges.rs` plans, with quadrature couplings of some
/// tens of deg/s. Every part is identified and calibrated; no output
/// error and no identified figure lies beyond 3 of its sigmas; at least
/// 90% of the 80 output errors lie within 2. Why each can fail: honest
/// sigmas put 95.4% within 2, so fewer than 72 of 80 (2.3 binomial
/// deviations below the 76.3 expected) about 1% of the time; and a figure
/// beyond 3 with 0.27% each, so the 80 outputs and 240 identified figures
/// (f, Q, couplings) hold none beyond in 42% of draws. These draws are
/// fixed, and they hold (measured 97.5% within 2, largest |t| 2.5); a
/// sigma that loses a term shows here as a figure beyond 3.
#[test]
fn a_low_q_family_split_beyond_the_planned_range_is_covered() {
    let config = root().join("examples/sweep/low_q_wide_split.toml");
    let v = json_object(gyrocal(&[
        "sweep",
        "--config",
        config.to_str().unwrap(),
        "--json",
    ]));
    let summary = &v["summary"];
    assert_eq!(summary["devices"], 40, "{summary}");
    assert_eq!(summary["failed"], 0, "{summary}");
    assert_eq!(summary["beyond_3_sigma"], 0, "{summary}");
    assert_eq!(summary["parameters_beyond_3_sigma"], 0, "{summary}");
    let within = summary["within_2_sigma"].as_f64().unwrap();
    assert!(within >= 0.9, "{within} of the outputs within 2 sigma");
    let parameters = summary["coverage_per_parameter"].as_array().unwrap();
    assert_eq!(parameters.len(), 6, "{parameters:?}");
    for p in parameters {
        assert_eq!(p["parts"], 40, "{p}");
    }
}

/// Part 0 of `examples/sweep/consumer.toml` (f1 21 Hz, two bandwidths,
/// below the carrier) on the line's one board, sized for the nominal
/// device (`gyrocal_sim::sweep`, "One board for every part"). On a board
/// sized for itself at the configured carrier, where it answers less than
/// at its mode, its cycle ran the drives at 0.24 of full scale, 0.27 of
/// the configured 0.9 (a line said so), and output 2's sigma was 1.03%.
/// On the nominal's board it runs them unscaled and output 2's sigma is
/// 0.24%. Asserted: the `sweep part` file runs alone, its drives not
/// scaled, output 2's sigma under 0.5% (twice the measured, half the
/// part-sized board's), both outputs within 3 sigma. About 1 s.
#[test]
fn a_part_off_the_carrier_runs_on_the_nominal_devices_board() {
    use gyrocal_sim::field::scenario;
    let path = root().join("examples/sweep/consumer.toml");
    let sweep = gyrocal_sim::sweep::parse("consumer.toml", &read(&path)).unwrap();
    let part = scenario::parse("part0.toml", &sweep.part_file(0).unwrap()).unwrap();
    let report = scenario::run(&part, &|_| {}).unwrap();
    assert!(report.failed.is_empty(), "{:?}", report.failed);
    let st = &report.steps[0];
    let op = &st.selfcal.operating;
    assert_eq!(op.scaled_drives, None, "{:?}", op.amplitude);
    assert!(
        st.sf_selfcal_uncertainty[1] < 5e-3,
        "{:?}",
        st.sf_selfcal_uncertainty
    );
    common::outputs_within_three_sigma("part 0", st);
}
