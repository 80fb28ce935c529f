//! The `verilator` engine: verilog-out/gyro_interface.v (the table core)
//! or verilog-out/ecp5/gyro_interface.v (the fine core, `[drive]
//! carrier_profile = "fine"`) compiled by Verilator (see build.rs) and
//! stepped one clock per call through the C ABI of `verilator/wrapper.cpp`,
//! compiled once per core.

use crate::engine::Engine;
use crate::error::EngineError;
use gyrocal_hdl::model::gyro_interface::{CarrierProfile, Outputs, Probes, Registers};

#[repr(C)]
struct CRegisters {
    carrier_step: u32,
    ref_phase: u32,
    mod_step: u64,
    iir_k0: i32,
    iir_k1: i32,
    iir_k2: i32,
    iir_alpha: i32,
    amp1: i16,
    amp2: i16,
    cic_decimation: u16,
    select: u8,
    ref_delay: u8,
    cic_shift: u8,
}

#[repr(C)]
#[derive(Default)]
struct COutputs {
    z1: i64,
    z2: i64,
    dac1: i16,
    dac2: i16,
    z_valid: u8,
}

#[repr(C)]
#[derive(Default)]
struct CProbes {
    cic1: i64,
    cic2: i64,
    w1: i32,
    w2: i32,
    ref1: i16,
    ref2: i16,
    am1: i16,
    am2: i16,
    cic_valid: u8,
}

#[repr(C)]
struct CModel {
    _private: [u8; 0],
}

/// Declares one core's C functions (`wrapper.cpp` compiled with its
/// prefix) and the table of them the engine calls through.
macro_rules! core_api {
    ($api:ident, $new:ident, $free:ident, $set:ident, $step:ident, $probes:ident) => {
        unsafe extern "C" {
            fn $new() -> *mut CModel;
            fn $free(model: *mut CModel);
            fn $set(model: *mut CModel, regs: *const CRegisters);
            fn $step(model: *mut CModel, adc1: i16, adc2: i16, out: *mut COutputs);
            fn $probes(model: *const CModel, probes: *mut CProbes);
        }

        static $api: Api = Api {
            new: $new,
            free: $free,
            set_registers: $set,
            step: $step,
            probes: $probes,
        };
    };
}

/// One Verilated core's functions.
struct Api {
    new: unsafe extern "C" fn() -> *mut CModel,
    free: unsafe extern "C" fn(*mut CModel),
    set_registers: unsafe extern "C" fn(*mut CModel, *const CRegisters),
    step: unsafe extern "C" fn(*mut CModel, i16, i16, *mut COutputs),
    probes: unsafe extern "C" fn(*const CModel, *mut CProbes),
}

core_api!(
    TABLE,
    gyrocal_verilator_new,
    gyrocal_verilator_free,
    gyrocal_verilator_set_registers,
    gyrocal_verilator_step,
    gyrocal_verilator_probes
);
core_api!(
    FINE,
    gyrocal_verilator_fine_new,
    gyrocal_verilator_fine_free,
    gyrocal_verilator_fine_set_registers,
    gyrocal_verilator_fine_step,
    gyrocal_verilator_fine_probes
);

/// The Verilated `gyro_interface` of one core, one instance per engine.
pub struct VerilatorEngine {
    model: *mut CModel,
    api: &'static Api,
    applied: Option<Registers>,
}

// The model is owned by this engine alone and used from one thread at a time.
unsafe impl Send for VerilatorEngine {}

impl Drop for VerilatorEngine {
    fn drop(&mut self) {
        // SAFETY: `model` came from gyrocal_verilator_new and is freed once.
        unsafe { (self.api.free)(self.model) }
    }
}

impl Engine for VerilatorEngine {
    fn power_up(profile: CarrierProfile) -> Result<Self, EngineError> {
        let api = match profile {
            CarrierProfile::Table => &TABLE,
            CarrierProfile::Fine => &FINE,
        };
        // SAFETY: plain constructor; null means allocation failed.
        let model = unsafe { (api.new)() };
        if model.is_null() {
            return Err(EngineError::NotCreated);
        }
        Ok(Self {
            model,
            api,
            applied: None,
        })
    }

    #[inline]
    fn step(&mut self, adc: (i16, i16), regs: &Registers) -> Outputs {
        if self.applied.as_ref() != Some(regs) {
            let c = CRegisters {
                carrier_step: regs.carrier_step,
                ref_phase: regs.ref_phase,
                mod_step: regs.mod_step,
                iir_k0: regs.iir.k0,
                iir_k1: regs.iir.k1,
                iir_k2: regs.iir.k2,
                iir_alpha: regs.iir.alpha,
                amp1: regs.amp.0,
                amp2: regs.amp.1,
                cic_decimation: regs.cic_decimation,
                select: regs.select as u8,
                ref_delay: regs.ref_delay,
                cic_shift: regs.cic_shift,
            };
            // SAFETY: valid model pointer and a live struct.
            unsafe { (self.api.set_registers)(self.model, &c) };
            self.applied = Some(*regs);
        }
        let mut out = COutputs::default();
        // SAFETY: valid model pointer and a live output struct.
        unsafe { (self.api.step)(self.model, adc.0, adc.1, &mut out) };
        Outputs {
            dac: (out.dac1, out.dac2),
            z: (out.z1, out.z2),
            z_valid: out.z_valid != 0,
        }
    }

    fn probes(&self) -> Probes {
        let mut p = CProbes::default();
        // SAFETY: valid model pointer and a live output struct.
        unsafe { (self.api.probes)(self.model, &mut p) };
        Probes {
            reference: (p.ref1, p.ref2),
            w: (p.w1, p.w2),
            cic: (p.cic1, p.cic2),
            cic_valid: p.cic_valid != 0,
            am: (p.am1, p.am2),
        }
    }
}
