//! A field scenario: the device of an experiment drifting over the
//! `[drift]` section's temperature steps, self-calibrated at each step by
//! host code that sees only the board, against the simulation's truth.
//!
//! - The board is built once, at the factory temperature T0: its ADC gains
//!   are the ones `experiment::plan` sets for the nominal device, the
//!   force gains those of `[drive]`. At each step T the gyroscope, the
//!   converter gains and the front-end phase are `Drift::at(T)`, on a fresh
//!   board (quasi-static steps; the steps run in parallel).
//! - Self-calibration: [`selfcal::self_calibrate`] from the datasheet (the
//!   host does not know the temperature).
//! - Truth: the rate table (`SimBoard::set_rate`) at the readout rates of
//!   `[experiment]`, with the self-calibration's carrier and phase
//!   correction: the least-squares slope of z against the rate, z LSB per
//!   deg/s.
//! - Baseline: the factory calibration at T0 (the cycle, then the rate
//!   table) fixes the carrier, the phase correction and the scale factor;
//!   at T its error is against the rate table with those fixed settings.

use super::board::{Board, SimBoard};
use super::identify::{Identified, Knowns};
use super::selfcal::{self, Operating, SelfCal, window_z};
use crate::config::Experiment;
use crate::config::{Drive, Filter, Frontend, Points};
use crate::drift::{DeviceAt, Drift};
use crate::experiment;
use crate::fit::linear_fit;
use crate::frontend::FrontEnd;
use crate::gyro::GyroParams;
use crate::noise::ThermalNoise;
use rayon::prelude::*;
use serde::Deserialize;
use serde::Serialize;
use std::time::Instant;

/// Amplitude time constants waited before the first rate of a table (the
/// readout offset of a detuned output can be 1e4 times the rate signal).
const TABLE_FIRST_TAUS: f64 = 30.0;

/// A scenario file: the sections of `gyrocal run` plus `[drift]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScenarioFile {
    gyro: GyroParams,
    drive: Drive,
    #[serde(default)]
    frontend: Frontend,
    #[serde(default)]
    filter: Filter,
    experiment: Points,
    #[serde(default)]
    noise: ThermalNoise,
    drift: Drift,
}

/// Parse a scenario file's text: the experiment (checked as `gyrocal run`
/// checks it) and its `[drift]` (checked by `Drift::validate`). Errors are
/// one line; `name` labels them (the file path).
pub fn parse(name: &str, text: &str) -> Result<(Experiment, Drift), String> {
    let file: ScenarioFile = toml::from_str(text).map_err(|e| {
        let message = e.message().replace('\n', " ");
        match e.span() {
            Some(span) => {
                let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
                format!("{name} line {line}: {message}")
            }
            None => format!("{name}: {message}"),
        }
    })?;
    let exp = Experiment {
        gyro: file.gyro,
        drive: file.drive,
        frontend: file.frontend,
        filter: file.filter,
        points: file.experiment,
        noise: file.noise,
    };
    exp.validate().map_err(|e| format!("{name}: {e}"))?;
    exp.derived().map_err(|e| format!("{name}: {e}"))?;
    file.drift.validate().map_err(|e| format!("{name}: {e}"))?;
    Ok((exp, file.drift))
}

/// One temperature step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FieldStep {
    /// Temperature (deg C).
    pub temperature_c: f64,
    /// The truth at this step (never seen by the host).
    pub truth: DeviceAt,
    /// Rate-table scale factor at the self-calibration's settings (z LSB per deg/s).
    pub sf_true_per_dps: [f64; 2],
    /// SF_cal x ratio(identified) (z LSB per deg/s).
    pub sf_selfcal_per_dps: [f64; 2],
    /// SF_cal x eqs. (5)/(6) ratio (z LSB per deg/s).
    pub sf_eq56_per_dps: [f64; 2],
    /// The factory scale factor (z LSB per deg/s).
    pub sf_baseline_per_dps: [f64; 2],
    /// Rate-table scale factor at the factory settings (z LSB per deg/s).
    pub sf_true_at_factory_settings_per_dps: [f64; 2],
    /// sf_selfcal / sf_true - 1.
    pub selfcal_error: [f64; 2],
    /// sf_baseline / sf_true_at_factory_settings - 1.
    pub baseline_error: [f64; 2],
    /// Identified parameters (JSON: f1_hz, ..., with `_uncertainty` twins).
    pub identified: IdentifiedJson,
    /// The whole cycle's result.
    pub selfcal: SelfCal,
    /// Clocks simulated at this step.
    pub clocks: u64,
}

/// The identified parameters as the interface names them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IdentifiedJson {
    /// Mode 1 frequency (Hz).
    pub f1_hz: f64,
    /// Its 1-sigma uncertainty.
    pub f1_hz_uncertainty: f64,
    /// Mode 2 frequency (Hz).
    pub f2_hz: f64,
    /// Its 1-sigma uncertainty.
    pub f2_hz_uncertainty: f64,
    /// Mode 1 Q.
    pub q1: f64,
    /// Its 1-sigma uncertainty.
    pub q1_uncertainty: f64,
    /// Mode 2 Q.
    pub q2: f64,
    /// Its 1-sigma uncertainty.
    pub q2_uncertainty: f64,
    /// Loop phase lag (deg).
    pub loop_phase_deg: f64,
    /// Its 1-sigma uncertainty.
    pub loop_phase_deg_uncertainty: f64,
}

impl From<&Identified> for IdentifiedJson {
    fn from(id: &Identified) -> Self {
        let [m1, m2] = &id.modes;
        Self {
            f1_hz: m1.f_hz.value,
            f1_hz_uncertainty: m1.f_hz.uncertainty,
            f2_hz: m2.f_hz.value,
            f2_hz_uncertainty: m2.f_hz.uncertainty,
            q1: m1.q.value,
            q1_uncertainty: m1.q.uncertainty,
            q2: m2.q.value,
            q2_uncertainty: m2.q.uncertainty,
            loop_phase_deg: id.loop_phase_deg.value,
            loop_phase_deg_uncertainty: id.loop_phase_deg.uncertainty,
        }
    }
}

/// A whole scenario.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FieldReport {
    /// What the host knew.
    pub knowns: Knowns,
    /// The factory calibration at T0.
    pub factory: Operating,
    /// The factory scale factor (z LSB per deg/s).
    pub sf_factory_per_dps: [f64; 2],
    /// One entry per temperature, in the scenario's order.
    pub steps: Vec<FieldStep>,
    /// Clocks simulated, all steps.
    pub clocks: u64,
    /// Wall time (s).
    pub wall_s: f64,
}

/// The board as built and what the host knows, for `exp`.
pub fn build(exp: &Experiment) -> Result<(FrontEnd, Knowns), String> {
    let plan = experiment::plan(exp)?;
    Ok((plan.front_end, Knowns::from_experiment(exp)?))
}

/// A fresh board at one step. The front-end phase lag is exact at the
/// nominal modes' mean frequency; the Brownian noise is `[noise]` as given
/// (off unless its temperature is set).
pub fn board_at(exp: &Experiment, fe: &FrontEnd, at: &DeviceAt) -> Result<SimBoard, String> {
    let reference = 0.5 * (exp.gyro.f1_hz + exp.gyro.f2_hz);
    SimBoard::new(at, fe, &exp.noise, exp.drive.clock_hz, reference)
}

/// The rate table: readout at `op` on a fresh board per rate (from
/// power-up, as `experiment` runs its points), settled and averaged over
/// the first window; returns the slopes (z LSB per deg/s) and the clocks.
///
/// Fresh boards, not one board stepping through the rates: the carrier
/// table's residual spurs (below -100 dBc) mix with the resonant output's
/// full-scale quadrature into slow beats, some 1e-7 of that quadrature,
/// which is a few tenths of a percent of the paper device's rate signal on
/// that output. From power-up every rate sees the same beat at the same
/// phase, so it stays in the intercept; from wherever the last rate left
/// the carrier's phase it moves the slope (measured: 0.5% from one table
/// to the next on one board).
pub fn rate_table(
    exp: &Experiment,
    fe: &FrontEnd,
    at: &DeviceAt,
    knowns: &Knowns,
    op: &Operating,
) -> Result<([f64; 2], u64), String> {
    let (regs, _) = knowns.registers(op.carrier_hz, None, knowns.amplitude, op.ref_lag_deg)?;
    let r = knowns.filter.decimation;
    let length = (knowns.filter.min_window_s * knowns.clock_hz).ceil();
    let mut clocks = 0;
    let mut z = vec![];
    for &rate in &knowns.rates_dps {
        let mut board = board_at(exp, fe, at)?;
        board
            .program(&regs)
            .map_err(|e| format!("board refused a register access: {e:?}"))?;
        board.set_rate(rate.to_radians());
        board.wait_clocks(knowns.settle_clocks(TABLE_FIRST_TAUS));
        z.push(window_z(&mut board, r, f64::from(r), length)?);
        clocks += board.cycle();
    }
    let sf = std::array::from_fn(|k| {
        let y: Vec<f64> = z.iter().map(|v| v[k]).collect();
        linear_fit(&knowns.rates_dps, &y).0
    });
    Ok((sf, clocks))
}

fn ratio_error(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] / b[0] - 1.0, a[1] / b[1] - 1.0]
}

/// Run a scenario: factory calibration at T0, then every step in parallel;
/// `progress` gets one line per finished step.
pub fn run(
    exp: &Experiment,
    drift: &Drift,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<FieldReport, String> {
    exp.validate()?;
    drift.validate()?;
    let start = Instant::now();
    let (fe, knowns) = build(exp)?;
    let at0 = drift.at(&exp.gyro, drift.reference_c());
    let mut board0 = board_at(exp, &fe, &at0)?;
    let factory = selfcal::self_calibrate(&mut board0, &knowns, &knowns.nominal)?;
    let (sf_factory, factory_table) = rate_table(exp, &fe, &at0, &knowns, &factory.operating)?;
    progress(&format!(
        "factory calibration at {} deg C: carrier {:.3} Hz, phase {:.4} deg",
        drift.reference_c(),
        factory.operating.carrier_hz,
        factory.operating.ref_lag_deg
    ));
    let steps: Vec<FieldStep> = drift
        .temperatures_c
        .par_iter()
        .map(|&t| {
            let at = drift.at(&exp.gyro, t);
            let mut board = board_at(exp, &fe, &at)?;
            let cal = selfcal::self_calibrate(&mut board, &knowns, &knowns.nominal)?;
            let (sf_true, c1) = rate_table(exp, &fe, &at, &knowns, &cal.operating)?;
            let (sf_fixed, c2) = rate_table(exp, &fe, &at, &knowns, &factory.operating)?;
            progress(&format!(
                "{t} deg C: self-cal error {:+.4}% / {:+.4}%, baseline {:+.2}% / {:+.2}%",
                100.0 * (cal.sf_selfcal_per_dps[0] / sf_true[0] - 1.0),
                100.0 * (cal.sf_selfcal_per_dps[1] / sf_true[1] - 1.0),
                100.0 * (sf_factory[0] / sf_fixed[0] - 1.0),
                100.0 * (sf_factory[1] / sf_fixed[1] - 1.0),
            ));
            Ok(FieldStep {
                temperature_c: t,
                truth: at,
                sf_true_per_dps: sf_true,
                sf_selfcal_per_dps: cal.sf_selfcal_per_dps,
                sf_eq56_per_dps: cal.sf_eq56_per_dps,
                sf_baseline_per_dps: sf_factory,
                sf_true_at_factory_settings_per_dps: sf_fixed,
                selfcal_error: ratio_error(cal.sf_selfcal_per_dps, sf_true),
                baseline_error: ratio_error(sf_factory, sf_fixed),
                identified: IdentifiedJson::from(&cal.identified),
                clocks: board.cycle() + c1 + c2,
                selfcal: cal,
            })
        })
        .collect::<Result<_, String>>()?;
    let clocks = board0.cycle() + factory_table + steps.iter().map(|s| s.clocks).sum::<u64>();
    Ok(FieldReport {
        knowns,
        factory: factory.operating,
        sf_factory_per_dps: sf_factory,
        steps,
        clocks,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
