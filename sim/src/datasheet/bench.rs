//! The test bench of the datasheet: simulated boards (`field::board`) at
//! a temperature, programmed in readout at the factory's settings (the
//! nominal carrier, the aligned reference phase: what `gyrocal run`
//! plans), on a rate table.
//!
//! Every measurement starts a fresh board at power-up: the clock count
//! from power-up is the turn-on time's origin, and fresh boards keep the
//! carrier table's slow beats in the intercept, not the slope
//! (`field::scenario::rate_table`).

use super::Error;
use crate::config::Experiment;
use crate::drift::{DeviceAt, Drift};
use crate::field::board::{Board, SimBoard};
use crate::field::lanes::LaneBoards;
use crate::field::scenario;
use crate::frontend::FrontEnd;
use gyrocal_host::Knowns;
use gyrocal_host::sampling::window_z;
use gyrocal_regs::Registers;
use rayon::prelude::*;

/// Amplitude time constants of the slower mode (with the filter's
/// settling) waited before a reading: the field scenario's rate-table
/// settling (measured settled from 30 on there).
pub const SETTLE_TAUS: f64 = 30.0;

/// Label of the only temperature of a file without `[drift]` (deg C).
const NOMINAL_C: f64 = 25.0;

/// The board as built, what a host knows and the readout registers.
pub struct Bench {
    /// The experiment (its `noise` is the Brownian part of `[noise]`).
    pub exp: Experiment,
    fe: FrontEnd,
    /// What the host knows (clock, filter, settling).
    pub knowns: Knowns,
    regs: Registers,
    /// The device at the factory temperature (the first `[drift]` step).
    pub at0: DeviceAt,
}

impl Bench {
    /// Plans `exp` and the readout registers; `drift` sets the factory
    /// temperature's device.
    pub fn new(exp: &Experiment, drift: Option<&Drift>) -> Result<Self, Error> {
        let (fe, knowns) = scenario::build(exp).map_err(|e| Error::Input(e.to_string()))?;
        let (regs, _) = knowns
            .registers(exp.drive.carrier_hz, None, knowns.amplitude, 0.0)
            .map_err(|e| Error::Input(e.to_string()))?;
        let at0 = match drift {
            Some(d) => d.at(&exp.gyro, d.reference_c()),
            None => DeviceAt {
                temperature_c: NOMINAL_C,
                delta_k: 0.0,
                gyro: exp.gyro.clone(),
                adc_gain: [1.0; 2],
                drive_gain: [1.0; 2],
                front_end_phase_deg: 0.0,
            },
        };
        Ok(Self {
            exp: exp.clone(),
            fe,
            knowns,
            regs,
            at0,
        })
    }

    /// A board at `at` from power-up, in readout, at `rate_dps`; `quiet`
    /// turns the Brownian and ADC noise off (the converters still
    /// quantize).
    pub fn board(&self, at: &DeviceAt, rate_dps: f64, quiet: bool) -> Result<SimBoard, Error> {
        let (mut exp, mut fe) = (self.exp.clone(), self.fe.clone());
        if quiet {
            exp.noise.temperature_k = 0.0;
            fe.noise_lsb = 0.0;
        }
        let mut board = scenario::board_at(&exp, &fe, at).map_err(|e| Error::Run(e.to_string()))?;
        board.program(&self.regs).map_err(run)?;
        board.set_rate(rate_dps.to_radians());
        Ok(board)
    }

    /// Clocks from programming to a settled reading.
    pub fn settle_clocks(&self) -> u64 {
        self.knowns.settle_clocks(SETTLE_TAUS)
    }

    /// z samples per second.
    pub fn z_rate_hz(&self) -> f64 {
        self.knowns.clock_hz / f64::from(self.knowns.filter.decimation)
    }

    /// z averaged over one first window of a settled board at `at` and
    /// `rate_dps` (z LSB).
    pub fn reading(&self, at: &DeviceAt, rate_dps: f64) -> Result<[f64; 2], Error> {
        let mut board = self.board(at, rate_dps, false)?;
        board.wait_clocks(self.settle_clocks()).map_err(run)?;
        let r = self.knowns.filter.decimation;
        window_z(&mut board, r, f64::from(r), self.window_clocks()).map_err(run)
    }

    /// `reading` at each of `rates_dps`, the boards in lanes
    /// (`crate::field::lanes`): lane 0 reads, each other lane's reads are
    /// replayed; the same readings, bit for bit.
    pub fn readings(&self, at: &DeviceAt, rates_dps: &[f64]) -> Result<Vec<[f64; 2]>, Error> {
        let settle = self.settle_clocks();
        let mut boards =
            LaneBoards::settled(&self.exp, &self.fe, at, &self.regs, rates_dps, settle)
                .map_err(run)?;
        let r = self.knowns.filter.decimation;
        let window = self.window_clocks();
        boards
            .each_lane(|board, _| window_z(board, r, f64::from(r), window).map_err(run))
            .into_iter()
            .collect()
    }

    /// `readings` over as many lane groups as there are threads, in
    /// parallel; the readings in the order of `rates_dps`.
    pub fn readings_in_parallel(
        &self,
        at: &DeviceAt,
        rates_dps: &[f64],
    ) -> Result<Vec<[f64; 2]>, Error> {
        let threads = rayon::current_num_threads().max(1);
        let groups: Vec<&[f64]> = rates_dps
            .chunks(rates_dps.len().div_ceil(threads).max(1))
            .collect();
        let z: Vec<Vec<[f64; 2]>> = groups
            .par_iter()
            .map(|rates| self.readings(at, rates))
            .collect::<Result<_, _>>()?;
        Ok(z.into_iter().flatten().collect())
    }

    /// Clocks of one reading's window (the experiment's first window).
    pub fn window_clocks(&self) -> f64 {
        (self.knowns.filter.min_window_s * self.knowns.clock_hz).ceil()
    }
}

/// A bus or host error during a run.
pub(super) fn run(e: impl std::fmt::Display) -> Error {
    Error::Run(e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Readings in lanes are the readings on a board each: the paper's
    /// device (ADC noise on) at four rates, in one group and in groups of
    /// two threads' worth, against `reading` at each rate.
    #[test]
    fn readings_in_lanes_are_the_readings_alone() {
        let bench = Bench::new(&Experiment::paper(), None).unwrap();
        let rates = [-20.0, 0.0, 7.5, 20.0];
        let lanes = bench.readings(&bench.at0, &rates).unwrap();
        let parallel = bench.readings_in_parallel(&bench.at0, &rates).unwrap();
        for (i, &rate) in rates.iter().enumerate() {
            let alone = bench.reading(&bench.at0, rate).unwrap();
            assert_eq!(lanes[i], alone, "at {rate} deg/s");
            assert_eq!(parallel[i], alone, "at {rate} deg/s, in parallel");
        }
        assert_ne!(lanes[0], lanes[3]);
    }
}
