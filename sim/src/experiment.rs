//! The paper's two experiments, co-simulated: a readout sweep over rotation
//! rates and a calibration staircase over calibration frequencies.
//!
//! Every point is an independent run from power-up (gyroscope at rest,
//! datapath at its power-up state), so points run in parallel on all cores.
//! A point runs for a settling time, then z1, z2 are averaged over a window
//! (`crate::average`). Both times are derived, never guessed:
//!
//! - Settling. From rest the resonator's transient decays as exp(-t / tau)
//!   with tau = 2 Q_k / w_k (the slowest mode). It starts as large as the
//!   largest low-frequency term of z at that output, Z (the readout offset
//!   of a detuned mode, or the calibration ripple), and must fall below
//!   `tolerance` times the signal the fit measures at that output,
//!   S = |SF| x (span of the rates). So t_res = tau ln(Z / (tolerance S)),
//!   both from the exact theory; on the paper's device the detuned readout
//!   output has Z / S near 8e3 and t_res near 18 tau = 33 ms. The filters
//!   then need ln(Z / (tolerance S)) / sigma more, sigma the slowest decay
//!   rate of the Butterworth poles (w_c / sqrt 2) and the RC pole, plus the
//!   CIC's 4 R clocks.
//! - Window. Readout: `min_window_s`. Calibration: the smallest whole number
//!   of periods of the 2 Om ripple (1 / (2 f_cal), with the realized f_cal)
//!   not shorter than `min_window_s`; any other length leaves part of a
//!   ripple about 100 / f_cal[Hz] times the DC value in the mean.
//!
//! Scale factors are least-squares slopes with intercept (`crate::fit`) of
//! the averaged outputs against the physical rate (readout) or the virtual
//! rate 360 f_cal (calibration), in deg/s. The exact theory is evaluated at
//! the same points with the same fit, for the same forces: the DAC words'
//! amplitude times the force gain, times sinc(f_c T) for the hold (the
//! reference words carry no hold, so z scales by that factor once).

use crate::average::window_mean;
use crate::cosim::CoSim;
use crate::engine::{Engine, EngineKind, ModelEngine, RtlEngine};
use crate::fit::linear_fit;
use crate::frontend::{Converters, FrontEnd};
use crate::gyro::{GyroModel, GyroParams};
use crate::theory::{self, Device};
use gyrocal_hdl::cic_decimator::OUTPUT_FRACTION_BITS;
use gyrocal_hdl::filter_design::FilterDesign;
use gyrocal_hdl::model::gyro_interface::{Outputs, Probes, Registers};
use gyrocal_hdl::settings::{self, FrequencyPlan};
use gyrocal_hdl::sine_table::PEAK;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// Everything an experiment needs: device, excitation, converters, filter,
/// points.
#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    /// The gyroscope.
    pub gyro: GyroParams,
    /// FPGA clock (Hz).
    pub clock_hz: f64,
    /// Carrier (excitation) frequency (Hz).
    pub carrier_hz: f64,
    /// Drive amplitudes F1, F2 as fractions of full scale.
    pub amplitude: (f64, f64),
    /// Force per unit mass of a full-scale DAC word, per channel (N/kg).
    pub force_full_scale: [f64; 2],
    /// DAC pipeline latency (clocks).
    pub dac_latency: u32,
    /// ADC pipeline latency (clocks).
    pub adc_latency: u32,
    /// DAC resolution (bits).
    pub dac_bits: u32,
    /// ADC resolution (bits).
    pub adc_bits: u32,
    /// Peak ADC input as a fraction of full scale, used to set the ADC gains
    /// from the theory when `adc_per_meter` is not given.
    pub adc_headroom: f64,
    /// ADC LSBs per metre, per channel; `None`: from `adc_headroom`.
    pub adc_per_meter: Option<[f64; 2]>,
    /// RMS noise at the ADC input (LSB).
    pub noise_lsb: f64,
    /// Noise seed.
    pub seed: u64,
    /// CIC decimation R.
    pub decimation: u32,
    /// Butterworth cut-off (Hz).
    pub butterworth_hz: f64,
    /// RC cut-off (Hz).
    pub rc_hz: f64,
    /// Readout rates (deg/s).
    pub readout_rates_dps: Vec<f64>,
    /// Calibration frequencies (Hz).
    pub cal_freqs_hz: Vec<f64>,
    /// Each point is settled to this fraction of the signal it measures.
    pub tolerance: f64,
    /// Shortest averaging window (s).
    pub min_window_s: f64,
}

impl Experiment {
    /// The paper's device and measurement: mode 1 at 9.64 MHz, mode 2 250 Hz
    /// above, Q 55,000, lambda 0.6 (n = 3 modes), excited at mode 1,
    /// 50 MHz clock, rates 1..20 deg/s, staircase 10..15 Hz.
    pub fn paper() -> Self {
        Self {
            gyro: GyroParams {
                f1_hz: 9.64e6,
                f2_hz: 9.64e6 + 250.0,
                q1: 55_000.0,
                q2: 55_000.0,
                angular_gain: 0.6,
            },
            clock_hz: 50e6,
            carrier_hz: 9.64e6,
            amplitude: (0.9, 0.9),
            force_full_scale: [1.0, 1.0],
            dac_latency: 2,
            adc_latency: 3,
            dac_bits: 16,
            adc_bits: 16,
            adc_headroom: 0.9,
            adc_per_meter: None,
            noise_lsb: 0.0,
            seed: 1,
            decimation: 1000,
            butterworth_hz: 500.0,
            rc_hz: 2000.0,
            readout_rates_dps: (1..=20).map(f64::from).collect(),
            cal_freqs_hz: (10..=15).map(f64::from).collect(),
            tolerance: 1e-4,
            min_window_s: 0.05,
        }
    }
}

/// Readout at a rotation rate, or calibration at a modulation frequency.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// SELECT = 0, gyroscope rotating.
    Readout,
    /// SELECT = 1, gyroscope at rest, rotating excitation.
    Calibration,
}

/// One point, ready to run.
#[derive(Clone, Debug, PartialEq)]
pub struct PointPlan {
    /// Readout or calibration.
    pub mode: Mode,
    /// The rate the fit uses (deg/s): physical, or virtual 360 f_cal with the
    /// realized f_cal.
    pub rate_dps: f64,
    /// Realized calibration frequency (Hz), 0 in readout.
    pub cal_hz: f64,
    /// Rotation rate of the gyroscope (rad/s).
    pub omz_rad_s: f64,
    /// Datapath registers.
    pub regs: Registers,
    /// Clocks before the window.
    pub settle_cycles: u64,
    /// Window length in clocks (not necessarily whole).
    pub window_cycles: f64,
    /// Clocks to simulate.
    pub total_cycles: u64,
}

/// What the planner derived.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The points, readout first.
    pub points: Vec<PointPlan>,
    /// Front end, with the ADC gains set.
    pub front_end: FrontEnd,
    /// Realized carrier (Hz).
    pub carrier_hz: f64,
    /// The output filter.
    pub filter: FilterDesign,
    /// Amplitude of the DAC words (LSB) per channel, in readout.
    pub drive_words: [f64; 2],
    /// Fundamental gain of the DAC's hold at the carrier.
    pub hold_gain: f64,
    /// Slowest resonator amplitude time constant (s).
    pub tau_s: f64,
    /// Things a user should know (commensurate frequency plan, ...).
    pub warnings: Vec<String>,
}

impl Plan {
    /// The device as the theory sees it: reference forces (DAC word
    /// amplitude times force gain). Multiply its z by `hold_gain`.
    pub fn theory_device(&self, exp: &Experiment) -> Device {
        Device {
            f1_hz: exp.gyro.f1_hz,
            f2_hz: exp.gyro.f2_hz,
            q1: exp.gyro.q1,
            q2: exp.gyro.q2,
            angular_gain: exp.gyro.angular_gain,
            carrier_hz: self.carrier_hz,
            f1_force: self.drive_words[0] * self.front_end.force_per_lsb[0],
            f2_force: self.drive_words[1] * self.front_end.force_per_lsb[1],
        }
    }

    /// Total clocks of all points.
    pub fn total_cycles(&self) -> u64 {
        self.points.iter().map(|p| p.total_cycles).sum()
    }

    /// Exact theory z (m^2/s^2) at a point, hold included.
    pub fn theory_z(&self, exp: &Experiment, p: &PointPlan) -> [f64; 2] {
        let dev = self.theory_device(exp);
        let z = match p.mode {
            Mode::Readout => theory::readout_z(&dev, p.omz_rad_s),
            Mode::Calibration => theory::calibration_z(&dev, p.cal_hz),
        };
        [z[0] * self.hold_gain, z[1] * self.hold_gain]
    }
}

/// Plan an experiment: registers, ADC gains, settling and windows.
pub fn plan(exp: &Experiment) -> Result<Plan, String> {
    // Every key's range, with the names of the configuration file.
    crate::config::validate(exp)?;
    let rates = &exp.readout_rates_dps;
    let cals = &exp.cal_freqs_hz;
    let base = FrequencyPlan {
        clock_hz: exp.clock_hz,
        carrier_hz: exp.carrier_hz,
        cal_hz: 0.0,
        calibration: false,
        amplitude: exp.amplitude,
        decimation: exp.decimation,
        butterworth_hz: exp.butterworth_hz,
        rc_hz: exp.rc_hz,
        dac_latency: exp.dac_latency,
        adc_latency: exp.adc_latency,
    };
    let (readout_regs, realized) = settings::registers(&base)?;
    let filter = realized.filter.clone();
    let peak = f64::from(PEAK);
    let word = |amp: i16| f64::from(amp) * peak * peak / 2f64.powi(30);
    let drive_words = [
        word(readout_regs.amp.0).abs(),
        word(readout_regs.amp.1).abs(),
    ];
    if drive_words.iter().any(|&w| w < 1.0) {
        return Err("amplitude: both drives need at least one DAC LSB".into());
    }
    let force_per_lsb = [
        exp.force_full_scale[0] / 32768.0,
        exp.force_full_scale[1] / 32768.0,
    ];
    let hold_gain = {
        let x = PI * realized.carrier_hz / exp.clock_hz;
        x.sin() / x
    };
    let mut warnings = vec![];
    if let Some(q) = settings::commensurate_period(exp.carrier_hz, exp.clock_hz) {
        warnings.push(format!(
            "carrier_hz / clock_hz is a ratio of small integers (period {q} clocks): the converters see only {q} phases and their quantization errors do not average out (errors of percent); use a non-round carrier or dither (noise_lsb)"
        ));
    }

    // Theory for gains and timing (the hold scales every force alike).
    let mut plan = Plan {
        points: vec![],
        front_end: FrontEnd {
            dac_latency: exp.dac_latency,
            adc_latency: exp.adc_latency,
            dac_bits: exp.dac_bits,
            adc_bits: exp.adc_bits,
            force_per_lsb,
            adc_per_meter: [1.0, 1.0],
            noise_lsb: exp.noise_lsb,
            seed: exp.seed,
        },
        carrier_hz: realized.carrier_hz,
        filter,
        drive_words,
        hold_gain,
        tau_s: 0.0,
        warnings,
    };
    let mut dev = plan.theory_device(exp);
    dev.f1_force *= hold_gain;
    dev.f2_force *= hold_gain;
    let rad = PI / 180.0;
    let cal_plans: Vec<(Registers, f64)> = cals
        .iter()
        .map(|&f| {
            let p = FrequencyPlan {
                cal_hz: f,
                calibration: true,
                ..base.clone()
            };
            settings::registers(&p).map(|(r, real)| (r, real.cal_hz))
        })
        .collect::<Result<_, _>>()?;
    // ADC gains: the largest displacement of any point at `adc_headroom`.
    let mut peak_x = [0.0f64; 2];
    for &r in rates {
        let x = theory::readout_peak_displacement(&dev, r * rad);
        peak_x = [peak_x[0].max(x[0]), peak_x[1].max(x[1])];
    }
    for (_, f) in &cal_plans {
        let x = theory::calibration_peak_displacement(&dev, *f);
        peak_x = [peak_x[0].max(x[0]), peak_x[1].max(x[1])];
    }
    plan.front_end.adc_per_meter = match exp.adc_per_meter {
        Some(g) => g,
        None => [
            exp.adc_headroom * 32767.0 / peak_x[0],
            exp.adc_headroom * 32767.0 / peak_x[1],
        ],
    };
    Converters::new(&plan.front_end)?;

    // Settling: see the module header.
    let w = [TAU * exp.gyro.f1_hz, TAU * exp.gyro.f2_hz];
    plan.tau_s = (2.0 * exp.gyro.q1 / w[0]).max(2.0 * exp.gyro.q2 / w[1]);
    let sigma = (TAU * exp.butterworth_hz / 2f64.sqrt()).min(TAU * exp.rc_hz);
    let span = |v: &[f64]| {
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
    };
    let sf_read = theory::sf_read_per_rad_s(&dev);
    let sf_cal = theory::sf_cal_per_rad_s(&dev);
    let read_signal = [
        sf_read[0].abs() * span(rates) * rad,
        sf_read[1].abs() * span(rates) * rad,
    ];
    let virtual_span = TAU * span(&cal_plans.iter().map(|c| c.1).collect::<Vec<_>>());
    let cal_signal = [
        sf_cal[0].abs() * virtual_span,
        sf_cal[1].abs() * virtual_span,
    ];
    let clock = exp.clock_hz;
    let settle = |big: [f64; 2], signal: [f64; 2]| -> u64 {
        let ratio = (0..2)
            .map(|k| big[k] / (exp.tolerance * signal[k]))
            .fold(1.0f64, f64::max);
        let t = plan.tau_s * ratio.ln() + ratio.ln() / sigma + 5.0 * exp.decimation as f64 / clock;
        (t * clock).ceil() as u64
    };
    let tail = 2 * exp.decimation as u64 + 64;
    for &r in rates {
        let z = theory::readout_z(&dev, r * rad);
        let settle_cycles = settle([z[0].abs(), z[1].abs()], read_signal);
        let window_cycles = exp.min_window_s * clock;
        plan.points.push(PointPlan {
            mode: Mode::Readout,
            rate_dps: r,
            cal_hz: 0.0,
            omz_rad_s: r * rad,
            regs: readout_regs,
            settle_cycles,
            window_cycles,
            total_cycles: settle_cycles + window_cycles.ceil() as u64 + tail,
        });
    }
    for (regs, f) in cal_plans {
        // Every low-frequency term of x_k times its reference is at most the
        // product of their peaks.
        let x = theory::calibration_peak_displacement(&dev, f);
        let big = [x[0] * dev.f2_force, x[1] * dev.f1_force];
        let settle_cycles = settle(big, cal_signal);
        let periods = (exp.min_window_s * 2.0 * f).ceil();
        let window_cycles = periods / (2.0 * f) * clock;
        plan.points.push(PointPlan {
            mode: Mode::Calibration,
            rate_dps: 360.0 * f,
            cal_hz: f,
            omz_rad_s: 0.0,
            regs,
            settle_cycles,
            window_cycles,
            total_cycles: settle_cycles + window_cycles.ceil() as u64 + tail,
        });
    }
    Ok(plan)
}

/// A decimated sample of the outputs, for plots.
pub type TraceSample = [f64; 3];

/// The measured result of one point.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PointResult {
    /// Readout or calibration.
    pub mode: Mode,
    /// Rate used by the fit (deg/s).
    pub rate_dps: f64,
    /// Realized calibration frequency (Hz), 0 in readout.
    pub cal_hz: f64,
    /// Settling time (s).
    pub settle_s: f64,
    /// Averaging window (s).
    pub window_s: f64,
    /// Clocks simulated.
    pub cycles: u64,
    /// Window means of z1, z2 in z LSBs (2^-8 mixer LSB).
    pub z_lsb: [f64; 2],
    /// The same in m^2/s^2 (the theory's units).
    pub z: [f64; 2],
    /// Exact theory at this point (m^2/s^2).
    pub z_theory: [f64; 2],
    /// (time s, z1, z2 in m^2/s^2) every few z samples, for plots.
    #[serde(skip)]
    pub trace: Vec<TraceSample>,
}

/// What an observer sees of one clock.
#[derive(Clone, Copy, Debug)]
pub struct ClockView<'a> {
    /// Number of the rising edge just played (1 for the first).
    pub cycle: u64,
    /// ADC words that edge captured (inputs during the cycle before it).
    pub adc: (i16, i16),
    /// Ports after the edge.
    pub outputs: &'a Outputs,
    /// Internal signals after the edge.
    pub probes: &'a Probes,
    /// Displacements x1, x2 at the edge (m).
    pub x: (f64, f64),
    /// SELECT.
    pub select: bool,
}

/// Watches every clock of a run (waveform dumps).
pub trait Observer {
    /// Called after each clock.
    fn clock(&mut self, view: &ClockView);
    /// The last clock the observer needs (the simulation stops there).
    fn last_cycle(&self) -> u64;
}

/// The closed loop of one point at power-up: engine `E`, the plan's
/// converters, the gyroscope at rest, rotating at the point's rate.
pub fn point_loop<E: Engine>(
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
) -> Result<CoSim<E>, String> {
    let gyro = GyroModel::new(&exp.gyro, exp.clock_hz)?;
    let converters = Converters::new(&plan.front_end)?;
    let mut sim = CoSim::new(E::power_up()?, converters, gyro, point.regs);
    sim.set_rate(point.omz_rad_s);
    Ok(sim)
}

/// Simulate one point with engine `E`; `progress` receives clock counts.
pub fn run_point<E: Engine>(
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<PointResult, String> {
    let mut sim = point_loop::<E>(exp, plan, point)?;
    let r = exp.decimation as u64;
    let first_kept = point.settle_cycles.saturating_sub(2 * r);
    let (mut t, mut z1, mut z2) = (vec![], vec![], vec![]);
    let mut trace = vec![];
    let trace_every = (point.total_cycles / r / 2000).max(1);
    let mut z_count = 0u64;
    const CHUNK: u64 = 1 << 20;
    for n in 1..=point.total_cycles {
        let o = sim.step();
        if o.z_valid {
            if n >= first_kept {
                t.push(n as f64);
                z1.push(o.z.0 as f64);
                z2.push(o.z.1 as f64);
            }
            if z_count.is_multiple_of(trace_every) {
                trace.push([n as f64, o.z.0 as f64, o.z.1 as f64]);
            }
            z_count += 1;
        }
        if n % CHUNK == 0 {
            progress(CHUNK);
        }
    }
    progress(point.total_cycles % CHUNK);
    let t0 = point.settle_cycles as f64;
    let t1 = t0 + point.window_cycles;
    let z_lsb = [window_mean(&t, &z1, t0, t1), window_mean(&t, &z2, t0, t1)];
    // z LSB -> mixer LSB (adc word x reference word) -> m^2/s^2.
    let fe = &plan.front_end;
    let reference_channel = |k: usize| match point.mode {
        Mode::Readout => k,
        Mode::Calibration => 1 - k,
    };
    let to_physical: [f64; 2] = std::array::from_fn(|k| {
        fe.force_per_lsb[reference_channel(k)]
            / fe.adc_per_meter[k]
            / (f64::from(1u32 << OUTPUT_FRACTION_BITS) * plan.filter.dc_gain)
    });
    let clock = exp.clock_hz;
    Ok(PointResult {
        mode: point.mode,
        rate_dps: point.rate_dps,
        cal_hz: point.cal_hz,
        settle_s: point.settle_cycles as f64 / clock,
        window_s: point.window_cycles / clock,
        cycles: point.total_cycles,
        z_lsb,
        z: [z_lsb[0] * to_physical[0], z_lsb[1] * to_physical[1]],
        z_theory: plan.theory_z(exp, point),
        trace: trace
            .into_iter()
            .map(|[n, a, b]| [n / clock, a * to_physical[0], b * to_physical[1]])
            .collect(),
    })
}

/// Scale factors per output, in the sign convention of the paper's
/// equations, (m^2/s^2) per deg/s.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScaleFactors {
    /// Readout scale factor [output 1, output 2].
    pub sf_read_per_dps: [f64; 2],
    /// Calibration scale factor per deg/s of virtual rate.
    pub sf_cal_per_dps: [f64; 2],
    /// sf_read / sf_cal.
    pub ratio: [f64; 2],
}

/// Fit scale factors to points.
pub fn fit_scale_factors(
    points: &[PointResult],
    z: impl Fn(&PointResult) -> [f64; 2],
) -> ScaleFactors {
    let slopes = |mode| fit_lines(points, mode, &z).map(|(slope, _)| slope);
    let sf_read_per_dps = slopes(Mode::Readout);
    let sf_cal_per_dps = slopes(Mode::Calibration);
    ScaleFactors {
        sf_read_per_dps,
        sf_cal_per_dps,
        ratio: [
            sf_read_per_dps[0] / sf_cal_per_dps[0],
            sf_read_per_dps[1] / sf_cal_per_dps[1],
        ],
    }
}

/// Least-squares `(slope, intercept)` of each output against the rate, over
/// the points of one mode.
pub fn fit_lines(
    points: &[PointResult],
    mode: Mode,
    z: impl Fn(&PointResult) -> [f64; 2],
) -> [(f64, f64); 2] {
    std::array::from_fn(|k| {
        let (x, y): (Vec<f64>, Vec<f64>) = points
            .iter()
            .filter(|p| p.mode == mode)
            .map(|p| (p.rate_dps, z(p)[k]))
            .unzip();
        linear_fit(&x, &y)
    })
}

/// Run every point of a plan on `engine`, in parallel.
pub fn run_points(
    exp: &Experiment,
    plan: &Plan,
    engine: EngineKind,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<PointResult>, String> {
    let run = |p: &PointPlan| match engine {
        EngineKind::Model => run_point::<ModelEngine>(exp, plan, p, progress),
        EngineKind::Rtl => run_point::<RtlEngine>(exp, plan, p, progress),
        EngineKind::Verilator => run_verilator(exp, plan, p, progress),
    };
    plan.points.par_iter().map(run).collect()
}

#[cfg(feature = "verilator")]
fn run_verilator(
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<PointResult, String> {
    run_point::<crate::verilator::VerilatorEngine>(exp, plan, point, progress)
}

#[cfg(not(feature = "verilator"))]
fn run_verilator(
    _: &Experiment,
    _: &Plan,
    _: &PointPlan,
    _: &(dyn Fn(u64) + Sync),
) -> Result<PointResult, String> {
    Err("engine = \"verilator\": this build has no Verilator engine (rebuild with --features verilator)".into())
}

/// Plan and run an experiment on `engine`, timing it; `progress` receives
/// clock counts as they are simulated.
pub fn run(
    exp: &Experiment,
    engine: EngineKind,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<crate::report::Report, String> {
    let plan = plan(exp)?;
    let start = std::time::Instant::now();
    let points = run_points(exp, &plan, engine, progress)?;
    let wall_s = start.elapsed().as_secs_f64();
    let cycles = plan.total_cycles();
    let timing = crate::report::Timing {
        engine: engine.name().into(),
        cycles,
        wall_s,
        cycles_per_s: cycles as f64 / wall_s,
    };
    Ok(crate::report::Report::new(exp, &plan, points, timing))
}

/// Simulate the first clocks of one point with an observer, up to the
/// observer's last clock (waveform dumps); the point's result is not
/// computed.
pub fn observe_point<E: Engine>(
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
    observer: &mut dyn Observer,
) -> Result<(), String> {
    let mut sim = point_loop::<E>(exp, plan, point)?;
    for n in 1..=observer.last_cycle() {
        let o = sim.step();
        let g = sim.gyro();
        observer.clock(&ClockView {
            cycle: n,
            adc: sim.last_adc(),
            outputs: &o,
            probes: &sim.engine().probes(),
            x: (g.x1(), g.x2()),
            select: point.regs.select,
        });
    }
    Ok(())
}

/// `observe_point` on the engine of `kind`.
pub fn observe_point_on(
    kind: EngineKind,
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
    observer: &mut dyn Observer,
) -> Result<(), String> {
    match kind {
        EngineKind::Model => observe_point::<ModelEngine>(exp, plan, point, observer),
        EngineKind::Rtl => observe_point::<RtlEngine>(exp, plan, point, observer),
        #[cfg(feature = "verilator")]
        EngineKind::Verilator => observe_point::<crate::verilator::VerilatorEngine>(exp, plan, point, observer),
        #[cfg(not(feature = "verilator"))]
        EngineKind::Verilator => Err(
            "engine = \"verilator\": this build has no Verilator engine (rebuild with --features verilator)".into(),
        ),
    }
}
