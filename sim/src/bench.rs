//! Side-by-side speed of the engines, in one process, on the same stimulus.
//!
//! For each engine: clocks per second running the datapath alone (ADC
//! words from a precomputed table) and inside the closed loop with the
//! gyroscope model (`CoSim`), each repeated and reported as the median with
//! its spread. Both run as the experiments do, through `Engine::run` (the
//! model engine in blocks, the others clock by clock). Stimulus: the
//! paper's device, calibration at 12 Hz (every block busy). The model
//! engine also runs the closed loop in [`RATE_LANES`] lanes (the device at
//! as many rates, `CoSimLanes`), counted in lane clocks. Optionally, the
//! whole `reproduce` experiment, timed wall to wall on all cores, with the
//! process's peak resident memory.

use crate::engine::{Engine, EngineKind, ModelEngine, RtlEngine};
use crate::error::RunError;
use crate::experiment::{self, Experiment, Plan};
use gyrocal_hdl::model::gyro_interface::{AnalogSide, Words};
use gyrocal_hdl::model::isa::Isa;
use serde::Serialize;
use std::hint::black_box;
use std::time::Instant;

/// One engine in one setting.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Measurement {
    /// Engine name.
    pub engine: String,
    /// True when the gyroscope model and converters were in the loop.
    pub with_gyro: bool,
    /// Lanes played together (`gyrocal_hdl::model::lanes`: one device at
    /// several rates, as a readout sweep or a rate table runs it): 1, or
    /// [`RATE_LANES`] on the model engine; `clocks` and the speeds count
    /// every lane's clocks.
    pub lanes: usize,
    /// Clocks per repetition.
    pub clocks: u64,
    /// Clocks per second of each repetition.
    pub samples: Vec<f64>,
    /// Median of `samples`.
    pub median_clocks_per_s: f64,
}

/// The whole reproduce experiment.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReproduceTiming {
    /// Wall time (s), all cores.
    pub wall_s: f64,
    /// Clocks simulated.
    pub clocks: u64,
    /// Worker threads.
    pub threads: usize,
    /// Peak resident memory of the process after the run (MB), from
    /// /proc/self/status (VmHWM).
    pub peak_memory_mb: Option<f64>,
}

/// Everything `gyrocal bench` measures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BenchReport {
    /// Per engine and setting.
    pub measurements: Vec<Measurement>,
    /// The instruction set the model engine's runs were compiled for
    /// (`gyrocal_hdl::model::isa`).
    pub model_isa: String,
    /// Median model speed over median Verilator speed, gyroscope in the loop.
    pub model_over_verilator_with_gyro: Option<f64>,
    /// The reproduce run, when asked.
    pub reproduce: Option<ReproduceTiming>,
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// The datapath alone's analog side: the ADC words of a table, in turn;
/// the DAC words summed so that they are computed.
struct Replay<'a> {
    words: &'a [Words],
    next: usize,
    check: i64,
}

impl AnalogSide for Replay<'_> {
    #[inline(always)]
    fn advance(&mut self, dac: Words) {
        self.check = self.check.wrapping_add(i64::from(dac.0));
    }

    #[inline(always)]
    fn convert(&mut self, adc: &mut [Words]) {
        for a in adc {
            *a = self.words[self.next];
            self.next = (self.next + 1) % self.words.len();
        }
    }
}

fn stimulus_plan() -> (Experiment, Plan) {
    let mut exp = Experiment::paper();
    exp.points.cal_freqs_hz = vec![12.0, 13.0];
    let plan = experiment::plan(&exp).expect("the paper's plan is valid");
    (exp, plan)
}

/// The stimulus's point: the plan's first calibration point.
fn stimulus_point(plan: &Plan) -> &experiment::PointPlan {
    plan.points
        .iter()
        .find(|p| p.mode == experiment::Mode::Calibration)
        .expect("a calibration point")
}

fn measure<E: Engine>(
    name: &str,
    clocks: u64,
    repetitions: usize,
) -> Result<[Measurement; 2], RunError> {
    let (exp, plan) = stimulus_plan();
    let point = stimulus_point(&plan);
    // ADC words for the datapath-alone runs: what the loop itself produces.
    let adc: Vec<(i16, i16)> = {
        let mut sim = experiment::point_loop::<ModelEngine>(&exp, &plan, point)?;
        (0..clocks.min(1 << 22))
            .map(|_| {
                sim.step();
                sim.last_adc()
            })
            .collect()
    };
    let mut alone = vec![];
    let mut looped = vec![];
    for _ in 0..repetitions {
        let mut engine = E::power_up(exp.drive.carrier_profile)?;
        let start = Instant::now();
        let mut check = 0i64;
        let mut table = Replay {
            words: &adc,
            next: 0,
            check: 0,
        };
        let mut z_sum = 0i64;
        let sum = |n: u64, z: (i64, i64)| z_sum = z_sum.wrapping_add(z.0 ^ n as i64);
        engine.run((0, 0), black_box(&point.regs), clocks, &mut table, sum);
        check = check.wrapping_add(table.check);
        black_box((check, z_sum));
        alone.push(clocks as f64 / start.elapsed().as_secs_f64());
        let mut sim = experiment::point_loop::<E>(&exp, &plan, point)?;
        let start = Instant::now();
        let mut check = 0i64;
        sim.run(clocks, |n, z| check = check.wrapping_add(z.0 ^ n as i64));
        black_box(check);
        looped.push(clocks as f64 / start.elapsed().as_secs_f64());
    }
    let make = |with_gyro: bool, samples: Vec<f64>| Measurement {
        engine: name.into(),
        with_gyro,
        lanes: 1,
        clocks,
        median_clocks_per_s: median(&samples),
        samples,
    };
    Ok([make(false, alone), make(true, looped)])
}

/// Lanes of the model engine's lane measurement.
pub const RATE_LANES: usize = 8;

/// The closed loop of `measure` in [`RATE_LANES`] lanes, the device at
/// rates from 0 to 7 deg/s: `clocks` lane clocks a repetition.
fn measure_lanes(clocks: u64, repetitions: usize) -> Result<Measurement, RunError> {
    let (exp, plan) = stimulus_plan();
    let point = stimulus_point(&plan);
    let per_lane = (clocks / RATE_LANES as u64).max(1);
    let mut samples = vec![];
    for _ in 0..repetitions {
        let rates: Vec<f64> = (0..RATE_LANES).map(|l| (l as f64).to_radians()).collect();
        let mut sim = experiment::lanes_loop(&exp, &plan, point.regs, &rates)?;
        let start = Instant::now();
        let mut check = 0i64;
        sim.run(per_lane, |l, n, z| {
            check = check.wrapping_add(z.0 ^ (n + l as u64) as i64)
        });
        black_box(check);
        samples.push((per_lane * RATE_LANES as u64) as f64 / start.elapsed().as_secs_f64());
    }
    Ok(Measurement {
        engine: "model".into(),
        with_gyro: true,
        lanes: RATE_LANES,
        clocks: per_lane * RATE_LANES as u64,
        median_clocks_per_s: median(&samples),
        samples,
    })
}

/// Clocks per repetition for an engine: a fraction of a second each.
pub fn default_clocks(kind: EngineKind) -> u64 {
    match kind {
        EngineKind::Model => 20_000_000,
        EngineKind::Verilator => 1_000_000,
        EngineKind::Rtl => 10_000,
    }
}

/// Peak resident memory of this process (MB), Linux only.
pub fn peak_memory_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

/// Measure the given engines; `reproduce` also times the full experiment.
pub fn run(
    engines: &[EngineKind],
    repetitions: usize,
    scale: f64,
    reproduce: bool,
    progress: &dyn Fn(&str),
) -> Result<BenchReport, RunError> {
    let mut measurements = vec![];
    for &kind in engines {
        let clocks = ((default_clocks(kind) as f64 * scale) as u64).max(1000);
        progress(&format!(
            "{}: {repetitions} x {clocks} clocks, alone and with the gyroscope",
            kind.name()
        ));
        let m = match kind {
            EngineKind::Model => {
                let [alone, looped] = measure::<ModelEngine>("model", clocks, repetitions)?;
                let lanes = measure_lanes(clocks, repetitions)?;
                measurements.extend([alone, looped, lanes]);
                continue;
            }
            EngineKind::Rtl => measure::<RtlEngine>("rtl", clocks, repetitions)?,
            #[cfg(feature = "verilator")]
            EngineKind::Verilator => {
                measure::<crate::verilator::VerilatorEngine>("verilator", clocks, repetitions)?
            }
            #[cfg(not(feature = "verilator"))]
            EngineKind::Verilator => return Err(RunError::NoVerilator),
        };
        measurements.extend(m);
    }
    let speed = |name: &str| {
        measurements
            .iter()
            .find(|m| m.engine == name && m.with_gyro && m.lanes == 1)
            .map(|m| m.median_clocks_per_s)
    };
    let model_over_verilator_with_gyro = speed("model").zip(speed("verilator")).map(|(a, b)| a / b);
    let reproduce = if reproduce {
        progress("reproduce: the paper's full experiment on the model engine, all cores");
        let exp = Experiment::paper();
        let start = Instant::now();
        let report = crate::report::run(&exp, EngineKind::Model, &|_| {})?;
        Some(ReproduceTiming {
            wall_s: start.elapsed().as_secs_f64(),
            clocks: report.timing.cycles,
            threads: rayon::current_num_threads(),
            peak_memory_mb: peak_memory_mb(),
        })
    } else {
        None
    };
    Ok(BenchReport {
        measurements,
        model_isa: Isa::selected().name().into(),
        model_over_verilator_with_gyro,
        reproduce,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }

    #[test]
    fn a_tiny_bench_reports_every_setting() {
        let r = run(
            &[EngineKind::Model, EngineKind::Rtl],
            3,
            1e-4,
            false,
            &|_| {},
        )
        .unwrap();
        assert_eq!(r.measurements.len(), 5);
        let lanes: Vec<usize> = r.measurements.iter().map(|m| m.lanes).collect();
        assert_eq!(lanes, [1, 1, RATE_LANES, 1, 1]);
        assert!(
            r.measurements
                .iter()
                .all(|m| m.samples.len() == 3 && m.median_clocks_per_s > 0.0)
        );
        assert!(r.model_over_verilator_with_gyro.is_none());
    }
}
