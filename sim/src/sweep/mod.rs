//! `gyrocal sweep`: self-calibration over a production spread. Each device
//! of `[spread]` ([`spread`]) runs the field cycle of
//! [`crate::field::scenario`]: at the factory temperature alone, or over the
//! whole `[drift]` when the file has one. Its error is against the rate
//! table of its own simulation, as in `gyrocal field`.
//!
//! **What the host knows.** One datasheet for every part: the file's
//! `[datasheet]` over its `[gyro]`, i.e. the nominal device, never the part
//! drawn. When lambda spreads and the file's `[datasheet]` does not give its
//! uncertainty, the datasheet states the spread's relative sigma
//! (`angular_gain_uncertainty`): a host cannot know a part's lambda better
//! than the process makes it, and the reported sigma must say so.
//!
//! **One board for every part.** The line builds one board, for the
//! nominal device: unless the file gives `[frontend] adc_per_meter1/2`,
//! [`parse`] writes in the ADC gains `experiment::plan` sizes for the
//! nominal `[gyro]` at the configured carrier, and every part runs with
//! them (its `gyrocal sweep part` file carries them). A part that answers
//! more than the nominal fills its ADCs further and its cycle scales its
//! drives down; one that answers less reads smaller words. Sized on each
//! part, as `gyrocal field` sizes a file without them, a part some
//! bandwidths off the carrier got gains that many times larger and ran
//! its drives at a fraction of full scale: part 0 of
//! `examples/sweep/fork_32khz.toml` at 0.23% to 0.28%, its output 2's
//! sigma 1.0 to 2.4% where it is now 0.06 to 0.29% (docs/sweep.md,
//! "Every part on the nominal's board").
//!
//! **Sharding.** A sweep can be cut in N shards ([`Shard`], `--shard I/N`,
//! I from 1): shard I runs the devices whose index i has i mod N = I - 1.
//! Device i is drawn from the seed and i alone ([`spread::Spread::draw`]),
//! so it is the same in any shard, and [`merge`] of the N shards' reports
//! is the unsharded report, bit for bit (the report holds no wall time; the
//! JSON's floats read back exactly, serde_json's `float_roundtrip`).
//!
//! Read in order: [`spread`] (the section and the draws), this file (one
//! device, the run, the merge), [`summary`] (yield and percentiles).

pub mod spread;
pub mod summary;

use crate::error::{FieldError, RunError, ScenarioError};
use crate::experiment;
use crate::field::scenario::{self, IdentifiedJson, Scenario};
use crate::gyro::GyroParams;
use gyrocal_host::selfcal::SfUncertainty;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spread::{Drawn, Spread, SpreadError};
use std::fmt;
use std::str::FromStr;
use summary::Summary;

/// What can go wrong with a sweep's input: each is one line.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The file (a section, a key) is wrong.
    #[error(transparent)]
    Config(#[from] ScenarioError),
    /// The file has no `[spread]`.
    #[error(
        "{0}: missing [spread]: `gyrocal sweep` needs `devices` and the parameters' spread (see `gyrocal sweep --help`)"
    )]
    NoSpread(String),
    /// A `[spread]` key is wrong.
    #[error("{name}: {source}")]
    Spread {
        /// The file.
        name: String,
        /// The key at fault.
        source: SpreadError,
    },
    /// `--shard` is not `I/N` with 1 <= I <= N.
    #[error("--shard {0}: give I/N with 1 <= I <= N, e.g. 2/8")]
    Shard(String),
    /// Shard reports that do not make one sweep.
    #[error("merge: {0}")]
    Merge(String),
    /// A part asked of `gyrocal sweep part` that the spread does not have.
    #[error("--index {index}: the spread has parts 0 to {last} (`devices` = {devices})", last = devices - 1)]
    NoSuchPart {
        /// The part asked.
        index: u32,
        /// The spread's `devices` (at least 1).
        devices: u32,
    },
    /// The nominal device's board could not be sized.
    #[error("{name}: the nominal device's board (its ADC gains): {source}")]
    Board {
        /// The file.
        name: String,
        /// Why.
        source: Box<RunError>,
    },
}

/// A checked sweep: the scenario every device runs (around the nominal
/// `[gyro]`) and its spread.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The file's scenario: the nominal device, its drive, plan and drift.
    pub scenario: Scenario,
    /// The spread.
    pub spread: Spread,
    /// FNV-1a hash of the file's text (hex): shards merge only with shards
    /// of the same file.
    pub fingerprint: String,
}

/// Parse a sweep file: the sections of `gyrocal field` (`[drift]` and
/// `[profile]` optional) plus `[spread]`. `name` labels the errors.
pub fn parse(name: &str, text: &str) -> Result<Sweep, SweepError> {
    let (scenario, spread, _) = scenario::parse_file(name, text)?;
    let spread = spread.ok_or_else(|| SweepError::NoSpread(name.into()))?;
    let refused = |source| SweepError::Spread {
        name: name.into(),
        source,
    };
    spread.validate(&scenario.exp.gyro).map_err(refused)?;
    spread
        .clock_sd(scenario.exp.drive.clock_error_ppm)
        .map_err(refused)?;
    let mut scenario = scenario;
    nominal_board(&mut scenario).map_err(|source| SweepError::Board {
        name: name.into(),
        source: Box::new(source),
    })?;
    Ok(Sweep {
        scenario,
        spread,
        fingerprint: format!("{:016x}", fnv1a(text.as_bytes())),
    })
}

/// The one board of the line (module header): the ADC gains sized for the
/// nominal device, written into `scenario`'s `[frontend]` unless the file
/// gave its own.
fn nominal_board(scenario: &mut Scenario) -> Result<(), RunError> {
    if scenario.exp.adc_per_meter().is_some() {
        return Ok(());
    }
    let [a1, a2] = experiment::plan(&scenario.exp)?.front_end.adc_per_meter;
    let fe = &mut scenario.exp.frontend;
    (fe.adc_per_meter1, fe.adc_per_meter2) = (Some(a1), Some(a2));
    Ok(())
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Shard `index` of `count` (1 <= index <= count): the devices whose index
/// i has i mod count = index - 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, from 1.
    pub index: u32,
    /// How many shards.
    pub count: u32,
}

impl FromStr for Shard {
    type Err = SweepError;
    fn from_str(s: &str) -> Result<Self, SweepError> {
        let bad = || SweepError::Shard(s.into());
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            i.trim().parse::<u32>().map_err(|_| bad())?,
            n.trim().parse::<u32>().map_err(|_| bad())?,
        );
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Self { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// Whether device `i` is this shard's.
    pub fn holds(&self, i: u32) -> bool {
        i % self.count == self.index - 1
    }
}

/// One temperature step of one device.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeviceStep {
    /// Temperature (deg C).
    pub temperature_c: f64,
    /// sf_selfcal / sf_true - 1, per output.
    pub sf_selfcal_error: [f64; 2],
    /// The self-calibrated scale factor's relative 1-sigma.
    pub sf_selfcal_uncertainty: [f64; 2],
    /// The error's own 1-sigma (the truth's in quadrature).
    pub selfcal_error_uncertainty: [f64; 2],
    /// `sf_selfcal_uncertainty` by source (the field step's
    /// `selfcal.sf_selfcal_uncertainty`).
    pub sf_selfcal_budget: SfUncertainty,
    /// The truth: the rate table's slope (z LSB per deg/s).
    pub sf_true_per_dps: [f64; 2],
    /// What the host identified.
    pub identified: IdentifiedJson,
    /// The device at this step (never seen by the host): what `identified`
    /// is scored against ([`IdentifiedJson::scored`]).
    pub truth: GyroParams,
}

impl DeviceStep {
    /// |self-calibration error| of output `k`.
    pub fn error(&self, k: usize) -> f64 {
        self.sf_selfcal_error[k].abs()
    }
}

/// A part of a device's run that failed (the rest stands).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeviceFailure {
    /// The step's temperature (null when the device could not start).
    pub temperature_c: Option<f64>,
    /// What failed: a field stage, or "device" (the drawn device is outside
    /// what the simulation supports).
    pub stage: String,
    /// The error, one line.
    pub error: String,
}

/// One device of the sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeviceResult {
    /// Its index in the spread, from 0.
    pub index: u32,
    /// The part drawn.
    pub device: GyroParams,
    /// Its `[frontend] seed`.
    pub frontend_seed: u64,
    /// Its `[noise] seed`.
    pub noise_seed: u64,
    /// Its board oscillator's error from `[drive] clock_error_ppm` (ppm;
    /// `[spread] clock_error_ppm`).
    #[serde(default)]
    pub clock_error_ppm: f64,
    /// Temperature of the worst step: the one with the largest |error|
    /// (either output); null when no step finished.
    pub worst_temperature_c: Option<f64>,
    /// The worst step's self-calibration error, per output.
    pub sf_selfcal_error: Option<[f64; 2]>,
    /// The worst step's self-calibrated scale factor's relative 1-sigma.
    pub sf_selfcal_uncertainty: Option<[f64; 2]>,
    /// What the host identified at the worst step.
    pub identified: Option<IdentifiedJson>,
    /// Every step finished and each |error| is within the tolerance.
    pub within_tolerance: bool,
    /// Every finished step.
    pub steps: Vec<DeviceStep>,
    /// What failed.
    pub failed: Vec<DeviceFailure>,
    /// Its field run's warnings, one line each: inputs no sigma covers
    /// (`FieldReport::warnings`).
    pub warnings: Vec<String>,
    /// Clocks simulated.
    pub clocks: u64,
}

/// A sweep's report (or one shard's).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepReport {
    /// [`Sweep::fingerprint`].
    pub fingerprint: String,
    /// The nominal device (`[gyro]`).
    pub nominal: GyroParams,
    /// The spread.
    pub spread: Spread,
    /// The temperature steps every device runs (deg C).
    pub temperatures_c: Vec<f64>,
    /// This report's shard; null for the whole sweep (or a merge).
    pub shard: Option<Shard>,
    /// The devices, by index.
    pub devices: Vec<DeviceResult>,
    /// Yield and percentiles over `devices`.
    pub summary: Summary,
}

impl Sweep {
    /// Device `index`'s scenario: the part drawn, its noise seeds, and the
    /// one datasheet of the nominal device (module header).
    pub fn device_scenario(&self, drawn: &Drawn) -> Scenario {
        let mut sc = self.scenario.clone();
        let nominal = &self.scenario.exp.gyro;
        let ds = &mut sc.exp.datasheet;
        let fill = |v: &mut Option<f64>, nominal: f64| {
            v.get_or_insert(nominal);
        };
        fill(&mut ds.f1_hz, nominal.f1_hz);
        fill(&mut ds.f2_hz, nominal.f2_hz);
        fill(&mut ds.q1, nominal.q1);
        fill(&mut ds.q2, nominal.q2);
        fill(&mut ds.quadrature_dps, nominal.quadrature_dps);
        fill(&mut ds.damping_coupling_dps, nominal.damping_coupling_dps);
        if ds.angular_gain.is_none() {
            ds.angular_gain = Some(nominal.angular_gain);
            let spread = self
                .spread
                .angular_gain
                .map_or(0.0, |s| s.relative(nominal.angular_gain));
            ds.angular_gain_uncertainty.get_or_insert(spread);
        }
        sc.exp.gyro = drawn.gyro.clone();
        sc.exp.frontend.seed = drawn.frontend_seed;
        sc.exp.noise.seed = drawn.noise_seed;
        sc.exp.drive.clock_error_ppm += drawn.clock_error_ppm;
        sc
    }

    /// Part `index` as a `gyrocal field` file: its drawn parameters, its
    /// seeds, its oscillator and the one datasheet of the nominal device,
    /// so that `gyrocal field` runs it again alone and gets the figures
    /// the sweep gave it. A scenario without `[drift]` gets the single step
    /// at the factory temperature its sweep ran.
    pub fn part_file(&self, index: u32) -> Result<String, SweepError> {
        if index >= self.spread.devices {
            return Err(SweepError::NoSuchPart {
                index,
                devices: self.spread.devices,
            });
        }
        Ok(self.device_scenario(&self.drawn(index)).to_toml()?)
    }

    /// Part `index` as the spread draws it around the nominal device.
    fn drawn(&self, index: u32) -> Drawn {
        self.spread
            .draw(&self.scenario.exp.gyro, index)
            .expect("the spread was validated by `parse`")
    }

    /// Run device `index`: draw it, run its field scenario, keep every
    /// step and every failure.
    pub fn run_device(&self, index: u32) -> DeviceResult {
        let drawn = self.drawn(index);
        let sc = self.device_scenario(&drawn);
        let mut failed = vec![];
        let mut steps = vec![];
        let mut clocks = 0;
        let mut warnings = vec![];
        let started = sc
            .validate()
            .map_err(FieldError::from)
            .and_then(|()| scenario::run(&sc, &|_| {}));
        match started {
            Err(error) => failed.push(DeviceFailure {
                temperature_c: None,
                stage: "device".into(),
                error: error.to_string(),
            }),
            Ok(report) => {
                clocks = report.clocks;
                // The summary names every uncovered error, and identified
                // parameter, of the spread itself
                // (`summary::uncovered_errors`), by part.
                let uncovered = [
                    scenario::uncovered_error_warning(&report.steps),
                    scenario::uncovered_parameter_warning(&report.steps),
                ];
                warnings = report.warnings;
                warnings.retain(|w| !uncovered.iter().flatten().any(|u| u == w));
                failed.extend(report.failed.into_iter().map(|f| DeviceFailure {
                    temperature_c: Some(f.temperature_c),
                    stage: f.stage.into(),
                    error: f.error,
                }));
                steps.extend(report.steps.into_iter().map(|st| DeviceStep {
                    temperature_c: st.temperature_c,
                    sf_selfcal_error: st.selfcal_error,
                    sf_selfcal_uncertainty: st.sf_selfcal_uncertainty,
                    selfcal_error_uncertainty: st.selfcal_error_uncertainty,
                    sf_selfcal_budget: st.selfcal.sf_selfcal_uncertainty,
                    sf_true_per_dps: st.sf_true_per_dps,
                    identified: st.identified,
                    truth: st.truth.gyro,
                }));
            }
        }
        let tolerance = self.spread.tolerance;
        DeviceResult::new(index, drawn, steps, failed, warnings, clocks, tolerance)
    }

    /// Run the sweep's devices (`shard`'s alone, if given) in parallel;
    /// `progress` gets each device when it finishes.
    pub fn run(
        &self,
        shard: Option<Shard>,
        progress: &(dyn Fn(&DeviceResult) + Sync),
    ) -> SweepReport {
        let devices: Vec<DeviceResult> = self
            .indices(shard)
            .par_iter()
            .map(|&i| {
                let d = self.run_device(i);
                progress(&d);
                d
            })
            .collect();
        SweepReport {
            fingerprint: self.fingerprint.clone(),
            nominal: self.scenario.exp.gyro.clone(),
            spread: self.spread.clone(),
            temperatures_c: self.scenario.drift.temperatures_c.clone(),
            shard,
            summary: Summary::of(&devices, self.spread.tolerance),
            devices,
        }
    }

    /// The indices of the devices a shard holds (all without one).
    fn indices(&self, shard: Option<Shard>) -> Vec<u32> {
        (0..self.spread.devices)
            .filter(|&i| shard.is_none_or(|s| s.holds(i)))
            .collect()
    }

    /// How many devices a shard holds (all without one).
    pub fn device_count(&self, shard: Option<Shard>) -> u32 {
        self.indices(shard).len() as u32
    }
}

impl DeviceResult {
    /// The largest |self-calibration error| of output `k` over the finished
    /// steps (0 without one).
    pub fn worst_error(&self, k: usize) -> f64 {
        self.steps.iter().fold(0.0, |m, s| m.max(s.error(k)))
    }

    fn new(
        index: u32,
        drawn: Drawn,
        steps: Vec<DeviceStep>,
        failed: Vec<DeviceFailure>,
        warnings: Vec<String>,
        clocks: u64,
        tolerance: f64,
    ) -> Self {
        let size = |s: &DeviceStep| 0.0f64.max(s.error(0)).max(s.error(1));
        let worst = steps.iter().max_by(|a, b| size(a).total_cmp(&size(b)));
        Self {
            index,
            device: drawn.gyro,
            frontend_seed: drawn.frontend_seed,
            noise_seed: drawn.noise_seed,
            clock_error_ppm: drawn.clock_error_ppm,
            worst_temperature_c: worst.map(|s| s.temperature_c),
            sf_selfcal_error: worst.map(|s| s.sf_selfcal_error),
            sf_selfcal_uncertainty: worst.map(|s| s.sf_selfcal_uncertainty),
            identified: worst.map(|s| s.identified.clone()),
            within_tolerance: failed.is_empty()
                && !steps.is_empty()
                && steps.iter().all(|s| size(s) <= tolerance),
            steps,
            failed,
            warnings,
            clocks,
        }
    }
}

/// The whole sweep from its shards' reports: every shard of one file's
/// sweep, each once, in any order. The result equals the unsharded run's
/// report.
pub fn merge(parts: Vec<SweepReport>) -> Result<SweepReport, SweepError> {
    let bad = |m: String| Err(SweepError::Merge(m));
    let Some(first) = parts.first() else {
        return bad("no reports given".into());
    };
    let count = match first.shard {
        Some(s) => s.count,
        None => return bad("part 1 is a whole sweep, not a shard (it has no `shard`)".into()),
    };
    let mut seen = vec![false; count as usize];
    for (k, p) in parts.iter().enumerate() {
        if p.fingerprint != first.fingerprint || p.spread != first.spread {
            return bad(format!(
                "part {} is from another file or spread than part 1 (fingerprint {} against {})",
                k + 1,
                p.fingerprint,
                first.fingerprint
            ));
        }
        match p.shard {
            Some(s) if s.count == count => {
                if std::mem::replace(&mut seen[s.index as usize - 1], true) {
                    return bad(format!("shard {s} is given twice"));
                }
                if let Some(d) = p.devices.iter().find(|d| !s.holds(d.index)) {
                    return bad(format!("shard {s} holds device {}, not its own", d.index));
                }
            }
            Some(s) => return bad(format!("part {} is shard {s}, part 1 is of {count}", k + 1)),
            None => return bad(format!("part {} is a whole sweep, not a shard", k + 1)),
        }
    }
    if let Some(missing) = seen.iter().position(|s| !s) {
        return bad(format!(
            "shard {}/{count} is missing ({} of {count} given)",
            missing + 1,
            parts.len()
        ));
    }
    let template = first.clone();
    let mut devices: Vec<DeviceResult> = parts.into_iter().flat_map(|p| p.devices).collect();
    devices.sort_by_key(|d| d.index);
    let complete = devices.len() == template.spread.devices as usize
        && devices
            .iter()
            .enumerate()
            .all(|(i, d)| d.index as usize == i);
    if !complete {
        return bad(format!(
            "the shards hold {} devices, the spread has {}",
            devices.len(),
            template.spread.devices
        ));
    }
    Ok(SweepReport {
        shard: None,
        summary: Summary::of(&devices, template.spread.tolerance),
        devices,
        ..template
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Experiment, Frontend};

    #[test]
    fn shards_parse_and_cover_every_device_once() {
        let s: Shard = "2/3".parse().unwrap();
        assert_eq!((s.index, s.count), (2, 3));
        assert_eq!(s.to_string(), "2/3");
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", ""] {
            let e = bad.parse::<Shard>().unwrap_err().to_string();
            assert!(e.contains("give I/N"), "{e}");
        }
        for n in 1..6 {
            for i in 0..50 {
                let holders = (1..=n)
                    .filter(|&k| Shard { index: k, count: n }.holds(i))
                    .count();
                assert_eq!(holders, 1);
            }
        }
    }

    const FILE: &str = "[gyro]\nf1_hz = 25.1e3\nf2_hz = 25.8e3\nq1 = 3000\nq2 = 3000\n\
        angular_gain = 0.8\n[drive]\ncarrier_hz = 25.1e3\nclock_hz = 1.2345e6\n\
        clock_error_ppm = 30\n[experiment]\nreadout_rates_dps = [50, 100]\n\
        cal_freqs_hz = [2, 4]\n[spread]\ndevices = 4\n";

    /// Every part runs on the nominal device's board (module header): its
    /// scenario, and its `sweep part` file, carry the ADC gains sized for
    /// the nominal `[gyro]`, which sized on the part would differ (ADC 1's
    /// 2.4 to 10.7 times on this file's four parts). A file's own gains
    /// are kept.
    #[test]
    fn every_part_runs_on_the_nominal_devices_board() {
        let text = format!("{FILE}f1_hz = {{ sd = 40.0 }}\nsplit_hz = {{ sd = 25.0 }}\n");
        let sweep = parse("s.toml", &text).unwrap();
        let board = experiment::plan(&sweep.scenario.exp)
            .unwrap()
            .front_end
            .adc_per_meter;
        let fe = &sweep.scenario.exp.frontend;
        assert_eq!([fe.adc_per_meter1, fe.adc_per_meter2], board.map(Some));
        for i in 0..4 {
            let sc = sweep.device_scenario(&sweep.drawn(i));
            assert_eq!(sc.exp.adc_per_meter(), Some(board));
            let back = scenario::parse("part.toml", &sweep.part_file(i).unwrap()).unwrap();
            assert_eq!(back.exp.adc_per_meter(), Some(board));
            let on_the_part = Experiment {
                frontend: Frontend {
                    adc_per_meter1: None,
                    adc_per_meter2: None,
                    ..sc.exp.frontend.clone()
                },
                ..sc.exp.clone()
            };
            let own = experiment::plan(&on_the_part)
                .unwrap()
                .front_end
                .adc_per_meter;
            let ratio: [f64; 2] = std::array::from_fn(|k| own[k] / board[k]);
            eprintln!("part {i}: sized on itself, {ratio:?} times the nominal's board");
            assert!(
                ratio.iter().any(|r| (r - 1.0).abs() > 0.05),
                "part {i}: {ratio:?}"
            );
        }
        let given = format!("{text}[frontend]\nadc_per_meter1 = 1e9\nadc_per_meter2 = 2e9\n");
        let own = parse("s.toml", &given).unwrap();
        assert_eq!(own.scenario.exp.adc_per_meter(), Some([1e9, 2e9]));
    }

    /// A part's board runs at the file's oscillator error plus its own
    /// draw; a spread whose 5 sigma passes `MAX_CLOCK_PPM` with the file's
    /// error added is refused in one line.
    #[test]
    fn each_parts_board_takes_its_drawn_oscillator() {
        let sweep = parse(
            "s.toml",
            &format!("{FILE}clock_error_ppm = {{ sd = 100.0 }}\n"),
        )
        .unwrap();
        let nominal = &sweep.scenario.exp.gyro;
        for i in 0..4 {
            let drawn = sweep.spread.draw(nominal, i).unwrap();
            assert_ne!(drawn.clock_error_ppm, 0.0);
            let sc = sweep.device_scenario(&drawn);
            assert_eq!(sc.exp.drive.clock_error_ppm, 30.0 + drawn.clock_error_ppm);
        }
        let err = parse(
            "s.toml",
            &format!("{FILE}clock_error_ppm = {{ sd = 1995.0 }}\n"),
        )
        .unwrap_err()
        .to_string();
        assert!(
            !err.contains('\n')
                && err.starts_with(
                    "s.toml: [spread] clock_error_ppm.sd = 1995: allowed 0..=1994 ppm, so that 5 \
                     sigma out from [drive] clock_error_ppm = 30 stays within 10000 ppm"
                ),
            "{err}"
        );
    }

    /// `part_file` gives each part's scenario back through `gyrocal
    /// field`'s parser, to the bit: its drawn device, seeds (below 2^63,
    /// which TOML's i64 holds), oscillator, datasheet and the single
    /// factory step of a file without `[drift]`. A part beyond `devices`
    /// is one line.
    #[test]
    fn a_parts_field_file_reads_back_to_its_scenario() {
        let text = format!(
            "{FILE}f1_hz = {{ sd = 40.0 }}\nq1 = {{ rel_sd = 0.1 }}\n\
             angular_gain = {{ rel_sd = 0.02 }}\nclock_error_ppm = {{ sd = 100.0 }}\n"
        );
        let sweep = parse("s.toml", &text).unwrap();
        let nominal = &sweep.scenario.exp.gyro;
        for i in 0..4 {
            let file = sweep.part_file(i).unwrap();
            let back =
                scenario::parse("part.toml", &file).unwrap_or_else(|e| panic!("{e}\n{file}"));
            let drawn = sweep.spread.draw(nominal, i).unwrap();
            assert_eq!(back, sweep.device_scenario(&drawn), "{file}");
            assert_eq!(back.exp.frontend.seed, drawn.frontend_seed);
            assert_eq!(back.drift.temperatures_c, [scenario::FACTORY_C]);
        }
        let err = sweep.part_file(4).unwrap_err().to_string();
        assert_eq!(
            err,
            "--index 4: the spread has parts 0 to 3 (`devices` = 4)"
        );
    }
}
