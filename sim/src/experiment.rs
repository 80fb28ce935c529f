//! The paper's two experiments, co-simulated: a readout sweep over rotation
//! rates and a calibration staircase over calibration frequencies.
//!
//! Every point is an independent run from power-up (gyroscope at rest,
//! datapath at its power-up state), so points run in parallel on all cores.
//! A point runs for a settling time, then z1, z2 are averaged over a window
//! made of equal batches (`crate::average`). Both are derived, never guessed:
//!
//! - Settling (`crate::settling`). From rest the resonator's transient
//!   decays as exp(-t / tau) with tau = 2 Q_k / w_k (the slowest mode;
//!   with a damping coupling, `GyroParams::slowest_time_constant_s`), from
//!   Z, x_k's amplitude times its reference's. It must fall below
//!   `settling::SETTLE_MARGIN`-th of `tolerance` of the signal the fit
//!   measures at that output, S = |SF| x (span of the rates), and below a
//!   share of a point's expected noise, both from the exact theory; the
//!   filters lag it and add their own transient. On the paper's device
//!   the detuned readout output waits about 24 tau = 43 ms. The plan keeps
//!   each point's bound on what is left (`PointPlan::residue`), and the
//!   budget its bias on the window's mean.
//! - Window and batches, readout. The window is cut into `BATCHES` equal
//!   batches, each a whole number of units: the first window
//!   (`Derived::min_window_s`) over `BATCHES`.
//! - Window and batches, calibration. The window is M whole periods P of
//!   the 2 Om ripple (P = 1 / (2 f_cal), realized f_cal), because any other
//!   length leaves part of a ripple about 100 / f_cal\[Hz\] times the DC
//!   value in the mean; M is the same at every point of the staircase, at
//!   least `MIN_RIPPLE_PERIODS` and enough for the first window at the
//!   slowest point. Each period is cut into I = `RIPPLE_BATCHES` batches.
//!   The ripple's first harmonics are fitted to the window's samples and
//!   subtracted before the batches are cut (`crate::ripple`): a few dozen
//!   z samples per period leave an interpolation error in every batch.
//!   Beside the sinusoid, the ripple has a deterministic shape that
//!   repeats every period: on the paper's device at 10 Hz, with the 2 Om and
//!   4 Om sinusoids fitted out, 10 ms batch means still repeat each period
//!   with an amplitude of 1.4e-5 (output 1) and 5.6e-5 (output 2) of the DC
//!   value, and only fitting some 60 harmonics of f_cal removes it. So
//!   batches shorter than P are not independent samples of the mean.
//!   Two-way layout instead: batch s_mi (period m, phase i), phase means
//!   s_i over the M periods, window mean c; the spread of
//!   s_mi - s_i is noise alone, with I (M - 1) degrees of freedom. The
//!   point's batches are reported as c + (s_mi - s_i) sqrt((I M - 1) /
//!   (I (M - 1))), whose mean is c and whose plain batch-mean variance is
//!   that estimate, so the fits below need not know the layout. A window of
//!   2 to 3 periods then measures what took 8 (on the paper's device
//!   0.1 to 0.15 s instead of 0.27 to 0.4 s per point).
//! - Uncertainty. A point's value is the mean of its batch means. A slope's
//!   statistical uncertainty is the spread of the slopes fitted batch by
//!   batch (`crate::fit::fit_batches`): estimated from the data, never from
//!   the theory, times the coverage factor of its degrees of freedom
//!   (`fit::coverage_factor`). The number of batches is fixed and their
//!   length grows with the window (batch means with a fixed number of
//!   batches): for a white residue this is the usual estimate (t
//!   distribution, BATCHES - 1 degrees of freedom); for the deterministic
//!   residue of a clean converter (spectral lines from its quantization)
//!   it errs high by about sqrt(BATCHES / 2) and still falls as fast as
//!   the error, 1 / window. Points of a sweep share their settling time,
//!   so their batches line up. The report adds the systematic terms
//!   (`crate::budget`): the settling bound and the DAC's images
//!   (`crate::images`).
//! - Growth. Rounds: all points run; if a sweep's slope uncertainty is above
//!   its share of the ratio's target, tolerance x max(|ratio|,
//!   `RATIO_FLOOR`), that sweep runs again from power-up with longer
//!   windows, unless the next round would overrun the wall-time budget. The
//!   next length assumes the uncertainty falls as window^-a, a from the
//!   last two rounds (clamped to 1/2..1; 1/2 before there are two), at most
//!   `MAX_GROWTH` times per round. Re-running costs the settling again but
//!   keeps every engine's run independent and reproducible; with growth of
//!   several times per round the earlier rounds cost a fraction of the
//!   last.
//!
//! Scale factors are least-squares slopes with intercept (`crate::fit`) of
//! the averaged outputs against the physical rate (readout) or the virtual
//! rate 360 f_cal (calibration), in deg/s. The exact theory is evaluated at
//! the same points with the same fit, for the same forces: the DAC words'
//! amplitude times the force gain, times sinc(f_c T) for the hold (the
//! reference words carry no hold, so z scales by that factor once).

use crate::average::window_mean;
use crate::config::Derived;
pub use crate::config::Experiment;
use crate::cosim::{CoSim, CoSimLanes};
use crate::engine::{Engine, EngineKind, ModelEngine, RtlEngine};
use crate::error::RunError;
use crate::fit::{
    Line, ScaleFactors, coverage_factor, fit_batches, linear_fit, mean_and_standard_error,
};
use crate::frontend::{Converters, FrontEnd};
use crate::gyro::GyroModel;
use crate::images::sampled_peak;
use crate::ripple;
use crate::settling::{self, Sweep};
use crate::theory::{self, Device};
use gyrocal_hdl::cic_decimator::OUTPUT_FRACTION_BITS;
use gyrocal_hdl::filter_design::FilterDesign;
use gyrocal_hdl::gyro_interface::DRIVE_START_CLOCKS;
use gyrocal_hdl::model::am_mixer::{carrier_fraction_bits, carrier_product};
use gyrocal_hdl::model::carrier_nco::carrier_word;
use gyrocal_hdl::model::gyro_interface::CarrierProfile;
use gyrocal_hdl::model::gyro_interface::{Outputs, Probes, Registers};
use gyrocal_hdl::model::q15_multiplier::q15_product;
use gyrocal_hdl::settings::{self, FrequencyPlan};
use gyrocal_hdl::sine_table::PEAK;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::{PI, TAU};
use std::time::Instant;

/// Batches per window; the uncertainty of a mean of n batch means is
/// estimated with n - 1 degrees of freedom.
pub const BATCHES: u32 = 8;
/// Batches per ripple period of a calibration window (module header).
pub const RIPPLE_BATCHES: u32 = 8;
/// Fewest whole ripple periods in a calibration window: the uncertainty
/// comes from the spread between periods.
pub const MIN_RIPPLE_PERIODS: u32 = 2;
/// A window grows at most this many times per step.
const MAX_GROWTH: f64 = 8.0;
/// Share of the ratio's relative variance given to the calibration slope
/// (its signal is large at the resonant output and its uncertainty small);
/// the readout slope gets the rest.
const CAL_SHARE: f64 = 0.1;
/// Below this |ratio| the ratio's target is `tolerance x RATIO_FLOOR`
/// instead of `tolerance x |ratio|`: a ratio near zero would otherwise ask
/// for unbounded averaging.
pub const RATIO_FLOOR: f64 = 0.5;

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
    /// The unit of a batch's length, in clocks (not necessarily whole).
    pub unit_cycles: f64,
    /// Units per batch of the first window.
    pub units: u32,
    /// Bound on the transient left at the window's start, per output (z
    /// in m^2/s^2, `crate::settling`).
    pub residue: [f64; 2],
}

impl PointPlan {
    /// Window length in clocks: readout, `BATCHES` batches of `units` units;
    /// calibration, `units` whole ripple periods.
    pub fn window_cycles(&self, units: u32) -> f64 {
        match self.mode {
            Mode::Readout => f64::from(BATCHES) * f64::from(units) * self.unit_cycles,
            Mode::Calibration => f64::from(units) * self.unit_cycles,
        }
    }

    /// Number of batches in the window: readout `BATCHES`; calibration
    /// `RIPPLE_BATCHES` per ripple period.
    pub fn batch_count(&self, units: u32) -> u32 {
        match self.mode {
            Mode::Readout => BATCHES,
            Mode::Calibration => RIPPLE_BATCHES * units,
        }
    }

    /// Length of one batch in clocks.
    pub fn batch_cycles(&self, units: u32) -> f64 {
        match self.mode {
            Mode::Readout => self.window_cycles(units) / f64::from(BATCHES),
            Mode::Calibration => self.unit_cycles / f64::from(RIPPLE_BATCHES),
        }
    }

    /// Clocks to simulate for `units` units per batch (the decimator's and
    /// the filter's tail included).
    pub fn cycles_for(&self, units: u32, decimation: u32) -> u64 {
        let tail = 2 * u64::from(decimation) + 64;
        self.settle_cycles + self.window_cycles(units).ceil() as u64 + tail
    }
}

/// What the planner derived.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The points, readout first.
    pub points: Vec<PointPlan>,
    /// Filter and first window, derived or given.
    pub derived: Derived,
    /// Front end, with the ADC gains set.
    pub front_end: FrontEnd,
    /// Realized carrier (Hz).
    pub carrier_hz: f64,
    /// The output filter.
    pub filter: FilterDesign,
    /// Fundamental amplitude of the DAC and reference words (LSB) per
    /// channel, in readout (`realized_words`).
    pub drive_words: [f64; 2],
    /// The same for each sideband's envelope in calibration.
    pub cal_drive_words: [f64; 2],
    /// Fundamental gain of the DAC's hold at the carrier.
    pub hold_gain: f64,
    /// Slowest resonator amplitude time constant (s).
    pub tau_s: f64,
    /// What settling depends on (`crate::settling`).
    pub settling: settling::Timing,
    /// The rate signal each output's fit sees, in ADC LSB of in-phase
    /// amplitude over the whole span of rates, [readout, calibration]
    /// (below 1 without dither: the converters' quantization decides).
    pub signal_lsb: [[f64; 2]; 2],
    /// Things a user should know (commensurate frequency plan, ...).
    pub warnings: Vec<String>,
}

impl Plan {
    /// The device as the theory sees it: reference forces (DAC word
    /// amplitude times force gain). Multiply its z by `hold_gain`.
    pub fn theory_device(&self, exp: &Experiment) -> Device {
        self.theory_device_in(exp, Mode::Readout)
    }

    /// The device as the theory sees it in one mode (the words' realized
    /// amplitudes differ slightly between readout and calibration).
    pub fn theory_device_in(&self, exp: &Experiment, mode: Mode) -> Device {
        let words = match mode {
            Mode::Readout => self.drive_words,
            Mode::Calibration => self.cal_drive_words,
        };
        Device {
            f1_hz: exp.gyro.f1_hz,
            f2_hz: exp.gyro.f2_hz,
            q1: exp.gyro.q1,
            q2: exp.gyro.q2,
            angular_gain: exp.gyro.angular_gain,
            quadrature_dps: exp.gyro.quadrature_dps,
            damping_coupling_dps: exp.gyro.damping_coupling_dps,
            carrier_hz: self.carrier_hz,
            f1_force: words[0] * self.front_end.force_per_lsb[0],
            f2_force: words[1] * self.front_end.force_per_lsb[1],
        }
    }

    /// Clocks of all points' first windows.
    pub fn total_cycles(&self) -> u64 {
        let r = self.filter.decimation;
        self.points.iter().map(|p| p.cycles_for(p.units, r)).sum()
    }

    /// Exact theory z (m^2/s^2) at a point, hold included.
    pub fn theory_z(&self, exp: &Experiment, p: &PointPlan) -> [f64; 2] {
        let dev = self.theory_device_in(exp, p.mode);
        let z = match p.mode {
            Mode::Readout => theory::readout_z(&dev, p.omz_rad_s),
            Mode::Calibration => {
                let clock = exp.drive.clock_hz;
                theory::calibration_z_of_datapath(
                    &dev,
                    p.cal_hz,
                    envelope_lead_rad(p.cal_hz, clock),
                    [-1.0, 1.0]
                        .map(|s| hold_gain(self.carrier_hz + s * p.cal_hz, clock) / self.hold_gain),
                )
            }
        };
        [z[0] * self.hold_gain, z[1] * self.hold_gain]
    }

    /// m^2/s^2 per z LSB at each output of a point: z LSB -> mixer LSB (ADC
    /// word x reference word) -> metres x N/kg.
    pub fn z_per_lsb(&self, mode: Mode) -> [f64; 2] {
        let fe = &self.front_end;
        let reference_channel = |k: usize| match mode {
            Mode::Readout => k,
            Mode::Calibration => 1 - k,
        };
        std::array::from_fn(|k| {
            fe.force_per_lsb[reference_channel(k)]
                / fe.adc_per_meter[k]
                / (f64::from(1u32 << OUTPUT_FRACTION_BITS) * self.filter.dc_gain)
        })
    }
}

/// Fundamental gain of the DAC's zero-order hold (the host's theory holds
/// the one definition).
pub(crate) use gyrocal_host::theory::hold_gain;

/// A ratio's 1-sigma target: `tolerance x max(|ratio|, RATIO_FLOOR)`.
pub fn ratio_target(tolerance: f64, ratio: f64) -> f64 {
    tolerance * ratio.abs().max(RATIO_FLOOR)
}

pub use crate::theory::envelope_lead_rad;

/// Fundamental gain of a sine generator, sin and cos alike: the phase
/// average of its output times the exact sine (a carrier whose frequency
/// is not a small-integer fraction of the clock visits the phases
/// uniformly), over 2^16 phases spread evenly over every table interval.
fn table_gain(sine: impl Fn(u32) -> f64) -> f64 {
    const PHASES: u64 = 1 << 16;
    let sum: f64 = (0..PHASES)
        .map(|i| {
            let phase = ((i << 32) / PHASES) as u32 + (1 << 15);
            sine(phase) * (f64::from(phase) * TAU / 2f64.powi(32)).sin()
        })
        .sum();
    2.0 * sum / PHASES as f64 / f64::from(PEAK)
}

/// Fundamental amplitude (LSB) of the drive and reference words per
/// channel, as the AM mixer of the core with `profile` realizes them,
/// rounding included (`carrier_product`). On the table core each word is E
/// times the integer carrier over 2^15, rounded half up, and that rounding
/// error is a deterministic function of the table values that correlates
/// with the sine (neglecting it left 2.3e-7 of the amplitude in readout and
/// 5.3e-7 in calibration at amplitude 0.9; z carries the amplitude twice,
/// so 1.1e-6 of the calibration scale factor, 4 to 6 of its sigmas on
/// resonant outputs). On the fine core the word is E times the quarter-LSB
/// carrier over 2^17, and its rounding error is fed back with zeros at the
/// carrier, so the exact product is what the carrier sees (the test below
/// measures both cores' words).
/// - Readout: the envelope is one integer E = q15(amp, PEAK) (29490 for
///   amplitude 0.9), and the word carrier_product(E, carrier), whose fundamental is
///   averaged over the carrier's phases (`table_gain`).
/// - Calibration: the envelope q15(amp, am) follows the modulation table;
///   its fundamental is averaged over the modulation phases, and the
///   carrier product's rounding, a different integer envelope at every
///   step, averages out (below 1e-8 over the thousands of envelope values
///   of a period), so the carrier enters with its table's gain.
fn realized_words(amp: (i16, i16), mode: Mode, profile: CarrierProfile) -> [f64; 2] {
    let peak = f64::from(PEAK);
    let carrier_lsb = f64::from(1 << carrier_fraction_bits(profile));
    [amp.0, amp.1].map(|a| {
        let words = match mode {
            Mode::Readout => {
                let envelope = q15_product(a, PEAK as i16);
                let word = |p| carrier_product(profile, envelope, carrier_word(profile, p));
                peak * table_gain(word)
            }
            Mode::Calibration => {
                let modulation = |p| q15_product(a, gyrocal_hdl::model::sine::sine(p, 0));
                let carrier = |p| f64::from(carrier_word(profile, p)) / carrier_lsb;
                peak * table_gain(|p| f64::from(modulation(p))) * peak * table_gain(carrier)
                    / 32768.0
            }
        };
        words.abs()
    })
}

/// The largest minus the smallest value.
fn span(v: &[f64]) -> f64 {
    v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
}

/// Plan an experiment: registers, ADC gains, settling, batches, targets.
/// In order: the readout registers and the plan's fixed parts
/// (`plan_without_points`), each calibration frequency's registers, the
/// ADC gains from the largest displacement any point samples
/// (`adc_gains`), then the settling and batches of each sweep
/// (`readout_points`, `calibration_points`).
pub fn plan(exp: &Experiment) -> Result<Plan, RunError> {
    exp.validate()?;
    let derived = exp.derived()?;
    let fe = &exp.frontend;
    let base = FrequencyPlan {
        clock_hz: exp.drive.clock_hz,
        carrier_hz: exp.drive.carrier_hz,
        cal_hz: 0.0,
        calibration: false,
        amplitude: exp.drive.amplitude(),
        decimation: derived.decimation,
        butterworth_hz: derived.butterworth_hz,
        rc_hz: derived.rc_hz,
        dac_latency: fe.dac_latency,
        adc_latency: fe.adc_latency,
    };
    let (readout_regs, realized) = settings::registers(&base)?;
    let mut plan = plan_without_points(exp, derived, &realized, readout_regs.amp)?;
    let mut dev = plan.theory_device(exp);
    dev.f1_force *= plan.hold_gain;
    dev.f2_force *= plan.hold_gain;
    let cal_plans: Vec<(Registers, f64)> = exp
        .points
        .cal_freqs_hz
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
    let cal_hz: Vec<f64> = cal_plans.iter().map(|c| c.1).collect();
    plan.front_end.adc_per_meter = adc_gains(exp, &dev, &cal_hz);
    Converters::new(&plan.front_end)?;
    let read = readout_points(exp, &mut plan, &dev, readout_regs);
    let cal = calibration_points(exp, &mut plan, &dev, cal_plans);
    plan.points = read.into_iter().chain(cal).collect();
    Ok(plan)
}

/// The plan's parts that do not depend on the points: the drive words
/// (an error if one is below an LSB), the front end with unit ADC gains,
/// the filter, the hold's gain, the settling's timing and the warnings.
fn plan_without_points(
    exp: &Experiment,
    derived: Derived,
    realized: &settings::Realized,
    amp: (i16, i16),
) -> Result<Plan, RunError> {
    let fe = &exp.frontend;
    let profile = exp.drive.carrier_profile;
    let drive_words = realized_words(amp, Mode::Readout, profile);
    let cal_drive_words = realized_words(amp, Mode::Calibration, profile);
    if drive_words.iter().any(|&w| w < 1.0) {
        return Err(RunError::DrivesBelowOneLsb);
    }
    let force_full_scale = exp.drive.force_full_scale();
    let force_per_lsb = [force_full_scale[0] / 32768.0, force_full_scale[1] / 32768.0];
    let clock = exp.drive.clock_hz;
    let mut warnings = vec![];
    if let Some(q) = settings::commensurate_period(exp.drive.carrier_hz, clock) {
        warnings.push(format!(
            "carrier_hz / clock_hz is a ratio of small integers (period {q} clocks): the converters see only {q} phases and their quantization errors do not average out (errors of percent); use a non-round carrier or dither (noise_lsb)"
        ));
    }
    // Theory for gains and timing (the hold scales every force alike).
    let tau_s = exp.gyro.slowest_time_constant_s();
    let step = f64::from(1u32 << (16 - fe.adc_bits));
    Ok(Plan {
        points: vec![],
        front_end: FrontEnd {
            dac_latency: fe.dac_latency,
            adc_latency: fe.adc_latency,
            dac_bits: fe.dac_bits,
            adc_bits: fe.adc_bits,
            force_per_lsb,
            adc_per_meter: [1.0, 1.0],
            noise_lsb: fe.noise_lsb,
            seed: fe.seed,
        },
        carrier_hz: realized.carrier_hz,
        filter: realized.filter.clone(),
        drive_words,
        cal_drive_words,
        hold_gain: hold_gain(realized.carrier_hz, clock),
        tau_s,
        settling: settling::Timing {
            tau_s,
            butterworth_hz: derived.butterworth_hz,
            rc_hz: derived.rc_hz,
            decimation: derived.decimation,
            clock_hz: clock,
            adc_variance: fe.noise_lsb * fe.noise_lsb + step * step / 12.0,
            drive_start: DRIVE_START_CLOCKS as u64,
        },
        derived,
        signal_lsb: [[0.0; 2]; 2],
        warnings,
    })
}

/// The ADC gains (LSB per metre): `exp`'s own, or the largest sampled
/// displacement of any point (the DAC's images included, `crate::images`)
/// at `adc_headroom`; `dev` the theory's device with the hold's gain,
/// `cal_hz` the realized calibration frequencies.
fn adc_gains(exp: &Experiment, dev: &Device, cal_hz: &[f64]) -> [f64; 2] {
    if let Some(g) = exp.adc_per_meter() {
        return g;
    }
    let clock = exp.drive.clock_hz;
    let rad = PI / 180.0;
    let mut peak_x = [0.0f64; 2];
    for &r in &exp.points.readout_rates_dps {
        let x = sampled_peak(dev, clock, |d| {
            theory::readout_peak_displacement(d, r * rad)
        });
        peak_x = [peak_x[0].max(x[0]), peak_x[1].max(x[1])];
    }
    for &f in cal_hz {
        let x = sampled_peak(dev, clock, |d| theory::calibration_peak_displacement(d, f));
        peak_x = [peak_x[0].max(x[0]), peak_x[1].max(x[1])];
    }
    let headroom = exp.frontend.adc_headroom;
    peak_x.map(|x| headroom * 32767.0 / x)
}

/// The readout sweep's points: one settling time for all (so the points'
/// batches line up) and one window, its rate signal in ADC LSB set in
/// `plan.signal_lsb[0]` (see the module header and `crate::settling`).
/// The transient's scale is the peak product: x_k's amplitude times its
/// reference's (output k mixes with drive k in readout).
fn readout_points(
    exp: &Experiment,
    plan: &mut Plan,
    dev: &Device,
    regs: Registers,
) -> Vec<PointPlan> {
    let rad = PI / 180.0;
    let rates = &exp.points.readout_rates_dps;
    let sf_read = theory::sf_read_per_rad_s(dev).map(|v| v * rad);
    let signal = sf_read.map(|s| s.abs() * span(rates));
    let forces = [dev.f1_force, dev.f2_force];
    let adc = plan.front_end.adc_per_meter;
    // Rate signal in ADC LSB of in-phase amplitude: mean(adc x ref) = A W / 2.
    plan.signal_lsb[0] = std::array::from_fn(|k| 2.0 * signal[k] * adc[k] / forces[k]);
    let window_cycles = plan.derived.min_window_s * exp.drive.clock_hz;
    let (settle_cycles, residues) = settling::settle(
        &Sweep {
            transient: rates
                .iter()
                .map(|&r| {
                    let x = theory::readout_peak_displacement(dev, r * rad);
                    [x[0] * forces[0], x[1] * forces[1]]
                })
                .collect(),
            signal,
            signal_lsb: plan.signal_lsb[0],
            window_cycles,
        },
        &plan.settling,
        exp.points.tolerance,
    );
    rates
        .iter()
        .zip(residues)
        .map(|(&r, residue)| PointPlan {
            mode: Mode::Readout,
            rate_dps: r,
            cal_hz: 0.0,
            omz_rad_s: r * rad,
            regs,
            settle_cycles,
            unit_cycles: window_cycles / f64::from(BATCHES),
            units: 1,
            residue,
        })
        .collect()
}

/// The calibration sweep's points (`cal_plans`: registers and realized
/// frequency of each), as `readout_points` does the readout's, in whole
/// ripple periods: the same number at every point (their batches pair up
/// in the slope fit), enough for the first window at the slowest point
/// and at least `MIN_RIPPLE_PERIODS`. Output k mixes with the other
/// drive in calibration.
fn calibration_points(
    exp: &Experiment,
    plan: &mut Plan,
    dev: &Device,
    cal_plans: Vec<(Registers, f64)>,
) -> Vec<PointPlan> {
    let rad = PI / 180.0;
    let clock = exp.drive.clock_hz;
    let sf_cal = theory::sf_cal_per_rad_s(dev).map(|v| v * rad);
    let virtual_rates: Vec<f64> = cal_plans.iter().map(|c| 360.0 * c.1).collect();
    let signal = sf_cal.map(|s| s.abs() * span(&virtual_rates));
    let forces = [dev.f1_force, dev.f2_force];
    let adc = plan.front_end.adc_per_meter;
    plan.signal_lsb[1] = std::array::from_fn(|k| 2.0 * signal[k] * adc[k] / forces[1 - k]);
    let window_cycles = plan.derived.min_window_s * clock;
    let slowest = cal_plans.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
    let fastest = cal_plans.iter().map(|c| c.1).fold(0.0, f64::max);
    let periods = ((window_cycles * 2.0 * slowest / clock).ceil() as u32).max(MIN_RIPPLE_PERIODS);
    let (settle_cycles, residues) = settling::settle(
        &Sweep {
            transient: cal_plans
                .iter()
                .map(|&(_, f)| {
                    let x = theory::calibration_peak_displacement(dev, f);
                    [x[0] * forces[1], x[1] * forces[0]]
                })
                .collect(),
            signal,
            signal_lsb: plan.signal_lsb[1],
            window_cycles: f64::from(periods) * clock / (2.0 * fastest),
        },
        &plan.settling,
        exp.points.tolerance,
    );
    cal_plans
        .into_iter()
        .zip(residues)
        .map(|((regs, f), residue)| PointPlan {
            mode: Mode::Calibration,
            rate_dps: 360.0 * f,
            cal_hz: f,
            omz_rad_s: 0.0,
            regs,
            settle_cycles,
            unit_cycles: clock / (2.0 * f),
            units: periods,
            residue,
        })
        .collect()
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
    /// Length of each of the window's `BATCHES` batches (s).
    pub batch_s: f64,
    /// Clocks simulated.
    pub cycles: u64,
    /// Window means of z1, z2 in z LSBs (2^-8 mixer LSB).
    pub z_lsb: [f64; 2],
    /// 1-sigma uncertainty of `z_lsb` from its batch means (this point
    /// alone; the slopes' uncertainties come from `batch_z`).
    pub z_lsb_uncertainty: [f64; 2],
    /// The same in m^2/s^2 (the theory's units).
    pub z: [f64; 2],
    /// 1-sigma uncertainty of `z`.
    pub z_uncertainty: [f64; 2],
    /// Exact theory at this point (m^2/s^2).
    pub z_theory: [f64; 2],
    /// What the DAC's images add to `z_theory` in the sampled loop
    /// (m^2/s^2, `crate::images`).
    pub z_images: [f64; 2],
    /// Bound on the bias the settling transient leaves on `z` (m^2/s^2,
    /// `crate::settling`).
    pub settling_bound: [f64; 2],
    /// Degrees of freedom of the batches' spread: `BATCHES` - 1 in
    /// readout, `RIPPLE_BATCHES` (periods - 1) in calibration.
    #[serde(skip)]
    pub dof: u32,
    /// The batch means of z1, z2 (m^2/s^2).
    #[serde(skip)]
    pub batch_z: Vec<[f64; 2]>,
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

/// Progress of a run, for a progress bar.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tick {
    /// This many more clocks were simulated.
    Clocks(u64),
    /// A window grew: this many more clocks are planned.
    Planned(u64),
}

/// The closed loop of one point at power-up: engine `E`, the plan's
/// converters, the gyroscope at rest, rotating at the point's rate.
pub fn point_loop<E: Engine>(
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
) -> Result<CoSim<E>, RunError> {
    let gyro = GyroModel::new(&exp.gyro, exp.drive.clock_hz)?.with_thermal_noise(&exp.noise)?;
    let converters = Converters::new(&plan.front_end)?;
    let profile = exp.drive.carrier_profile;
    let mut sim = CoSim::new(E::power_up(profile)?, profile, converters, gyro, point.regs);
    sim.set_rate(point.omz_rad_s);
    Ok(sim)
}

/// `point_loop`'s loops at each of `rates_rad_s` on the model engine, as
/// lanes (`CoSimLanes`): each lane the loop `point_loop` makes for a point
/// with `regs` at that rate.
pub fn lanes_loop(
    exp: &Experiment,
    plan: &Plan,
    regs: Registers,
    rates_rad_s: &[f64],
) -> Result<CoSimLanes, RunError> {
    let gyros = rates_rad_s
        .iter()
        .map(|&rate| {
            let gyro = GyroModel::new(&exp.gyro, exp.drive.clock_hz)?;
            let mut gyro = gyro.with_thermal_noise(&exp.noise)?;
            gyro.set_rate(rate);
            Ok(gyro)
        })
        .collect::<Result<Vec<_>, RunError>>()?;
    let converters = Converters::new(&plan.front_end)?;
    let profile = exp.drive.carrier_profile;
    Ok(CoSimLanes::new(profile, converters, gyros, regs)?)
}

/// The z samples of one point from just before its window, and a thinned
/// trace of all of them.
#[derive(Clone)]
struct Samples {
    t: Vec<f64>,
    z: [Vec<f64>; 2],
    trace: Vec<TraceSample>,
    trace_every: u64,
    count: u64,
    first_kept: u64,
}

impl Samples {
    /// A point's samples to be (`run_point`), and the clock its run ends.
    fn for_point(plan: &Plan, point: &PointPlan, units: u32) -> (Self, u64) {
        let r = plan.filter.decimation;
        let end = point.cycles_for(units, r);
        let samples = Samples {
            t: vec![],
            z: [vec![], vec![]],
            trace: vec![],
            trace_every: (end / u64::from(r) / 2000).max(1),
            count: 0,
            first_kept: point.settle_cycles.saturating_sub(2 * u64::from(r)),
        };
        (samples, end)
    }

    /// Most trace samples kept; beyond, every other one is dropped.
    const TRACE_MAX: usize = 4000;

    fn push(&mut self, n: u64, z: (i64, i64)) {
        let z = [z.0 as f64, z.1 as f64];
        if n >= self.first_kept {
            self.t.push(n as f64);
            self.z[0].push(z[0]);
            self.z[1].push(z[1]);
        }
        if self.count.is_multiple_of(self.trace_every) {
            self.trace.push([n as f64, z[0], z[1]]);
            if self.trace.len() > Self::TRACE_MAX {
                self.trace = self.trace.iter().step_by(2).copied().collect();
                self.trace_every *= 2;
            }
        }
        self.count += 1;
    }

    /// `count` consecutive batch means of length `batch` from `t0`, per output.
    fn batch_means(&self, t0: f64, batch: f64, count: u32) -> Vec<[f64; 2]> {
        (0..count)
            .map(|j| {
                let a = t0 + f64::from(j) * batch;
                std::array::from_fn(|k| window_mean(&self.t, &self.z[k], a, a + batch))
            })
            .collect()
    }
}

/// Clocks a point's loop runs at a time, between progress ticks. A point
/// alone (`advance`) and in lanes (`run_points_in_lanes`) take the same
/// runs, so their blocks fall on the same clocks.
const RUN_CHUNK: u64 = 1 << 20;

/// Simulate up to clock `end`, keeping the z samples.
fn advance<E: Engine>(
    sim: &mut CoSim<E>,
    samples: &mut Samples,
    end: u64,
    progress: &(dyn Fn(Tick) + Sync),
) {
    while sim.cycle() < end {
        let clocks = (end - sim.cycle()).min(RUN_CHUNK);
        sim.run(clocks, |n, z| samples.push(n, z));
        progress(Tick::Clocks(clocks));
    }
}

/// Calibration batches (consecutive, `per_period` to a ripple period, whole
/// periods) with the ripple's shape taken out (module header): batch
/// (m, i) becomes c + (s_mi - s_i) sqrt((I M - 1) / (I (M - 1))), c the
/// window's mean and s_i the mean of phase i over the periods.
fn without_ripple_shape(raw: &[[f64; 2]], per_period: usize) -> Vec<[f64; 2]> {
    let periods = (raw.len() / per_period) as f64;
    let shape: Vec<[f64; 2]> = (0..per_period)
        .map(|i| {
            std::array::from_fn(|k| {
                raw.iter()
                    .skip(i)
                    .step_by(per_period)
                    .map(|b| b[k])
                    .sum::<f64>()
                    / periods
            })
        })
        .collect();
    let c: [f64; 2] =
        std::array::from_fn(|k| shape.iter().map(|s| s[k]).sum::<f64>() / per_period as f64);
    let n = raw.len() as f64;
    let scale = ((n - 1.0) / (n - per_period as f64)).sqrt();
    raw.iter()
        .enumerate()
        .map(|(j, b)| std::array::from_fn(|k| c[k] + (b[k] - shape[j % per_period][k]) * scale))
        .collect()
}

/// Mean and 1-sigma uncertainty of the mean of batch means, per output.
fn mean_and_uncertainty(batches: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    let [a, b] = std::array::from_fn(|k| {
        let column: Vec<f64> = batches.iter().map(|v| v[k]).collect();
        mean_and_standard_error(&column)
    });
    ([a.0, b.0], [a.1, b.1])
}

/// Simulate one point with engine `E` and `units` units per batch;
/// `progress` receives ticks.
pub fn run_point<E: Engine>(
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
    units: u32,
    progress: &(dyn Fn(Tick) + Sync),
) -> Result<PointResult, RunError> {
    let mut sim = point_loop::<E>(exp, plan, point)?;
    let (mut samples, end) = Samples::for_point(plan, point, units);
    advance(&mut sim, &mut samples, end, progress);
    Ok(point_result(exp, plan, point, units, samples))
}

/// Points that differ only in their rate, simulated in lanes
/// (`CoSimLanes`): each the result `run_point` on the model engine gives
/// it alone, bit for bit, where the drive half, the DAC forces and the
/// ADC noise are worked out once for all. The caller groups them
/// ([`lane_key`]); `progress` receives ticks.
pub fn run_points_in_lanes(
    exp: &Experiment,
    plan: &Plan,
    points: &[&PointPlan],
    units: u32,
    progress: &(dyn Fn(Tick) + Sync),
) -> Result<Vec<PointResult>, RunError> {
    let Some(&first) = points.first() else {
        return Ok(vec![]);
    };
    debug_assert!(points.iter().all(|p| lane_key(p) == lane_key(first)));
    let rates: Vec<f64> = points.iter().map(|p| p.omz_rad_s).collect();
    let mut sim = lanes_loop(exp, plan, first.regs, &rates)?;
    let (samples, end) = Samples::for_point(plan, first, units);
    let mut samples = vec![samples; points.len()];
    while sim.cycle() < end {
        let clocks = (end - sim.cycle()).min(RUN_CHUNK);
        sim.run(clocks, |l, n, z| samples[l].push(n, z));
        progress(Tick::Clocks(clocks * points.len() as u64));
    }
    let results = points.iter().zip(samples);
    Ok(results
        .map(|(p, s)| point_result(exp, plan, p, units, s))
        .collect())
}

/// What points must share to run in lanes (`run_points_in_lanes`): the
/// registers, the settling and the mode (a readout sweep's points share
/// them; their rates differ).
pub fn lane_key(point: &PointPlan) -> (Mode, Registers, u64) {
    (point.mode, point.regs, point.settle_cycles)
}

/// A point's result from its z samples (`run_point`).
fn point_result(
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
    units: u32,
    mut samples: Samples,
) -> PointResult {
    let end = point.cycles_for(units, plan.filter.decimation);
    let batch = point.batch_cycles(units);
    if point.mode == Mode::Calibration {
        let t0 = point.settle_cycles as f64;
        let t1 = t0 + point.window_cycles(units);
        for z in &mut samples.z {
            ripple::remove(&samples.t, z, point.unit_cycles, t0, t1);
        }
    }
    let raw = samples.batch_means(point.settle_cycles as f64, batch, point.batch_count(units));
    let batch_lsb = match point.mode {
        Mode::Readout => raw,
        Mode::Calibration => without_ripple_shape(&raw, RIPPLE_BATCHES as usize),
    };
    let (mean, sigma) = mean_and_uncertainty(&batch_lsb);
    let per_lsb = plan.z_per_lsb(point.mode);
    let clock = exp.drive.clock_hz;
    let window_s = point.window_cycles(units) / clock;
    PointResult {
        mode: point.mode,
        rate_dps: point.rate_dps,
        cal_hz: point.cal_hz,
        settle_s: point.settle_cycles as f64 / clock,
        window_s,
        batch_s: batch / clock,
        cycles: end,
        z_lsb: mean,
        z_lsb_uncertainty: sigma,
        z: [mean[0] * per_lsb[0], mean[1] * per_lsb[1]],
        z_uncertainty: [sigma[0] * per_lsb[0], sigma[1] * per_lsb[1]],
        z_theory: plan.theory_z(exp, point),
        z_images: plan.image_z(exp, point),
        settling_bound: settling::bias_bound(point.residue, &plan.settling, window_s),
        dof: match point.mode {
            Mode::Readout => BATCHES - 1,
            Mode::Calibration => RIPPLE_BATCHES * (units - 1),
        },
        batch_z: batch_lsb
            .iter()
            .map(|b| [b[0] * per_lsb[0], b[1] * per_lsb[1]])
            .collect(),
        trace: samples
            .trace
            .into_iter()
            .map(|[n, a, b]| [n / clock, a * per_lsb[0], b * per_lsb[1]])
            .collect(),
    }
}

/// Lines of each output against the rate over one sweep, from the points'
/// batch means, with their statistical uncertainties: the batch slopes'
/// spread times the `coverage_factor` of its degrees of freedom
/// (`crate::budget`).
pub fn measured_lines(points: &[PointResult], mode: Mode) -> [Line; 2] {
    let sweep: Vec<&PointResult> = points.iter().filter(|p| p.mode == mode).collect();
    let x: Vec<f64> = sweep.iter().map(|p| p.rate_dps).collect();
    let dof = sweep.iter().map(|p| p.dof).min().unwrap_or(1);
    std::array::from_fn(|k| {
        let batches: Vec<Vec<f64>> = sweep
            .iter()
            .map(|p| p.batch_z.iter().map(|b| b[k]).collect())
            .collect();
        let line = fit_batches(&x, &batches);
        Line {
            slope_uncertainty: line.slope_uncertainty * coverage_factor(dof),
            ..line
        }
    })
}

/// Lines of the exact theory at the same points, with the same fit.
pub fn exact_lines(points: &[PointResult], mode: Mode) -> [Line; 2] {
    let sweep: Vec<&PointResult> = points.iter().filter(|p| p.mode == mode).collect();
    let x: Vec<f64> = sweep.iter().map(|p| p.rate_dps).collect();
    std::array::from_fn(|k| {
        let y: Vec<f64> = sweep.iter().map(|p| p.z_theory[k]).collect();
        let (slope, intercept) = linear_fit(&x, &y);
        Line {
            slope,
            intercept,
            slope_uncertainty: 0.0,
        }
    })
}

/// The simulated scale factors with their uncertainties.
pub fn measured_scale_factors(points: &[PointResult]) -> ScaleFactors {
    ScaleFactors::from_lines(
        measured_lines(points, Mode::Readout),
        measured_lines(points, Mode::Calibration),
    )
}

/// The exact theory's scale factors at the same points, with the same fit.
pub fn exact_scale_factors(points: &[PointResult]) -> ScaleFactors {
    ScaleFactors::from_lines(
        exact_lines(points, Mode::Readout),
        exact_lines(points, Mode::Calibration),
    )
}

/// The points of a run and how long they took.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// Every point of the last round, in the plan's order.
    pub points: Vec<PointResult>,
    /// Engine and speed, all rounds.
    pub timing: Timing,
    /// Whether the budget stopped the windows before their targets.
    pub budget_exhausted: bool,
}

/// Timing of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Timing {
    /// Engine that ran the datapath.
    pub engine: String,
    /// Clocks simulated, all points and rounds.
    pub cycles: u64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Clocks per second of wall time (all cores).
    pub cycles_per_s: f64,
    /// Wall-time budget for growing the windows (s).
    pub budget_s: f64,
    /// Rounds run (the windows grew `rounds - 1` times).
    pub rounds: u32,
}

/// Each sweep's [readout, calibration] uncertainty over its target,
/// worst output: the ratio's target tolerance x max(|ratio|, RATIO_FLOOR)
/// split `1 - CAL_SHARE` : `CAL_SHARE` in relative variance.
pub fn excess(exp: &Experiment, sf: &ScaleFactors) -> [f64; 2] {
    let worst = |f: &dyn Fn(usize) -> f64| (0..2).map(f).fold(0.0f64, f64::max);
    let relative = |k: usize| ratio_target(exp.points.tolerance, sf.ratio[k]) / sf.ratio[k].abs();
    [
        worst(&|k| {
            sf.sf_read_uncertainty[k]
                / ((1.0 - CAL_SHARE).sqrt() * relative(k) * sf.sf_read_per_dps[k].abs())
        }),
        worst(&|k| {
            sf.sf_cal_uncertainty[k] / (CAL_SHARE.sqrt() * relative(k) * sf.sf_cal_per_dps[k].abs())
        }),
    ]
}

/// How many times longer a sweep's windows should be: the uncertainty
/// falls as window^-a (module header), with a 20% margin.
fn growth(history: &[(f64, f64)]) -> f64 {
    let (length, excess) = history[history.len() - 1];
    if excess <= 1.0 {
        return 1.0;
    }
    let a = match history {
        [.., (l0, e0), _] if *e0 > 0.0 && excess > 0.0 => {
            ((e0 / excess).ln() / (length / l0).ln()).clamp(0.5, 1.0)
        }
        _ => 0.5,
    };
    (1.2 * excess).powf(1.0 / a).clamp(1.1, MAX_GROWTH)
}

/// Run every point of a plan on `engine`, in parallel, in rounds of
/// growing windows until the targets are met or the experiment's wall-time
/// budget would be overrun (module header).
pub fn run_points(
    exp: &Experiment,
    plan: &Plan,
    engine: EngineKind,
    progress: &(dyn Fn(Tick) + Sync),
) -> Result<Measured, RunError> {
    let start = Instant::now();
    let r = plan.filter.decimation;
    let mut units: Vec<u32> = plan.points.iter().map(|p| p.units).collect();
    let mut history: [Vec<(f64, f64)>; 2] = [vec![], vec![]];
    let mut length = [1.0f64; 2];
    let mut cycles = 0;
    let mut rounds = 0;
    let sweep = |p: &PointPlan| match p.mode {
        Mode::Readout => 0,
        Mode::Calibration => 1,
    };
    loop {
        let round_start = Instant::now();
        let jobs: Vec<(&PointPlan, u32)> = plan.points.iter().zip(units.iter().copied()).collect();
        let run = |&(p, u): &(&PointPlan, u32)| match engine {
            EngineKind::Model => run_point::<ModelEngine>(exp, plan, p, u, progress),
            EngineKind::Rtl => run_point::<RtlEngine>(exp, plan, p, u, progress),
            EngineKind::Verilator => run_verilator(exp, plan, p, u, progress),
        };
        let points: Vec<PointResult> = match engine {
            EngineKind::Model => run_model_points(exp, plan, &jobs, progress)?,
            _ => jobs.par_iter().map(run).collect::<Result<_, _>>()?,
        };
        let round_cycles: u64 = points.iter().map(|p| p.cycles).sum();
        cycles += round_cycles;
        rounds += 1;
        let over = excess(exp, &measured_scale_factors(&points));
        for m in 0..2 {
            history[m].push((length[m], over[m]));
        }
        let mut grow = [growth(&history[0]), growth(&history[1])];
        let finish = |budget_exhausted| {
            let wall_s = start.elapsed().as_secs_f64();
            Ok(Measured {
                points: points.clone(),
                timing: Timing {
                    engine: engine.name().into(),
                    cycles,
                    wall_s,
                    cycles_per_s: cycles as f64 / wall_s,
                    budget_s: exp.points.budget_s,
                    rounds,
                },
                budget_exhausted,
            })
        };
        if grow == [1.0, 1.0] {
            return finish(false);
        }
        // Time the next round from this one's speed; shrink the growth
        // until it fits what is left of the budget.
        let seconds_per_cycle = round_start.elapsed().as_secs_f64() / round_cycles as f64;
        let left = exp.points.budget_s - start.elapsed().as_secs_f64();
        let next_units = |grow: [f64; 2]| -> Vec<u32> {
            plan.points
                .iter()
                .zip(&units)
                .map(|(p, &u)| (f64::from(u) * grow[sweep(p)]).ceil() as u32)
                .collect()
        };
        let next_cycles = |u: &[u32]| -> u64 {
            plan.points
                .iter()
                .zip(u)
                .map(|(p, &u)| p.cycles_for(u, r))
                .sum()
        };
        while next_cycles(&next_units(grow)) as f64 * seconds_per_cycle > left {
            grow = grow.map(|g| 1.0 + (g - 1.0) / 2.0);
            if grow.iter().all(|&g| g < 1.1) {
                return finish(true);
            }
        }
        units = next_units(grow);
        length = [length[0] * grow[0], length[1] * grow[1]];
        progress(Tick::Planned(next_cycles(&units)));
    }
}

/// The points of one round on the model engine: those that may share
/// lanes ([`lane_key`], and the same units) in as many lane groups as
/// there are threads, each group in lanes (`run_points_in_lanes`); the
/// same results in the same order as one `run_point` each.
fn run_model_points(
    exp: &Experiment,
    plan: &Plan,
    jobs: &[(&PointPlan, u32)],
    progress: &(dyn Fn(Tick) + Sync),
) -> Result<Vec<PointResult>, RunError> {
    let mut groups: Vec<Vec<usize>> = vec![];
    let key = |i: usize| (lane_key(jobs[i].0), jobs[i].1);
    for i in 0..jobs.len() {
        match groups.iter_mut().find(|g| key(g[0]) == key(i)) {
            Some(g) => g.push(i),
            None => groups.push(vec![i]),
        }
    }
    let threads = rayon::current_num_threads().max(1);
    let lanes: Vec<&[usize]> = groups
        .iter()
        .flat_map(|g| g.chunks(g.len().div_ceil(threads)))
        .collect();
    let results: Vec<Vec<PointResult>> = lanes
        .par_iter()
        .map(|lane| {
            let points: Vec<&PointPlan> = lane.iter().map(|&i| jobs[i].0).collect();
            run_points_in_lanes(exp, plan, &points, jobs[lane[0]].1, progress)
        })
        .collect::<Result<_, _>>()?;
    Ok(in_item_order(jobs.len(), &lanes, results))
}

/// Work units' results back in the order of the items they hold:
/// `results[u][j]` is item `units[u][j]`'s, and each of the `items` is in
/// exactly one unit (a round's points in lanes, a scenario's jobs).
pub(crate) fn in_item_order<T, U: AsRef<[usize]>>(
    items: usize,
    units: &[U],
    results: Vec<Vec<T>>,
) -> Vec<T> {
    let mut ordered: Vec<Option<T>> = (0..items).map(|_| None).collect();
    for (unit, results) in units.iter().zip(results) {
        for (&i, r) in unit.as_ref().iter().zip(results) {
            ordered[i] = Some(r);
        }
    }
    ordered
        .into_iter()
        .map(|r| r.expect("every item is in a unit"))
        .collect()
}

#[cfg(feature = "verilator")]
fn run_verilator(
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
    units: u32,
    progress: &(dyn Fn(Tick) + Sync),
) -> Result<PointResult, RunError> {
    run_point::<crate::verilator::VerilatorEngine>(exp, plan, point, units, progress)
}

#[cfg(not(feature = "verilator"))]
fn run_verilator(
    _: &Experiment,
    _: &Plan,
    _: &PointPlan,
    _: u32,
    _: &(dyn Fn(Tick) + Sync),
) -> Result<PointResult, RunError> {
    Err(RunError::NoVerilator)
}

/// Simulate the first clocks of one point with an observer, up to the
/// observer's last clock (waveform dumps); the point's result is not
/// computed.
pub fn observe_point<E: Engine>(
    exp: &Experiment,
    plan: &Plan,
    point: &PointPlan,
    observer: &mut dyn Observer,
) -> Result<(), RunError> {
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
) -> Result<(), RunError> {
    match kind {
        EngineKind::Model => observe_point::<ModelEngine>(exp, plan, point, observer),
        EngineKind::Rtl => observe_point::<RtlEngine>(exp, plan, point, observer),
        #[cfg(feature = "verilator")]
        EngineKind::Verilator => {
            observe_point::<crate::verilator::VerilatorEngine>(exp, plan, point, observer)
        }
        #[cfg(not(feature = "verilator"))]
        EngineKind::Verilator => Err(RunError::NoVerilator),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::ConfigError;
    use rand_distr::{Distribution, StandardNormal};
    use rand_xoshiro::Xoshiro256PlusPlus;
    use rand_xoshiro::rand_core::SeedableRng;

    /// Points in lanes are the points run alone: three of the paper's
    /// readout points (ADC noise on) and, as a lane group of one, a
    /// calibration point, each `PointResult` the same field for field as
    /// `run_point`'s on the model engine; `run_model_points` gives every
    /// round's points back in the plan's order.
    #[test]
    fn points_in_lanes_are_the_points_alone() {
        let exp = Experiment::paper();
        let plan = plan(&exp).unwrap();
        let quiet = |_: Tick| {};
        let readout: Vec<&PointPlan> = plan
            .points
            .iter()
            .filter(|p| p.mode == Mode::Readout)
            .step_by(7)
            .collect();
        assert_eq!(readout.len(), 3);
        assert!(readout.iter().all(|p| lane_key(p) == lane_key(readout[0])));
        let lanes = run_points_in_lanes(&exp, &plan, &readout, 1, &quiet).unwrap();
        for (p, lane) in readout.iter().zip(&lanes) {
            let alone = run_point::<ModelEngine>(&exp, &plan, p, 1, &quiet).unwrap();
            assert_eq!(*lane, alone, "the point at {} deg/s", p.rate_dps);
        }
        assert_ne!(lanes[0].z, lanes[1].z);
        let cal = plan
            .points
            .iter()
            .find(|p| p.mode == Mode::Calibration)
            .unwrap();
        let jobs: Vec<(&PointPlan, u32)> = vec![(readout[2], 1), (cal, 2), (readout[0], 1)];
        let round = run_model_points(&exp, &plan, &jobs, &quiet).unwrap();
        let cal_alone = run_point::<ModelEngine>(&exp, &plan, cal, 2, &quiet).unwrap();
        assert!(
            cal_alone.z.iter().all(|z| z.is_finite()),
            "{:?}",
            cal_alone.z
        );
        assert_eq!(round, vec![lanes[2].clone(), cal_alone, lanes[0].clone()]);
    }

    /// Samples of DC + a ripple 10 times larger at 2 f + a sharp shape that
    /// repeats every ripple period + white noise, from `t0` (clocks).
    fn calibration_like(rng: &mut Xoshiro256PlusPlus, period: f64, noise: f64) -> Samples {
        let h = 17.0;
        let t: Vec<f64> = (0..(3.2 * period / h) as usize)
            .map(|n| n as f64 * h)
            .collect();
        let shape = |x: f64| {
            let phase = (x / period).fract();
            if (0.3..0.35).contains(&phase) {
                40.0
            } else {
                0.0
            }
        };
        let z: Vec<f64> = t
            .iter()
            .map(|&x| {
                let white: f64 = StandardNormal.sample(rng);
                1.0 + 10.0 * (TAU * x / period + 0.7).cos() + shape(x) + noise * white
            })
            .collect();
        Samples {
            t,
            z: [z.clone(), z],
            trace: vec![],
            trace_every: 1,
            count: 0,
            first_kept: 0,
        }
    }

    #[test]
    fn ripple_batches_cancel_the_shape_and_estimate_the_noise() {
        // 2 whole periods of 1000 samples each: batch means of 1/8 period
        // carry the shape (40 x 0.05 x 8 = 16 in one batch of each period),
        // 400 times the noise of a batch mean (noise 0.1 / sqrt(125)); the
        // two-way layout must remove it. (c - 1) / sigma is then t with
        // I (M - 1) = 8 degrees of freedom: P(|t| <= 1) = 0.653, and over
        // 400 windows the count lies within 3 binomial standard deviations
        // (9.5) of 261; a sigma 1.5 times too small or too large (0.48,
        // 0.83) lands far outside.
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let period = 17_000.0;
        let mut within = 0;
        for _ in 0..400 {
            let s = calibration_like(&mut rng, period, 0.1);
            let raw = s.batch_means(0.1 * period, period / 8.0, 16);
            let batches = without_ripple_shape(&raw, 8);
            assert_eq!(batches.len(), 16);
            let (mean, sigma) = mean_and_uncertainty(&batches);
            if (mean[0] - 1.0 - 40.0 * 0.05).abs() <= sigma[0] {
                within += 1;
            }
        }
        assert!(
            (233..=289).contains(&within),
            "{within} of 400 within 1 sigma"
        );
    }
    /// `plan` tells its refusals apart: a drive that rounds to no DAC
    /// word, a key out of range, a plan the datapath cannot realize.
    #[test]
    fn plan_errors_are_typed() {
        let mut tiny = Experiment::paper();
        tiny.drive.amplitude1 = 1e-6;
        assert_eq!(plan(&tiny).unwrap_err(), RunError::DrivesBelowOneLsb);
        let mut bad = Experiment::paper();
        bad.gyro.q1 = -1.0;
        assert!(matches!(
            plan(&bad).unwrap_err(),
            RunError::Config(ConfigError::Key {
                section: "gyro",
                ..
            })
        ));
        let e = plan(&tiny).unwrap_err().to_string();
        assert_eq!(
            e,
            "[drive] amplitude1, amplitude2: both drives need at least one DAC LSB"
        );
    }

    #[test]
    fn the_realized_words_are_what_each_core_puts_out() {
        // The readout drive word's fundamental, measured on the core's
        // bit-true model over 2^24 clocks at the golden-ratio step (the
        // carrier farthest from every fold: its phases fill the turn
        // evenly soonest), against `realized_words` for the same core. The
        // measurement's own rounding noise is 0.3 x sqrt(2 / 2^24) = 1e-4
        // LSB; `realized_words` averages 2^16 phases, whose rounding
        // pattern leaves it about 0.3 x sqrt(2 / 2^16) = 1.7e-3 LSB from the
        // whole turn's average. 0.004 LSB bounds both (measured 0.0018 on
        // the table core, 0.0009 on the fine). The cores' words differ by
        // 0.009 LSB (3e-7: their carriers' gains and roundings), so the
        // table core's words, which this crate used for both cores before,
        // fail on the fine core.
        use gyrocal_hdl::model::gyro_interface::{GyroInterface, Registers};
        let amp = (29490, -20000);
        let step = 0x61c8_8647_u32;
        let mut measured = Vec::new();
        for profile in CarrierProfile::ALL {
            let mut core = GyroInterface::with_profile(profile);
            let regs = Registers {
                carrier_step: step,
                amp,
                ..Default::default()
            };
            for _ in 0..gyrocal_regs::datapath::DRIVE_START_CLOCKS + 64 {
                core.step((0, 0), &regs);
            }
            let n = 1u32 << 24;
            let (mut i, mut q) = (0.0, 0.0);
            for k in 0..n {
                let dac = f64::from(core.step((0, 0), &regs).dac.0);
                let angle = f64::from(step.wrapping_mul(k)) * TAU / 2f64.powi(32);
                i += dac * angle.cos();
                q += dac * angle.sin();
            }
            let amplitude = 2.0 * i.hypot(q) / f64::from(n);
            let want = realized_words(amp, Mode::Readout, profile)[0];
            eprintln!("{profile}: measured {amplitude:.5} LSB, realized_words {want:.5}");
            assert!(
                (amplitude - want).abs() < 0.004,
                "{profile}: {amplitude} against {want}"
            );
            measured.push(amplitude);
        }
        let table_words = realized_words(amp, Mode::Readout, CarrierProfile::Table)[0];
        assert!(
            (measured[1] - table_words).abs() > 0.004,
            "the fine core's words {} are the table core's {table_words}",
            measured[1]
        );
    }
}
