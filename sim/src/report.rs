//! The outcome of an experiment: simulated scale factors beside the exact
//! theory at the same points, the paper's closed forms, and the readout
//! scale factor predicted from calibration, in one serializable value.

use crate::budget::{Budget, ImageShifts, budget};
use crate::config::{Derived, Experiment};
use crate::engine::EngineKind;
use crate::error::RunError;
use crate::experiment::{
    self, Measured, Mode, Plan, PointResult, Tick, Timing, exact_scale_factors,
    measured_scale_factors,
};
use crate::fit::ScaleFactors;
use crate::gyro::GyroParams;
use crate::theory;
use serde::Serialize;

/// Degrees per radian factor for scale factors: (per rad/s) -> (per deg/s).
const PER_DPS: f64 = std::f64::consts::PI / 180.0;

/// The device as simulated.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DeviceSummary {
    /// The gyroscope's parameters (its fields at this level in JSON).
    #[serde(flatten)]
    pub gyro: GyroParams,
    /// Realized carrier (Hz).
    pub carrier_hz: f64,
    /// FPGA clock (Hz).
    pub clock_hz: f64,
    /// Drive forces F1, F2 seen by the theory (N/kg, DAC word amplitude
    /// times force gain; the hold scales the applied force by `hold_gain`).
    pub force_n_per_kg: [f64; 2],
    /// Fundamental gain of the DAC hold at the carrier, sin(x)/x.
    pub hold_gain: f64,
    /// ADC gains (LSB per metre).
    pub adc_per_meter: [f64; 2],
    /// CIC decimation and z rate (Hz).
    pub decimation: u32,
    /// z sample rate (Hz).
    pub z_rate_hz: f64,
    /// Realized DC gain of CIC and IIR.
    pub filter_dc_gain: f64,
    /// Slowest resonator time constant 2 Q / w (s).
    pub tau_s: f64,
}

/// Closed forms at the simulated device.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SmallSignal {
    /// Exact small-signal readout scale factor, per deg/s.
    pub sf_read_per_dps: [f64; 2],
    /// Exact small-signal calibration scale factor, per deg/s of virtual rate.
    pub sf_cal_per_dps: [f64; 2],
    /// Their ratio.
    pub ratio: [f64; 2],
    /// Paper eq. (5), per deg/s (same for both outputs).
    pub eq5_sf_read_per_dps: f64,
    /// Paper eq. (6), per deg/s, [SF_cal1, SF_cal2].
    pub eq6_sf_cal_per_dps: [f64; 2],
    /// eq. (5) / eq. (6): the paper's predicted ratio.
    pub eq56_ratio: [f64; 2],
}

/// Exact theory under the same names as the simulated values.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Theory {
    /// Fitted readout scale factor at the same points, same fit.
    pub sf_read_per_dps: [f64; 2],
    /// Fitted calibration scale factor at the same points, same fit.
    pub sf_cal_per_dps: [f64; 2],
    /// Ratio of the two.
    pub ratio: [f64; 2],
    /// What the DAC's images, aliased back by the ADC, add to the fitted
    /// values in the sampled loop (signed; `crate::images`): the theory
    /// leaves them out, and the budget counts them.
    pub images: ImageShifts,
    /// Small-signal values and the paper's closed forms.
    pub small_signal: SmallSignal,
}

/// Everything `gyrocal run --json` prints and `results.json` holds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// The simulated scale factors, their ratio and the fits' intercepts
    /// (JSON: at the top level, `sf_read_per_dps` ... `intercept_cal`),
    /// in (m^2/s^2) per deg/s (calibration: per deg/s of virtual rate 360
    /// f_cal); each 1-sigma against the exact theory, all sources
    /// (`uncertainty_budget`).
    #[serde(flatten)]
    pub scale_factors: ScaleFactors,
    /// The ratio's target uncertainty, tolerance x max(|ratio|, 0.5).
    pub ratio_target_uncertainty: [f64; 2],
    /// The 1-sigma terms of each figure by source, whose root sum of
    /// squares is its `_uncertainty` (`crate::budget`).
    pub uncertainty_budget: Budget,
    /// The readout scale factor in the gateware's own units, what a board
    /// measures: z LSB (one unit of the 40-bit z word, 1/256 of a mixer
    /// LSB) per deg/s. It carries the DAC and ADC gains that the equations'
    /// units divide out.
    pub sf_read_lsb_per_dps: [f64; 2],
    /// Its 1-sigma uncertainty.
    pub sf_read_lsb_uncertainty: [f64; 2],
    /// The calibration scale factor in z LSB per deg/s of virtual rate.
    pub sf_cal_lsb_per_dps: [f64; 2],
    /// Its 1-sigma uncertainty.
    pub sf_cal_lsb_uncertainty: [f64; 2],
    /// The exact theory at the same points, and closed forms.
    pub theory: Theory,
    /// Relative error of the simulated ratio against the exact fitted one.
    pub ratio_error: [f64; 2],
    /// Readout scale factor predicted from the simulated calibration and the
    /// exact theory's ratio (what self-calibration delivers).
    pub predicted_sf_read_per_dps: [f64; 2],
    /// Same, predicted with the paper's eqs. (5)/(6) ratio, as in the paper.
    pub predicted_sf_read_eq56_per_dps: [f64; 2],
    /// Relative error of the eq. (5)/(6) prediction against the simulated
    /// readout scale factor (the paper's "3%").
    pub prediction_error_eq56: [f64; 2],
    /// Relative error of the exact-theory prediction.
    pub prediction_error: [f64; 2],
    /// Output (0 or 1) whose mode is farther from the carrier, if any.
    pub detuned_output: Option<usize>,
    /// The device and converters as simulated.
    pub device: DeviceSummary,
    /// Filter and first window as used (derived or given).
    pub settings: Derived,
    /// RMS noise at the ADCs as used (LSB): given, or derived (dither).
    pub noise_lsb: f64,
    /// Each sweep's rate signal in ADC LSB of in-phase amplitude over the
    /// whole span of its points, [readout, calibration] x [output 1, 2]:
    /// below 1, the quantizer decides unless dithered.
    pub rate_signal_adc_lsb: [[f64; 2]; 2],
    /// Every point.
    pub points: Vec<PointResult>,
    /// Engine and speed.
    pub timing: Timing,
    /// Things worth knowing about the setup.
    pub warnings: Vec<String>,
}

impl Report {
    /// Assemble the report of a finished run.
    pub fn new(exp: &Experiment, plan: &Plan, measured: Measured) -> Self {
        let points = measured.points;
        let statistical: ScaleFactors = measured_scale_factors(&points);
        let (uncertainty_budget, images) = budget(&points, &statistical);
        let sim = ScaleFactors {
            sf_read_uncertainty: uncertainty_budget.sf_read_per_dps.map(|t| t.total),
            sf_cal_uncertainty: uncertainty_budget.sf_cal_per_dps.map(|t| t.total),
            ratio_uncertainty: uncertainty_budget.ratio.map(|t| t.total),
            ..statistical
        };
        // Equations' units per z LSB, per output: a constant of each mode.
        let read_per_lsb = plan.z_per_lsb(Mode::Readout);
        let cal_per_lsb = plan.z_per_lsb(Mode::Calibration);
        let in_lsb = |v: [f64; 2], per_lsb: [f64; 2]| [v[0] / per_lsb[0], v[1] / per_lsb[1]];
        let exact: ScaleFactors = exact_scale_factors(&points);
        let small_signal = SmallSignal::of(exp, plan);
        let predicted: [f64; 2] = std::array::from_fn(|k| sim.sf_cal_per_dps[k] * exact.ratio[k]);
        let predicted_eq56: [f64; 2] =
            std::array::from_fn(|k| sim.sf_cal_per_dps[k] * small_signal.eq56_ratio[k]);
        let rel = |a: f64, b: f64| a / b - 1.0;
        let target = sim
            .ratio
            .map(|r| experiment::ratio_target(exp.points.tolerance, r));
        let mut warnings = plan.warnings.clone();
        warnings.extend(accuracy_warnings(
            exp,
            plan,
            measured.budget_exhausted,
            &statistical,
            target,
        ));
        warnings.extend(crate::budget::warnings(
            &uncertainty_budget,
            target,
            plan.carrier_hz / exp.drive.clock_hz,
        ));
        Report {
            ratio_error: std::array::from_fn(|k| rel(sim.ratio[k], exact.ratio[k])),
            predicted_sf_read_per_dps: predicted,
            predicted_sf_read_eq56_per_dps: predicted_eq56,
            prediction_error: std::array::from_fn(|k| rel(predicted[k], sim.sf_read_per_dps[k])),
            prediction_error_eq56: std::array::from_fn(|k| {
                rel(predicted_eq56[k], sim.sf_read_per_dps[k])
            }),
            ratio_target_uncertainty: target,
            uncertainty_budget,
            sf_read_lsb_per_dps: in_lsb(sim.sf_read_per_dps, read_per_lsb),
            sf_read_lsb_uncertainty: in_lsb(sim.sf_read_uncertainty, read_per_lsb),
            sf_cal_lsb_per_dps: in_lsb(sim.sf_cal_per_dps, cal_per_lsb),
            sf_cal_lsb_uncertainty: in_lsb(sim.sf_cal_uncertainty, cal_per_lsb),
            theory: Theory {
                sf_read_per_dps: exact.sf_read_per_dps,
                sf_cal_per_dps: exact.sf_cal_per_dps,
                ratio: exact.ratio,
                images,
                small_signal,
            },
            detuned_output: detuned_output(exp, plan),
            device: DeviceSummary::of(exp, plan),
            settings: plan.derived.clone(),
            noise_lsb: plan.front_end.noise_lsb,
            rate_signal_adc_lsb: plan.signal_lsb,
            points,
            timing: measured.timing,
            warnings,
            scale_factors: sim,
        }
    }
}

impl SmallSignal {
    /// The small-signal theory of `exp`'s device as `plan` drives it, the
    /// hold's gain split evenly between drive and pick-off.
    fn of(exp: &Experiment, plan: &Plan) -> Self {
        let mut dev = plan.theory_device(exp);
        dev.f1_force *= plan.hold_gain.sqrt();
        dev.f2_force *= plan.hold_gain.sqrt();
        let sf_read = theory::sf_read_per_rad_s(&dev).map(|v| v * PER_DPS);
        let sf_cal = theory::sf_cal_per_rad_s(&dev).map(|v| v * PER_DPS);
        let eq5 = theory::eq5_sf_read_per_rad_s(&dev) * PER_DPS;
        let eq6 = theory::eq6_sf_cal_per_rad_s(&dev).map(|v| v * PER_DPS);
        SmallSignal {
            sf_read_per_dps: sf_read,
            sf_cal_per_dps: sf_cal,
            ratio: [sf_read[0] / sf_cal[0], sf_read[1] / sf_cal[1]],
            eq5_sf_read_per_dps: eq5,
            eq6_sf_cal_per_dps: eq6,
            eq56_ratio: [eq5 / eq6[0], eq5 / eq6[1]],
        }
    }
}

impl DeviceSummary {
    /// `exp`'s device and the settings `plan` gives it.
    fn of(exp: &Experiment, plan: &Plan) -> Self {
        let theory_device = plan.theory_device(exp);
        DeviceSummary {
            gyro: exp.gyro.clone(),
            carrier_hz: plan.carrier_hz,
            clock_hz: exp.drive.clock_hz,
            force_n_per_kg: [theory_device.f1_force, theory_device.f2_force],
            hold_gain: plan.hold_gain,
            adc_per_meter: plan.front_end.adc_per_meter,
            decimation: plan.filter.decimation,
            z_rate_hz: plan.filter.output_rate_hz,
            filter_dc_gain: plan.filter.dc_gain,
            tau_s: plan.tau_s,
        }
    }
}

/// The output (0, 1) whose mode lies farther from the carrier, `None`
/// when both are as far.
fn detuned_output(exp: &Experiment, plan: &Plan) -> Option<usize> {
    let d1 = (exp.gyro.f1_hz - plan.carrier_hz).abs();
    let d2 = (exp.gyro.f2_hz - plan.carrier_hz).abs();
    if d1 == d2 {
        None
    } else if d2 > d1 {
        Some(1)
    } else {
        Some(0)
    }
}

/// One line per output whose ratio missed its target because the budget
/// ran out, or whose rate signal is below the ADC's resolution: which
/// output, the statistical uncertainty reached (`sim`'s, what longer
/// windows lower), and what would lower it.
fn accuracy_warnings(
    exp: &Experiment,
    plan: &Plan,
    exhausted: bool,
    sim: &ScaleFactors,
    target: [f64; 2],
) -> Vec<String> {
    let dithered = crate::frontend::dithers(plan.front_end.noise_lsb, plan.front_end.adc_bits);
    let fixes = if !dithered {
        "dither ([frontend] noise_lsb = 1) or more ADC bits ([frontend] adc_bits)"
    } else {
        "more ADC bits ([frontend] adc_bits) or longer first windows ([experiment] min_window_s)"
    };
    let mut lines = vec![];
    for (k, &target) in target.iter().enumerate() {
        let reached = sim.ratio_uncertainty[k];
        let signal = plan.signal_lsb[0][k].min(plan.signal_lsb[1][k]);
        if exhausted && reached > target {
            lines.push(format!(
                "output {}: ratio uncertainty {reached:.2e} (target {:.2e}) when the wall-time budget of {} s ran out; raise [experiment] budget_s, or lower the residue: {fixes}",
                k + 1,
                target,
                exp.points.budget_s
            ));
        } else if signal < 1.0 && !dithered {
            lines.push(format!(
                "output {}: its rate signal spans {signal:.2} ADC LSB over the points, below the ADC's resolution, and the ADCs are not dithered: each point's mean carries a static quantization bias that the uncertainty {reached:.2e} (target {:.2e}) cannot see; dither ([frontend] noise_lsb = 1, the default) or more ADC bits ([frontend] adc_bits) remove it",
                k + 1,
                target
            ));
        }
    }
    lines
}

/// Plan and run an experiment on `engine`, and report it; `progress`
/// receives ticks as clocks are simulated.
pub fn run(
    exp: &Experiment,
    engine: EngineKind,
    progress: &(dyn Fn(Tick) + Sync),
) -> Result<Report, RunError> {
    let plan = experiment::plan(exp)?;
    let measured = experiment::run_points(exp, &plan, engine, progress)?;
    Ok(Report::new(exp, &plan, measured))
}
