//! The inputs of the cocotb bus tests (tests/axi/test_gyro_axi.py) that come
//! from the Rust model: the bus writes of a working frequency plan
//! (`GYRO_PROGRAM`) and golden vectors of the bit-true bus model
//! (`GYRO_VECTORS`). Shared by tests/axi_bus.rs and tests/fusesoc.rs.

#![allow(dead_code)] // reason: each test crate uses part of this module

use gyrocal_hdl::host::model::{BusInputs, BusOutputs, GyroInterfaceAxi};
use gyrocal_hdl::host::register_map;
use gyrocal_hdl::host::traffic::{Bias, traffic};
use gyrocal_hdl::model::gyro_interface::CarrierProfile;
use gyrocal_hdl::settings::{FrequencyPlan, registers};
use std::path::Path;

/// Cycles of golden vectors replayed in each simulator.
pub const REPLAY_CYCLES: usize = 3_000;

/// Bus writes for a working plan (the least decimation), from the register map.
pub fn program() -> String {
    let plan = FrequencyPlan {
        clock_hz: 10e6,
        carrier_hz: 1.0123e6,
        cal_hz: 5e3,
        calibration: false,
        amplitude: (0.9, -0.7),
        decimation: gyrocal_hdl::filter_design::MIN_DECIMATION,
        butterworth_hz: 5e3,
        rc_hz: 10e3,
        dac_latency: 1,
        adc_latency: 2,
    };
    let (regs, _) = registers(&plan).unwrap();
    register_map::encode(&regs)
        .iter()
        .map(|(offset, word)| format!("0x{offset:02x} 0x{word:08x}\n"))
        .collect()
}

fn input_line(i: &BusInputs) -> String {
    format!(
        "{:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x}",
        i.aresetn as u8,
        i.adc.0 as u16,
        i.adc.1 as u16,
        i.awvalid as u8,
        i.awaddr,
        i.wvalid as u8,
        i.wdata,
        i.wstrb & 0xf,
        i.bready as u8,
        i.arvalid as u8,
        i.araddr,
        i.rready as u8,
        i.tready as u8
    )
}

fn output_line(o: &BusOutputs) -> String {
    format!(
        "{:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x} {:x}",
        o.dac.0 as u16,
        o.dac.1 as u16,
        o.awready as u8,
        o.wready as u8,
        o.bvalid as u8,
        o.bresp,
        o.arready as u8,
        o.rvalid as u8,
        o.rdata,
        o.rresp,
        o.tvalid as u8,
        o.tdata,
        o.tlast as u8
    )
}

/// Line n: the inputs of cycle n | the outputs before edge n + 1 (line 0:
/// power-up outputs), as the model computes them.
pub fn golden_vectors(profile: CarrierProfile) -> String {
    let inputs = traffic(
        0x00a1_0b05,
        Bias {
            valid: 60,
            ready: 60,
            tready: 50,
        },
        REPLAY_CYCLES,
    );
    let mut model = GyroInterfaceAxi::with_profile(profile);
    let mut text = String::new();
    let mut before = model.outputs();
    for i in &inputs {
        text.push_str(&format!("{} | {}\n", input_line(i), output_line(&before)));
        before = model.step(i);
    }
    text
}

/// Write [`program`] and [`golden_vectors`] into `dir`: (program file, vectors file).
pub fn write_inputs(
    dir: &Path,
    profile: CarrierProfile,
) -> (std::path::PathBuf, std::path::PathBuf) {
    let (program_file, vectors_file) = (dir.join("program.txt"), dir.join("vectors.txt"));
    std::fs::write(&program_file, program()).unwrap();
    std::fs::write(&vectors_file, golden_vectors(profile)).unwrap();
    (program_file, vectors_file)
}
