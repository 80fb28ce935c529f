//! Verilog export of `GyroInterface` and its port description.
//!
//! rust-hdl names the top module `top` and every sub-module after its
//! instance path (`top$carrier_nco$drive`). The export renames them to
//! `gyro_interface` and `gyro_interface__carrier_nco__drive`, which every
//! FPGA tool accepts, and puts a header on the file. Nothing else is
//! touched: the body is rust-hdl's output. `verilog-out/` holds the result;
//! a test fails when the committed files differ from what this code writes.

use crate::gyro_interface::GyroInterface;
use gyrocal_regs::datapath::CarrierProfile;
use regex::Regex;
use rust_hdl::prelude::{Block, generate_verilog};

/// Name of the top module in the exported Verilog.
pub const TOP_MODULE: &str = "gyro_interface";
/// File name of the exported Verilog inside `verilog-out/`.
pub const VERILOG_FILE: &str = "gyro_interface.v";
/// The fine-carrier core (`crate::gyro_interface::FineGyroInterface`,
/// the ECP5 core) inside `verilog-out/`: the same module name and ports as
/// `VERILOG_FILE`, so either file drops into the same design.
pub const FINE_VERILOG_FILE: &str = "ecp5/gyro_interface.v";
/// File name of the port description inside `verilog-out/`.
pub const PORTS_FILE: &str = "PORTS.md";
/// Name of the bus-attached top module (`crate::host::axi_top`).
pub const AXI_TOP_MODULE: &str = "gyro_interface_axi";
/// File name of the bus-attached top's Verilog inside `verilog-out/`.
pub const AXI_VERILOG_FILE: &str = "gyro_interface_axi.v";
/// The bus-attached top around the fine-carrier core inside `verilog-out/`:
/// module `gyro_interface_axi`, as [`AXI_VERILOG_FILE`], for ECP5 and larger parts.
pub const FINE_AXI_VERILOG_FILE: &str = "ecp5/gyro_interface_axi.v";
/// The core's Verilog inside `verilog-out/` for a carrier profile:
/// [`VERILOG_FILE`] or [`FINE_VERILOG_FILE`].
pub fn verilog_file(profile: CarrierProfile) -> &'static str {
    match profile {
        CarrierProfile::Table => VERILOG_FILE,
        CarrierProfile::Fine => FINE_VERILOG_FILE,
    }
}

/// The bus top's Verilog inside `verilog-out/` for a carrier profile:
/// [`AXI_VERILOG_FILE`] or [`FINE_AXI_VERILOG_FILE`].
pub fn axi_verilog_file(profile: CarrierProfile) -> &'static str {
    match profile {
        CarrierProfile::Table => AXI_VERILOG_FILE,
        CarrierProfile::Fine => FINE_AXI_VERILOG_FILE,
    }
}

/// The exported Verilog of the core with this carrier profile:
/// [`verilog`] or [`fine_verilog`].
pub fn verilog_for(profile: CarrierProfile) -> String {
    match profile {
        CarrierProfile::Table => verilog(),
        CarrierProfile::Fine => fine_verilog(),
    }
}

/// File name of the register map inside `verilog-out/`.
pub const REGISTERS_FILE: &str = "REGISTERS.md";
/// File name of the register map's C header inside `verilog-out/`.
pub const C_HEADER_FILE: &str = "gyro_interface_regs.h";
/// File name of the register map's SystemRDL description inside `verilog-out/`.
pub const SYSTEMRDL_FILE: &str = "gyro_interface.rdl";

/// Direction of a top-level port.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortDirection {
    /// Input port.
    Input,
    /// Output port.
    Output,
}

/// One port of the top module, as documented in `PORTS.md`.
#[derive(Clone, Copy, Debug)]
pub struct Port {
    /// Port name.
    pub name: &'static str,
    /// Direction.
    pub direction: PortDirection,
    /// Width in bits.
    pub bits: usize,
    /// Two's complement (`signed`) or unsigned.
    pub signed: bool,
    /// Number format and range.
    pub format: &'static str,
    /// What the port does.
    pub description: &'static str,
}

const fn port(
    name: &'static str,
    direction: PortDirection,
    bits: usize,
    signed: bool,
    format: &'static str,
    description: &'static str,
) -> Port {
    Port {
        name,
        direction,
        bits,
        signed,
        format,
        description,
    }
}

use PortDirection::{Input, Output};

/// `adc1`, the same port in both tops.
const ADC1: Port = port(
    "adc1",
    Input,
    16,
    true,
    "two's complement",
    "ADC word of gyroscope output 1 (mode 1 pick-off).",
);
/// `adc2`, the same port in both tops.
const ADC2: Port = port(
    "adc2",
    Input,
    16,
    true,
    "two's complement",
    "ADC word of gyroscope output 2 (mode 2 pick-off).",
);
/// `dac1`, the same port in both tops.
const DAC1: Port = port(
    "dac1",
    Output,
    16,
    true,
    "two's complement, -32767..32767",
    "Drive 1 = F1 A1 cos(wt), to DAC 1 (mode 1).",
);
/// `dac2`, the same port in both tops.
const DAC2: Port = port(
    "dac2",
    Output,
    16,
    true,
    "two's complement, -32767..32767",
    "Drive 2 = F2 A2 sin(wt), to DAC 2 (mode 2).",
);

/// The ports of `gyro_interface`, in declaration order. A test checks this
/// table against the generated Verilog.
pub const PORTS: &[Port] = &[
    port(
        "clock",
        Input,
        1,
        false,
        "clock",
        "Every register uses its rising edge; one clock domain.",
    ),
    ADC1,
    ADC2,
    DAC1,
    DAC2,
    port(
        "z1",
        Output,
        40,
        true,
        "two's complement, 8 fractional bits",
        "Filtered demodulator output 1, in mixer LSBs (adc x reference) times the filter's DC gain.",
    ),
    port(
        "z2",
        Output,
        40,
        true,
        "two's complement, 8 fractional bits",
        "Filtered demodulator output 2, as z1.",
    ),
    port(
        "z_valid",
        Output,
        1,
        false,
        "pulse",
        "High for one clock when z1 and z2 change (rate f_clk / R).",
    ),
    port(
        "select",
        Input,
        1,
        false,
        "0 / 1",
        "SELECT of paper Fig. 1: 0 readout (A = 1, each output mixed with its own drive), 1 calibration (A = cos/sin, outputs mixed with the other drive).",
    ),
    port(
        "carrier_step",
        Input,
        32,
        false,
        "unsigned",
        "Carrier phase step: f_carrier = carrier_step * f_clk / 2^32.",
    ),
    port(
        "ref_phase",
        Input,
        32,
        false,
        "unsigned, 2^32 = 360 deg",
        "Phase advance of the demodulation references over the drives; carrier_step / 2 cancels the DAC's half-sample hold delay.",
    ),
    port(
        "ref_delay",
        Input,
        6,
        false,
        "0..63",
        "References are delayed by ref_delay + 1 clocks; set to DAC latency + ADC latency (clocks).",
    ),
    port(
        "mod_step",
        Input,
        48,
        false,
        "unsigned",
        "Calibration rate: f_cal = mod_step * f_clk / 2^48 (virtual rate 360 f_cal deg/s).",
    ),
    port(
        "amp1",
        Input,
        16,
        true,
        "Q1.15",
        "Drive amplitude F1; 32767 is full scale. Any value is safe.",
    ),
    port(
        "amp2",
        Input,
        16,
        true,
        "Q1.15",
        "Drive amplitude F2; 32767 is full scale. Any value is safe.",
    ),
    port(
        "cic_decimation",
        Input,
        13,
        false,
        "166..4096",
        "CIC decimation R; z is updated every R clocks.",
    ),
    port(
        "cic_shift",
        Input,
        6,
        false,
        "0..40",
        "CIC output shift, ceil(4 log2 R) - 8.",
    ),
    port(
        "iir_k0",
        Input,
        32,
        true,
        "Q2.30",
        "Biquad numerator gain g (Butterworth b0 times the CIC gain correction).",
    ),
    port(
        "iir_k1",
        Input,
        32,
        true,
        "Q2.30",
        "Biquad feedback -a1 - 2.",
    ),
    port(
        "iir_k2",
        Input,
        32,
        true,
        "Q2.30",
        "Biquad feedback 1 - a2.",
    ),
    port(
        "iir_alpha",
        Input,
        32,
        true,
        "Q2.30",
        "RC section: 1 - exp(-2 pi f_rc R / f_clk).",
    ),
];

/// The exported Verilog of `GyroInterface`: rust-hdl's output with the
/// modules renamed and a header.
pub fn verilog() -> String {
    let mut uut = GyroInterface::new();
    uut.connect_all();
    core_verilog(&generate_verilog(&uut), "")
}

/// The exported Verilog of `FineGyroInterface`, the ECP5 core: module
/// `gyro_interface` as in [`verilog`], with the fine carriers.
pub fn fine_verilog() -> String {
    let mut uut = crate::gyro_interface::FineGyroInterface::new();
    uut.connect_all();
    core_verilog(&generate_verilog(&uut), FINE_NOTE)
}

/// A core's rust-hdl output with the modules renamed and the header, plus
/// `note` (comment lines) after the header's first paragraph.
fn core_verilog(raw: &str, note: &str) -> String {
    let body = rename_modules(raw, TOP_MODULE);
    format!(
        "// {TOP_MODULE}: reconfigurable phase-readout and self-calibration datapath\n\
         // for MEMS gyroscopes (Shirazi et al., TRANSDUCERS 2013, Fig. 1).\n\
         //\n\
         {note}\
         // Generated by `gyrocal export` from the rust-hdl design in hdl/ (gyrocal-hdl\n\
         // {version}); do not edit. Ports: verilog-out/PORTS.md. One clock domain,\n\
         // power-up values from `initial` blocks, no reset.\n\
         {body}",
        version = env!("CARGO_PKG_VERSION"),
        body = body.trim_end_matches('\n').to_owned() + "\n"
    )
}

/// The exported Verilog of the bus-attached top `GyroInterfaceAxi`: its own
/// copy of the datapath (`gyro_interface_axi__core`), so the file stands
/// alone and can sit beside `gyro_interface.v` without a name clash.
pub fn axi_verilog() -> String {
    let mut uut = crate::host::axi_top::GyroInterfaceAxi::new();
    uut.connect_all();
    bus_verilog(&generate_verilog(&uut), "")
}

/// The exported Verilog of `FineGyroInterfaceAxi`, the ECP5 bus top:
/// module `gyro_interface_axi` as in [`axi_verilog`], with the fine carriers.
pub fn fine_axi_verilog() -> String {
    let mut uut = crate::host::axi_top::FineGyroInterfaceAxi::new();
    uut.connect_all();
    bus_verilog(&generate_verilog(&uut), FINE_NOTE)
}

/// The header lines that name the fine-carrier core.
const FINE_NOTE: &str = "// This is the fine-carrier core (CarrierProfile::Fine): interpolated carrier\n\
     // sines from an initialized dual-port ROM and four 18 x 18 multipliers, for\n\
     // an ECP5 or a larger part. Same ports, registers and latencies as the table\n\
     // core one folder up, which fits an iCE40 UltraPlus.\n//\n";

/// A bus top's rust-hdl output with the modules renamed and the header,
/// plus `note` (comment lines) after the header's first paragraph.
fn bus_verilog(raw: &str, note: &str) -> String {
    let body = rename_modules(raw, AXI_TOP_MODULE);
    format!(
        "// {AXI_TOP_MODULE}: the gyro_interface datapath behind an AXI4-Lite register\n\
         // slave and an AXI4-Stream master of z samples.\n\
         //\n\
         {note}\
         // Generated by `gyrocal export` from the rust-hdl design in hdl/src/host\n\
         // (gyrocal-hdl {version}); do not edit. Registers: verilog-out/REGISTERS.md and\n\
         // verilog-out/{C_HEADER_FILE}. One clock (aclk); aresetn, active low and\n\
         // synchronous, resets the bus wrapper, not the datapath core.\n\
         {body}",
        version = env!("CARGO_PKG_VERSION"),
        body = body.trim_end_matches('\n').to_owned() + "\n"
    )
}

/// Rename `top` to `top_name` and `top$a$b` to `top_name__a__b` in module
/// declarations, instantiations and `endmodule` comments.
fn rename_modules(verilog: &str, top_name: &str) -> String {
    let declaration = Regex::new(r"^module (top(?:\$[A-Za-z0-9_]+)*)\(").unwrap();
    let instance = Regex::new(r"^(\s*)(top(?:\$[A-Za-z0-9_]+)*) ([A-Za-z0-9_$]+)\($").unwrap();
    let end = Regex::new(r"^endmodule // (top(?:\$[A-Za-z0-9_]+)*)$").unwrap();
    let rename = |path: &str| path.replacen("top", top_name, 1).replace('$', "__");
    let mut out = String::with_capacity(verilog.len());
    for line in verilog.lines() {
        let line = line.trim_end();
        let renamed = if let Some(c) = declaration.captures(line) {
            line.replacen(&c[1], &rename(&c[1]), 1)
        } else if let Some(c) = instance.captures(line) {
            format!("{}{} {}(", &c[1], rename(&c[2]), &c[3])
        } else if let Some(c) = end.captures(line) {
            format!("endmodule // {}", rename(&c[1]))
        } else {
            line.to_owned()
        };
        out.push_str(&renamed);
        out.push('\n');
    }
    out
}

/// The ports of `gyro_interface_axi`, the bus-attached top, in declaration
/// order (the place-and-route wrapper takes them from here). A test checks
/// this table against the generated Verilog.
pub const AXI_PORTS: &[Port] = &[
    port(
        "aclk",
        Input,
        1,
        false,
        "clock",
        "AXI clock: the core's clock; every register uses its rising edge.",
    ),
    port(
        "aresetn",
        Input,
        1,
        false,
        "active low",
        "Synchronous AXI reset of the bus wrapper (settings, handshakes, counters, FIFO); the datapath has none.",
    ),
    ADC1,
    ADC2,
    DAC1,
    DAC2,
    port(
        "s_axil_awvalid",
        Input,
        1,
        false,
        "AXI4-Lite",
        "Write address valid.",
    ),
    port(
        "s_axil_awready",
        Output,
        1,
        false,
        "AXI4-Lite",
        "Write address ready.",
    ),
    port(
        "s_axil_awaddr",
        Input,
        8,
        false,
        "byte address",
        "Write address (REGISTERS.md).",
    ),
    port(
        "s_axil_wvalid",
        Input,
        1,
        false,
        "AXI4-Lite",
        "Write data valid.",
    ),
    port(
        "s_axil_wready",
        Output,
        1,
        false,
        "AXI4-Lite",
        "Write data ready.",
    ),
    port(
        "s_axil_wdata",
        Input,
        32,
        false,
        "register word",
        "Write data.",
    ),
    port(
        "s_axil_wstrb",
        Input,
        4,
        false,
        "byte strobes",
        "Write strobes.",
    ),
    port(
        "s_axil_bvalid",
        Output,
        1,
        false,
        "AXI4-Lite",
        "Write response valid.",
    ),
    port(
        "s_axil_bready",
        Input,
        1,
        false,
        "AXI4-Lite",
        "Write response ready.",
    ),
    port(
        "s_axil_bresp",
        Output,
        2,
        false,
        "OKAY 0, SLVERR 2",
        "Write response.",
    ),
    port(
        "s_axil_arvalid",
        Input,
        1,
        false,
        "AXI4-Lite",
        "Read address valid.",
    ),
    port(
        "s_axil_arready",
        Output,
        1,
        false,
        "AXI4-Lite",
        "Read address ready.",
    ),
    port(
        "s_axil_araddr",
        Input,
        8,
        false,
        "byte address",
        "Read address (REGISTERS.md).",
    ),
    port(
        "s_axil_rvalid",
        Output,
        1,
        false,
        "AXI4-Lite",
        "Read data valid.",
    ),
    port(
        "s_axil_rready",
        Input,
        1,
        false,
        "AXI4-Lite",
        "Read data ready.",
    ),
    port(
        "s_axil_rdata",
        Output,
        32,
        false,
        "register word",
        "Read data.",
    ),
    port(
        "s_axil_rresp",
        Output,
        2,
        false,
        "OKAY 0, SLVERR 2",
        "Read response.",
    ),
    port(
        "m_axis_tvalid",
        Output,
        1,
        false,
        "AXI4-Stream",
        "Sample valid.",
    ),
    port(
        "m_axis_tready",
        Input,
        1,
        false,
        "AXI4-Stream",
        "Sample ready (backpressure).",
    ),
    port(
        "m_axis_tdata",
        Output,
        96,
        false,
        "{count[15:0], z2, z1}",
        "z1, z2 (40 bits each) and the low 16 bits of the sample counter.",
    ),
    port(
        "m_axis_tlast",
        Output,
        1,
        false,
        "AXI4-Stream",
        "1 on every sample.",
    ),
];

/// `PORTS.md`: the port table with formats, for the FPGA engineer.
pub fn ports_markdown() -> String {
    let mut md = String::from(
        "# gyro_interface ports\n\n\
         Generated by `gyrocal export` from `hdl/src/export.rs`; a test checks this table\n\
         against the exported Verilog. Every input is sampled at the rising edge of\n\
         `clock`; drive the settings from a register bank in the same clock domain.\n\
         `gyrocal_hdl::settings` computes them from frequencies in Hz.\n\n\
         | port | dir | bits | format | description |\n\
         |---|---|---|---|---|\n",
    );
    for p in PORTS {
        let dir = match p.direction {
            Input => "in",
            Output => "out",
        };
        let signed = if p.signed { " signed" } else { "" };
        md.push_str(&format!(
            "| `{}` | {dir} | {}{signed} | {} | {} |\n",
            p.name, p.bits, p.format, p.description
        ));
    }
    md.push_str(&format!(
        "\nLatencies: carrier phase to DAC word {} clocks; ADC word to mixer product 2;\n\
         mixer product to CIC output at most R + {}; CIC output to z {}.\n\
         Reference alignment for converter latencies L_dac, L_adc (clocks):\n\
         `ref_delay = L_dac + L_adc`, `ref_phase = carrier_step / 2`.\n",
        crate::carrier_nco::LATENCY + crate::am_mixer::CARRIER_LATENCY,
        crate::cic_decimator::SAMPLE_TO_OUTPUT,
        crate::iir_lowpass::LATENCY
    ));
    md
}

/// The files of `verilog-out/` that `gyrocal export` writes, as (name, text).
pub fn files() -> Vec<(&'static str, String)> {
    vec![
        (VERILOG_FILE, verilog()),
        (FINE_VERILOG_FILE, fine_verilog()),
        (PORTS_FILE, ports_markdown()),
        (AXI_VERILOG_FILE, axi_verilog()),
        (FINE_AXI_VERILOG_FILE, fine_axi_verilog()),
        (REGISTERS_FILE, crate::host::register_map::markdown()),
        (C_HEADER_FILE, crate::host::register_map::c_header()),
        (
            SYSTEMRDL_FILE,
            gyrocal_regs::systemrdl::systemrdl(&crate::host::register_map::REGISTERS),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decimation port's documented range is the limits of record
    /// (`gyrocal_regs::datapath`), as the register map's text says.
    #[test]
    fn decimation_port_text_follows_the_limits() {
        use gyrocal_regs::datapath::{MAX_DECIMATION, MIN_DECIMATION};
        let range = format!("{MIN_DECIMATION}..{MAX_DECIMATION}");
        let port = PORTS.iter().find(|p| p.name == "cic_decimation");
        assert_eq!(port.map(|p| p.format), Some(range.as_str()));
    }

    #[test]
    fn port_table_matches_the_verilog_declarations() {
        check_port_table(&verilog(), TOP_MODULE, PORTS);
        check_port_table(&fine_verilog(), TOP_MODULE, PORTS);
    }

    #[test]
    fn bus_top_port_table_matches_the_verilog_declarations() {
        check_port_table(&axi_verilog(), AXI_TOP_MODULE, AXI_PORTS);
        check_port_table(&fine_axi_verilog(), AXI_TOP_MODULE, AXI_PORTS);
    }

    fn check_port_table(v: &str, module: &str, ports: &[Port]) {
        let header = Regex::new(&format!(r"(?m)^module {module}\(([^)]*)\);")).unwrap();
        let names: Vec<&str> = header
            .captures(v)
            .unwrap()
            .get(1)
            .unwrap()
            .as_str()
            .split(',')
            .collect();
        let table: Vec<&str> = ports.iter().map(|p| p.name).collect();
        assert_eq!(names, table, "port order or names differ");
        let decl = Regex::new(
            r"^\s*(input wire|output reg)\s+(signed)?\s*(?:\[(\d+):0\])?\s*([a-z0-9_]+);$",
        )
        .unwrap();
        let start = v.find(&format!("module {module}(")).unwrap();
        let top = v[start..].split("endmodule").next().unwrap();
        let mut seen = 0;
        for line in top.lines() {
            if let Some(c) = decl.captures(line) {
                let p = ports.iter().find(|p| p.name == &c[4]).unwrap();
                let dir = if &c[1] == "input wire" { Input } else { Output };
                let bits = c
                    .get(3)
                    .map_or(1, |m| m.as_str().parse::<usize>().unwrap() + 1);
                assert_eq!(
                    (dir, bits, c.get(2).is_some()),
                    (p.direction, p.bits, p.signed),
                    "{}",
                    p.name
                );
                seen += 1;
            }
        }
        assert_eq!(seen, ports.len());
    }

    #[test]
    fn every_module_of_the_bus_top_is_renamed() {
        let v = axi_verilog();
        assert!(!v.contains("module top"), "a module kept rust-hdl's name");
        assert!(v.contains(&format!("module {AXI_TOP_MODULE}(")));
        assert!(v.contains(&format!("module {AXI_TOP_MODULE}__core(")));
    }

    #[test]
    fn every_module_is_renamed() {
        let v = verilog();
        assert!(!v.contains("module top"), "a module kept rust-hdl's name");
        assert!(
            !Regex::new(r"(?m)^\s*top\$").unwrap().is_match(&v),
            "an instance kept rust-hdl's name"
        );
        assert!(v.contains(&format!("module {TOP_MODULE}(")));
    }
}
