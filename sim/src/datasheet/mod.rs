//! A gyroscope datasheet in the style of IEEE Std 952-1997 and 1431-2004,
//! measured on the simulated board (`gyrocal datasheet`).
//!
//! - [`setup`]: the file (`[noise]` with the rate noises, optional
//!   `[drift]`).
//! - [`bench`](mod@bench): fresh boards at a temperature, in readout at the factory's
//!   settings.
//! - [`sweep`]: scale factor, nonlinearity, asymmetry over +-full scale.
//! - [`dynamics`]: -3 dB bandwidth (rate step) and turn-on time.
//! - [`temperature`]: bias and scale-factor temperature coefficients over
//!   the `[drift]` steps.
//! - [`series`]: the rate series at rest with every noise, whose Allan
//!   deviation, confidence intervals and noise terms
//!   ([`crate::noise_terms`]) fill the noise half of the sheet.
//!
//! The measurements run in parallel (rayon); the series, the longest, runs
//! beside the others and is turned into a rate with the sweep's line.

pub mod bench;
pub mod dynamics;
pub mod series;
pub mod setup;
pub mod sweep;
pub mod temperature;

use crate::edf::ONE_SIGMA;
use crate::noise::ThermalNoise;
use crate::noise_terms::{self, NoiseAnalysis, NoiseFit, Reading};
use crate::rate_drift::RateNoise;
use bench::Bench;
use dynamics::Dynamics;
use serde::Serialize;
use series::Series;
use setup::Setup;
use std::time::Instant;
use sweep::Sweep;
use temperature::Temperature;

/// The fit starts at `FIT_MIN_TAU_OVER_BANDWIDTH / bandwidth`: 50 time
/// constants `1 / (2 pi f_bw)` of a one-pole output, where the filter
/// lowers the white noise's Allan variance by `3 / (2 x 50)` = 3 %.
pub const FIT_MIN_TAU_OVER_BANDWIDTH: f64 = 50.0 / std::f64::consts::TAU;

/// What went wrong: the user's input, or the run.
#[derive(Clone, Debug, PartialEq)]
pub enum Error {
    /// A file, key or option is out of range (exit status 2).
    Input(String),
    /// The simulation failed (exit status 1).
    Run(String),
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::Input(m) | Error::Run(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for Error {}

/// How to run the datasheet.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Seconds of the Allan series.
    pub seconds: f64,
    /// Full scale (deg/s); `None`: the largest |readout rate| of the file.
    pub full_scale_dps: Option<f64>,
}

/// The Allan deviation table of one output (deg/h; one-sigma intervals).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AdevTable {
    /// Cluster times (s).
    pub tau_s: Vec<f64>,
    /// Overlapping Allan deviation (deg/h).
    pub sigma_deg_per_h: Vec<f64>,
    /// Lower ends (deg/h).
    pub ci_low: Vec<f64>,
    /// Upper ends (deg/h).
    pub ci_high: Vec<f64>,
    /// Equivalent degrees of freedom.
    pub edf: Vec<f64>,
    /// Samples per cluster.
    pub cluster: Vec<usize>,
}

/// One output's sheet.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputSheet {
    /// 1 or 2.
    pub output: usize,
    /// IEEE 952 ARW at 1 s (deg/sqrt(h)), null if not resolved.
    pub arw_deg_per_sqrt_h: Option<f64>,
    /// IEEE 952 bias instability, `min sigma / 0.664` (deg/h).
    pub bias_instability_deg_per_h: Option<f64>,
    /// Its tau (s).
    pub bias_instability_tau_s: Option<f64>,
    /// Rate random walk (deg/h/sqrt(h)), the +1/2 term of the fit.
    pub rrw_deg_per_h_per_sqrt_h: Option<f64>,
    /// Scale factor (z LSB per deg/s).
    pub sf_lsb_per_dps: f64,
    /// Nonlinearity (ppm of full scale).
    pub sf_nonlinearity_ppm: f64,
    /// Asymmetry (ppm).
    pub sf_asymmetry_ppm: f64,
    /// Bias temperature coefficient (deg/h per K), with `[drift]`.
    pub bias_tc_deg_per_h_per_k: Option<f64>,
    /// Scale-factor temperature coefficient (ppm per K), with `[drift]`.
    pub sf_tc_ppm_per_k: Option<f64>,
    /// -3 dB bandwidth (Hz).
    pub bandwidth_hz: Option<f64>,
    /// Turn-on time (s).
    pub turn_on_s: Option<f64>,
    /// The readings with their intervals and notes.
    pub arw: Reading,
    /// See `arw`.
    pub bias_instability: Reading,
    /// See `arw`.
    pub rrw: Reading,
    /// The three-term fit.
    pub noise_fit: NoiseFit,
    /// The Allan deviation.
    pub adev: AdevTable,
}

/// The whole datasheet.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Datasheet {
    /// Full scale (deg/s).
    pub full_scale_dps: f64,
    /// Seconds of the Allan series.
    pub seconds: f64,
    /// Confidence of every interval (one sigma).
    pub confidence: f64,
    /// The Brownian noise of the file.
    pub thermal_noise: ThermalNoise,
    /// The rate noises of the file.
    pub rate_noise: RateNoise,
    /// Shortest tau of the noise fit (s).
    pub fit_min_tau_s: f64,
    /// The Allan series.
    pub series: Series,
    /// The sweep.
    pub sweep: Sweep,
    /// Bandwidth and turn-on.
    pub dynamics: Dynamics,
    /// Temperature coefficients (null without `[drift]`).
    pub temperature: Option<Temperature>,
    /// One entry per output.
    pub outputs: Vec<OutputSheet>,
    /// Wall time (s).
    pub wall_s: f64,
    /// The rate series (deg/s), per output, at `series.sample_rate_hz`.
    #[serde(skip)]
    pub rate_dps: [Vec<f64>; 2],
}

/// The table of an analysis, in deg/h.
fn table(a: &NoiseAnalysis) -> AdevTable {
    let h = |v: f64| v * 3600.0;
    AdevTable {
        tau_s: a.points.iter().map(|p| p.tau_s).collect(),
        sigma_deg_per_h: a.points.iter().map(|p| h(p.adev_dps)).collect(),
        ci_low: a.points.iter().map(|p| h(p.ci_low_dps)).collect(),
        ci_high: a.points.iter().map(|p| h(p.ci_high_dps)).collect(),
        edf: a.points.iter().map(|p| p.edf).collect(),
        cluster: a.points.iter().map(|p| p.cluster).collect(),
    }
}

/// Check the options against the setup; the full scale they give.
fn full_scale(setup: &Setup, options: &Options) -> Result<f64, Error> {
    crate::rate_noise::check_seconds(options.seconds).map_err(|e| Error::Input(e.to_string()))?;
    let max = crate::config::MAX_RATE_DPS;
    match options.full_scale_dps {
        Some(fs) if !(fs.is_finite() && fs > 0.0 && fs <= max) => Err(Error::Input(format!(
            "--full-scale-dps {fs}: allowed above 0 up to {max} deg/s"
        ))),
        Some(fs) => Ok(fs),
        None => {
            let rates = &setup.exp.points.readout_rates_dps;
            Ok(rates.iter().fold(0.0, |m: f64, r| m.max(r.abs())))
        }
    }
}

/// Measure the datasheet of `setup`; `progress` gets the series' clocks.
pub fn run(
    setup: &Setup,
    options: &Options,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Datasheet, Error> {
    let fs = full_scale(setup, options)?;
    let start = Instant::now();
    let bench = Bench::new(&setup.exp, setup.drift.as_ref())?;
    let (series, rest) = rayon::join(
        || series::run_series(&bench, &setup.rate_noise, options.seconds, progress),
        || -> Result<_, Error> {
            let sweep = sweep::run(&bench, fs)?;
            let dynamics = dynamics::run_dynamics(&bench, fs, sweep.sf_lsb_per_dps)?;
            let temperature = match &setup.drift {
                Some(d) => Some(temperature::run(&bench, d)?),
                None => None,
            };
            Ok((sweep, dynamics, temperature))
        },
    );
    let (series, (sweep, dynamics, temperature)) = (series?, rest?);
    let slowest = dynamics
        .bandwidth_hz
        .iter()
        .flatten()
        .fold(f64::INFINITY, |a: f64, b| a.min(*b));
    let bw = if slowest.is_finite() {
        slowest
    } else {
        bench.knowns.filter.butterworth_hz
    };
    let fit_min_tau_s = FIT_MIN_TAU_OVER_BANDWIDTH / bw;
    let rate_dps: [Vec<f64>; 2] = std::array::from_fn(|k| {
        let (sf, b) = (sweep.sf_lsb_per_dps[k], sweep.intercept_lsb[k]);
        series.z_lsb[k].iter().map(|z| (z - b) / sf).collect()
    });
    let outputs = (0..2)
        .map(|k| {
            let a = noise_terms::analyze(&rate_dps[k], series.sample_rate_hz, fit_min_tau_s)
                .map_err(|e| Error::Run(e.to_string()))?;
            Ok(sheet(k, &a, &sweep, &dynamics, temperature.as_ref()))
        })
        .collect::<Result<Vec<_>, Error>>()?;
    Ok(Datasheet {
        full_scale_dps: fs,
        seconds: options.seconds,
        confidence: ONE_SIGMA,
        thermal_noise: setup.exp.noise.clone(),
        rate_noise: setup.rate_noise.clone(),
        fit_min_tau_s,
        series,
        sweep,
        dynamics,
        temperature,
        outputs,
        wall_s: start.elapsed().as_secs_f64(),
        rate_dps,
    })
}

/// Output `k`'s sheet.
fn sheet(
    k: usize,
    a: &NoiseAnalysis,
    sweep: &Sweep,
    dynamics: &Dynamics,
    temperature: Option<&Temperature>,
) -> OutputSheet {
    OutputSheet {
        output: k + 1,
        arw_deg_per_sqrt_h: a.arw_deg_per_sqrt_h.value,
        bias_instability_deg_per_h: a.bias_instability_deg_per_h.value,
        bias_instability_tau_s: a.bias_instability_deg_per_h.tau_s,
        rrw_deg_per_h_per_sqrt_h: a.rrw_deg_per_h_per_sqrt_h.value,
        sf_lsb_per_dps: sweep.sf_lsb_per_dps[k],
        sf_nonlinearity_ppm: sweep.nonlinearity_ppm[k],
        sf_asymmetry_ppm: sweep.asymmetry_ppm[k],
        bias_tc_deg_per_h_per_k: temperature.and_then(|t| t.bias_tc_deg_per_h_per_k.map(|v| v[k])),
        sf_tc_ppm_per_k: temperature.and_then(|t| t.sf_tc_ppm_per_k.map(|v| v[k])),
        bandwidth_hz: dynamics.bandwidth_hz[k],
        turn_on_s: dynamics.turn_on_s[k],
        arw: a.arw_deg_per_sqrt_h.clone(),
        bias_instability: a.bias_instability_deg_per_h.clone(),
        rrw: a.rrw_deg_per_h_per_sqrt_h.clone(),
        noise_fit: a.fit.clone(),
        adev: table(a),
    }
}
