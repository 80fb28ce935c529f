//! The three simulators of one datapath, behind one interface.
//!
//! - `model`: the bit-true, cycle-true plain-Rust model
//!   (`gyrocal_hdl::model`), the default: fast, no system dependency.
//! - `rtl`: rust-hdl's own simulation of the design, driven directly. Slow
//!   (thousands of clocks per second) but it is the design itself.
//! - `verilator`: the exported Verilog compiled by Verilator and stepped
//!   through a small C ABI wrapper (cargo feature `verilator`).
//!
//! All three give identical outputs on every cycle (tests prove it), so an
//! experiment's results do not depend on the engine, only its speed does.

use crate::error::EngineError;
use gyrocal_hdl::model::gyro_interface::{
    AnalogSide, CarrierProfile, GyroInterface, Outputs, Probes, Registers, Words,
};
use gyrocal_hdl::model::isa::Isa;
use gyrocal_hdl::rtl::RtlGyroInterface;

/// One clock at a time: inputs during a cycle in, outputs after the edge out.
pub trait Engine {
    /// A fresh instance of the core with this carrier profile at its
    /// power-up state.
    fn power_up(profile: CarrierProfile) -> Result<Self, EngineError>
    where
        Self: Sized;
    /// One rising edge with these inputs; returns the ports after it.
    fn step(&mut self, adc: (i16, i16), regs: &Registers) -> Outputs;
    /// Internal signals during the current cycle (for waveforms).
    fn probes(&self) -> Probes;

    /// Edges from now none of which can publish z with the registers held
    /// (a lower bound, 0 when unknown): a loop may play them in one
    /// `run` while it waits for the next sample.
    fn quiet_clocks(&self) -> u64 {
        0
    }

    /// `clocks` rising edges with the registers held, in a loop closed by
    /// `analog` (the converters and the gyroscope); `dac` are the DAC
    /// words during the first cycle. `on_z(i, z)` is called when edge `i`
    /// (from 0) publishes z. Returns the ports after the last edge
    /// (`clocks` > 0). Clock by clock here; the model engine plays it in
    /// blocks (`GyroInterface::run`).
    #[inline(always)]
    fn run<A, Z>(
        &mut self,
        mut dac: Words,
        regs: &Registers,
        clocks: u64,
        analog: &mut A,
        mut on_z: Z,
    ) -> Outputs
    where
        A: AnalogSide,
        Z: FnMut(u64, (i64, i64)),
        Self: Sized,
    {
        assert!(clocks > 0, "Engine::run: no clock to play");
        let mut out = Outputs::default();
        for i in 0..clocks {
            let mut adc = [(0, 0)];
            analog.advance(dac);
            analog.convert(&mut adc);
            out = self.step(adc[0], regs);
            dac = out.dac;
            if out.z_valid {
                on_z(i, out.z);
            }
        }
        out
    }
}

/// Which simulator runs the datapath.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EngineKind {
    /// Bit-true plain-Rust model (default).
    #[default]
    Model,
    /// rust-hdl's simulation of the design.
    Rtl,
    /// The exported Verilog through Verilator.
    Verilator,
}

impl EngineKind {
    /// All engines, in speed order.
    pub const ALL: [EngineKind; 3] = [EngineKind::Model, EngineKind::Verilator, EngineKind::Rtl];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            EngineKind::Model => "model",
            EngineKind::Rtl => "rtl",
            EngineKind::Verilator => "verilator",
        }
    }

    /// Parse a command-line name.
    pub fn parse(name: &str) -> Result<Self, EngineError> {
        match name {
            "model" => Ok(EngineKind::Model),
            "rtl" => Ok(EngineKind::Rtl),
            "verilator" => Ok(EngineKind::Verilator),
            _ => Err(EngineError::Unknown(name.into())),
        }
    }
}

/// The bit-true model engine.
#[derive(Clone, Debug)]
pub struct ModelEngine {
    datapath: GyroInterface,
    /// What its runs are compiled for (`Isa::selected` at power-up).
    isa: Isa,
}

impl ModelEngine {
    /// Runs compiled for `isa` from now on (the portable build if this
    /// processor lacks it): the same results, at another speed.
    pub fn set_isa(&mut self, isa: Isa) {
        self.isa = isa;
    }

    /// What its runs are compiled for.
    pub fn isa(&self) -> Isa {
        self.isa
    }
}

impl Engine for ModelEngine {
    fn power_up(profile: CarrierProfile) -> Result<Self, EngineError> {
        Ok(Self {
            datapath: GyroInterface::with_profile(profile),
            isa: Isa::selected(),
        })
    }

    #[inline(always)]
    fn step(&mut self, adc: (i16, i16), regs: &Registers) -> Outputs {
        self.datapath.step(adc, regs)
    }

    fn probes(&self) -> Probes {
        self.datapath.probes()
    }

    fn quiet_clocks(&self) -> u64 {
        self.datapath.quiet_clocks()
    }

    #[inline(always)]
    fn run<A, Z>(
        &mut self,
        _dac: Words,
        regs: &Registers,
        clocks: u64,
        analog: &mut A,
        on_z: Z,
    ) -> Outputs
    where
        A: AnalogSide,
        Z: FnMut(u64, (i64, i64)),
    {
        assert!(clocks > 0, "Engine::run: no clock to play");
        self.datapath.run_on(self.isa, regs, clocks, analog, on_z)
    }
}

/// rust-hdl's simulation of `GyroInterface`.
pub struct RtlEngine(RtlGyroInterface);

impl Engine for RtlEngine {
    fn power_up(profile: CarrierProfile) -> Result<Self, EngineError> {
        Ok(Self(RtlGyroInterface::with_profile(profile)))
    }

    fn step(&mut self, adc: (i16, i16), regs: &Registers) -> Outputs {
        self.0.step(adc, regs)
    }

    fn probes(&self) -> Probes {
        self.0.probes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_and_a_wrong_one_is_named_with_the_allowed() {
        for kind in EngineKind::ALL {
            assert_eq!(EngineKind::parse(kind.name()), Ok(kind));
        }
        let e = EngineKind::parse("fast").unwrap_err();
        assert_eq!(e, EngineError::Unknown("fast".into()));
        assert_eq!(
            e.to_string(),
            "engine \"fast\": allowed model, verilator, rtl"
        );
    }
}
