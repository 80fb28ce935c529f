//! The closed loop: datapath engine, DACs, gyroscope, ADCs
//! (`crate::analog`).
//!
//! Per clock n (the gyroscope at time nT, the engine's ports during cycle n):
//!
//! ```text
//!  1. the ADCs sample x(nT); the converters return the ADC words of cycle n
//!     and the force the DACs hold over [nT, (n+1)T) (word of cycle n - L_dac);
//!  2. the engine takes the ADC words and plays the rising edge n + 1;
//!  3. the gyroscope advances to (n+1)T under the held force.
//! ```
//!
//! `CoSim::step` plays one clock so; `CoSim::run` plays many with the
//! registers held, which the model engine does in blocks (the drive half
//! ahead of the gyroscope, `gyrocal_hdl::model::gyro_interface`'s `run`):
//! the same clocks, 1.3 to 1.4 times as fast.
//!
//! The demodulation references are lined up from the converter latencies by
//! `gyrocal_hdl::settings` (ref_delay = L_dac + L_adc, ref_phase =
//! carrier_step / 2), which is derived for exactly this timing.
//!
//! The settings reach the engine through the register map of
//! `gyro_interface_axi` (`gyrocal_hdl::host::register_map`), as host
//! software would program the bus-attached top: `CoSim` keeps the slave's
//! register bank, every change is a bus write, and the engine's
//! `Registers` are decoded from the bank once per change (never per
//! clock). `CoSim` implements `RegisterAccess`, reads included: the z
//! snapshot is latched by a SAMPLE_COUNT read, as in the hardware.

use crate::analog::{self, Analog, Watched};
use crate::engine::Engine;
use crate::frontend::Converters;
use crate::gyro::GyroModel;
use gyrocal_hdl::host::register_map::{
    self, BusError, RegisterAccess, RegisterBank, SAMPLE_COUNT, STREAM_OVERFLOW, Z1_HI, Z1_LO,
    Z2_HI, Z2_LO,
};
use gyrocal_hdl::model::gyro_interface::{
    CarrierProfile, GyroInterface, Outputs, Registers, Words,
};
use gyrocal_hdl::model::isa::Isa;
use gyrocal_hdl::model::lanes::{Lanes, NoLane};

/// Engine, converters and gyroscope in a loop.
pub struct CoSim<E: Engine> {
    engine: E,
    analog: Analog,
    host: HostRegisters,
    outputs: Outputs,
    adc: (i16, i16),
    cycle: u64,
    samples: u32,
}

impl<E: Engine> CoSim<E> {
    /// A loop at power-up with the gyroscope at rest, the engine's core
    /// of carrier profile `profile` (PROFILE reads it).
    /// The registers are programmed through the register map.
    pub fn new(
        engine: E,
        profile: CarrierProfile,
        converters: Converters,
        gyro: GyroModel,
        regs: Registers,
    ) -> Self {
        let mut sim = Self {
            engine,
            analog: Analog::new(converters, gyro, None),
            host: HostRegisters::power_up(profile),
            outputs: Outputs::default(),
            adc: (0, 0),
            cycle: 0,
            samples: 0,
        };
        sim.set_registers(regs);
        sim
    }

    /// One clock; returns the engine's ports after the edge.
    #[inline(always)]
    pub fn step(&mut self) -> Outputs {
        self.adc = self.analog.step(self.outputs.dac);
        self.outputs = self.engine.step(self.adc, self.host.registers());
        self.cycle += 1;
        self.samples = self.samples.wrapping_add(self.outputs.z_valid as u32);
        self.outputs
    }

    /// `clocks` clocks with the registers and the rate held, in the
    /// engine's blocks (`Engine::run`): the same clocks as `step` that
    /// many times. `on_z(cycle, z)` gets each z the engine publishes, with
    /// the cycle `step` would have returned it at.
    #[inline(always)]
    pub fn run(&mut self, clocks: u64, mut on_z: impl FnMut(u64, (i64, i64))) {
        if clocks == 0 {
            return;
        }
        let mut last_adc = self.adc;
        let mut analog = Watched {
            analog: &mut self.analog,
            watch: |adc: &[Words]| last_adc = adc[adc.len() - 1],
        };
        let first = self.cycle + 1;
        let mut samples = self.samples;
        self.outputs = self.engine.run(
            self.outputs.dac,
            self.host.registers(),
            clocks,
            &mut analog,
            |i, z| {
                samples = samples.wrapping_add(1);
                on_z(first + i, z);
            },
        );
        self.samples = samples;
        self.adc = last_adc;
        self.cycle += clocks;
    }

    /// The ADC words the last clock's edge captured.
    pub fn last_adc(&self) -> (i16, i16) {
        self.adc
    }

    /// Clocks played so far.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// Change the registers from the next clock on, through the bus
    /// writes of the register map.
    pub fn set_registers(&mut self, regs: Registers) {
        register_map::program(self, &regs).expect("the register map's own writes are accepted");
    }

    /// The settings the engine sees (decoded from the register bank).
    pub fn registers(&self) -> &Registers {
        self.host.registers()
    }

    /// Change the rotation rate (rad/s) from the next clock on.
    pub fn set_rate(&mut self, omz_rad_s: f64) {
        self.analog.gyro.set_rate(omz_rad_s);
    }

    /// The engine (for internal signals).
    pub fn engine(&self) -> &E {
        &self.engine
    }

    /// The engine, to set it up (`ModelEngine::set_isa`).
    pub fn engine_mut(&mut self) -> &mut E {
        &mut self.engine
    }

    /// The gyroscope.
    pub fn gyro(&self) -> &GyroModel {
        &self.analog.gyro
    }
}

/// Co-simulations in lanes on the model engine
/// (`gyrocal_hdl::model::lanes`, `crate::analog::Lanes`): one datapath
/// from power-up, one set of registers and converters, and a gyroscope per
/// lane (one device at several rates: a readout sweep's points). Each
/// lane plays the clocks a `CoSim` of its own gyroscope plays, bit for
/// bit, where the drive half, the DAC forces and the ADC noise are worked
/// out once for all.
pub struct CoSimLanes {
    datapaths: Lanes,
    analogs: Vec<Analog>,
    host: HostRegisters,
    isa: Isa,
    cycle: u64,
}

impl CoSimLanes {
    /// A lane per gyroscope, each with `converters` and the datapath
    /// `CoSim::new` makes, programmed with `regs`; or why not (none).
    pub fn new(
        profile: CarrierProfile,
        converters: Converters,
        gyros: Vec<GyroModel>,
        regs: Registers,
    ) -> Result<Self, NoLane> {
        let datapaths = Lanes::new(GyroInterface::with_profile(profile), gyros.len())?;
        let analogs = gyros
            .into_iter()
            .map(|gyro| Analog::new(converters.clone(), gyro, None))
            .collect();
        let mut host = HostRegisters::power_up(profile);
        for (offset, word) in register_map::encode(&regs) {
            host.write(offset, word)
                .expect("the register map's own writes are accepted");
        }
        Ok(Self {
            datapaths,
            analogs,
            host,
            isa: Isa::selected(),
            cycle: 0,
        })
    }

    /// `CoSim::run` on every lane: `on_z(l, n, z)` when lane `l`'s clock
    /// `n` (numbered as `CoSim` numbers them) publishes z.
    pub fn run(&mut self, clocks: u64, mut on_z: impl FnMut(usize, u64, (i64, i64))) {
        if clocks == 0 {
            return;
        }
        let mut analogs =
            analog::Lanes::new(&mut self.analogs).expect("the lanes share one set of converters");
        let first = self.cycle + 1;
        let regs = self.host.registers();
        self.datapaths
            .run(self.isa, regs, clocks, &mut analogs, |l, i, z| {
                on_z(l, first + i, z)
            });
        self.cycle += clocks;
    }

    /// Clocks played since power-up.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// Lane `lane`'s gyroscope.
    pub fn gyro(&self, lane: usize) -> &GyroModel {
        &self.analogs[lane].gyro
    }

    /// Sets the instruction set the lanes run on (`ModelEngine::set_isa`).
    pub fn set_isa(&mut self, isa: Isa) {
        self.isa = isa;
    }
}

impl<E: Engine> RegisterAccess for CoSim<E> {
    /// A write between two clocks: acts from the next clock on.
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        self.host.write(offset, word)
    }

    /// A read between two clocks. STREAM_OVERFLOW is 0: the co-simulation
    /// has no stream.
    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        self.host.read(offset, self.outputs.z, self.samples)
    }
}

/// The slave's registers as host software sees them between two clocks:
/// the register bank, the settings decoded from it (once per write, never
/// per clock) and the z snapshot a SAMPLE_COUNT read latches. What the
/// co-simulation and a simulated board (`crate::field::board`) share.
#[derive(Clone, Copy, Debug)]
pub struct HostRegisters {
    bank: RegisterBank,
    regs: Registers,
    snapshot: (i64, i64),
}

impl HostRegisters {
    /// Every register at its power-up value, in the core with this
    /// carrier profile.
    pub fn power_up(profile: CarrierProfile) -> Self {
        let bank = RegisterBank::power_up_for(profile);
        Self {
            bank,
            regs: bank.registers(),
            snapshot: (0, 0),
        }
    }

    /// The settings the engine sees.
    #[inline(always)]
    pub fn registers(&self) -> &Registers {
        &self.regs
    }

    /// A bus write of a whole word.
    pub fn write(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        self.bank.write(offset, word, 0xf)?;
        self.regs = self.bank.registers();
        Ok(())
    }

    /// A bus read with the engine's z now and its sample count: SAMPLE_COUNT
    /// latches z, the z words read the latched pair, STREAM_OVERFLOW is 0
    /// (no stream consumer), settings come from the bank.
    pub fn read(&mut self, offset: u32, z_now: (i64, i64), samples: u32) -> Result<u32, BusError> {
        let reg = register_map::lookup(offset).ok_or(BusError::Unmapped)?;
        let z = |v: i64, high: bool| if high { (v >> 32) as u32 } else { v as u32 };
        let (z1, z2) = self.snapshot;
        let live = match reg.offset {
            o if o == SAMPLE_COUNT.offset => {
                self.snapshot = z_now;
                samples
            }
            o if o == STREAM_OVERFLOW.offset => 0,
            o if o == Z1_LO.offset => z(z1, false),
            o if o == Z1_HI.offset => z(z1, true),
            o if o == Z2_LO.offset => z(z2, false),
            o if o == Z2_HI.offset => z(z2, true),
            _ => return self.bank.read(offset),
        };
        Ok(reg.extend(live))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::ModelEngine;
    use crate::experiment::{Experiment, plan, point_loop};
    use crate::frontend::Converters;
    use crate::gyro::GyroModel;
    use gyrocal_hdl::host::register_map::{CIC_DECIMATION, ID, ID_WORD};
    use gyrocal_hdl::model::isa::Isa;

    #[test]
    fn the_engine_is_programmed_through_the_register_map() {
        let exp = Experiment::paper();
        let plan = plan(&exp).unwrap();
        let point = &plan.points[0];
        let mut sim = point_loop::<ModelEngine>(&exp, &plan, point).unwrap();
        assert_eq!(*sim.registers(), point.regs.at_ports());
        assert_eq!(sim.read_register(ID.offset), Ok(ID_WORD));
        assert_eq!(
            sim.read_register(CIC_DECIMATION.offset),
            Ok(u32::from(point.regs.cic_decimation))
        );
        assert_eq!(sim.write_register(0xfc, 1), Err(BusError::Unmapped));
        assert_eq!(sim.write_register(ID.offset, 1), Err(BusError::ReadOnly));
    }

    #[test]
    fn the_snapshot_holds_the_sample_the_count_names() {
        let exp = Experiment::paper();
        let plan = plan(&exp).unwrap();
        let mut sim = point_loop::<ModelEngine>(&exp, &plan, &plan.points[0]).unwrap();
        let r = u64::from(sim.registers().cic_decimation);
        let mut last_z = (0, 0);
        for _ in 0..40 * r {
            let o = sim.step();
            if o.z_valid {
                last_z = o.z;
            }
        }
        let count = sim.read_register(SAMPLE_COUNT.offset).unwrap();
        assert!(count >= 39, "{count} samples in 40 R clocks");
        for _ in 0..3 * r {
            sim.step();
        }
        let word = |sim: &mut CoSim<ModelEngine>,
                    lo: &register_map::Register,
                    hi: &register_map::Register| {
            let (lo, hi) = (
                sim.read_register(lo.offset).unwrap(),
                sim.read_register(hi.offset).unwrap(),
            );
            (i64::from(hi as i32) << 32) | i64::from(lo)
        };
        assert_eq!(
            (
                word(&mut sim, &Z1_LO, &Z1_HI),
                word(&mut sim, &Z2_LO, &Z2_HI)
            ),
            last_z
        );
        assert_ne!(
            last_z, sim.outputs.z,
            "z moved on after the snapshot (else the test proves nothing)"
        );
    }

    /// `run` plays the clocks `step` plays: on a calibration and a
    /// readout point at a rate (ADC noise on), runs of lengths around the
    /// engine's block give every z at the cycle `step` gives it, and leave
    /// the same ports, ADC words, sample count and gyroscope state; with
    /// the run compiled for every instruction set this processor runs
    /// (the gyroscope's float products among what it compiles), while
    /// `step` stays portable.
    #[test]
    fn a_run_is_the_steps_it_replaces() {
        let exp = Experiment::paper();
        let plan = plan(&exp).unwrap();
        use crate::experiment::Mode;
        let modes = [Mode::Calibration, Mode::Readout];
        let isas = Isa::supported_all();
        for (mode, &isa) in modes.iter().flat_map(|m| isas.iter().map(move |i| (m, i))) {
            let point = plan.points.iter().find(|p| p.mode == *mode).unwrap();
            let mut blocked = point_loop::<ModelEngine>(&exp, &plan, point).unwrap();
            blocked.engine_mut().set_isa(isa);
            assert_eq!(blocked.engine().isa(), isa);
            let mut stepped = point_loop::<ModelEngine>(&exp, &plan, point).unwrap();
            for sim in [&mut blocked, &mut stepped] {
                sim.set_rate(0.3);
            }
            for clocks in [1u64, 255, 256, 257, 100_000, 7, 30_001] {
                let mut z_blocked = vec![];
                blocked.run(clocks, |n, z| z_blocked.push((n, z)));
                let mut z_stepped = vec![];
                for _ in 0..clocks {
                    let o = stepped.step();
                    if o.z_valid {
                        z_stepped.push((stepped.cycle(), o.z));
                    }
                }
                assert_eq!(z_blocked, z_stepped, "{mode:?} ({isa}), {clocks} clocks");
                assert_eq!(blocked.outputs, stepped.outputs);
                assert_eq!(blocked.last_adc(), stepped.last_adc());
                assert_eq!(blocked.samples, stepped.samples);
                assert_eq!(blocked.cycle(), stepped.cycle());
                assert_eq!(blocked.gyro().state(), stepped.gyro().state(), "{isa}");
            }
            assert!(
                blocked.samples > 10,
                "{mode:?}: {} samples",
                blocked.samples
            );
        }
    }

    /// Lanes play what each point's `CoSim` plays alone: six rates on a
    /// calibration and a readout point (ADC noise on, so the lanes' shared
    /// draws must be each one's own; the lanes after the first abreast two
    /// by two, one pair coupled and uncoupled, the last alone), runs of lengths around a block's,
    /// compiled for every instruction set this processor runs; every z at
    /// the same cycle and the same gyroscope state after each run. The
    /// rates' z differ (else the lanes could be mixed up unseen).
    #[test]
    fn lanes_play_what_each_cosim_plays_alone() {
        let exp = Experiment::paper();
        let plan = plan(&exp).unwrap();
        use crate::experiment::Mode;
        let rates = [0.3, -0.1, 0.05, 0.0, 0.2, -0.4];
        for (mode, isa) in [Mode::Calibration, Mode::Readout]
            .into_iter()
            .flat_map(|m| Isa::supported_all().into_iter().map(move |i| (m, i)))
        {
            let point = plan.points.iter().find(|p| p.mode == mode).unwrap();
            let gyros = rates.map(|r| {
                let mut gyro = GyroModel::new(&exp.gyro, exp.drive.clock_hz).unwrap();
                gyro.set_rate(r);
                gyro
            });
            let converters = Converters::new(&plan.front_end).unwrap();
            let profile = exp.drive.carrier_profile;
            let mut lanes =
                CoSimLanes::new(profile, converters, gyros.to_vec(), point.regs).unwrap();
            lanes.set_isa(isa);
            let mut alone: Vec<CoSim<ModelEngine>> = rates
                .iter()
                .map(|&r| {
                    let mut sim = point_loop::<ModelEngine>(&exp, &plan, point).unwrap();
                    sim.set_rate(r);
                    sim.engine_mut().set_isa(isa);
                    sim
                })
                .collect();
            let mut last = vec![vec![]; rates.len()];
            for clocks in [1u64, 255, 257, 100_000, 7, 60_001] {
                let mut z_lanes = vec![vec![]; rates.len()];
                lanes.run(clocks, |l, n, z| z_lanes[l].push((n, z)));
                for (l, sim) in alone.iter_mut().enumerate() {
                    let mut z = vec![];
                    sim.run(clocks, |n, v| z.push((n, v)));
                    assert_eq!(z_lanes[l], z, "{mode:?} ({isa}), lane {l}, {clocks} clocks");
                    assert_eq!(
                        lanes.gyro(l).state(),
                        sim.gyro().state(),
                        "{mode:?} ({isa})"
                    );
                    assert_eq!(lanes.cycle(), sim.cycle());
                    last[l] = z;
                }
            }
            assert!(last[0].len() > 10, "{mode:?}: {} z", last[0].len());
            assert_ne!(last[0], last[1], "{mode:?}: two rates read the same z");
        }
    }
}
