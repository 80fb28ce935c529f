//! The uncertainties are honest: over many runs of random devices, the
//! exact theory lies within 2 and 3 reported sigmas as often as promised,
//! and no sigma is inflated far beyond the errors it describes.
//!
//! Runs. 40 devices drawn by `common/random_device.rs` from seeds 1001..
//! 1040 in its `FAST` span (10 kHz..10 MHz, Q 100..1e4, split 0..20
//! bandwidths either sign, carrier at a mode or between, clock 2.6 to 40
//! carriers, 2..8 rates and 2..6 calibration frequencies), keeping those
//! whose first round is at most `MAX_FIRST_CYCLES` (a seed whose device
//! is dearer is drawn again from seed x 1000 + 1, + 2, ...): none is a
//! device the budget was tuned on (seeds 1..45 of the wide span). Required
//! keys only, plus `tolerance = 1e-2` and a budget that never binds, so a
//! run's rounds (and the test) do not depend on the machine's load. Then
//! the first `SPREAD_DEVICES` devices again with dither seeds 2..=8.
//!
//! Each run gives six figures, SF_read, SF_cal and the ratio of both
//! outputs, and t = (simulated - exact theory) / reported sigma for each.
//!
//! Assertions (issue 20 section 1), and why they can fail. The reported
//! sigma is the budget's total (`gyrocal_sim::budget`): its statistical
//! term carries the coverage factor of its degrees of freedom (1.51 at the
//! readout's 7), and the systematic terms add in quadrature.
//! - Between 90% and 99.5% of all t within 2. Expected: 95.4% if every
//!   sigma were a normal's, 98.1% if every figure were a t with 7 degrees
//!   of freedom over its coverage factor (|t7| <= 3.02); the runs mix both.
//!   A sigma 1.5 times too small (a missing systematic of the size of the
//!   statistics) puts 81% of a normal within 2; sigmas twice too large put
//!   99.99% within 2. The figures of one run are correlated (a ratio's
//!   error is mostly its SF_read's or its SF_cal's), so the 366 count as
//!   about 180 trials: a binomial standard deviation of 1.3% at 97%,
//!   and 90% lies 5 of them below it.
//! - Every t within 3: a systematic the budget misses puts its runs far
//!   outside (before this budget, 5 of 20 ratios lay 3.4 to 11.6 sigma
//!   from the theory), and the bare batch spread without its coverage
//!   factor leaves 2% of a t7 beyond 3 (7 of 366). For a calibrated sigma
//!   each figure has a 0.27% chance (1 expected in 366 if they were
//!   independent normals, fewer here since the batch spread errs high on
//!   deterministic residues), so this is a guard on the pinned seeds: it
//!   holds on them (largest |t| 2.93) and other seeds may need a look
//!   before they are pinned.
//! - No sigma inflated: for each figure, the RMS of t over all runs is at
//!   least 0.2 (the sigmas at most 5 times the errors, on average); an
//!   honest set gives 0.78 to 1 (a t7, standard deviation 1.18, over its
//!   coverage factor 1.51; a normal), and the RMS of 61 such t falls
//!   below 0.2 (a mean square 15 times below its expectation) with a
//!   probability far below 1e-9.
//! - Spread: for each of the `SPREAD_DEVICES` devices and each figure,
//!   the mean reported sigma over its 8 dither seeds is at most 5 times
//!   the root mean square of its 8 errors (the spread it describes,
//!   systematic shifts included). For an honest sigma the ratio is about
//!   1.5 (the coverage factor at 7 degrees of freedom); the RMS of 8
//!   errors falls below 0.3 of its expectation with probability 5e-4
//!   (chi-square, 8 degrees of freedom, below 0.72), 1% over the 18.
//!
//! `survey` (ignored) prints one JSON line per device of the wide span
//! (10 kHz..10 MHz, Q 100..1e5, required keys only) for exploring, and
//! `device_file` the configuration of one coverage device:
//!
//! ```sh
//! GYROCAL_SURVEY_SEEDS=1..45 cargo test --release --test uncertainty_is_honest -- --ignored --nocapture survey
//! GYROCAL_DEVICE=1001 cargo test --release --test uncertainty_is_honest -- --ignored --nocapture device_file
//! ```

#[path = "common/random_device.rs"]
mod random_device;

use gyrocal_sim::config;
use gyrocal_sim::engine::EngineKind;
use gyrocal_sim::experiment::plan;
use gyrocal_sim::report::{Report, run};
use random_device::{FAST, RandomDevice, WIDE};
use rayon::prelude::*;
use serde_json::json;

/// Devices of the coverage runs.
const SEEDS: std::ops::Range<u64> = 1001..1041;
/// The first this many are run again with dither seeds 2..=8.
const SPREAD_DEVICES: usize = 3;
/// Dither seeds of the spread runs.
const DITHER_SEEDS: std::ops::RangeInclusive<u64> = 1..=8;
/// Most clocks of a device's first round (about a second on one core).
const MAX_FIRST_CYCLES: u64 = 6_000_000;
/// What the runs add to the required keys.
const EXTRA: &str = "tolerance = 1e-2\nbudget_s = 10000\n";

/// The device of `seed` in `FAST` whose first round fits `MAX_FIRST_CYCLES`.
fn device(seed: u64) -> RandomDevice {
    (0..)
        .map(|attempt| match attempt {
            0 => seed,
            a => seed * 1000 + a,
        })
        .map(|s| RandomDevice::draw(s, FAST))
        .find(|d| {
            let e = config::parse("random.toml", &d.toml(EXTRA)).unwrap();
            plan(&e).unwrap().total_cycles() <= MAX_FIRST_CYCLES
        })
        .unwrap()
}

/// Run `d` with dither seed `dither`.
fn run_device(d: &RandomDevice, dither: u64) -> Report {
    let text = format!("{}[frontend]\nseed = {dither}\n", d.toml(EXTRA));
    let e = config::parse("random.toml", &text).unwrap();
    run(&e, EngineKind::Model, &|_| {}).unwrap()
}

/// One run: its device's index in `SEEDS` and `errors`.
struct Run {
    device: usize,
    errors: [(f64, f64); 6],
}

/// Figure names, in the order of `errors`.
const FIGURES: [&str; 6] = [
    "ratio 1",
    "ratio 2",
    "SF_read 1",
    "SF_read 2",
    "SF_cal 1",
    "SF_cal 2",
];

/// (simulated - exact, reported sigma) of each figure of a run.
fn errors(r: &Report) -> [(f64, f64); 6] {
    let pair = |m: [f64; 2], x: [f64; 2], s: [f64; 2], k: usize| (m[k] - x[k], s[k]);
    let t = &r.theory;
    [
        pair(
            r.scale_factors.ratio,
            t.ratio,
            r.scale_factors.ratio_uncertainty,
            0,
        ),
        pair(
            r.scale_factors.ratio,
            t.ratio,
            r.scale_factors.ratio_uncertainty,
            1,
        ),
        pair(
            r.scale_factors.sf_read_per_dps,
            t.sf_read_per_dps,
            r.scale_factors.sf_read_uncertainty,
            0,
        ),
        pair(
            r.scale_factors.sf_read_per_dps,
            t.sf_read_per_dps,
            r.scale_factors.sf_read_uncertainty,
            1,
        ),
        pair(
            r.scale_factors.sf_cal_per_dps,
            t.sf_cal_per_dps,
            r.scale_factors.sf_cal_uncertainty,
            0,
        ),
        pair(
            r.scale_factors.sf_cal_per_dps,
            t.sf_cal_per_dps,
            r.scale_factors.sf_cal_uncertainty,
            1,
        ),
    ]
}

/// One line per run: the device and its t values.
fn describe(d: &RandomDevice, dither: u64, r: &Report, e: &[(f64, f64); 6]) -> String {
    let t: Vec<String> = e.iter().map(|(x, s)| format!("{:+5.2}", x / s)).collect();
    format!(
        "seed {:>7} dither {dither}: {}, {} rounds {:.1e} clocks: t = {}",
        d.seed,
        d.summary(),
        r.timing.rounds,
        r.timing.cycles as f64,
        t.join(" ")
    )
}

#[test]
fn the_exact_theory_lies_within_the_reported_sigmas_as_promised() {
    let devices: Vec<RandomDevice> = SEEDS.map(device).collect();
    let mut jobs: Vec<(usize, u64)> = (0..devices.len()).map(|i| (i, 1)).collect();
    for i in 0..SPREAD_DEVICES {
        jobs.extend(DITHER_SEEDS.skip(1).map(|s| (i, s)));
    }
    let runs: Vec<Run> = jobs
        .par_iter()
        .map(|&(i, dither)| {
            let r = run_device(&devices[i], dither);
            let e = errors(&r);
            eprintln!("{}", describe(&devices[i], dither, &r, &e));
            Run {
                device: i,
                errors: e,
            }
        })
        .collect();
    let t: Vec<f64> = runs
        .iter()
        .flat_map(|r| r.errors.iter().map(|(x, s)| x / s))
        .collect();
    print_distribution(&t);
    let within = |n: f64| t.iter().filter(|x| x.abs() <= n).count();
    let in2 = within(2.0) as f64 / t.len() as f64;
    assert!(
        (0.90..=0.995).contains(&in2),
        "{:.1}% within 2 sigma",
        100.0 * in2
    );
    assert_eq!(within(3.0), t.len(), "figures beyond 3 sigma");
    for (k, rms) in rms_by_figure(&runs).into_iter().enumerate() {
        assert!(
            rms >= 0.2,
            "{}: RMS error / sigma {rms:.2} over all runs",
            FIGURES[k]
        );
    }
    for (i, k, ratio) in spread_ratios(&runs) {
        assert!(
            ratio <= 5.0,
            "device {}, {}: sigma {ratio:.2} x the RMS error",
            devices[i].seed,
            FIGURES[k]
        );
    }
}

/// Print the distribution of the signed t = error / sigma: counts within
/// 1, 2, 3, and a histogram in half-sigma bins.
fn print_distribution(t: &[f64]) {
    let within = |n: f64| t.iter().filter(|x| x.abs() <= n).count();
    let n = t.len();
    let mean = t.iter().sum::<f64>() / n as f64;
    let rms = (t.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
    eprintln!(
        "{n} figures: within 1 sigma {} ({:.1}%), 2 sigma {} ({:.1}%), 3 sigma {}; \
         mean t {mean:+.3}, RMS t {rms:.3}, largest |t| {:.2}",
        within(1.0),
        100.0 * within(1.0) as f64 / n as f64,
        within(2.0),
        100.0 * within(2.0) as f64 / n as f64,
        within(3.0),
        t.iter().map(|x| x.abs()).fold(0.0, f64::max)
    );
    let bins: Vec<String> = (-7..7)
        .map(|i| {
            let (lo, hi) = (f64::from(i) * 0.5, f64::from(i + 1) * 0.5);
            let c = t
                .iter()
                .filter(|x| match i {
                    -7 => **x < hi,
                    6 => **x >= lo,
                    _ => (lo..hi).contains(*x),
                })
                .count();
            match i {
                -7 => format!("t < {hi}: {c}"),
                6 => format!("t >= {lo}: {c}"),
                _ => format!("[{lo:+}, {hi:+}): {c}"),
            }
        })
        .collect();
    eprintln!("error / sigma histogram: {}", bins.join(", "));
}

/// For each figure: the RMS of t over all runs (1 / (how many times the
/// sigmas exceed the errors they describe), on average).
fn rms_by_figure(runs: &[Run]) -> [f64; 6] {
    std::array::from_fn(|k| {
        let sum: f64 = runs
            .iter()
            .map(|r| (r.errors[k].0 / r.errors[k].1).powi(2))
            .sum();
        let rms = (sum / runs.len() as f64).sqrt();
        eprintln!("{}: RMS t {rms:.3} over {} runs", FIGURES[k], runs.len());
        rms
    })
}

/// For each spread device and figure: mean reported sigma over the RMS
/// error of its runs.
fn spread_ratios(runs: &[Run]) -> Vec<(usize, usize, f64)> {
    let mut out = vec![];
    for i in 0..SPREAD_DEVICES {
        let mine: Vec<&[(f64, f64); 6]> = runs
            .iter()
            .filter(|r| r.device == i)
            .map(|r| &r.errors)
            .collect();
        for k in 0..6 {
            let m = mine.len() as f64;
            let rms = (mine.iter().map(|e| e[k].0 * e[k].0).sum::<f64>() / m).sqrt();
            let sigma = mine.iter().map(|e| e[k].1).sum::<f64>() / m;
            eprintln!(
                "device {i}, {}: mean sigma {sigma:.3e}, RMS error {rms:.3e} over {} runs, ratio {:.2}",
                FIGURES[k],
                mine.len(),
                sigma / rms
            );
            out.push((i, k, sigma / rms));
        }
    }
    out
}

/// (simulated - exact) / sigma and simulated / exact - 1 of a figure.
fn misses(m: [f64; 2], s: [f64; 2], x: [f64; 2]) -> serde_json::Value {
    json!({
        "t": [(m[0] - x[0]) / s[0], (m[1] - x[1]) / s[1]],
        "rel": [m[0] / x[0] - 1.0, m[1] / x[1] - 1.0],
        "rel_sigma": [s[0] / x[0].abs(), s[1] / x[1].abs()],
    })
}

#[test]
#[ignore = "exploration, run by hand (module header)"]
fn survey() {
    let seeds = std::env::var("GYROCAL_SURVEY_SEEDS").unwrap_or("1..4".into());
    let (a, b) = seeds.split_once("..").expect("GYROCAL_SURVEY_SEEDS=a..b");
    let extra = std::env::var("GYROCAL_SURVEY_EXTRA")
        .unwrap_or_default()
        .replace("\\n", "\n");
    for seed in a.parse::<u64>().unwrap()..b.parse::<u64>().unwrap() {
        let d = RandomDevice::draw(seed, WIDE);
        let e = config::parse("random.toml", &d.toml(&extra)).unwrap();
        let r = run(&e, EngineKind::Model, &|_| {}).unwrap();
        let line = json!({
            "seed": d.seed, "f": d.f_hz, "q": d.q, "carrier": d.carrier_hz,
            "clock": d.clock_hz, "lambda": d.lambda, "rates": d.rates_dps, "cals": d.cal_hz,
            "cycles": r.timing.cycles, "wall_s": r.timing.wall_s, "rounds": r.timing.rounds,
            "warnings": r.warnings,
            "ratio": misses(r.scale_factors.ratio, r.scale_factors.ratio_uncertainty, r.theory.ratio),
            "sf_read": misses(r.scale_factors.sf_read_per_dps, r.scale_factors.sf_read_uncertainty, r.theory.sf_read_per_dps),
            "sf_cal": misses(r.scale_factors.sf_cal_per_dps, r.scale_factors.sf_cal_uncertainty, r.theory.sf_cal_per_dps),
            "budget": r.uncertainty_budget, "images": r.theory.images,
        });
        eprintln!("{line}");
    }
}

/// The configuration file of coverage device `GYROCAL_DEVICE` (a seed of
/// `SEEDS`), to rerun it with `gyrocal run --config`.
#[test]
#[ignore = "prints a device, run by hand"]
fn device_file() {
    let seed: u64 = std::env::var("GYROCAL_DEVICE")
        .expect("GYROCAL_DEVICE=seed")
        .parse()
        .unwrap();
    println!("{}", device(seed).toml(EXTRA));
}
