//! The closed loop: datapath engine, DACs, gyroscope, ADCs, one clock at a
//! time.
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
//! The demodulation references are lined up from the converter latencies by
//! `gyrocal_hdl::settings` (ref_delay = L_dac + L_adc, ref_phase =
//! carrier_step / 2), which is derived for exactly this timing.

use crate::engine::Engine;
use crate::frontend::Converters;
use crate::gyro::GyroModel;
use gyrocal_hdl::model::gyro_interface::{Outputs, Registers};

/// Engine, converters and gyroscope in a loop.
pub struct CoSim<E: Engine> {
    engine: E,
    converters: Converters,
    gyro: GyroModel,
    regs: Registers,
    outputs: Outputs,
    adc: (i16, i16),
    cycle: u64,
}

impl<E: Engine> CoSim<E> {
    /// A loop at power-up with the gyroscope at rest.
    pub fn new(engine: E, converters: Converters, gyro: GyroModel, regs: Registers) -> Self {
        Self {
            engine,
            converters,
            gyro,
            regs,
            outputs: Outputs::default(),
            adc: (0, 0),
            cycle: 0,
        }
    }

    /// One clock; returns the engine's ports after the edge.
    #[inline(always)]
    pub fn step(&mut self) -> Outputs {
        let (adc, force) = self
            .converters
            .step(self.outputs.dac, (self.gyro.x1(), self.gyro.x2()));
        self.adc = adc;
        self.outputs = self.engine.step(adc, &self.regs);
        self.gyro.step(force.0, force.1);
        self.cycle += 1;
        self.outputs
    }

    /// The ADC words the last clock's edge captured.
    pub fn last_adc(&self) -> (i16, i16) {
        self.adc
    }

    /// Clocks played so far.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// Change the registers from the next clock on.
    pub fn set_registers(&mut self, regs: Registers) {
        self.regs = regs;
    }

    /// Change the rotation rate (rad/s) from the next clock on.
    pub fn set_rate(&mut self, omz_rad_s: f64) {
        self.gyro.set_rate(omz_rad_s);
    }

    /// The engine (for internal signals).
    pub fn engine(&self) -> &E {
        &self.engine
    }

    /// The gyroscope.
    pub fn gyro(&self) -> &GyroModel {
        &self.gyro
    }
}
