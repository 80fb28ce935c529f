//! `gyrocal datasheet --config FILE [--seconds S] [--full-scale-dps FS]
//! [--json] [--out DIR]`: a gyroscope datasheet in the style of IEEE Std
//! 952/1431, measured on the simulated board (`gyrocal_sim::datasheet`).
//!
//! Noise (from `S` seconds at rest with every `[noise]` term, the rate
//! noises included): ARW, bias instability and its tau, rate random walk,
//! the overlapping Allan deviation with one-sigma intervals. Scale factor,
//! nonlinearity and asymmetry over +-FS (default: the largest |readout
//! rate| of the file). Bias and scale-factor temperature coefficients over
//! `[drift]`. Bandwidth (-3 dB) and turn-on time.
//!
//! `--json` prints one object; `--out` writes `datasheet.json` (the same
//! object), `rate.csv` (the series the Allan deviation was computed from:
//! `time_s,rate1_dps,rate2_dps`) and the figures `datasheet_adev`,
//! `datasheet_nonlinearity` and, with `[drift]`, `datasheet_temperature`
//! (PNG and SVG). Every option and the file are checked before the run:
//! bad input is one line on stderr, exit status 2, nothing written.

use crate::Failure;
use gyrocal_sim::datasheet::{self, Datasheet, Error, Options};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Default series length (simulated s): a bias-instability floor at tau =
/// 20 s then has `5 T / (4 tau)` = 62 flicker degrees of freedom (NIST SP
/// 1065 table 5), a one-sigma interval of about +-9 %.
pub const DEFAULT_SECONDS: f64 = 1000.0;

/// Options of `gyrocal datasheet`.
#[derive(clap::Args)]
pub struct Args {
    /// Device, noise and (optionally) `[drift]` (TOML: the sections of
    /// `gyrocal run`; `[noise]` also takes arw_deg_per_sqrt_h,
    /// bias_instability_deg_per_h, rrw_deg_per_h_per_sqrt_h).
    #[arg(long)]
    pub config: PathBuf,
    /// Simulated seconds of the Allan series.
    #[arg(long, default_value_t = DEFAULT_SECONDS)]
    pub seconds: f64,
    /// Full scale of the sweep (deg/s); default the largest |readout rate|.
    #[arg(long)]
    pub full_scale_dps: Option<f64>,
    /// Print the datasheet as one JSON object instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Write datasheet.json, rate.csv and the figures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Do not show a progress bar.
    #[arg(long)]
    pub quiet: bool,
}

fn failure(e: Error) -> Failure {
    match e {
        Error::Input(m) => Failure::Input(m),
        Error::Run(m) => Failure::Run(m),
    }
}

/// Measure and report the datasheet.
pub fn run(args: &Args) -> Result<(), Failure> {
    let (name, text) = super::experiment::read_config(&args.config)?;
    let setup = datasheet::setup::parse(&name, &text).map_err(failure)?;
    if let Some(dir) = &args.out {
        super::allan::check_folder(dir)?;
    }
    let options = Options {
        seconds: args.seconds,
        full_scale_dps: args.full_scale_dps,
    };
    let clock = setup.exp.drive.clock_hz;
    let bar = progress_bar(args.quiet, (args.seconds.max(0.0) * clock) as u64);
    let tick = |n: u64| bar.inc(n);
    let ds = datasheet::run(&setup, &options, &tick).map_err(failure)?;
    bar.finish_and_clear();
    let json = json(&ds, &name);
    if let Some(dir) = &args.out {
        for path in write_outputs(&ds, &json, dir)? {
            eprintln!("wrote {}", path.display());
        }
    }
    if args.json {
        println!("{json}");
    } else {
        print!("{}", summary(&ds));
    }
    Ok(())
}

/// The datasheet as one JSON object, `config` added.
fn json(ds: &Datasheet, config: &str) -> serde_json::Value {
    let mut v = serde_json::to_value(ds).expect("the datasheet serializes");
    v["config"] = serde_json::Value::String(config.to_string());
    v
}

fn progress_bar(quiet: bool, total: u64) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} Allan series [{bar:40}] {percent:>3}%  {human_pos}/{human_len} clocks  eta {eta}",
        )
        .expect("a valid template")
        .progress_chars("=> "),
    );
    bar
}

/// `time_s,rate1_dps,rate2_dps`, every value in full precision.
fn rate_csv(ds: &Datasheet) -> String {
    let mut s = String::from("time_s,rate1_dps,rate2_dps\n");
    let dt = 1.0 / ds.series.sample_rate_hz;
    for (i, (a, b)) in ds.rate_dps[0].iter().zip(&ds.rate_dps[1]).enumerate() {
        let _ = writeln!(s, "{},{a},{b}", i as f64 * dt);
    }
    s
}

/// Write datasheet.json, rate.csv and the figures into `dir`.
fn write_outputs(
    ds: &Datasheet,
    json: &serde_json::Value,
    dir: &Path,
) -> Result<Vec<PathBuf>, Failure> {
    let text = serde_json::to_string_pretty(json).map_err(|e| Failure::Run(e.to_string()))?;
    let mut written = super::experiment::write_files(
        dir,
        vec![("datasheet.json", text), ("rate.csv", rate_csv(ds))],
    )?;
    written.extend(crate::plots::write_datasheet_figures(ds, dir).map_err(Failure::run)?);
    Ok(written)
}

/// A number or "n/a".
fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("n/a".into(), |v| format!("{v:.digits$}"))
}

/// A reading with its interval, or its note.
fn reading(r: &gyrocal_sim::noise_terms::Reading) -> String {
    match (r.value, r.ci_low, r.ci_high) {
        (Some(v), Some(lo), Some(hi)) => format!("{v:.4} [{lo:.4}, {hi:.4}]"),
        _ => r.note.clone().unwrap_or_else(|| "n/a".into()),
    }
}

/// Human summary, one block per output.
fn summary(ds: &Datasheet) -> String {
    let mut s = format!(
        "datasheet: {} s Allan series at {:.4} Hz, full scale {} deg/s, intervals one sigma (68.3 %), {:.1} s wall\n",
        ds.seconds, ds.series.sample_rate_hz, ds.full_scale_dps, ds.wall_s
    );
    for o in &ds.outputs {
        let _ = writeln!(s, "output {}:", o.output);
        let _ = writeln!(s, "  ARW (deg/sqrt h) at 1 s          {}", reading(&o.arw));
        if let (Some(_), Some(note)) = (o.arw.value, &o.arw.note) {
            let _ = writeln!(s, "    ({note})");
        }
        let _ = writeln!(
            s,
            "  bias instability (deg/h)        {} at tau {} s",
            reading(&o.bias_instability),
            opt(o.bias_instability_tau_s, 3)
        );
        if let Some(note) = &o.bias_instability.note {
            let _ = writeln!(s, "    ({note})");
        }
        let _ = writeln!(s, "  rate random walk (deg/h/sqrt h) {}", reading(&o.rrw));
        let _ = writeln!(
            s,
            "  fit: N {}, B {}, K {}",
            reading(&o.noise_fit.arw_deg_per_sqrt_h),
            reading(&o.noise_fit.bias_instability_deg_per_h),
            reading(&o.noise_fit.rrw_deg_per_h_per_sqrt_h)
        );
        let _ = writeln!(
            s,
            "  scale factor (z LSB per deg/s)  {:.6e}",
            o.sf_lsb_per_dps
        );
        let _ = writeln!(
            s,
            "  nonlinearity (ppm FS)           {:.2}, asymmetry (ppm) {:.2}",
            o.sf_nonlinearity_ppm, o.sf_asymmetry_ppm
        );
        let _ = writeln!(
            s,
            "  TC bias (deg/h/K)               {}, TC SF (ppm/K) {}",
            opt(o.bias_tc_deg_per_h_per_k, 4),
            opt(o.sf_tc_ppm_per_k, 3)
        );
        let _ = writeln!(
            s,
            "  bandwidth -3 dB (Hz)            {}, turn-on to 1 % FS (s) {}",
            opt(o.bandwidth_hz, 3),
            opt(o.turn_on_s, 4)
        );
    }
    s
}
