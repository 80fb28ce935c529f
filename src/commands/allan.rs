//! `gyrocal allan --config FILE.toml [--seconds S] [--rate-dps R] [--json]
//! [--out DIR]`: the noise floor of the readout's rate output.
//!
//! Reads the same file as `gyrocal run` (its `[noise]` section sets the
//! Brownian force noise, `[frontend] noise_lsb` the ADC's), predicts each
//! output's rate-noise density and angle random walk from the noise model
//! (`gyrocal_sim::rate_noise`), runs the readout at one constant rate for
//! `S` simulated seconds on the model engine, and prints the angle random
//! walk and bias instability measured beside the prediction. With `--out`
//! it writes `allan.json`, `allan.csv` (tau and both outputs' deviations,
//! measured and predicted) and one figure per output
//! (`allan_output1.png/.svg`, `allan_output2.png/.svg`). Every option and
//! the file are checked before the run: bad input is one line on stderr,
//! exit status 2, and nothing is written.

use crate::Failure;
use gyrocal_sim::config::Experiment;
use gyrocal_sim::rate_noise::{self, NoisyRun, RateNoisePrediction};
use std::path::{Path, PathBuf};

/// Default run length (simulated s): the reading at tau = 1 s then has
/// about 1.5 x 310 = 463 equivalent degrees of freedom (white rate noise),
/// a relative standard deviation of 1 / sqrt(2 x 463) = 3.3 %, so 10 % is
/// 3 sigma.
pub const DEFAULT_SECONDS: f64 = 310.0;

/// Options of `gyrocal allan`.
#[derive(clap::Args)]
pub struct Args {
    /// Device and noise description (TOML: the sections of `gyrocal run`
    /// plus `[noise]` mass_kg, temperature_k, seed).
    #[arg(long)]
    pub config: PathBuf,
    /// Simulated seconds of rate output after the settling.
    #[arg(long, default_value_t = DEFAULT_SECONDS)]
    pub seconds: f64,
    /// The constant rotation rate of the run (deg/s).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub rate_dps: f64,
    /// Print one JSON object (prediction and run) to stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Write allan.json, allan.csv and the figures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Do not show a progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// What `--json` prints and `allan.json` holds ([`AllanReport::json`]).
struct AllanReport<'a> {
    config: String,
    experiment: &'a Experiment,
    prediction: &'a RateNoisePrediction,
    run: &'a NoisyRun,
    /// The prediction's Allan deviation at each measured tau, per output (deg/s).
    predicted_adev_dps: [Vec<f64>; 2],
}

impl AllanReport<'_> {
    /// One JSON object: config, experiment, prediction, run and the
    /// predicted deviations.
    fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "config": self.config,
            "experiment": self.experiment,
            "prediction": self.prediction,
            "run": self.run,
            "predicted_adev_dps": self.predicted_adev_dps,
        })
    }
}

/// Run the noisy readout and report its Allan deviation.
pub fn run(args: &Args) -> Result<(), Failure> {
    let exp = super::experiment::load_experiment(&args.config)?;
    rate_noise::check_seconds(args.seconds).map_err(Failure::input)?;
    let max_rate = gyrocal_sim::config::MAX_RATE_DPS;
    if !(args.rate_dps.is_finite() && args.rate_dps.abs() <= max_rate) {
        return Err(Failure::Input(format!(
            "--rate-dps {}: allowed -{max_rate} to {max_rate} deg/s",
            args.rate_dps
        )));
    }
    if let Some(dir) = &args.out {
        check_folder(dir)?;
    }
    let (plan, prediction) =
        rate_noise::plan_and_predict(&exp, args.rate_dps).map_err(Failure::input)?;
    for w in &plan.warnings {
        eprintln!("warning: {w}");
    }
    if !exp.noise.is_on() {
        eprintln!("note: [noise] temperature_k is 0: no Brownian noise, the ADC's alone");
    }
    let total = plan.points[0].settle_cycles + (args.seconds * exp.drive.clock_hz).ceil() as u64;
    let bar = super::progress_bar(
        args.quiet,
        total,
        "{spinner} noisy readout [{bar:40}] {percent:>3}%  {human_pos}/{human_len} clocks  {per_sec}  eta {eta}",
    );
    let tick = |n: u64| bar.inc(n);
    let run = rate_noise::run_noisy(&exp, &plan, args.rate_dps, args.seconds, &tick)
        .map_err(Failure::run)?;
    bar.finish_and_clear();
    let predicted_adev_dps = std::array::from_fn(|k| {
        run.outputs[k]
            .analysis
            .points
            .iter()
            .map(|p| prediction.adev(k, p.tau_s))
            .collect()
    });
    let report = AllanReport {
        config: args.config.display().to_string(),
        experiment: &exp,
        prediction: &prediction,
        run: &run,
        predicted_adev_dps,
    };
    if let Some(dir) = &args.out {
        for path in write_outputs(&report, dir)? {
            eprintln!("wrote {}", path.display());
        }
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&report.json()).map_err(|e| Failure::Run(e.to_string()))?
        );
    } else {
        print!("{}", summary(&report));
    }
    Ok(())
}

/// `dir` may not exist yet; its nearest existing ancestor must be a folder
/// (also `gyrocal datasheet`'s check).
pub(super) fn check_folder(dir: &Path) -> Result<(), Failure> {
    match dir
        .ancestors()
        .find(|a| a.as_os_str().is_empty() || a.exists())
    {
        Some(a) if !a.as_os_str().is_empty() && !a.is_dir() => Err(Failure::Input(format!(
            "--out {}: {} is not a folder",
            dir.display(),
            a.display()
        ))),
        _ => Ok(()),
    }
}

/// One row per tau: measured and predicted deviations of both outputs.
fn csv(report: &AllanReport) -> String {
    let mut s = String::from(
        "tau_s,adev1_dps,adev2_dps,predicted_adev1_dps,predicted_adev2_dps,white_rate_edf\n",
    );
    let [a, b] = &report.run.outputs;
    let n = (report.run.seconds * report.run.series_rate_hz).round() as usize;
    for (i, (p, q)) in a.analysis.points.iter().zip(&b.analysis.points).enumerate() {
        s.push_str(&format!(
            "{},{:e},{:e},{:e},{:e},{}\n",
            p.tau_s,
            p.adev,
            q.adev,
            report.predicted_adev_dps[0][i],
            report.predicted_adev_dps[1][i],
            gyrocal_sim::allan::white_rate_edf(n, p.cluster)
        ));
    }
    s
}

/// Write allan.json, allan.csv and the two figures into `dir`.
fn write_outputs(report: &AllanReport, dir: &Path) -> Result<Vec<PathBuf>, Failure> {
    let json =
        serde_json::to_string_pretty(&report.json()).map_err(|e| Failure::Run(e.to_string()))?;
    let mut written = super::experiment::write_files(
        dir,
        vec![("allan.json", json), ("allan.csv", csv(report))],
    )?;
    for k in 0..2 {
        let analysis = &report.run.outputs[k].analysis;
        let curve: Vec<(f64, f64)> = analysis
            .points
            .iter()
            .zip(&report.predicted_adev_dps[k])
            .map(|(p, &s)| (p.tau_s, s))
            .collect();
        let o = &report.prediction.outputs[k];
        let label = format!(
            "predicted from the noise model: N = {:.4} °/√h (Brownian {:.1} %, ADC {:.1} % of the density)",
            o.arw_deg_per_sqrt_h,
            100.0 * o.thermal_rate_psd / o.rate_psd,
            100.0 * o.adc_rate_psd / o.rate_psd
        );
        let title = format!(
            "Allan deviation of output {}, readout at {} °/s, {} s",
            k + 1,
            report.run.rate_dps,
            report.run.seconds
        );
        let name = format!("allan_output{}", k + 1);
        written.extend(
            crate::plots::write_allan_figure_with_prediction(
                analysis, &curve, &label, &title, dir, &name,
            )
            .map_err(Failure::run)?,
        );
    }
    Ok(written)
}

/// Human summary: prediction and measurement side by side.
fn summary(report: &AllanReport) -> String {
    let run = report.run;
    let p = report.prediction;
    let mut s = format!(
        "noisy readout at {} deg/s: {} s after {:.3} s settling, {} clocks in {:.1} s; rate series at {:.1} Hz\n",
        run.rate_dps, run.seconds, run.settle_s, run.cycles, run.wall_s, run.series_rate_hz
    );
    s.push_str(&format!(
        "noise: {} K, mass {:e} kg (Brownian); ADC {} LSB rms + quantization step {} LSB\n",
        p.thermal.temperature_k, p.thermal.mass_kg, p.adc_noise_lsb, p.adc_step_lsb
    ));
    s.push_str("                                              output 1          output 2\n");
    let row = |(name, v): (&str, [f64; 2])| format!("{name:<40}{:>16.5}  {:>16.5}\n", v[0], v[1]);
    noise_rows(run, p)
        .into_iter()
        .for_each(|r| s.push_str(&row(r)));
    let at_longest = (0..2).any(|k| {
        let a = &run.outputs[k].analysis;
        a.points.last().map(|p| p.tau_s) == Some(a.bias_instability.tau_s)
    });
    if at_longest {
        s.push_str(
            "  (minimum at the longest tau: no floor reached in this run, an upper bound)\n",
        );
    }
    s.push_str(&row((
        "mean rate less the applied (deg/s)",
        both(|k| run.outputs[k].mean_rate_dps - run.rate_dps),
    )));
    s.push_str(&row((
        "scale factor (z LSB per deg/s)",
        both(|k| p.outputs[k].sf_lsb_per_dps),
    )));
    s
}

/// `f` of output 0 and output 1.
fn both(f: impl Fn(usize) -> f64) -> [f64; 2] {
    [f(0), f(1)]
}

/// The summary's noise rows, predicted against measured: the angle
/// random walk three ways, its fit, and the bias instability.
fn noise_rows(run: &NoisyRun, p: &RateNoisePrediction) -> [(&'static str, [f64; 2]); 10] {
    let predicted_at_1s = |k: usize| {
        let tau = run.outputs[k].arw_at_1s.tau_s;
        60.0 * p.adev(k, tau) * tau.sqrt()
    };
    let fitted = |k: usize| run.outputs[k].analysis.angle_random_walk.as_ref();
    [
        (
            "predicted ARW, white density (deg/sqrt h)",
            both(|k| p.outputs[k].arw_deg_per_sqrt_h),
        ),
        (
            "  Brownian share of the density (%)",
            both(|k| 100.0 * p.outputs[k].thermal_rate_psd / p.outputs[k].rate_psd),
        ),
        ("predicted 60 sigma(1 s) sqrt(1 s)", both(predicted_at_1s)),
        (
            "measured ARW = 60 sigma(1 s) (deg/sqrt h)",
            both(|k| run.outputs[k].arw_at_1s.deg_per_sqrt_h),
        ),
        (
            "  its 1-sigma (%, white-noise edf)",
            both(|k| 100.0 * run.outputs[k].arw_at_1s.relative_sigma),
        ),
        (
            "  measured / predicted - 1 (%)",
            both(|k| 100.0 * (run.outputs[k].arw_at_1s.deg_per_sqrt_h / predicted_at_1s(k) - 1.0)),
        ),
        (
            "ARW fitted over 0.25..4 s (deg/sqrt h)",
            both(|k| fitted(k).map_or(f64::NAN, |a| a.deg_per_sqrt_h)),
        ),
        (
            "  its free slope",
            both(|k| fitted(k).map_or(f64::NAN, |a| a.fitted_slope)),
        ),
        (
            "bias instability (deg/h)",
            both(|k| run.outputs[k].analysis.bias_instability.deg_per_h),
        ),
        (
            "  at tau (s)",
            both(|k| run.outputs[k].analysis.bias_instability.tau_s),
        ),
    ]
}
