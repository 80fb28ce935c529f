//! The noise floor of the readout's rate output: predicted from the noise
//! model, and measured on a noisy co-simulation at a constant rate.
//!
//! # Prediction
//!
//! Conventions: `S` is a one-sided power spectral density (variance per Hz
//! over `f >= 0`); a two-sided density is `S / 2` over all `f`.
//!
//! Readout output k is the low-passed product of ADC k's word and the
//! digital reference of drive k. In the theory's units
//! ([`crate::experiment::Plan::z_per_lsb`]) that is
//!
//! ```text
//! z_k = LPF[ x_k(nT) F_k cos(wb nT + phi) ],    F_k = reference word amplitude x force gain (N/kg)
//! ```
//!
//! with `x_k` the displacement the ADC sees. A stationary noise `n(t)` of
//! one-sided PSD `S_n` mixed with `F cos(wb t + phi)` has, near DC, the
//! one-sided PSD `F^2 / 4 [S_n(fb + f) + S_n(fb - f)]` whatever `phi`
//! (the two sidebands fold onto baseband; cross terms average out for a
//! stationary noise), i.e. `F^2 / 2 S_n(fb)` at `f = 0`. Two noises reach
//! `x_k`:
//!
//! - **Brownian force** on mode k ([`crate::noise`]): one-sided force PSD
//!   per unit mass `S_a,k = 4 k_B T w_k / (Q_k m)`, through the mode's
//!   response: `S_x,k(f) = S_a,k / ((w_k^2 - w^2)^2 + (w w_k / Q_k)^2)`.
//!   The Coriolis coupling `c = 2 lam Omz wb` changes this, and lets the
//!   other mode's force in, by terms of order `c^2 / |D_1 D_2|`
//!   (`D_k = w_k^2 - wb^2 + j wb w_k / Q_k`): 2e-6 on the test device at
//!   50 deg/s, 5e-8 on the paper's at 20 deg/s. They are left out.
//! - **ADC noise**: `noise_lsb` (sigma_n, 16-bit word LSB) Gaussian per
//!   clock plus the quantization error of a step `D = 2^(16 - adc_bits)`
//!   word LSB, uniform and white, variance `D^2 / 12` (Widrow: exact once
//!   the quantizer is dithered, by `noise_lsb` >~ D / 2 or by the
//!   Brownian noise itself). White samples of variance `s^2` at `f_clk`
//!   have the one-sided PSD `2 s^2 / f_clk`; referred to displacement,
//!   `S_x,adc,k = 2 (sigma_n^2 + D^2 / 12) / (G_k^2 f_clk)` with `G_k`
//!   the ADC gain (word LSB per metre).
//!
//! The output filter (CIC and IIR) has unity gain at DC
//! (`FilterDesign::dc_gain` is divided out), so its equivalent noise
//! bandwidth sets the variance of each z sample, `S_z B_eq`, but not the
//! density at the low frequencies an Allan deviation at `tau >= 0.1 s`
//! looks at: the cut-offs sit at tens of Hz or more, and the filter moves
//! `sigma(tau)` by `O(1 / (f_c tau))`.
//!
//! The rate is `z` over the readout scale factor `SF_k` (z per deg/s, the
//! exact theory's slope at the run's rate, DAC hold included), so the
//! white rate-noise density at DC is
//!
//! ```text
//! S_Om,k = F_k^2 / 2 (S_x,k(fb) + S_x,adc,k) / SF_k^2        ((deg/s)^2 / Hz, one-sided)
//! ```
//!
//! and white rate noise of one-sided density `S` has the Allan variance
//! `sigma^2(tau) = S / (2 tau)`. IEEE Std 952 reads the angle random walk
//! as `N = sigma(tau = 1 s)`, in deg/sqrt(s) when `sigma` is in deg/s
//! (`N^2` is the two-sided density, `S / 2`); x 60 gives deg/sqrt(h):
//!
//! ```text
//! N_k = 60 sqrt(S_Om,k / 2)                                  (deg/sqrt(h))
//! ```
//!
//! The Brownian part is white only well inside the mode's bandwidth: its
//! baseband spectrum rolls off at `|f_k - fb|` and `f_k / (2 Q_k)`. So
//! [`RateNoisePrediction::adev`] also evaluates the Allan variance of the
//! whole spectrum, `sigma^2(tau) = int_0^inf S(f) 2 sin^4(pi f tau) /
//! (pi f tau)^2 df` (IEEE 952 annex C, with the one-sided `S`), which at
//! `tau = 1 s` is within `~3 / (4 pi f_roll tau)` of `N / sqrt(tau)`.
//!
//! # Measurement
//!
//! [`run_noisy`] runs the co-simulation (model engine, the gyroscope with
//! its Brownian noise, the converters with theirs) in readout at one
//! constant rate: the settling of the experiment's plan, then `seconds` of
//! z samples. Each z sample becomes a rate, `rate + (z - z_theory) / SF`,
//! and consecutive samples are averaged in blocks to at most
//! `MAX_SERIES_HZ` (an Allan deviation from block means is the same
//! estimator at the taus it still resolves, `tau >= block / f_z`). The
//! Allan analysis ([`crate::allan`]) then gives the deviation at octave
//! taus, the angle random walk read at 1 s with its equivalent degrees of
//! freedom, and the bias instability.

use crate::allan::{self, AllanAnalysis, ArwReading};
use crate::config::Experiment;
use crate::engine::ModelEngine;
use crate::error::{AllanError, RunError};
use crate::experiment::{self, Mode, Plan, PointPlan, point_loop};
use crate::noise::ThermalNoise;
use serde::Serialize;
use std::f64::consts::PI;
use std::time::Instant;

/// Highest sample rate of the rate series the Allan analysis gets (Hz):
/// the z samples are averaged in blocks down to it.
pub const MAX_SERIES_HZ: f64 = 1000.0;

/// Longest noisy run (simulated s).
pub const MAX_SECONDS: f64 = 100_000.0;

/// Shortest noisy run (simulated s): the deviation at tau = 1 s needs two
/// clusters of 1 s.
pub const MIN_SECONDS: f64 = 2.0;

/// The rate noise of one output, predicted.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputNoise {
    /// Mode frequency (Hz).
    pub mode_hz: f64,
    /// Mode quality factor.
    pub q: f64,
    /// Reference amplitude `F_k` (N/kg): the reference word's fundamental
    /// times the force gain.
    pub reference_force_n_per_kg: f64,
    /// Readout scale factor at the run's rate, z (m^2/s^2) per deg/s
    /// (exact theory, DAC hold included).
    pub sf_per_dps: f64,
    /// The same in z LSB per deg/s (what the gateware's output shows).
    pub sf_lsb_per_dps: f64,
    /// Brownian displacement PSD at the carrier (m^2/Hz, one-sided).
    pub thermal_displacement_psd: f64,
    /// ADC noise and quantization referred to displacement (m^2/Hz, one-sided).
    pub adc_displacement_psd: f64,
    /// White rate-noise density at DC from the Brownian force ((deg/s)^2/Hz, one-sided).
    pub thermal_rate_psd: f64,
    /// The same from the ADC.
    pub adc_rate_psd: f64,
    /// Both ((deg/s)^2/Hz, one-sided).
    pub rate_psd: f64,
    /// Angle random walk `60 sqrt(rate_psd / 2)` (deg/sqrt(h)).
    pub arw_deg_per_sqrt_h: f64,
}

/// The predicted rate noise of both outputs at one rate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RateNoisePrediction {
    /// The constant rate (deg/s).
    pub rate_dps: f64,
    /// Realized carrier (Hz).
    pub carrier_hz: f64,
    /// The Brownian noise settings.
    pub thermal: ThermalNoise,
    /// ADC noise (16-bit word LSB rms per clock) and quantization step (word LSB).
    pub adc_noise_lsb: f64,
    /// ADC quantization step (16-bit word LSB).
    pub adc_step_lsb: f64,
    /// Per output.
    pub outputs: [OutputNoise; 2],
}

/// The readout point of `plan` at `rate_dps` (the readout registers and
/// settling of the plan's readout sweep).
fn readout_point(plan: &Plan, rate_dps: f64) -> Result<PointPlan, RateNoiseError> {
    let first = plan
        .points
        .iter()
        .find(|p| p.mode == Mode::Readout)
        .ok_or(RateNoiseError::NoReadoutPoint)?;
    Ok(PointPlan {
        rate_dps,
        omz_rad_s: rate_dps.to_radians(),
        ..first.clone()
    })
}

/// Readout scale factors at `rate_dps` (z in m^2/s^2 per deg/s): the exact
/// theory's central difference over +-1 deg/s (its quadratic term cancels;
/// the cubic one is below 1e-9 of the slope at a readout's rates).
fn local_scale_factors(
    exp: &Experiment,
    plan: &Plan,
    rate_dps: f64,
) -> Result<[f64; 2], RateNoiseError> {
    let z = |r: f64| readout_point(plan, r).map(|p| plan.theory_z(exp, &p));
    let (up, down) = (z(rate_dps + 1.0)?, z(rate_dps - 1.0)?);
    Ok([(up[0] - down[0]) / 2.0, (up[1] - down[1]) / 2.0])
}

/// The predicted rate noise of `exp`'s readout at `rate_dps` (module header).
pub fn predict(
    exp: &Experiment,
    plan: &Plan,
    rate_dps: f64,
) -> Result<RateNoisePrediction, RateNoiseError> {
    let sf = local_scale_factors(exp, plan, rate_dps)?;
    let per_lsb = plan.z_per_lsb(Mode::Readout);
    let fe = &plan.front_end;
    let clock = exp.drive.clock_hz;
    let step = f64::from(1u32 << (16 - fe.adc_bits));
    let adc_variance = fe.noise_lsb * fe.noise_lsb + step * step / 12.0;
    let g = &exp.gyro;
    let modes = [(g.f1_hz, g.q1), (g.f2_hz, g.q2)];
    let outputs = std::array::from_fn(|k| {
        let (mode_hz, q) = modes[k];
        let force = plan.drive_words[k] * fe.force_per_lsb[k];
        let thermal_x = exp.noise.displacement_psd(mode_hz, q, plan.carrier_hz);
        let adc_x = 2.0 * adc_variance / (fe.adc_per_meter[k].powi(2) * clock);
        let to_rate = force * force / 2.0 / (sf[k] * sf[k]);
        let rate_psd = to_rate * (thermal_x + adc_x);
        OutputNoise {
            mode_hz,
            q,
            reference_force_n_per_kg: force,
            sf_per_dps: sf[k],
            sf_lsb_per_dps: sf[k] / per_lsb[k],
            thermal_displacement_psd: thermal_x,
            adc_displacement_psd: adc_x,
            thermal_rate_psd: to_rate * thermal_x,
            adc_rate_psd: to_rate * adc_x,
            rate_psd,
            arw_deg_per_sqrt_h: 60.0 * (rate_psd / 2.0).sqrt(),
        }
    });
    Ok(RateNoisePrediction {
        rate_dps,
        carrier_hz: plan.carrier_hz,
        thermal: exp.noise.clone(),
        adc_noise_lsb: fe.noise_lsb,
        adc_step_lsb: step,
        outputs,
    })
}

/// Periods of the Allan kernel integrated exactly before its mean is used
/// ([`RateNoisePrediction::adev`]).
const NEAR_PERIODS: u32 = 64;

/// Gauss-Legendre nodes and weights on [-1, 1], 8 points.
const GAUSS8: [(f64, f64); 4] = [
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// `int_a^b f` by 8-point Gauss-Legendre on `n` equal panels.
fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    (0..n)
        .map(|i| {
            let mid = a + (i as f64 + 0.5) * h;
            GAUSS8
                .iter()
                .map(|&(x, w)| w * (f(mid - x * h / 2.0) + f(mid + x * h / 2.0)))
                .sum::<f64>()
                * h
                / 2.0
        })
        .sum()
}

impl RateNoisePrediction {
    /// Baseband one-sided PSD of output k's Brownian rate noise at `f`
    /// ((deg/s)^2/Hz): `F^2 / 4 [S_x(fb + f) + S_x(fb - f)] / SF^2`.
    fn thermal_rate_psd_at(&self, k: usize, f: f64) -> f64 {
        let o = &self.outputs[k];
        let sx = |fx: f64| self.thermal.displacement_psd(o.mode_hz, o.q, fx.abs());
        let scale = o.reference_force_n_per_kg.powi(2) / 4.0 / o.sf_per_dps.powi(2);
        scale * (sx(self.carrier_hz + f) + sx(self.carrier_hz - f))
    }

    /// Predicted Allan deviation of output k at `tau_s` (deg/s): the ADC's
    /// white part exactly, `S / (2 tau)`, plus the Allan variance of the
    /// Brownian part's whole baseband spectrum (module header), without the
    /// output filter (valid for `tau` well above its time constants).
    ///
    /// The integral runs panel by panel: panels of `1 / (16 tau)` (a
    /// sixteenth of the kernel's period) up to `NEAR_PERIODS / tau`, then,
    /// with the kernel's `sin^4` replaced by its mean 3/8 (a unit test
    /// bounds what that costs), panels of a quarter of the mode's
    /// half-bandwidth up to 64 half-bandwidths past the mode, and a tail
    /// `S f^-2` beyond.
    pub fn adev(&self, k: usize, tau_s: f64) -> f64 {
        self.adev_with(k, tau_s, NEAR_PERIODS)
    }

    /// [`RateNoisePrediction::adev`] with the exact kernel over `near`
    /// of its periods.
    fn adev_with(&self, k: usize, tau_s: f64, near: u32) -> f64 {
        let o = &self.outputs[k];
        let white = o.adc_rate_psd / (2.0 * tau_s);
        if self.thermal.temperature_k == 0.0 {
            return white.sqrt();
        }
        let s = |f: f64| self.thermal_rate_psd_at(k, f);
        let kernel = |f: f64| {
            let x = PI * f * tau_s;
            if x < 1e-4 {
                2.0 * x * x
            } else {
                2.0 * x.sin().powi(4) / (x * x)
            }
        };
        let f1 = f64::from(near) / tau_s;
        let near = integrate(&|f| s(f) * kernel(f), 0.0, f1, 16 * near as usize);
        let half_bw = o.mode_hz / (2.0 * o.q);
        let f2 = f1.max((o.mode_hz - self.carrier_hz).abs() + 64.0 * half_bw);
        let panels = ((f2 - f1) / (half_bw / 4.0)).ceil().clamp(1.0, 1e6) as usize;
        let mean_kernel = |f: f64| 0.75 / (PI * f * tau_s).powi(2);
        let far = if f2 > f1 {
            integrate(&|f| s(f) * mean_kernel(f), f1, f2, panels)
        } else {
            0.0
        };
        // Beyond f2, S falls at least as f^-2 from S(f2): int f^-4 = 1/(3 f2^3).
        let tail = s(f2) * f2 * f2 * 0.75 / (PI * tau_s).powi(2) / (3.0 * f2.powi(3));
        (white + near + far + tail).sqrt()
    }
}

/// The measured noise of one output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputRun {
    /// Mean of the rate series (deg/s): the applied rate plus the output's
    /// residual bias against the theory.
    pub mean_rate_dps: f64,
    /// The Allan analysis of the rate series.
    pub analysis: AllanAnalysis,
    /// The angle random walk read at tau = 1 s, with its confidence.
    pub arw_at_1s: ArwReading,
}

/// A noisy readout run at a constant rate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NoisyRun {
    /// The constant rate (deg/s).
    pub rate_dps: f64,
    /// Settling before the series (s).
    pub settle_s: f64,
    /// Length of the series (s).
    pub seconds: f64,
    /// z sample rate (Hz).
    pub z_rate_hz: f64,
    /// z samples per sample of the rate series.
    pub block: u32,
    /// Sample rate of the rate series (Hz).
    pub series_rate_hz: f64,
    /// Clocks simulated.
    pub cycles: u64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Per output.
    pub outputs: [OutputRun; 2],
}

/// Mean-of-blocks accumulator of one rate series.
struct Blocks {
    block: u32,
    filled: u32,
    sum: f64,
    series: Vec<f64>,
}

impl Blocks {
    fn push(&mut self, v: f64) {
        self.sum += v;
        self.filled += 1;
        if self.filled == self.block {
            self.series.push(self.sum / f64::from(self.block));
            self.sum = 0.0;
            self.filled = 0;
        }
    }
}

/// Checks a run length (s): one line naming what is allowed.
pub fn check_seconds(seconds: f64) -> Result<(), RateNoiseError> {
    if seconds.is_finite() && (MIN_SECONDS..=MAX_SECONDS).contains(&seconds) {
        Ok(())
    } else {
        Err(RateNoiseError::Seconds(seconds))
    }
}

/// What predicting or running a readout's rate noise refuses.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RateNoiseError {
    /// A plan without a readout point.
    #[error("the plan has no readout point")]
    NoReadoutPoint,
    /// A run length out of range (s).
    #[error("--seconds {0}: allowed {MIN_SECONDS} to {MAX_SECONDS} s of simulated time")]
    Seconds(f64),
    /// Planning or running the point.
    #[error(transparent)]
    Run(#[from] RunError),
    /// The rate series' Allan deviation.
    #[error(transparent)]
    Allan(#[from] AllanError),
}

impl From<RateNoiseError> for String {
    fn from(e: RateNoiseError) -> Self {
        e.to_string()
    }
}

/// Runs `exp`'s readout at `rate_dps` with its noise (the gyroscope's
/// `[noise]`, the converters' `noise_lsb`) for the plan's settling plus
/// `seconds`, and analyses each output's rate series (module header).
/// `progress` gets the clocks simulated, in chunks.
pub fn run_noisy(
    exp: &Experiment,
    plan: &Plan,
    rate_dps: f64,
    seconds: f64,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<NoisyRun, RateNoiseError> {
    check_seconds(seconds)?;
    let start = Instant::now();
    let point = readout_point(plan, rate_dps)?;
    let sf = local_scale_factors(exp, plan, rate_dps)?;
    let z_theory = plan.theory_z(exp, &point);
    let per_lsb = plan.z_per_lsb(Mode::Readout);
    let clock = exp.drive.clock_hz;
    let z_rate = plan.filter.output_rate_hz;
    let block = (z_rate / MAX_SERIES_HZ).ceil().max(1.0) as u32;
    let settle = point.settle_cycles;
    let end = settle + (seconds * clock).ceil() as u64;
    let mut sim = point_loop::<ModelEngine>(exp, plan, &point)?;
    let mut blocks: [Blocks; 2] = std::array::from_fn(|_| Blocks {
        block,
        filled: 0,
        sum: 0.0,
        series: Vec::with_capacity((seconds * z_rate / f64::from(block)) as usize + 1),
    });
    const CHUNK: u64 = 1 << 22;
    let mut n = 0u64;
    while n < end {
        let stop = (n + CHUNK).min(end);
        sim.run(stop - n, |cycle, z| {
            if cycle > settle {
                let z = [z.0 as f64, z.1 as f64];
                for k in 0..2 {
                    blocks[k].push(rate_dps + (z[k] * per_lsb[k] - z_theory[k]) / sf[k]);
                }
            }
        });
        progress(stop - n);
        n = stop;
    }
    let series_rate = z_rate / f64::from(block);
    let outputs = blocks
        .iter()
        .map(|b| output_run(&b.series, series_rate))
        .collect::<Result<Vec<_>, _>>()?;
    let [o1, o2]: [OutputRun; 2] = outputs.try_into().expect("two outputs");
    Ok(NoisyRun {
        rate_dps,
        settle_s: settle as f64 / clock,
        seconds,
        z_rate_hz: z_rate,
        block,
        series_rate_hz: series_rate,
        cycles: end,
        wall_s: start.elapsed().as_secs_f64(),
        outputs: [o1, o2],
    })
}

fn output_run(series: &[f64], rate_hz: f64) -> Result<OutputRun, AllanError> {
    let mean_rate_dps = series.iter().sum::<f64>() / series.len().max(1) as f64;
    Ok(OutputRun {
        mean_rate_dps,
        analysis: allan::analyze(series, rate_hz)?,
        arw_at_1s: allan::arw_at(series, rate_hz, 1.0)?,
    })
}

/// Plan `exp` and predict its rate noise at `rate_dps`.
pub fn plan_and_predict(
    exp: &Experiment,
    rate_dps: f64,
) -> Result<(Plan, RateNoisePrediction), RateNoiseError> {
    let plan = experiment::plan(exp)?;
    let prediction = predict(exp, &plan, rate_dps)?;
    Ok((plan, prediction))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gyro::GyroParams;

    /// A 101 kHz device, Q 1000, mode 2 150 Hz above, on a 1.2345 MHz clock.
    fn device(temperature_k: f64) -> Experiment {
        let mut e = Experiment::with_required(
            GyroParams {
                f1_hz: 101.23e3,
                f2_hz: 101.38e3,
                q1: 1000.0,
                q2: 1000.0,
                angular_gain: 0.6,
                quadrature_dps: 0.0,
                damping_coupling_dps: 0.0,
            },
            101.23e3,
            1.2345e6,
            vec![100.0, 200.0],
            vec![2.0, 4.0],
        );
        e.noise = ThermalNoise {
            mass_kg: 1e-6,
            temperature_k,
            seed: 3,
        };
        e
    }

    #[test]
    fn the_density_follows_temperature_mass_and_the_adc() {
        let (_, hot) = plan_and_predict(&device(300.0), 0.0).unwrap();
        let (_, cold) = plan_and_predict(&device(75.0), 0.0).unwrap();
        for k in 0..2 {
            let (h, c) = (&hot.outputs[k], &cold.outputs[k]);
            // Brownian PSD proportional to T; the ADC's unchanged.
            assert!((h.thermal_rate_psd / c.thermal_rate_psd - 4.0).abs() < 1e-12);
            assert_eq!(h.adc_rate_psd, c.adc_rate_psd);
            assert!((h.rate_psd - h.thermal_rate_psd - h.adc_rate_psd).abs() <= 1e-12 * h.rate_psd);
        }
        // The resonant output sees the mode at its peak: |D(f1)| = w^2 / Q.
        let o = &hot.outputs[0];
        let w = 2.0 * PI * 101.23e3;
        let sa = hot.thermal.force_psd(101.23e3, 1000.0);
        let peak = sa * 1000.0f64.powi(2) / w.powi(4);
        assert!((o.thermal_displacement_psd / peak - 1.0).abs() < 1e-6);
    }

    #[test]
    fn the_exact_adev_tends_to_the_white_line() {
        // Well inside the modes' bandwidths (50 Hz half-width, 150 Hz
        // split) the rate noise is white: sigma(tau) sqrt(tau) = N / 60
        // within the roll-off's 3 / (4 pi f_roll tau).
        let (_, p) = plan_and_predict(&device(300.0), 0.0).unwrap();
        for k in 0..2 {
            let n = p.outputs[k].arw_deg_per_sqrt_h / 60.0;
            for tau in [1.0, 10.0] {
                let got = p.adev(k, tau) * f64::sqrt(tau) / n;
                let bound = 3.0 / (4.0 * PI * 50.0 * tau);
                assert!((got - 1.0).abs() < bound, "output {k} tau {tau}: {got}");
            }
        }
        // The mean kernel beyond 64 periods: against 1024 exact periods.
        for tau in [0.01, 0.1, 1.0, 10.0] {
            let (a, b) = (p.adev(0, tau), p.adev_with(0, tau, 1024));
            assert!((a / b - 1.0).abs() < 1e-4, "tau {tau}: {a} vs {b}");
        }
        // With the noise off only the ADC's white part is left.
        let (_, q) = plan_and_predict(&device(0.0), 0.0).unwrap();
        let n = q.outputs[0].arw_deg_per_sqrt_h / 60.0;
        assert!((q.adev(0, 4.0) * 2.0 / n - 1.0).abs() < 1e-12);
    }
}
