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
//!   host does not know the temperature). The first step's (at T0) is the
//!   factory calibration.
//! - Truth: the rate table (`SimBoard::set_rate`) at the readout rates of
//!   `[experiment]`, with the self-calibration's carrier and phase
//!   correction: the least-squares slope of z against the rate, z LSB per
//!   deg/s.
//! - Baseline: the factory calibration at T0 (the cycle, then the rate
//!   table) fixes the carrier, the phase correction and the scale factor;
//!   at T its error is against the rate table with those fixed settings.
//! - With a `[drive_probe]` ([`drive_ratio`]): after its cycle each step's
//!   board turns at the probe's rate while the host measures the drive-gain
//!   ratio, and the prediction uses it instead of the design ratio.
//! - With a `[profile]` ([`profile`]): after its cycle each step's board
//!   switches to readout, measures its null at rest and runs the profile;
//!   the rate output is (z - null) / SF_selfcal. The baseline runs the
//!   profile on a fresh board at the factory's settings and reads it with
//!   the factory's null and scale factor.

use super::board::{Board, SimBoard};
use super::lanes::LaneBoards;
use super::probe::DriveProbe;
use super::profile::{self, ClippedRecords, Profile, ProfileRun, RateTrace};
use crate::config::{self, Experiment};
use crate::config::{Drive, Filter, Frontend, Points};
use crate::coverage::{Scored, beyond_three_sigma, uncovered_parameters, uncovered_selfcal_errors};
use crate::drift::{DeviceAt, Drift};
use crate::engine::Engine;
use crate::error::{ConfigError, FieldError, RunError, ScenarioError};
use crate::experiment;
use crate::fit::{coverage_factor, linear_fit};
use crate::frontend::FrontEnd;
use crate::gyro::GyroParams;
use crate::noise::ThermalNoise;
use crate::sweep::spread::Spread;
use gyrocal_host::Knowns;
use gyrocal_host::datasheet::Datasheet;
use gyrocal_host::identify::{self, CouplingFigure, Estimate, Identified};
use gyrocal_host::sampling::{Signal, mean_of_parts, part_means};
use gyrocal_host::selfcal::StaticFold;
use gyrocal_host::selfcal::{self, Operating, SelfCal};
use gyrocal_host::{clip, drive_ratio};
use gyrocal_regs::plan::{FOLD_CLEAR_CORNERS, nearest_fold};
use rayon::prelude::*;
use serde::Deserialize;
use serde::Serialize;
use std::time::Instant;

/// Amplitude time constants waited before the first rate of a table (the
/// readout offset of a detuned output can be 1e4 times the rate signal).
/// Measured on the consumer device's output 1 (its rate term 1e-4 of its
/// offset), the slope after 20, 25, 30, 40, 60 of these: -188.83, -189.06,
/// -189.10, -189.08, -189.03 z LSB per deg/s: settled from 30 on, within
/// the +-0.04% the spurs' beats leave (`rate_table`).
const TABLE_FIRST_TAUS: f64 = 30.0;

/// A scenario file: the sections of `gyrocal run` plus `[drift]` and,
/// optionally, `[profile]` and `[drive_probe]`.
#[derive(Deserialize, Serialize)]
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
    #[serde(default, skip_serializing_if = "Option::is_none")]
    drift: Option<Drift>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    profile: Option<Profile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    drive_probe: Option<DriveProbe>,
    #[serde(default)]
    datasheet: Datasheet,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    spread: Option<Spread>,
}

/// A checked scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// The experiment (the device at T0, its drive, front end, filter, points).
    pub exp: Experiment,
    /// The temperature steps and drift coefficients.
    pub drift: Drift,
    /// The rate profile applied at every step, if any.
    pub profile: Option<Profile>,
    /// The turn during which the host measures the drive-gain ratio, if any.
    pub drive_probe: Option<DriveProbe>,
}

/// Parse a scenario file's text: the experiment (checked as `gyrocal run`
/// checks it), its `[drift]` (checked by `Drift::validate`) and its
/// `[profile]` (`Profile::validate`). Errors are one line; `name` labels
/// them (the file path). A `[spread]` is refused: it is `gyrocal sweep`'s
/// (`crate::sweep::parse`).
pub fn parse(name: &str, text: &str) -> Result<Scenario, ScenarioError> {
    let (sc, spread, has_drift) = parse_file(name, text)?;
    if spread.is_some() {
        return Err(ScenarioError::SpreadInField(name.into()));
    }
    if !has_drift {
        return Err(ScenarioError::NoDrift(name.into()));
    }
    Ok(sc)
}

/// The scenario of a file, its `[spread]` and whether it had a `[drift]`
/// (without one, the scenario's drift is the single step
/// [`Drift::constant`] at [`FACTORY_C`]).
pub(crate) fn parse_file(
    name: &str,
    text: &str,
) -> Result<(Scenario, Option<Spread>, bool), ScenarioError> {
    let file: ScenarioFile = toml::from_str(text)
        .map_err(|e| ScenarioError::Syntax(config::parse_error(name, text, e)))?;
    let exp = Experiment {
        gyro: file.gyro,
        drive: file.drive,
        frontend: file.frontend,
        filter: file.filter,
        points: file.experiment,
        noise: file.noise,
        datasheet: file.datasheet,
    };
    let has_drift = file.drift.is_some();
    let drift = file.drift.unwrap_or_else(|| Drift::constant(FACTORY_C));
    let sc = Scenario {
        exp,
        drift,
        profile: file.profile,
        drive_probe: file.drive_probe,
    };
    sc.validate().map_err(|error| ScenarioError::Invalid {
        file: name.into(),
        error,
    })?;
    Ok((sc, file.spread, has_drift))
}

/// The factory temperature of a file without `[drift]` (deg C).
pub const FACTORY_C: f64 = 25.0;

impl Scenario {
    /// The scenario as a `gyrocal field` file: [`parse`] reads it back to
    /// this scenario, every value to the bit (floats are written in their
    /// shortest round-trip form). How `gyrocal sweep part` hands a user one
    /// part of a spread to run again alone.
    pub fn to_toml(&self) -> Result<String, ScenarioError> {
        let exp = self.exp.clone();
        let file = ScenarioFile {
            gyro: exp.gyro,
            drive: exp.drive,
            frontend: exp.frontend,
            filter: exp.filter,
            experiment: exp.points,
            noise: exp.noise,
            drift: Some(self.drift.clone()),
            profile: self.profile.clone(),
            drive_probe: self.drive_probe.clone(),
            datasheet: exp.datasheet,
            spread: None,
        };
        toml::to_string(&file).map_err(|e| ScenarioError::Unwritable(e.to_string()))
    }

    /// Checks the experiment (as `gyrocal run` does), the drift over the
    /// device, the profile and the drive probe: one line naming the key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let exp = &self.exp;
        exp.validate()?;
        let derived = exp.derived()?;
        self.drift.validate()?;
        self.drift.validate_device(&exp.gyro)?;
        if let Some(p) = &self.profile {
            let sample_s = f64::from(derived.decimation) / exp.drive.clock_hz;
            p.validate(sample_s)?;
        }
        if let Some(p) = &self.drive_probe {
            p.validate()?;
        }
        Ok(())
    }
}

/// Where a near-commensurate carrier folds the carrier tables'
/// quantization errors back (`gyrocal_regs::plan::nearest_fold`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CarrierFold {
    /// The period q in clocks (the carrier is near n / q of the clock).
    pub period: u64,
    /// The fold's distance from the carrier (Hz).
    pub offset_hz: f64,
    /// Whether it lies within `FOLD_CLEAR_CORNERS` Butterworth corners
    /// (`gyrocal_regs::plan`), which the host's operating point keeps its
    /// carrier out of where it can (`gyrocal_host::selfcal`).
    pub in_passband: bool,
    /// A fold of short period that beats slower than once a measurement
    /// window, if any: the operating point's own
    /// (`gyrocal_host::selfcal::Operating::static_fold`). Its error is the
    /// same in every batch of a window, so no sigma sees it, and the
    /// step's figures may lie beyond their sigmas.
    pub static_fold: Option<StaticFold>,
}

impl CarrierFold {
    fn of(op: &Operating, knowns: &Knowns) -> Self {
        let (period, offset_hz) = nearest_fold(op.carrier_hz, knowns.clock_hz);
        Self {
            period,
            offset_hz,
            in_passband: offset_hz < FOLD_CLEAR_CORNERS * knowns.filter.butterworth_hz,
            static_fold: op.static_fold,
        }
    }

    /// One clause for the step's line: the static fold, else the one in
    /// the passband, else nothing.
    pub fn clause(&self) -> Option<String> {
        if let Some(s) = self.static_fold {
            return Some(s.to_string());
        }
        self.in_passband.then(|| {
            format!(
                "the carrier folds {:.1} Hz from itself (period {} clocks): the rate may ripple at that offset",
                self.offset_hz, self.period
            )
        })
    }
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
    /// Its own relative 1-sigma uncertainty ([`RateTable::uncertainty`]):
    /// the truth is a measurement too.
    pub sf_true_uncertainty: [f64; 2],
    /// Windows each rate of that table averaged ([`RateTable::windows`]).
    pub sf_true_windows: usize,
    /// SF_cal x ratio(identified) (z LSB per deg/s).
    pub sf_selfcal_per_dps: [f64; 2],
    /// Its relative 1-sigma uncertainty (`selfcal.sf_selfcal_uncertainty`
    /// holds the sources).
    pub sf_selfcal_uncertainty: [f64; 2],
    /// SF_cal x eqs. (5)/(6) ratio (z LSB per deg/s).
    pub sf_eq56_per_dps: [f64; 2],
    /// The factory scale factor (z LSB per deg/s); null without a
    /// baseline (the report's `failed` says why).
    pub sf_baseline_per_dps: Option<[f64; 2]>,
    /// Rate-table scale factor at the factory settings (z LSB per deg/s);
    /// null without a baseline.
    pub sf_true_at_factory_settings_per_dps: Option<[f64; 2]>,
    /// sf_selfcal / sf_true - 1.
    pub selfcal_error: [f64; 2],
    /// That error's own relative 1-sigma: `sf_selfcal_uncertainty` and
    /// `sf_true_uncertainty` in quadrature (the two are independent
    /// measurements).
    pub selfcal_error_uncertainty: [f64; 2],
    /// sf_baseline / sf_true_at_factory_settings - 1; null without a baseline.
    pub baseline_error: Option<[f64; 2]>,
    /// The true g_2 / g_1 over the design ratio (what `[drive_probe]`'s
    /// measurement, `selfcal.drive_ratio`, estimates).
    pub drive_gain_ratio_true: f64,
    /// The operating carrier's nearest fold on the clock
    /// (`gyrocal_regs::plan::nearest_fold`): within `FOLD_CLEAR_CORNERS` Butterworth
    /// corners of the carrier, the rate carries a ripple at that offset
    /// and its multiples, and the step's line says so.
    pub carrier_fold: CarrierFold,
    /// Identified parameters (JSON: f1_hz, ..., with `_uncertainty` twins).
    pub identified: IdentifiedJson,
    /// The whole cycle's result.
    pub selfcal: SelfCal,
    /// The rate output under `[profile]`, if the scenario has one.
    pub profile: Option<RateTrace>,
    /// Clocks simulated at this step.
    pub clocks: u64,
}

/// The identified parameters as the interface names them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
    /// Quadrature (stiffness) coupling Omega_q (deg/s, the sign convention
    /// of `[gyro] quadrature_dps`), measured at rest
    /// (`gyrocal_host::coupling`).
    pub quadrature_dps: f64,
    /// Its 1-sigma uncertainty.
    pub quadrature_dps_uncertainty: f64,
    /// Damping coupling Omega_d (deg/s, the sign convention of `[gyro]
    /// damping_coupling_dps`), measured with it.
    pub damping_coupling_dps: f64,
    /// Its 1-sigma uncertainty.
    pub damping_coupling_dps_uncertainty: f64,
    /// Drive-gain ratio g2 / g1 over the design ratio, measured while the
    /// device turned (`[drive_probe]`; null without it).
    pub drive_gain_ratio: Option<f64>,
    /// Its 1-sigma uncertainty (null without it).
    pub drive_gain_ratio_uncertainty: Option<f64>,
}

impl IdentifiedJson {
    /// Each parameter that has a truth, its error against `truth` (the
    /// device at the step) over its reported sigma: f1, f2, Q1, Q2, the
    /// quadrature coupling, and the damping coupling where the device has
    /// one (one seen as none is reported as exactly 0,
    /// `selfcal::DAMPING_SEEN`: on a device without it that t is 0 by
    /// construction and says nothing of the sigma). A figure not measured
    /// (a null coupling) is left out.
    pub fn scored(
        &self,
        device: Option<u32>,
        temperature_c: f64,
        truth: &GyroParams,
    ) -> Vec<Scored> {
        use crate::coverage::{Figure, Parameter};
        let g = truth;
        [
            (Parameter::F1, self.f1_hz - g.f1_hz, self.f1_hz_uncertainty),
            (Parameter::F2, self.f2_hz - g.f2_hz, self.f2_hz_uncertainty),
            (Parameter::Q1, self.q1 - g.q1, self.q1_uncertainty),
            (Parameter::Q2, self.q2 - g.q2, self.q2_uncertainty),
            (
                Parameter::Quadrature,
                self.quadrature_dps - g.quadrature_dps,
                self.quadrature_dps_uncertainty,
            ),
            (
                Parameter::Damping,
                self.damping_coupling_dps - g.damping_coupling_dps,
                self.damping_coupling_dps_uncertainty,
            ),
        ]
        .into_iter()
        .filter(|p| p.0 != Parameter::Damping || g.damping_coupling_dps != 0.0)
        .filter(|p| p.1.is_finite() && p.2.is_finite())
        .map(|(p, error, sigma)| Scored {
            device,
            temperature_c,
            figure: Figure::Parameter(p),
            t: error / sigma,
        })
        .collect()
    }
}

impl From<&SelfCal> for IdentifiedJson {
    /// What identification found, the couplings at rest and the
    /// drive-gain ratio measured after it.
    fn from(cal: &SelfCal) -> Self {
        let ratio = cal.drive_ratio.as_ref().map(|d| d.relative);
        Self {
            drive_gain_ratio: ratio.map(|r| r.value),
            drive_gain_ratio_uncertainty: ratio.map(|r| r.uncertainty),
            ..Self::from(&cal.identified)
        }
    }
}

impl From<&Identified> for IdentifiedJson {
    /// What identification found; the couplings null until measured at
    /// rest, the drive-gain ratio null.
    fn from(id: &Identified) -> Self {
        let [m1, m2] = &id.modes;
        let none = Estimate {
            value: f64::NAN,
            uncertainty: f64::NAN,
        };
        // The figures' sigmas, lambda's part in them (`CouplingFigure`).
        let figure = |c: Option<CouplingFigure>| {
            c.map_or(none, |c| Estimate {
                value: c.value,
                uncertainty: c.uncertainty,
            })
        };
        let quadrature = figure(id.quadrature_dps);
        let damping = figure(id.damping_coupling_dps);
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
            quadrature_dps: quadrature.value,
            quadrature_dps_uncertainty: quadrature.uncertainty,
            damping_coupling_dps: damping.value,
            damping_coupling_dps_uncertainty: damping.uncertainty,
            drive_gain_ratio: None,
            drive_gain_ratio_uncertainty: None,
        }
    }
}

/// A whole scenario.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FieldReport {
    /// What the host knew.
    pub knowns: Knowns,
    /// The factory calibration at T0 (null when that step failed).
    pub factory: Option<Operating>,
    /// The factory scale factor (z LSB per deg/s; null when T0 failed).
    pub sf_factory_per_dps: Option<[f64; 2]>,
    /// The factory's readout null at its settings (z LSB).
    pub null_factory_z: Option<[f64; 2]>,
    /// The rate profile applied at every step.
    pub profile: Option<Profile>,
    /// One entry per finished step, in the scenario's order.
    pub steps: Vec<FieldStep>,
    /// The steps (or their baselines) that failed, in the scenario's order;
    /// empty when every step finished.
    pub failed: Vec<StepFailure>,
    /// Inputs that make a figure less than it says, one line each, also
    /// printed as progress: ADCs the scenario leaves undithered, a
    /// carrier configured off both modes (`Knowns::carrier_off_the_modes`)
    /// and a profile beyond the rate table (`Profile::beyond_the_table`;
    /// when the run starts), a datasheet beyond a part's spread of what
    /// was identified ([`datasheet_warning`]) and steps whose sigma leaves
    /// a drifted drive gain out ([`design_ratio_warning`], when the steps
    /// are done).
    pub warnings: Vec<String>,
    /// Clocks simulated, all steps (a failed step's cycle too).
    pub clocks: u64,
    /// Wall time (s).
    pub wall_s: f64,
}

/// The scenario's inputs that make a figure less than it says, one line
/// each, in this order: a carrier configured off both modes
/// ([`Knowns::carrier_off_the_modes`]), ADC noise below half an ADC step
/// ([`crate::frontend::dithers`]), a profile beyond the rate table
/// ([`Profile::beyond_the_table`]). `knowns` are the host's, as
/// [`build`] makes them.
pub fn warnings(sc: &Scenario, knowns: &Knowns) -> Vec<String> {
    let fe = &sc.exp.frontend;
    let mut lines: Vec<String> = knowns.carrier_off_the_modes().into_iter().collect();
    if !crate::frontend::dithers(fe.noise_lsb, fe.adc_bits) {
        lines.push(format!(
            "warning: [frontend] noise_lsb = {} is below half an ADC step ({} word LSB at adc_bits = {}): unless the device's own noise dithers the ADCs, an output far below their range carries a static quantization error that no sigma includes",
            fe.noise_lsb,
            crate::frontend::dither_lsb(fe.adc_bits),
            fe.adc_bits
        ));
    }
    let profile = sc.profile.as_ref();
    lines.extend(profile.and_then(|p| p.beyond_the_table(&knowns.rates_dps)));
    lines
}

/// The steps whose drive-gain ratio g2/g1 is the design's (no coupling
/// at rest measured it within [`selfcal::AT_REST_RATIO_SIGMA`], no
/// `[drive_probe]`) while `[datasheet]` gives no
/// `drive_gain_ratio_uncertainty`: a drive gain that drifted moves their
/// scale factors and no sigma includes it. One line naming them, or None.
pub fn design_ratio_warning(steps: &[FieldStep], knowns: &Knowns) -> Option<String> {
    let design: Vec<String> = steps
        .iter()
        .filter(|st| st.selfcal.rests_on_design_ratio(knowns))
        .map(|st| format!("{}", st.temperature_c))
        .collect();
    (!design.is_empty()).then(|| {
        format!(
            "warning: at {} deg C the drive-gain ratio g2/g1 is the design's (no coupling at rest that measures it within {:e}, no [drive_probe]) and [datasheet] gives no drive_gain_ratio_uncertainty: a drive gain that drifted is not in the sigma",
            design.join(", "),
            selfcal::AT_REST_RATIO_SIGMA
        )
    })
}

/// The datasheet's resonances, split and Qs beyond a part's spread from what the
/// first step identified (`Identified::datasheet_departures`): one line,
/// or None. The figures rest on the identified values; the line is for
/// whoever wrote the datasheet or owns the part.
pub fn datasheet_warning(steps: &[FieldStep], knowns: &Knowns) -> Option<String> {
    let first = steps.first()?;
    first
        .selfcal
        .identified
        .datasheet_departures(&knowns.nominal)
}

/// The self-calibration errors (against the simulated truth) that lie
/// beyond 3 of their reported sigmas: one line naming each by step and
/// output, and the inputs outside the budget that most often put them
/// there, or None. A run on a board has no truth to compare with; in the
/// simulator a sigma that does not cover its error is said, never left
/// to be read off the table.
pub fn uncovered_error_warning(steps: &[FieldStep]) -> Option<String> {
    let scored: Vec<Scored> = steps
        .iter()
        .flat_map(|st| {
            Scored::outputs(
                None,
                st.temperature_c,
                st.selfcal_error,
                st.selfcal_error_uncertainty,
            )
        })
        .collect();
    uncovered_selfcal_errors(&scored)
}

/// The identified parameters (against the simulated truth) that lie
/// beyond 3 of their reported sigmas ([`IdentifiedJson::scored`]): one
/// line naming each by step and parameter, or None.
pub fn uncovered_parameter_warning(steps: &[FieldStep]) -> Option<String> {
    let scored: Vec<Scored> = steps
        .iter()
        .flat_map(|st| st.identified.scored(None, st.temperature_c, &st.truth.gyro))
        .collect();
    uncovered_parameters(&beyond_three_sigma(&scored), scored.len())
}

/// The steps whose profile runs clipped an ADC (`RateTrace::clipped`):
/// one line naming them, where the profile went and what became of those
/// records, or None.
pub fn profile_clip_warning(steps: &[FieldStep]) -> Option<String> {
    let parts: Vec<String> = steps
        .iter()
        .filter_map(|st| {
            let clipped = st.profile.as_ref()?.clipped?;
            Some(clipped.describe(st.temperature_c))
        })
        .collect();
    (!parts.is_empty()).then(|| {
        format!(
            "warning: an ADC clipped under [profile] {}: a clipped record's z holds the converter's rail, not the rate, so it and the settle_s after it are left out of the RMS errors (their `settled` is false)",
            parts.join("; ")
        )
    })
}

/// What a host programmed for `exp` would know: its `[datasheet]` over its
/// `[gyro]` (the keys the datasheet leaves out), its drive, latencies,
/// filter and points. The filter and first window are derived from the
/// datasheet, as a host must.
pub fn knowns(exp: &Experiment) -> Result<Knowns, ConfigError> {
    let nominal = exp.datasheet.over(&exp.gyro)?;
    let host_view = Experiment {
        gyro: nominal.gyro.clone(),
        ..exp.clone()
    };
    Ok(Knowns {
        clock_hz: exp.drive.clock_hz,
        clock_tolerance: exp.drive.clock_tolerance_ppm * 1e-6,
        nominal: nominal.gyro,
        angular_gain_uncertainty: nominal.angular_gain_uncertainty,
        drive_gain_ratio_uncertainty: nominal.drive_gain_ratio_uncertainty,
        amplitude: exp.drive.amplitude(),
        force_full_scale: exp.drive.force_full_scale(),
        dac_latency: exp.frontend.dac_latency,
        adc_latency: exp.frontend.adc_latency,
        filter: host_view.derived()?,
        carrier_hz: exp.drive.carrier_hz,
        rates_dps: exp.points.readout_rates_dps.clone(),
        cal_freqs_hz: exp.points.cal_freqs_hz.clone(),
        carrier_profile: exp.drive.carrier_profile,
        rest_bound_dps: exp.points.rest_bound_dps,
    })
}

/// The board as built and what the host knows, for `exp`.
pub fn build(exp: &Experiment) -> Result<(FrontEnd, Knowns), RunError> {
    let plan = experiment::plan(exp)?;
    Ok((plan.front_end, knowns(exp)?))
}

/// A fresh board at one step, on the model engine ([`board_on`]).
pub fn board_at(exp: &Experiment, fe: &FrontEnd, at: &DeviceAt) -> Result<SimBoard, FieldError> {
    board_on(exp, fe, at)
}

/// A fresh board at one step on engine `E`, powered up. The front-end
/// phase lag is exact at the nominal modes' mean frequency; the Brownian
/// noise is `[noise]` as given (off unless its temperature is set).
pub fn board_on<E: Engine>(
    exp: &Experiment,
    fe: &FrontEnd,
    at: &DeviceAt,
) -> Result<SimBoard<E>, FieldError> {
    let reference = 0.5 * (exp.gyro.f1_hz + exp.gyro.f2_hz);
    // The board's own oscillator (`[drive] clock_error_ppm`); the host
    // programs it as if it ran at `clock_hz`.
    let mut board = SimBoard::new(
        at,
        fe,
        &exp.noise,
        exp.drive.board_clock_hz(),
        reference,
        exp.drive.carrier_profile,
    )?;
    // As a host does: wait until the core has filled its carrier tables
    // (GYRO_DRIVE_START_CLOCKS in the C header) before using it.
    board.wait_clocks(gyrocal_regs::datapath::DRIVE_START_CLOCKS)?;
    Ok(board)
}

/// A fresh board at `at`, programmed in readout at `op` and settled
/// `TABLE_FIRST_TAUS` from power-up, at rotation rate `rate_dps`.
fn settled_readout_board(
    exp: &Experiment,
    fe: &FrontEnd,
    at: &DeviceAt,
    knowns: &Knowns,
    op: &Operating,
    rate_dps: f64,
) -> Result<SimBoard, FieldError> {
    let mut board = board_at(exp, fe, at)?;
    program_readout(&mut board, knowns, op)?;
    board.set_rate(rate_dps.to_radians());
    board.wait_clocks(settle_clocks_at(knowns, at))?;
    Ok(board)
}

/// Clocks from power-up or a new setting to a settled table or readout:
/// `TABLE_FIRST_TAUS` of the slower mode's amplitude time constant of the
/// device as it is at this step, then the filter's settling. The
/// simulation's own measurements (the truth's table, the profile's
/// readout) wait on the true device, not the datasheet: a part's Q can be
/// a factor off its datasheet's, which the cycle finds and says in one
/// line, and a table that waited on the datasheet (the consumer device at
/// Q 20,000 against its datasheet's 3000: 30 of the datasheet's time
/// constants are 4.5 of the part's) read its truth 0.3% to 1.1% off, 4.7
/// of its sigma and more.
fn settle_clocks_at(knowns: &Knowns, at: &DeviceAt) -> u64 {
    knowns.with_device(&at.gyro).settle_clocks(TABLE_FIRST_TAUS)
}

fn program_readout(
    board: &mut dyn Board,
    knowns: &Knowns,
    op: &Operating,
) -> Result<(), FieldError> {
    let (regs, _) = knowns.registers(op.carrier_hz, None, op.amplitude, op.ref_lag_deg)?;
    Ok(board.program(&regs)?)
}

/// Parts each rate-table window is cut into: the table's slope per part
/// gives the truth's own uncertainty ([`RateTable`]).
pub const TABLE_PARTS: usize = 8;

/// Windows each rate-table point averages, `TABLE_PARTS` parts each: 16
/// parts, 15 degrees of freedom for the truth's uncertainty. With one
/// window (7 degrees of freedom) the part spread scattered by a factor
/// of 3 from seed to seed, and on the consumer device read at 50 and 100
/// deg/s (output 1's rate term 6e-5 of its offset) one dither seed of
/// ten put the truth 0.5% off with a part spread of 0.09%: 5.4 sigma.
/// Two windows with the coverage factor left that seed at 2.1 sigma and
/// the ten seeds at |t| <= 1.1 (`tests/field_coverage.rs` measures the
/// coverage over random devices); four windows cost the paper scenario
/// 60% more clocks for no change in coverage. Where the truth's sigma
/// weighs in the comparison the table runs on to
/// [`TABLE_EXTENDED_WINDOWS`].
pub const TABLE_WINDOWS: usize = 2;

/// Windows a rate-table point runs in all when, after `TABLE_WINDOWS`,
/// the truth's sigma exceeds [`TABLE_EXTEND_SHARE`] of the sigma it is
/// compared with on either output.
///
/// Two windows' part spread misses a slow part of the table's noise. The
/// rates share their dither, so what is left in the slope is the ADC's
/// rounding flipping between rates (its size did not change with the
/// dither from 0.5 to 2 LSB), and some of it wanders over about two
/// windows: the part spread, taken within them, cannot see it. On a
/// resonant output whose rate term is small against its offset the
/// truth's sigma is then short. Measured on a 76.5 kHz device (Q 1964 and
/// 2666, output 1 at 19 z LSB per deg/s against an offset of -20,000,
/// rates 50, 150 and 300 deg/s) over 48 dither seeds: the slope scattered
/// 1.23 times the part spread with two windows (t RMS 1.26, 2 of 48 beyond
/// 3), 1.17 with four, 0.94 with eight (t RMS 0.95, none beyond 3).
/// Eight windows double the paper scenario's time, so the table pays for
/// them only where its sigma matters.
pub const TABLE_EXTENDED_WINDOWS: usize = 8;

/// The share of the compared sigma (the self-calibration's) beyond which
/// the truth's sigma matters. Below it a truth's sigma 1.25 times short
/// moves the quadrature sum of the two by at most 4%.
pub const TABLE_EXTEND_SHARE: f64 = 0.5;

/// Whose settings a rate-table point runs at, which decides what its
/// clipping means.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TableAt {
    /// The step's own cycle's: its drives were scaled to the predicted
    /// peaks, so a clip means the device answers more than predicted.
    Cycle,
    /// The factory's, on the device drifted to the step: a part left
    /// uncalibrated clips there (`FieldReport::warnings` says so).
    Factory,
}

/// `windows` more windows of one rate-table point on its settled `board`,
/// `TABLE_PARTS` parts each: the parts' z (z LSB; their mean is the
/// windows'). A window during which an ADC clipped is an error, never a
/// slope.
fn table_windows(
    board: &mut dyn Board,
    knowns: &Knowns,
    windows: usize,
    whose: TableAt,
    rate_dps: f64,
) -> Result<Vec<[f64; 2]>, FieldError> {
    let r = knowns.filter.decimation;
    let length = (windows as f64 * knowns.filter.min_window_s * knowns.clock_hz).ceil();
    // The table's truth is a slope: a clipped window would bend it unseen.
    clip::restart(board)?;
    let parts = part_means(
        board,
        r,
        f64::from(r),
        length,
        TABLE_PARTS * windows,
        Signal::Steady,
    )?;
    let detail = match whose {
        TableAt::Cycle => format!(
            "at {rate_dps} deg/s; the cycle scaled its drives to keep the predicted peaks at every rate of [experiment] readout_rates_dps within range, and the device answers more than predicted (lower the largest rate, or check [datasheet] angular_gain)"
        ),
        TableAt::Factory => format!(
            "at {rate_dps} deg/s, at the factory's carrier and drives on the device as it drifted here"
        ),
    };
    clip::check(board, "rate table", &detail)?;
    Ok(parts)
}

/// The points of a rate table: readout at `op` on a fresh board per rate
/// (from power-up, as `experiment` runs its points; the boards in lanes,
/// `super::lanes`), settled, then `TABLE_WINDOWS` windows
/// ([`table_windows`]); returns the boards, to run on, and each rate's
/// parts or why it has none.
fn table_points(
    exp: &Experiment,
    fe: &FrontEnd,
    at: &DeviceAt,
    knowns: &Knowns,
    (op, whose): (&Operating, TableAt),
    rates_dps: &[f64],
) -> Result<(LaneBoards, Vec<TablePart>), FieldError> {
    let mut boards = settled_lanes(exp, fe, at, knowns, op, rates_dps)?;
    let parts = table_windows_in_lanes(&mut boards, knowns, TABLE_WINDOWS, whose, rates_dps);
    Ok((boards, parts))
}

/// Boards in lanes at `rates_dps`, powered up, programmed in readout at
/// `op` and settled, as `settled_readout_board` makes each alone.
fn settled_lanes(
    exp: &Experiment,
    fe: &FrontEnd,
    at: &DeviceAt,
    knowns: &Knowns,
    op: &Operating,
    rates_dps: &[f64],
) -> Result<LaneBoards, FieldError> {
    let (regs, _) = knowns.registers(op.carrier_hz, None, op.amplitude, op.ref_lag_deg)?;
    LaneBoards::settled(exp, fe, at, &regs, rates_dps, settle_clocks_at(knowns, at))
}

/// One rate's parts of a table, or why it has none.
type TablePart = Result<Vec<[f64; 2]>, FieldError>;

/// [`table_windows`] on every lane of `boards` at `rates_dps`: run on the
/// boards (lane 0's face), then replayed on each other lane's reads.
fn table_windows_in_lanes(
    boards: &mut LaneBoards,
    knowns: &Knowns,
    windows: usize,
    whose: TableAt,
    rates_dps: &[f64],
) -> Vec<TablePart> {
    boards.each_lane(|board, l| table_windows(board, knowns, windows, whose, rates_dps[l]))
}

/// Least-squares slopes of the table's z against its rates (z LSB per deg/s).
fn table_slopes(rates_dps: &[f64], z: &[[f64; 2]]) -> [f64; 2] {
    std::array::from_fn(|k| {
        let y: Vec<f64> = z.iter().map(|v| v[k]).collect();
        linear_fit(rates_dps, &y).0
    })
}

/// The truth of a field step: the rate table's slopes and their own
/// uncertainty.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RateTable {
    /// Least-squares slopes of z against the rates (z LSB per deg/s).
    pub sf_per_dps: [f64; 2],
    /// Their relative 1-sigma uncertainty: the spread of the slopes
    /// fitted part by part (`TABLE_PARTS` parts a window, part i of every
    /// rate together) over sqrt(parts), times the coverage factor of its
    /// degrees of freedom (`fit::coverage_factor`: 1.2 at 15, two windows;
    /// 1.03 at 63, eight). Noise common to the rates
    /// (every board starts from the same seed) cancels in it as it does in
    /// the slope; it does not see the carrier spurs' beats, which repeat
    /// from power-up at every rate (`rate_table`).
    pub uncertainty: [f64; 2],
    /// Windows each rate averaged: `TABLE_WINDOWS`, or
    /// `TABLE_EXTENDED_WINDOWS` where the truth's sigma weighed in.
    pub windows: usize,
}

impl RateTable {
    /// The table of `parts[rate][part]` at `rates_dps`.
    fn from_parts(rates_dps: &[f64], parts: &[Vec<[f64; 2]>]) -> Self {
        let means: Vec<[f64; 2]> = parts.iter().map(|p| mean_of_parts(p)).collect();
        let sf = table_slopes(rates_dps, &means);
        let n = parts[0].len();
        let slopes: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let z: Vec<[f64; 2]> = parts.iter().map(|p| p[i]).collect();
                table_slopes(rates_dps, &z)
            })
            .collect();
        let uncertainty = std::array::from_fn(|k| {
            let ss: f64 = slopes.iter().map(|s| (s[k] - sf[k]).powi(2)).sum();
            let dof = (n - 1) as u32;
            (ss / f64::from(dof) / n as f64).sqrt() / sf[k].abs() * coverage_factor(dof)
        });
        Self {
            sf_per_dps: sf,
            uncertainty,
            windows: n / TABLE_PARTS,
        }
    }
}

/// The rate table: readout at `op` on a fresh board per rate, the boards
/// in lanes (`table_points`); returns the slopes with their uncertainty,
/// and the clocks (every board's).
/// `compared_with` is the relative sigma of the figures the table will
/// judge (the self-calibration's, per output), if any: where the table's
/// own sigma after `TABLE_WINDOWS` exceeds `TABLE_EXTEND_SHARE` of it,
/// every point runs on to `TABLE_EXTENDED_WINDOWS` windows.
///
/// Fresh boards, not one board stepping through the rates: the carrier
/// table's residual spurs (below -80 dBc; 90 dBc measured) mix with the resonant output's
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
    compared_with: Option<[f64; 2]>,
) -> Result<(RateTable, u64), FieldError> {
    let rates = &knowns.rates_dps;
    let (mut boards, parts) = table_points(exp, fe, at, knowns, (op, TableAt::Cycle), rates)?;
    let mut parts: Vec<Vec<[f64; 2]>> = parts.into_iter().collect::<Result<_, _>>()?;
    let mut table = RateTable::from_parts(rates, &parts);
    if needs_more_windows(&table, compared_with) {
        let more = TABLE_EXTENDED_WINDOWS - TABLE_WINDOWS;
        let run = table_windows_in_lanes(&mut boards, knowns, more, TableAt::Cycle, rates);
        for (parts, run) in parts.iter_mut().zip(run) {
            parts.extend(run?);
        }
        table = RateTable::from_parts(rates, &parts);
    }
    Ok((table, boards.cycle() * rates.len() as u64))
}

/// Whether the table's sigma exceeds `TABLE_EXTEND_SHARE` of the compared
/// sigma on either output ([`TABLE_EXTENDED_WINDOWS`]).
fn needs_more_windows(table: &RateTable, compared_with: Option<[f64; 2]>) -> bool {
    compared_with.is_some_and(|c| {
        (0..2).any(|k| {
            table.windows < TABLE_EXTENDED_WINDOWS
                && table.uncertainty[k] > TABLE_EXTEND_SHARE * c[k]
        })
    })
}

fn ratio_error(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] / b[0] - 1.0, a[1] / b[1] - 1.0]
}

/// One step's cycle on its board, and what that board reads afterwards.
struct Cycle {
    at: DeviceAt,
    cal: SelfCal,
    /// Readout null at rest and the profile's run, with `[profile]`.
    readout: Option<([f64; 2], ProfileRun)>,
    /// The rate table at the cycle's settings.
    truth: RateTable,
    clocks: u64,
}

/// Self-calibrate a fresh board at `t`; with a profile, then switch to
/// readout, measure the null at rest and run the profile on that board.
/// The rate table at the cycle's settings follows (its rates in lanes, `super::lanes`).
fn cycle_at(sc: &Scenario, fe: &FrontEnd, knowns: &Knowns, t: f64) -> Result<Cycle, CycleFailure> {
    let at = sc.drift.at(&sc.exp.gyro, t);
    let mut board = board_at(&sc.exp, fe, &at).map_err(|e| CycleFailure::before(e, 0))?;
    let identified = identify::identify(&mut board, knowns, &knowns.nominal)
        .map_err(|e| CycleFailure::before(e.into(), board.cycle()))?;
    let kept = IdentifiedJson::from(&identified);
    cycle_from(sc, fe, knowns, at, &mut board, identified).map_err(|error| CycleFailure {
        identified: Some(Box::new(kept)),
        error,
        clocks: board.cycle(),
    })
}

/// A step's cycle that failed: its error, what identification found
/// when it finished before the failure, and the clocks its board ran (a
/// rate table that failed does not count its own boards').
#[derive(Debug)]
struct CycleFailure {
    identified: Option<Box<IdentifiedJson>>,
    error: FieldError,
    clocks: u64,
}

impl CycleFailure {
    /// A failure before identification finished, after `clocks`.
    fn before(error: FieldError, clocks: u64) -> Self {
        Self {
            identified: None,
            error,
            clocks,
        }
    }
}

/// `cycle_at` after identification: the rest of the self-calibration
/// cycle, the drive probe, the profile and the rate table.
fn cycle_from(
    sc: &Scenario,
    fe: &FrontEnd,
    knowns: &Knowns,
    at: DeviceAt,
    board: &mut SimBoard,
    identified: Identified,
) -> Result<Cycle, FieldError> {
    let mut cal = selfcal::self_calibrate_from(board, knowns, identified)?;
    if let Some(probe) = &sc.drive_probe {
        // The probe's waits are the identified modes', as the cycle's are
        // (`selfcal::self_calibrate_from`), not the datasheet's.
        let device = knowns.with_device(&cal.identified.gyro(&knowns.nominal));
        board.set_rate(probe.rate_dps.to_radians());
        let measured = drive_ratio::measure(board, &device, &cal.operating, &cal.identified)?;
        board.set_rate(0.0);
        selfcal::apply_drive_ratio(knowns, &mut cal, measured)?;
    }
    let readout = match &sc.profile {
        None => None,
        Some(p) => {
            program_readout(board, knowns, &cal.operating)?;
            board.wait_clocks(settle_clocks_at(knowns, &at))?;
            let r = knowns.filter.decimation;
            let length = (knowns.filter.min_window_s * knowns.clock_hz).ceil();
            let null = profile::readout_null(board, r, length)?;
            Some((null, profile::run_profile(board, p, r, knowns.clock_hz)?))
        }
    };
    let judged = Some(cal.sf_selfcal_uncertainty.total);
    let (truth, table_clocks) = rate_table(&sc.exp, fe, &at, knowns, &cal.operating, judged)?;
    Ok(Cycle {
        at,
        cal,
        readout,
        truth,
        clocks: board.cycle() + table_clocks,
    })
}

/// The simulation's measurements at the factory's settings, run as
/// independent jobs in parallel once the factory calibration is known.
enum Job {
    /// Rate-table point of step `step` at the factory's settings.
    Factory { step: usize, rate: usize },
    /// The profile of step `step` at the factory's settings.
    BaselineProfile { step: usize },
}

impl Job {
    fn step(&self) -> usize {
        match *self {
            Job::Factory { step, .. } | Job::BaselineProfile { step } => step,
        }
    }
}

enum Done {
    Point([f64; 2]),
    Profile(ProfileRun),
}

/// Every step but the first (at T0 the factory's settings are its own)
/// whose own cycle finished.
fn jobs(cycles: &[Result<Cycle, CycleFailure>], rates: usize, with_profile: bool) -> Vec<Job> {
    let mut jobs = vec![];
    for step in (1..cycles.len()).filter(|&i| cycles[i].is_ok()) {
        jobs.extend((0..rates).map(|rate| Job::Factory { step, rate }));
        if with_profile {
            jobs.push(Job::BaselineProfile { step });
        }
    }
    jobs
}

/// A step, or a part of one, that failed: the scenario's other steps stand.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StepFailure {
    /// Temperature of the step (deg C).
    pub temperature_c: f64,
    /// What failed: [`FAILED_CYCLE`] (the step has no entry in `steps`) or
    /// [`FAILED_BASELINE`] (its baseline fields are null).
    pub stage: &'static str,
    /// The error, one line.
    pub error: String,
    /// What the step's identification found, when the cycle failed after
    /// it (null otherwise): a step that fails keeps what finished.
    pub identified: Option<IdentifiedJson>,
}

/// [`StepFailure::stage`] of a self-calibration cycle (or its rate table).
pub const FAILED_CYCLE: &str = "self-calibration cycle";
/// [`StepFailure::stage`] of the measurements at the factory's settings.
pub const FAILED_BASELINE: &str = "baseline at the factory settings";

/// The factory calibration: the first step's cycle, when it finished.
struct Factory {
    operating: Operating,
    sf_per_dps: [f64; 2],
    null_z: Option<[f64; 2]>,
}

/// Every step's cycle and rate table in parallel; a failed one is kept as
/// its error.
fn run_cycles(
    sc: &Scenario,
    fe: &FrontEnd,
    knowns: &Knowns,
    progress: &(dyn Fn(&str) + Sync),
) -> Vec<Result<Cycle, CycleFailure>> {
    sc.drift
        .temperatures_c
        .par_iter()
        .map(|&t| {
            let c = cycle_at(sc, fe, knowns, t);
            match &c {
                Ok(c) => progress(&format!(
                    "{t} deg C: cycle and rate table done, self-cal error {:+.4}% / {:+.4}%",
                    100.0 * (c.cal.sf_selfcal_per_dps[0] / c.truth.sf_per_dps[0] - 1.0),
                    100.0 * (c.cal.sf_selfcal_per_dps[1] / c.truth.sf_per_dps[1] - 1.0),
                )),
                Err(e) => progress(&format!("{t} deg C: FAILED: {}", e.error)),
            }
            c
        })
        .collect()
}

/// A job's result and the clocks it ran, or its error.
type JobResult = Result<(Done, u64), FieldError>;

/// The rate-table points and baseline profiles at the factory's settings,
/// in parallel (a step's points together, in lanes: [`table_points`]);
/// each job's result (and its clocks) or its error.
fn run_jobs(
    sc: &Scenario,
    fe: &FrontEnd,
    knowns: &Knowns,
    factory: &Operating,
    cycles: &[Result<Cycle, CycleFailure>],
    jobs: &[Job],
) -> Vec<JobResult> {
    // A step's table points as one unit, each profile as its own.
    let mut units: Vec<Vec<usize>> = vec![];
    for (i, job) in jobs.iter().enumerate() {
        let same_table = |u: &&mut Vec<usize>| {
            matches!(job, Job::Factory { .. })
                && matches!(jobs[u[0]], Job::Factory { step, .. } if step == job.step())
        };
        match units.iter_mut().find(same_table) {
            Some(unit) => unit.push(i),
            None => units.push(vec![i]),
        }
    }
    let done: Vec<Vec<JobResult>> = units
        .par_iter()
        .map(|unit| match &cycles[jobs[unit[0]].step()] {
            Ok(c) => run_unit(sc, fe, knowns, factory, &c.at, jobs, unit),
            Err(f) => unit.iter().map(|_| Err(f.error.clone())).collect(),
        })
        .collect();
    experiment::in_item_order(jobs.len(), &units, done)
}

/// One unit of `run_jobs` on the device `at` of its step: a table's
/// points (the jobs `unit` names), or a profile; each job's result, in the unit's order.
fn run_unit(
    sc: &Scenario,
    fe: &FrontEnd,
    knowns: &Knowns,
    factory: &Operating,
    at: &DeviceAt,
    jobs: &[Job],
    unit: &[usize],
) -> Vec<JobResult> {
    if let Job::BaselineProfile { .. } = jobs[unit[0]] {
        return vec![baseline_profile(sc, fe, knowns, factory, at)];
    }
    let rates: Vec<f64> = unit
        .iter()
        .map(|&i| match jobs[i] {
            Job::Factory { rate, .. } => knowns.rates_dps[rate],
            Job::BaselineProfile { .. } => unreachable!("a table's unit holds its points"),
        })
        .collect();
    let whose = (factory, TableAt::Factory);
    match table_points(&sc.exp, fe, at, knowns, whose, &rates) {
        Ok((boards, parts)) => {
            let point = |p: Vec<[f64; 2]>| (Done::Point(mean_of_parts(&p)), boards.cycle());
            let results = parts.into_iter().map(|p| p.map(point));
            results.collect()
        }
        Err(e) => unit.iter().map(|_| Err(e.clone())).collect(),
    }
}

/// The profile of a step at the factory's settings, on its own board.
fn baseline_profile(
    sc: &Scenario,
    fe: &FrontEnd,
    knowns: &Knowns,
    factory: &Operating,
    at: &DeviceAt,
) -> JobResult {
    let p = sc.profile.as_ref().ok_or(FieldError::NoProfile)?;
    let mut board = settled_readout_board(&sc.exp, fe, at, knowns, factory, 0.0)?;
    let r = knowns.filter.decimation;
    let run = profile::run_profile(&mut board, p, r, knowns.clock_hz)?;
    Ok((Done::Profile(run), board.cycle()))
}

/// Run a scenario: every step's cycle and rate table in parallel (the
/// first step's cycle is the factory calibration), then every rate-table
/// point and baseline profile at the factory's settings in parallel;
/// `progress` gets one line per step.
///
/// A step whose cycle fails is reported in [`FieldReport::failed`] and the
/// other steps stand; without the factory calibration (the first step
/// failed) no step has a baseline. Only a scenario that cannot start (its
/// board or the host's knowledge cannot be built) is an error.
pub fn run(sc: &Scenario, progress: &(dyn Fn(&str) + Sync)) -> Result<FieldReport, FieldError> {
    let (exp, drift) = (&sc.exp, &sc.drift);
    exp.validate()?;
    drift.validate()?;
    let start = Instant::now();
    let (fe, knowns) = build(exp)?;
    let mut warnings = warnings(sc, &knowns);
    warnings.iter().for_each(|w| progress(w));
    let cycles = run_cycles(sc, &fe, &knowns, progress);
    let factory = cycles[0].as_ref().ok().map(|c| Factory {
        operating: c.cal.operating.clone(),
        sf_per_dps: c.truth.sf_per_dps,
        null_z: c.readout.as_ref().map(|r| r.0),
    });
    let (jobs, done) = match &factory {
        Some(f) => {
            progress(&format!(
                "factory calibration at {} deg C: carrier {:.3} Hz, phase {:.4} deg",
                drift.reference_c(),
                f.operating.carrier_hz,
                f.operating.ref_lag_deg
            ));
            let jobs = jobs(&cycles, knowns.rates_dps.len(), sc.profile.is_some());
            let done = run_jobs(sc, &fe, &knowns, &f.operating, &cycles, &jobs);
            (jobs, done)
        }
        None => (vec![], vec![]),
    };
    let job_clocks: u64 = done.iter().flatten().map(|d| d.1).sum();
    let at_factory = factory.as_ref().map(|factory| AtFactory {
        factory,
        jobs: &jobs,
        done: &done,
    });
    let Steps {
        steps,
        failed,
        baseline_clips,
        failed_clocks,
    } = steps_of(cycles, drift, at_factory, &knowns, progress);
    if factory.is_none() && !steps.is_empty() {
        progress("no factory calibration (the first step failed): no step has a baseline");
    }
    let baseline_clip_warning = (!baseline_clips.is_empty()).then(|| {
        format!(
            "warning: the factory's settings clip an ADC {}: a part left uncalibrated reads the converter's rail there, so those steps' baseline fields are null",
            baseline_clips.join("; ")
        )
    });
    for w in [
        datasheet_warning(&steps, &knowns),
        design_ratio_warning(&steps, &knowns),
        profile_clip_warning(&steps),
        baseline_clip_warning,
        uncovered_error_warning(&steps),
        uncovered_parameter_warning(&steps),
    ]
    .into_iter()
    .flatten()
    {
        progress(&w);
        warnings.push(w);
    }
    let clocks = job_clocks + failed_clocks + steps.iter().map(|s| s.clocks).sum::<u64>();
    Ok(FieldReport {
        knowns,
        sf_factory_per_dps: factory.as_ref().map(|f| f.sf_per_dps),
        null_factory_z: factory.as_ref().and_then(|f| f.null_z),
        factory: factory.map(|f| f.operating),
        profile: sc.profile.clone(),
        steps,
        failed,
        warnings,
        clocks,
        wall_s: start.elapsed().as_secs_f64(),
    })
}

/// The factory calibration with its jobs and what each did.
struct AtFactory<'a> {
    factory: &'a Factory,
    jobs: &'a [Job],
    done: &'a [JobResult],
}

/// The steps of a run as its cycles and the factory's jobs left them.
struct Steps {
    /// The steps whose cycle finished, in temperature order.
    steps: Vec<FieldStep>,
    /// The stages that failed, each with its step's temperature.
    failed: Vec<StepFailure>,
    /// The steps whose baseline clipped at the factory's settings (a
    /// finding about a part left uncalibrated, said in one warning).
    baseline_clips: Vec<String>,
    /// Clocks the failed cycles ran.
    failed_clocks: u64,
}

/// Each cycle made a step, with its baseline from the factory's jobs
/// (`at_factory`: the factory, its jobs and what they did) where the
/// factory calibration exists; `progress` gets one line per step.
fn steps_of(
    cycles: Vec<Result<Cycle, CycleFailure>>,
    drift: &Drift,
    at_factory: Option<AtFactory>,
    knowns: &Knowns,
    progress: &(dyn Fn(&str) + Sync),
) -> Steps {
    let mut out = Steps {
        steps: vec![],
        failed: vec![],
        baseline_clips: vec![],
        failed_clocks: 0,
    };
    for (i, c) in cycles.into_iter().enumerate() {
        let t = drift.temperatures_c[i];
        let c = match c {
            Ok(c) => c,
            Err(CycleFailure {
                identified,
                error,
                clocks,
            }) => {
                out.failed_clocks += clocks;
                out.failed.push(StepFailure {
                    temperature_c: t,
                    stage: FAILED_CYCLE,
                    error: error.to_string(),
                    identified: identified.map(|id| *id),
                });
                continue;
            }
        };
        let baseline = at_factory.as_ref().and_then(|f| {
            f.baseline(i, &c, &knowns.rates_dps)
                .map_err(|error| match error {
                    // What a part left uncalibrated does here: a finding,
                    // said in a line, not a failure of the run.
                    FieldError::Host(gyrocal_host::Error::Clipped { .. }) => {
                        out.baseline_clips.push(format!("at {t} deg C ({error})"));
                    }
                    _ => out.failed.push(StepFailure {
                        temperature_c: t,
                        stage: FAILED_BASELINE,
                        error: error.to_string(),
                        identified: None,
                    }),
                })
                .ok()
        });
        let step = field_step(c, baseline, knowns);
        progress(&step_line(&step));
        out.steps.push(step);
    }
    out
}

/// Step `i`'s measurements at the factory's settings: the rate table's
/// slopes and (with a profile) the baseline's run; at the first step the
/// factory's settings are the cycle's own (`run` None: the cycle's run).
struct Baseline<'a> {
    sf_fixed: [f64; 2],
    run: Option<&'a ProfileRun>,
    sf_factory: [f64; 2],
    null_factory: Option<[f64; 2]>,
}

impl<'a> AtFactory<'a> {
    /// Step `i`'s [`Baseline`] for its finished cycle `c`, from the
    /// factory's jobs at the table's `rates`; a job's error is the step's.
    fn baseline(&self, i: usize, c: &Cycle, rates: &[f64]) -> Result<Baseline<'a>, FieldError> {
        let (f, jobs, done) = (self.factory, self.jobs, self.done);
        if i == 0 {
            return Ok(Baseline {
                sf_fixed: c.truth.sf_per_dps,
                run: None,
                sf_factory: f.sf_per_dps,
                null_factory: f.null_z,
            });
        }
        let mut z = vec![[0.0; 2]; rates.len()];
        let mut run = None;
        for (job, d) in jobs.iter().zip(done).filter(|(j, _)| j.step() == i) {
            match (job, &d.as_ref().map_err(Clone::clone)?.0) {
                (Job::Factory { rate, .. }, Done::Point(v)) => z[*rate] = *v,
                (Job::BaselineProfile { .. }, Done::Profile(r)) => run = Some(r),
                _ => unreachable!("a job's result is of its kind"),
            }
        }
        Ok(Baseline {
            sf_fixed: table_slopes(rates, &z),
            run,
            sf_factory: f.sf_per_dps,
            null_factory: f.null_z,
        })
    }
}

/// The report's entry of a finished cycle, with its baseline when the
/// factory calibration and the step's measurements at its settings exist.
fn field_step(c: Cycle, baseline: Option<Baseline>, knowns: &Knowns) -> FieldStep {
    let sf_true = c.truth.sf_per_dps;
    let trace = c.readout.as_ref().map(|(null, run)| {
        let selfcal_rate = profile::calibrated(&run.z, *null, c.cal.sf_selfcal_per_dps);
        let base = baseline.as_ref().map(|b| {
            let base = b.run.unwrap_or(run);
            let rate = profile::calibrated(&base.z, b.null_factory.unwrap_or(*null), b.sf_factory);
            let rms = profile::rms_error(&rate, &base.true_rate_dps, &base.settled);
            (rate, rms)
        });
        RateTrace {
            selfcal_rms_error_dps: profile::rms_error(
                &selfcal_rate,
                &run.true_rate_dps,
                &run.settled,
            ),
            baseline_rms_error_dps: base.as_ref().map(|b| b.1),
            clipped: ClippedRecords::of(run, baseline.as_ref().and_then(|b| b.run)),
            clip_clocks: run.clip_clocks.clone(),
            settled: run.settled.clone(),
            time_s: run.time_s.clone(),
            true_rate_dps: run.true_rate_dps.clone(),
            selfcal_rate_dps: selfcal_rate,
            baseline_rate_dps: base.map(|b| b.0),
            null_selfcal_z: *null,
            spur_bound_dps: c
                .cal
                .carrier_spurs
                .as_ref()
                .map(|sp| sp.rms_over_records_dps(profile::record_spacing_s(&run.time_s))),
        }
    });
    FieldStep {
        temperature_c: c.at.temperature_c,
        drive_gain_ratio_true: c.at.drive_gain[1] / c.at.drive_gain[0],
        carrier_fold: CarrierFold::of(&c.cal.operating, knowns),
        truth: c.at,
        sf_true_per_dps: sf_true,
        sf_true_uncertainty: c.truth.uncertainty,
        sf_true_windows: c.truth.windows,
        sf_selfcal_per_dps: c.cal.sf_selfcal_per_dps,
        sf_selfcal_uncertainty: c.cal.sf_selfcal_uncertainty.total,
        sf_eq56_per_dps: c.cal.sf_eq56_per_dps,
        sf_baseline_per_dps: baseline.as_ref().map(|b| b.sf_factory),
        sf_true_at_factory_settings_per_dps: baseline.as_ref().map(|b| b.sf_fixed),
        selfcal_error: ratio_error(c.cal.sf_selfcal_per_dps, sf_true),
        selfcal_error_uncertainty: std::array::from_fn(|k| {
            c.cal.sf_selfcal_uncertainty.total[k].hypot(c.truth.uncertainty[k])
        }),
        baseline_error: baseline
            .as_ref()
            .map(|b| ratio_error(b.sf_factory, b.sf_fixed)),
        identified: IdentifiedJson::from(&c.cal),
        clocks: c.clocks,
        selfcal: c.cal,
        profile: trace,
    }
}

/// The progress line of a finished step.
fn step_line(st: &FieldStep) -> String {
    let e = st.selfcal_error;
    let base = match st.baseline_error {
        Some(b) => format!("baseline {:+.2}% / {:+.2}%", 100.0 * b[0], 100.0 * b[1]),
        None => "no baseline".to_string(),
    };
    let fold = st
        .carrier_fold
        .clause()
        .map_or(String::new(), |c| format!("; {c}"));
    format!(
        "{} deg C: self-cal error {:+.4}% / {:+.4}%, {base}{fold}",
        st.temperature_c,
        100.0 * e[0],
        100.0 * e[1],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyrocal_host::selfcal::static_fold;

    fn paper() -> Scenario {
        let text = include_str!("../../../tests/data/field_paper.toml");
        parse("field_paper.toml", text).expect("the paper scenario parses")
    }

    /// An operating point at `carrier_hz`, its static fold found as
    /// `selfcal::operating` finds it.
    fn operating_at(carrier_hz: f64, knowns: &Knowns) -> Operating {
        Operating {
            carrier_hz,
            ref_lag_deg: 0.0,
            envelope_delay_s: 0.0,
            amplitude: knowns.amplitude,
            fold_shift_hz: 0.0,
            static_fold: static_fold(knowns, carrier_hz),
            spur_move: None,
            scaled_drives: None,
            cycle_rate_dps: 0.0,
        }
    }

    #[test]
    fn a_short_fold_slower_than_a_window_is_named_and_a_faster_one_is_not() {
        // The unseen device's 25 deg C step: 15 kHz on 1.2 MHz, 0.4 s windows.
        let mut k = knowns(&paper().exp).expect("knowns");
        k.clock_hz = 1.2e6;
        k.filter.min_window_s = 0.4;
        let at = |carrier_hz: f64| CarrierFold::of(&operating_at(carrier_hz, &k), &k);
        let slow = at(15000.0005);
        let s = slow
            .static_fold
            .expect("a fold 0.04 Hz off beats slower than 0.4 s");
        assert_eq!(s.period, 80);
        assert!((s.offset_hz - 0.04).abs() < 1e-6, "{}", s.offset_hz);
        let line = slow.clause().expect("a clause");
        assert!(line.contains("may lie beyond their sigmas"), "{line}");
        assert!(
            line.contains("0.040 Hz from a fold of period 80 clocks"),
            "{line}"
        );
        // 2.4 Hz is 0.96 of a beat a window: named, though its figures
        // were within their sigmas (the line errs on the side of saying
        // it); 4 Hz, 1.6 beats a window, is not.
        assert!(at(15000.03).static_fold.is_some());
        assert_eq!(at(15000.05).static_fold, None);
        assert_eq!(at(15011.25).static_fold, None);
        // The paper's 30 deg C carrier (q = 83, 18.2 Hz, 0.1 s windows) ripples, but is not static.
        let paper = knowns(&paper().exp).expect("knowns");
        let f = CarrierFold::of(&operating_at(9638553.9975, &paper), &paper);
        assert!(f.in_passband && f.static_fold.is_none(), "{f:?}");
        assert!(f.clause().expect("a clause").contains("may ripple"));
    }

    /// The consumer scenario at 25 deg C, its factory operating point and
    /// its knowns with the rates 50 and 100 deg/s: a rate table's setting.
    fn consumer_table() -> (Scenario, FrontEnd, Knowns, DeviceAt, Operating) {
        let text = include_str!("../../../tests/data/field_consumer.toml");
        let sc = parse("field_consumer.toml", text).expect("the consumer scenario parses");
        let (fe, mut k) = build(&sc.exp).expect("the board and knowns");
        let at = sc.drift.at(&sc.exp.gyro, 25.0);
        let op = operating_at(sc.exp.drive.carrier_hz, &k);
        k.rates_dps = vec![50.0, 100.0];
        (sc, fe, k, at, op)
    }

    /// A rate table whose window clips an ADC is an error naming the
    /// table, the ADC and the rate, never a slope: the consumer device at
    /// its configured (unscaled) drives clips ADC 2 at 100,000 deg/s, and
    /// at 100 deg/s does not.
    #[test]
    fn a_rate_table_that_clips_is_refused_at_its_rate() {
        let (sc, fe, mut k, at, op) = consumer_table();
        let (table, _) = rate_table(&sc.exp, &fe, &at, &k, &op, None).expect("within range");
        assert!(table.sf_per_dps.iter().all(|s| s.is_finite() && *s != 0.0));
        k.rates_dps = vec![50.0, 100_000.0];
        let e = rate_table(&sc.exp, &fe, &at, &k, &op, None)
            .expect_err("clipped")
            .to_string();
        assert!(
            e.starts_with("rate table: ADC 2 clipped on ") && e.contains("(at 100000 deg/s;"),
            "{e}"
        );
        assert!(!e.contains('\n'), "{e}");
    }

    /// The table runs on to `TABLE_EXTENDED_WINDOWS` where its sigma after
    /// `TABLE_WINDOWS` exceeds `TABLE_EXTEND_SHARE` of the compared sigma
    /// on either output, and only there, on the boards it settled.
    #[test]
    fn a_rate_table_runs_on_where_its_sigma_weighs() {
        let (sc, fe, k, at, op) = consumer_table();
        let table = |judged| rate_table(&sc.exp, &fe, &at, &k, &op, judged).expect("in range");
        let (short, clocks) = table(None);
        assert_eq!(short.windows, TABLE_WINDOWS);
        // Just covered on both outputs: the same table.
        let share = |u: [f64; 2], f: f64| u.map(|u| u / TABLE_EXTEND_SHARE * f);
        assert_eq!(table(Some(share(short.uncertainty, 1.01))), (short, clocks));
        // Each of the two rates' boards runs on by the added windows (and
        // the few samples a window's start waits for), not from power-up.
        let window = k.filter.min_window_s * k.clock_hz;
        let more = ((TABLE_EXTENDED_WINDOWS - TABLE_WINDOWS) * 2) as f64 * window;
        for out in 0..2 {
            // Just beyond on output `out` alone.
            let mut judged = share(short.uncertainty, 1.01);
            judged[out] = share(short.uncertainty, 0.99)[out];
            let (long, long_clocks) = table(Some(judged));
            assert_eq!(long.windows, TABLE_EXTENDED_WINDOWS, "output {}", out + 1);
            let added = (long_clocks - clocks) as f64;
            assert!(
                (added - more).abs() < 0.01 * more,
                "{added} clocks for {more}"
            );
            assert_ne!(long.sf_per_dps, short.sf_per_dps);
        }
    }

    /// The scenario's warnings with the host's knowns.
    fn said(sc: &Scenario) -> Vec<String> {
        warnings(sc, &knowns(&sc.exp).expect("knowns"))
    }

    #[test]
    fn a_carrier_configured_off_both_modes_is_named_in_one_line() {
        let mut sc = paper();
        assert!(said(&sc).is_empty(), "{:?}", said(&sc));
        // The datasheet's f1 0.3% high, the carrier at the device's f1:
        // 28.9 kHz from the datasheet's f1, the split 250 Hz.
        sc.exp.datasheet.f1_hz = Some(9.66892e6);
        sc.exp.datasheet.f2_hz = Some(9.66917e6);
        let lines = said(&sc);
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert!(
            lines[0].starts_with(
                "warning: [drive] carrier_hz = 9640000.0 Hz is -28920.0 Hz from the datasheet's f1"
            ),
            "{lines:?}"
        );
    }

    #[test]
    fn an_undithered_adc_is_named_in_one_line_and_a_dithered_one_is_not() {
        let mut sc = paper();
        assert!(said(&sc).is_empty(), "{:?}", said(&sc));
        sc.exp.frontend.noise_lsb = 0.0;
        let lines = said(&sc);
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert!(lines[0].contains("noise_lsb = 0 is below half an ADC step (0.5 word LSB"));
        // The criterion is in ADC steps: 1 word LSB does not dither a 12-bit ADC.
        sc.exp.frontend.noise_lsb = 1.0;
        sc.exp.frontend.adc_bits = 12;
        let lines = said(&sc);
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert!(
            lines[0].contains("(8 word LSB at adc_bits = 12)"),
            "{}",
            lines[0]
        );
    }
}
