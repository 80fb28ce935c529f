//! The simulated board: a datapath engine (the bit-true model by default),
//! the converters and the gyroscope at one temperature behind the register
//! map, as host code (`gyrocal_host`, through its [`Board`] trait) sees a
//! real one.
//!
//! [`SimBoard`] closes the loop of an engine over the gyroscope at
//! one temperature ([`crate::drift::DeviceAt`]): drive gains scale the DAC
//! forces, ADC gains the pick-offs, and an unmodelled phase lag
//! ([`crate::frontend::PickoffPhase`]) sits before both ADCs. Per clock,
//! as in [`crate::cosim`]: the ADCs sample, the engine plays an edge, the
//! gyroscope advances under the held force. Register writes act from the
//! next clock on; the settings are decoded from the bank once per write.
//!
//! The rotation rate is not a register: [`SimBoard::set_rate`] is the rate
//! table of the simulation harness, which host code (that sees a
//! `&mut dyn Board`) cannot reach.

use crate::cosim::HostRegisters;
use crate::drift::DeviceAt;
use crate::engine::{Engine, ModelEngine};
use crate::frontend::{Converters, FrontEnd, PickoffPhase};
use crate::gyro::GyroModel;
use crate::noise::ThermalNoise;
use gyrocal_hdl::host::clip_counter::{ClipCount, clip_word};
use gyrocal_hdl::model::gyro_interface::{CarrierProfile, Outputs};
pub use gyrocal_host::board::{Board, ZSample};
use gyrocal_regs::map::{ADC_CLIP, BusError, RegisterAccess};

/// An engine (`E`: the model engine unless asked otherwise, e.g.
/// `crate::verilator::VerilatorEngine`), converters and gyroscope behind
/// the register map.
pub struct SimBoard<E: Engine = ModelEngine> {
    engine: E,
    converters: Converters,
    gyro: GyroModel,
    phase: Option<PickoffPhase>,
    host: HostRegisters,
    outputs: Outputs,
    samples: u32,
    cycle: u64,
    clip: [ClipCount; 2],
}

impl<E: Engine> SimBoard<E> {
    /// A board at power-up with the device and front end of `at`:
    /// `front_end` holds the converters as built (gains at T0), which
    /// `at`'s drive and ADC multipliers scale; the front-end phase lag is
    /// exact at `phase_reference_hz`; `noise` is the Brownian force noise.
    pub fn new(
        at: &DeviceAt,
        front_end: &FrontEnd,
        noise: &ThermalNoise,
        clock_hz: f64,
        phase_reference_hz: f64,
        profile: CarrierProfile,
    ) -> Result<Self, String> {
        let mut fe = front_end.clone();
        for k in 0..2 {
            fe.force_per_lsb[k] *= at.drive_gain[k];
            fe.adc_per_meter[k] *= at.adc_gain[k];
        }
        let p = at.front_end_phase_deg;
        let phase = if p == 0.0 {
            None
        } else {
            Some(PickoffPhase::new(p, phase_reference_hz)?)
        };
        Ok(Self {
            engine: E::power_up(profile)?,
            converters: Converters::new(&fe)?,
            gyro: GyroModel::new(&at.gyro, clock_hz)?.with_thermal_noise(noise)?,
            phase,
            host: HostRegisters::power_up(),
            outputs: Outputs::default(),
            samples: 0,
            cycle: 0,
            clip: [ClipCount::default(); 2],
        })
    }

    /// The rate table: rotation rate (rad/s) from the next clock on.
    pub fn set_rate(&mut self, omz_rad_s: f64) {
        self.gyro.set_rate(omz_rad_s);
    }

    /// Clocks played since power-up.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    #[inline(always)]
    fn step(&mut self) {
        let x = match &self.phase {
            None => (self.gyro.x1(), self.gyro.x2()),
            Some(p) => {
                let s = self.gyro.state();
                (p.apply(s[0], s[1]), p.apply(s[2], s[3]))
            }
        };
        let (adc, force) = self.converters.step(self.outputs.dac, x);
        self.clip[0].step(adc.0, false);
        self.clip[1].step(adc.1, false);
        self.outputs = self.engine.step(adc, self.host.registers());
        self.gyro.step(force.0, force.1);
        self.samples = self.samples.wrapping_add(self.outputs.z_valid as u32);
        self.cycle += 1;
    }
}

impl<E: Engine> Board for SimBoard<E> {
    fn wait_clocks(&mut self, clocks: u64) -> Result<(), BusError> {
        for _ in 0..clocks {
            self.step();
        }
        Ok(())
    }

    /// Steps the clock until the count moves past `after` (at most R
    /// clocks when `after` is the current count), then reads the snapshot.
    fn next_sample(&mut self, after: u32) -> Result<ZSample, BusError> {
        while self.samples == after {
            self.step();
        }
        self.read_z()
    }
}

impl<E: Engine> RegisterAccess for SimBoard<E> {
    /// A write between two clocks: acts from the next clock on.
    fn write_register(&mut self, offset: u32, word: u32) -> Result<(), BusError> {
        self.host.write(offset, word)
    }

    /// A read between two clocks; SAMPLE_COUNT latches z, ADC_CLIP returns
    /// the over-range counts and restarts them. STREAM_OVERFLOW is 0: the
    /// board has no stream consumer.
    fn read_register(&mut self, offset: u32) -> Result<u32, BusError> {
        if offset & !3 == ADC_CLIP.offset {
            let word = clip_word(self.clip);
            self.clip = [ClipCount::default(); 2];
            return Ok(word);
        }
        self.host.read(offset, self.outputs.z, self.samples)
    }
}
