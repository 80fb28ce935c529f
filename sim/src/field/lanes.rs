//! A rate table's boards in lanes: one simulated board per rate, all of one
//! device at one step, which the table powers up, programs and reads
//! alike (`crate::field::scenario`, "rate table"). They differ only in the
//! rate, so they run as lanes of the model engine
//! (`gyrocal_hdl::model::lanes`, `crate::analog::Lanes`): one drive half,
//! one set of DAC forces and one block of ADC noise for all, a gyroscope,
//! a readout half and converters' ADC words per lane.
//!
//! [`LaneBoards`] is a `Board` with lane 0's face: the host's code runs on
//! it as on one `SimBoard`, and every lane plays the same clocks and takes
//! the same writes. The host's clocks and register accesses do not depend
//! on what a board reads but through the sample counts, which are every
//! lane's (the filter's schedule does not read the data), and the clip
//! counts, which a table reads only to stop. So each lane's reads are kept,
//! and the same code run again on [`Replay`] of lane l gets lane l's words
//! in the same order: what lane l's own `SimBoard` would have answered
//! (`tests`: a table in lanes is the table on boards of its own).

use super::board::{Board, analog_at};
use crate::analog::{self, Analog};
use crate::config::Experiment;
use crate::cosim::HostRegisters;
use crate::drift::DeviceAt;
use crate::error::{FieldError, RunError};
use crate::frontend::FrontEnd;
use crate::noise::ThermalNoise;
use gyrocal_hdl::host::clip_counter::{ClipCount, clip_word};
use gyrocal_hdl::model::gyro_interface::{CarrierProfile, GyroInterface, Words};
use gyrocal_hdl::model::isa::Isa;
use gyrocal_hdl::model::lanes::Lanes;
use gyrocal_regs::Registers;
use gyrocal_regs::datapath::DRIVE_START_CLOCKS;
use gyrocal_regs::map::{ADC_CLIP, BusError, RegisterAccess};
use std::collections::VecDeque;

/// Boards in lanes, one per rate (module header).
pub struct LaneBoards {
    datapaths: Lanes,
    analogs: Vec<Analog>,
    /// Each lane's register bank: the writes go to all, the z snapshot a
    /// SAMPLE_COUNT read latches is each one's.
    hosts: Vec<HostRegisters>,
    /// Each lane's z during the current cycle.
    z: Vec<(i64, i64)>,
    /// Samples published since power-up (every lane's).
    samples: u32,
    cycle: u64,
    clip: Vec<[ClipCount; 2]>,
    isa: Isa,
    /// Each lane's reads (offset, word) since its last `LaneBoards::replay`.
    reads: Vec<VecDeque<(u32, u32)>>,
}

impl LaneBoards {
    /// `lanes` boards at `at`, each built as `SimBoard::new` builds it
    /// (the clock and the phase lag's reference frequency in Hz), at
    /// power-up; the rates are set later ([`LaneBoards::set_rates`]: a
    /// table sets them after programming).
    pub fn new(
        at: &DeviceAt,
        front_end: &FrontEnd,
        noise: &ThermalNoise,
        (clock_hz, phase_reference_hz): (f64, f64),
        profile: CarrierProfile,
        lanes: usize,
    ) -> Result<Self, RunError> {
        let analog = analog_at(at, front_end, noise, clock_hz, phase_reference_hz)?;
        let datapaths = Lanes::new(GyroInterface::with_profile(profile), lanes)?;
        Ok(Self {
            datapaths,
            analogs: vec![analog; lanes],
            hosts: vec![HostRegisters::power_up(profile); lanes],
            z: vec![(0, 0); lanes],
            samples: 0,
            cycle: 0,
            clip: vec![[ClipCount::default(); 2]; lanes],
            isa: Isa::selected(),
            reads: vec![VecDeque::new(); lanes],
        })
    }

    /// Boards at `rates_dps` of `exp`'s device at `at`, each as
    /// `scenario::board_at` makes one (powered up, `DRIVE_START_CLOCKS`
    /// waited), then programmed with `regs`, its rate set and `settle`
    /// clocks waited: a table's settled boards.
    pub fn settled(
        exp: &Experiment,
        fe: &FrontEnd,
        at: &DeviceAt,
        regs: &Registers,
        rates_dps: &[f64],
        settle: u64,
    ) -> Result<Self, FieldError> {
        let reference = 0.5 * (exp.gyro.f1_hz + exp.gyro.f2_hz);
        let timing = (exp.drive.board_clock_hz(), reference);
        let profile = exp.drive.carrier_profile;
        let lanes = rates_dps.len();
        let mut boards = LaneBoards::new(at, fe, &exp.noise, timing, profile, lanes)?;
        boards.wait_clocks(DRIVE_START_CLOCKS)?;
        boards.program(regs)?;
        let rates: Vec<f64> = rates_dps.iter().map(|r| r.to_radians()).collect();
        boards.set_rates(&rates);
        boards.wait_clocks(settle)?;
        Ok(boards)
    }

    /// `read(board, lane)` on every lane: on these boards for lane 0 (the
    /// clocks and writes every lane's), then on each other lane's
    /// `LaneBoards::replay` of the reads it made.
    pub fn each_lane<T>(&mut self, mut read: impl FnMut(&mut dyn Board, usize) -> T) -> Vec<T> {
        self.forget_reads();
        let mut out = vec![read(self, 0)];
        for l in 1..self.analogs.len() {
            out.push(read(&mut self.replay(l), l));
        }
        out
    }

    /// Lane l's rotation rate (rad/s) from the next clock on: the rate
    /// table of the harness, as `SimBoard::set_rate`.
    pub fn set_rates(&mut self, rates_rad_s: &[f64]) {
        assert_eq!(rates_rad_s.len(), self.analogs.len(), "a rate per lane");
        for (analog, &rate) in self.analogs.iter_mut().zip(rates_rad_s) {
            analog.gyro.set_rate(rate);
        }
    }

    /// Clocks played since power-up, by each lane.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// Lane `lane`'s reads since its last replay, to run the host's code
    /// again as that lane's board answered it.
    fn replay(&mut self, lane: usize) -> Replay {
        Replay {
            reads: std::mem::take(&mut self.reads[lane]),
        }
    }

    /// Forgets the reads kept so far (those no replay will need).
    fn forget_reads(&mut self) {
        self.reads.iter_mut().for_each(VecDeque::clear);
    }

    /// `clocks` clocks on every lane (`SimBoard::run`).
    fn run(&mut self, clocks: u64) {
        if clocks == 0 {
            return;
        }
        let clip = &mut self.clip;
        let watch = |l: usize, adc: &[Words]| {
            clip[l][0].steps(adc.iter().map(|a| a.0));
            clip[l][1].steps(adc.iter().map(|a| a.1));
        };
        let mut analogs = analog::Lanes::watched(&mut self.analogs, watch)
            .expect("the lanes share one set of converters");
        let samples = &mut self.samples;
        let on_z = |l: usize, _, _| {
            if l == 0 {
                *samples = samples.wrapping_add(1);
            }
        };
        let regs = self.hosts[0].registers();
        self.datapaths
            .run(self.isa, regs, clocks, &mut analogs, on_z);
        for (z, lane) in self.z.iter_mut().zip(self.datapaths.lanes()) {
            *z = lane.outputs().z;
        }
        self.cycle += clocks;
    }
}

impl Board for LaneBoards {
    fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
        self.run(clocks);
        Ok(())
    }

    /// `SimBoard::next_sample`, the clocks on every lane: the edges that
    /// cannot publish in one run, the rest one at a time.
    fn next_sample(&mut self, after: u32) -> Result<gyrocal_host::board::ZSample, BusError> {
        while self.samples == after {
            let quiet = self.datapaths.lanes()[0].quiet_clocks();
            self.run(quiet.max(1));
        }
        self.read_z()
    }
}

impl RegisterAccess for LaneBoards {
    /// A write between two clocks, to every lane's bank.
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        for host in &mut self.hosts {
            host.write(offset, word)?;
        }
        Ok(())
    }

    /// A read between two clocks on every lane (`SimBoard`'s), each lane's
    /// word kept for its replay; lane 0's returned.
    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        let mut first = None;
        for l in 0..self.hosts.len() {
            let word = if offset & !3 == ADC_CLIP.offset {
                let word = clip_word(self.clip[l]);
                self.clip[l] = [ClipCount::default(); 2];
                word
            } else {
                self.hosts[l].read(offset, self.z[l], self.samples)?
            };
            self.reads[l].push_back((offset, word));
            first.get_or_insert(word);
        }
        Ok(first.expect("lanes are never empty"))
    }
}

/// One lane's reads, answered again in order (`LaneBoards::replay`):
/// the host's code run on it gets the words that lane's board gave. The
/// clocks it waits were played already; its writes were made.
pub struct Replay {
    reads: VecDeque<(u32, u32)>,
}

impl Board for Replay {
    fn wait_clocks(&mut self, _clocks: u64) -> Result<(), BusError> {
        Ok(())
    }

    fn next_sample(&mut self, _after: u32) -> Result<gyrocal_host::board::ZSample, BusError> {
        self.read_z()
    }
}

impl RegisterAccess for Replay {
    fn write_register(&mut self, _offset: u32, _word: u32) -> Result<(), BusError> {
        Ok(())
    }

    /// The next kept read; it must be of `offset` (else the code replayed
    /// is not the code that ran: a bug, never an input).
    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        let (at, word) = self
            .reads
            .pop_front()
            .expect("a replay reads what was read");
        assert_eq!(
            at, offset,
            "a replay reads the registers in the order they were read"
        );
        Ok(word)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Experiment;
    use crate::field::board::tests::readout_setting;
    use crate::field::scenario;
    use gyrocal_host::clip;
    use gyrocal_host::sampling::{Signal, part_means};

    /// Waits of odd lengths and windows read through `part_means` (quiet
    /// runs, then single clocks to each sample), then the clip counts.
    fn read_table(board: &mut dyn Board, r: u32) -> (Vec<Vec<[f64; 2]>>, Result<(), String>) {
        let mut windows = vec![];
        for wait in [0u64, 1, 255, 257, 10_000, 3] {
            board.wait_clocks(wait).unwrap();
            clip::restart(board).unwrap();
            let length = 37.5 * f64::from(r);
            windows.push(part_means(board, r, f64::from(r), length, 4, Signal::Steady).unwrap());
        }
        let clipped = clip::check(board, "a table", "here").map_err(|e| e.to_string());
        (windows, clipped)
    }

    /// A table on boards in lanes reads what it reads on a board per rate:
    /// the paper's board in readout (ADC noise on, a 3 deg pick-off lag)
    /// at three rates, the largest (30,000 deg/s, its Coriolis coupling
    /// comparable to the modes' split) so far beyond what the ADCs were
    /// sized for that an ADC clips there alone; every lane's windows and
    /// clip counts (through its replay) and clocks are its own board's.
    #[test]
    fn a_table_in_lanes_reads_what_its_own_boards_read() {
        let exp = Experiment::paper();
        let (fe, regs, at) = readout_setting(&exp, [1.0, 1.0]);
        let r = regs.cic_decimation as u32;
        let rates: Vec<f64> = [0.0, -10.0, 30000.0]
            .iter()
            .map(|r: &f64| r.to_radians())
            .collect();
        let reference = 0.5 * (exp.gyro.f1_hz + exp.gyro.f2_hz);
        let timing = (exp.drive.board_clock_hz(), reference);
        let profile = exp.drive.carrier_profile;
        let mut lanes = LaneBoards::new(&at, &fe, &exp.noise, timing, profile, 3).unwrap();
        let start = gyrocal_regs::datapath::DRIVE_START_CLOCKS;
        lanes.wait_clocks(start).unwrap();
        lanes.program(&regs).unwrap();
        lanes.set_rates(&rates);
        let read = lanes.each_lane(|board, _| read_table(board, r));
        for (l, &rate) in rates.iter().enumerate() {
            let mut board = scenario::board_at(&exp, &fe, &at).unwrap();
            board.program(&regs).unwrap();
            board.set_rate(rate);
            let own = read_table(&mut board, r);
            assert_eq!(read[l], own, "lane {l}");
            assert_eq!(lanes.cycle(), board.cycle(), "lane {l}'s clocks");
        }
        // The premises: the rates read apart, and one lane alone clipped.
        assert_ne!(read[0].0, read[1].0);
        let clipped: Vec<bool> = read.iter().map(|r| r.1.is_err()).collect();
        assert_eq!(clipped, [false, false, true], "{:?}", read[2].1);
    }
}
