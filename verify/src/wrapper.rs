//! The pin-limited wrapper that place and route runs on.
//!
//! An exported core has far more port bits than a package has pins
//! (`gyro_interface`: 330 input bits, 113 output bits; the UP5K's SG48 has
//! 39 I/Os). Placed and routed with its ports on pins, it would not fit,
//! and placed out of context, nextpnr would time paths from and to pins
//! whose placement is arbitrary. The flow therefore wraps any core in a
//! generated top with three pins:
//!
//! ```text
//!            settings_in ──► chain[0] ─► chain[1] ─► ... ─► chain[N-1]      (N = input bits)
//!                              │ one register per input bit, shifted every clock
//!                              ▼ slices
//!                         ┌──────────┐ outputs (M bits, all of them)
//!   clk ─────────────────►│   core   ├──► fold0 ──► fold1 ──► ... ──► fold_out
//!                         └──────────┘    ceil(M/4)  ceil(M/16)        1 bit
//!                                          each bit the XOR of 4 bits of the stage
//!                                          before it, registered
//! ```
//!
//! * Every input bit (settings, converter words, resets) comes from its own
//!   flip-flop of one shift register fed by the pin `settings_in`, as if a
//!   host shifted the settings in serially: no input is constant, so Yosys
//!   can optimize nothing away, and every input path starts at a register.
//! * Every output bit goes into an XOR tree of fan-in [`FOLD_FAN_IN`] (one
//!   4-input LUT per bit on iCE40 and ECP5) with a register after each
//!   level, ending in the registered pin `fold_out`: every output is
//!   observable, and the wrapper adds no path longer than one LUT.
//! * So every path nextpnr times is register to register: the core's own,
//!   or one LUT of wrapper logic. Fmax is the core's, not the pins'.
//!
//! The wrapper's own cost is reported beside the figures
//! ([`Wrapper::flip_flops`], [`Wrapper::fold_luts`]): N + M/3 + ... flip-flops
//! (for `gyro_interface`: 330 + 29 + 8 + 2 + 1 = 370 flip-flops and 40 LUTs).
//!
//! The core is described by a [`Core`]: module name, Verilog files and port
//! list, so the same flow runs on `gyro_interface` and on any bus-attached
//! top exported beside it.

use gyrocal_hdl::export::{Port, PortDirection};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Name of the generated top module.
pub const WRAPPER_MODULE: &str = "gyrocal_pnr_top";
/// File name of the generated wrapper in a place-and-route scratch folder.
pub const WRAPPER_FILE: &str = "gyrocal_pnr_top.v";
/// The wrapper's clock pin.
pub const CLOCK_PIN: &str = "clk";
/// The wrapper's serial settings input pin.
pub const SETTINGS_PIN: &str = "settings_in";
/// The wrapper's folded output pin.
pub const FOLD_PIN: &str = "fold_out";
/// Bits XOR-ed into one register per fold level: one 4-input LUT.
pub const FOLD_FAN_IN: usize = 4;

/// One port of a core.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CorePort {
    /// Port name in the Verilog.
    pub name: String,
    /// Direction.
    pub direction: PortDirection,
    /// Width in bits (at least 1).
    pub bits: usize,
}

/// An exported top to place and route: its module, files and ports.
#[derive(Clone, Debug)]
pub struct Core {
    /// Module name of the top.
    pub module: String,
    /// The Verilog files that hold it and everything it instantiates.
    pub verilog: Vec<PathBuf>,
    /// Name of the clock input (one clock domain).
    pub clock: String,
    /// Every port, in any order.
    pub ports: Vec<CorePort>,
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// What [`Core::new`] refuses: one line naming the module, port or clock.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CoreError {
    /// The module name is no Verilog identifier, or the wrapper's own.
    Module(String),
    /// No Verilog file given (the module).
    NoVerilog(String),
    /// A port that is no Verilog identifier or has no bit (name, bits).
    Port(String, usize),
    /// A port listed twice.
    Twice(String),
    /// The clock is no 1-bit input port (the clock, the module).
    Clock(String, String),
    /// No input but the clock, or no output (the module).
    NoData(String),
}

impl std::fmt::Display for CoreError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Module(m) => write!(
                f,
                "module name `{m}`: not a Verilog identifier, or `{WRAPPER_MODULE}`"
            ),
            Self::NoVerilog(m) => write!(f, "module `{m}`: no Verilog file given"),
            Self::Port(name, bits) => write!(
                f,
                "port `{name}` of {bits} bits: allowed are Verilog identifiers of at least 1 bit"
            ),
            Self::Twice(name) => write!(f, "port `{name}` is listed twice"),
            Self::Clock(clock, m) => write!(f, "clock `{clock}`: not a 1-bit input port of `{m}`"),
            Self::NoData(m) => write!(
                f,
                "`{m}` needs at least one input besides the clock and one output"
            ),
        }
    }
}

impl std::error::Error for CoreError {}

impl Core {
    /// A core, checked: Verilog identifiers, unique port names, widths of
    /// at least one bit, a 1-bit clock input, at least one other input and
    /// one output, and no name the wrapper uses itself.
    pub fn new(
        module: &str,
        verilog: Vec<PathBuf>,
        clock: &str,
        ports: Vec<CorePort>,
    ) -> Result<Self, CoreError> {
        if !is_identifier(module) || module == WRAPPER_MODULE {
            return Err(CoreError::Module(module.into()));
        }
        if verilog.is_empty() {
            return Err(CoreError::NoVerilog(module.into()));
        }
        for (i, p) in ports.iter().enumerate() {
            if !is_identifier(&p.name) || p.bits == 0 {
                return Err(CoreError::Port(p.name.clone(), p.bits));
            }
            if ports[..i].iter().any(|q| q.name == p.name) {
                return Err(CoreError::Twice(p.name.clone()));
            }
        }
        let clock_port = ports.iter().find(|p| p.name == clock);
        if !clock_port.is_some_and(|p| p.direction == PortDirection::Input && p.bits == 1) {
            return Err(CoreError::Clock(clock.into(), module.into()));
        }
        let core = Self {
            module: module.to_owned(),
            verilog,
            clock: clock.to_owned(),
            ports,
        };
        if core.input_bits() == 0 || core.output_bits() == 0 {
            return Err(CoreError::NoData(module.into()));
        }
        Ok(core)
    }

    /// A core from a port table as `gyrocal_hdl::export` describes it.
    pub fn from_export(
        module: &str,
        verilog: Vec<PathBuf>,
        clock: &str,
        ports: &[Port],
    ) -> Result<Self, CoreError> {
        let ports = ports
            .iter()
            .map(|p| CorePort {
                name: p.name.to_owned(),
                direction: p.direction,
                bits: p.bits,
            })
            .collect();
        Self::new(module, verilog, clock, ports)
    }

    /// The exported `gyro_interface` in `verilog` (its committed file is
    /// `gyrocal_verify::committed_verilog()`).
    pub fn gyro_interface(verilog: PathBuf) -> Self {
        use gyrocal_hdl::export::{PORTS, TOP_MODULE};
        Self::from_export(TOP_MODULE, vec![verilog], "clock", PORTS)
            .expect("export::PORTS describes a valid core")
    }

    /// The exported bus-attached top `gyro_interface_axi` in `verilog` (the
    /// file holds its own copy of the core).
    pub fn gyro_interface_axi(verilog: PathBuf) -> Self {
        use gyrocal_hdl::export::{AXI_PORTS, AXI_TOP_MODULE};
        Self::from_export(AXI_TOP_MODULE, vec![verilog], "aclk", AXI_PORTS)
            .expect("export::AXI_PORTS describes a valid core")
    }

    /// Input ports other than the clock, in the given order.
    fn data_inputs(&self) -> impl Iterator<Item = &CorePort> {
        self.ports
            .iter()
            .filter(|p| p.direction == PortDirection::Input && p.name != self.clock)
    }

    fn outputs(&self) -> impl Iterator<Item = &CorePort> {
        self.ports
            .iter()
            .filter(|p| p.direction == PortDirection::Output)
    }

    /// Input bits without the clock: the length of the settings chain.
    pub fn input_bits(&self) -> usize {
        self.data_inputs().map(|p| p.bits).sum()
    }

    /// Output bits: the width folded into `fold_out`.
    pub fn output_bits(&self) -> usize {
        self.outputs().map(|p| p.bits).sum()
    }
}

/// The generated wrapper around one core.
#[derive(Clone, Debug)]
pub struct Wrapper {
    /// Widths of the fold levels, first (widest) to last (1 bit).
    pub fold_widths: Vec<usize>,
    /// Length of the settings chain.
    pub chain_bits: usize,
    /// The Verilog of module [`WRAPPER_MODULE`].
    pub verilog: String,
}

impl Wrapper {
    /// The wrapper of `core`.
    pub fn new(core: &Core) -> Self {
        let chain_bits = core.input_bits();
        let mut fold_widths = Vec::new();
        let mut width = core.output_bits();
        while width > 1 {
            width = width.div_ceil(FOLD_FAN_IN);
            fold_widths.push(width);
        }
        if fold_widths.is_empty() {
            fold_widths.push(1); // one output bit: still registered once
        }
        let verilog = wrapper_verilog(core, chain_bits, &fold_widths);
        Self {
            fold_widths,
            chain_bits,
            verilog,
        }
    }

    /// Flip-flops the wrapper adds: the chain and every fold level.
    pub fn flip_flops(&self) -> usize {
        self.chain_bits + self.fold_widths.iter().sum::<usize>()
    }

    /// LUTs the fold needs: one per fold register.
    pub fn fold_luts(&self) -> usize {
        self.fold_widths.iter().sum()
    }
}

fn wrapper_verilog(core: &Core, chain_bits: usize, fold_widths: &[usize]) -> String {
    let outs = core.output_bits();
    let mut v = String::new();
    let _ = writeln!(
        v,
        "// Generated by gyrocal-verify (verify/src/wrapper.rs): pin-limited wrapper of\n\
         // `{module}` for place and route. Settings shift in from `{SETTINGS_PIN}`,\n\
         // outputs fold (XOR, {FOLD_FAN_IN} bits per registered LUT) into `{FOLD_PIN}`.\n\
         `default_nettype none\n\
         module {WRAPPER_MODULE}(input wire {CLOCK_PIN}, input wire {SETTINGS_PIN}, output wire {FOLD_PIN});",
        module = core.module
    );
    let _ = writeln!(v, "    reg [{}:0] chain = 0;", chain_bits - 1);
    let shifted = if chain_bits == 1 {
        SETTINGS_PIN.to_owned()
    } else {
        format!("{{chain[{}:0], {SETTINGS_PIN}}}", chain_bits - 2)
    };
    let _ = writeln!(v, "    always @(posedge {CLOCK_PIN}) chain <= {shifted};");
    let _ = writeln!(v, "    wire [{}:0] outs;", outs - 1);
    let mut conns = vec![format!(".{}({CLOCK_PIN})", core.clock)];
    let mut lo = 0;
    for p in core.data_inputs() {
        conns.push(format!(".{}(chain[{}:{lo}])", p.name, lo + p.bits - 1));
        lo += p.bits;
    }
    lo = 0;
    for p in core.outputs() {
        conns.push(format!(".{}(outs[{}:{lo}])", p.name, lo + p.bits - 1));
        lo += p.bits;
    }
    let _ = writeln!(
        v,
        "    {} core (\n        {}\n    );",
        core.module,
        conns.join(",\n        ")
    );
    let (mut previous, mut previous_width) = ("outs".to_owned(), outs);
    for (level, &width) in fold_widths.iter().enumerate() {
        let name = format!("fold{level}");
        let _ = writeln!(v, "    reg [{}:0] {name} = 0;", width - 1);
        let _ = writeln!(v, "    always @(posedge {CLOCK_PIN}) begin");
        for bit in 0..width {
            let low = bit * FOLD_FAN_IN;
            let high = (low + FOLD_FAN_IN).min(previous_width) - 1;
            let _ = writeln!(v, "        {name}[{bit}] <= ^{previous}[{high}:{low}];");
        }
        let _ = writeln!(v, "    end");
        (previous, previous_width) = (name, width);
    }
    let _ = writeln!(
        v,
        "    assign {FOLD_PIN} = {previous}[0];\nendmodule\n`default_nettype wire"
    );
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use PortDirection::{Input, Output};

    fn port(name: &str, direction: PortDirection, bits: usize) -> CorePort {
        CorePort {
            name: name.into(),
            direction,
            bits,
        }
    }

    fn small() -> Core {
        let ports = vec![
            port("clk_i", Input, 1),
            port("a", Input, 3),
            port("b", Input, 1),
            port("y", Output, 5),
            port("z", Output, 13),
        ];
        Core::new("small", vec!["small.v".into()], "clk_i", ports).unwrap()
    }

    #[test]
    fn every_port_bit_is_wired_once() {
        let core = small();
        let w = Wrapper::new(&core);
        assert_eq!(w.chain_bits, 4);
        assert_eq!(w.fold_widths, vec![5, 2, 1]); // 18 -> 5 -> 2 -> 1
        assert_eq!(w.flip_flops(), 4 + 8);
        let v = &w.verilog;
        for needle in [
            ".clk_i(clk)",
            ".a(chain[2:0])",
            ".b(chain[3:3])",
            ".y(outs[4:0])",
            ".z(outs[17:5])",
            "chain <= {chain[2:0], settings_in};",
            "fold0[4] <= ^outs[17:16];",
            "fold1[1] <= ^fold0[4:4];",
            "fold2[0] <= ^fold1[1:0];",
            "assign fold_out = fold2[0];",
        ] {
            assert!(v.contains(needle), "missing `{needle}` in\n{v}");
        }
    }

    #[test]
    fn gyro_interface_wrapper_cost() {
        let w = Wrapper::new(&Core::gyro_interface("gyro_interface.v".into()));
        assert_eq!(w.chain_bits, 330);
        assert_eq!(w.fold_widths, vec![29, 8, 2, 1]);
        assert_eq!(w.flip_flops(), 370);
        assert_eq!(w.fold_luts(), 40);
    }

    #[test]
    fn bad_cores_are_refused() {
        let ok = small();
        let with = |f: &dyn Fn(&mut Vec<CorePort>)| {
            let mut ports = ok.ports.clone();
            f(&mut ports);
            Core::new("small", vec!["s.v".into()], "clk_i", ports)
        };
        assert!(with(&|_| {}).is_ok());
        let clock = CoreError::Clock("clk_i".into(), "small".into());
        assert_eq!(with(&|p| p[0].bits = 2).unwrap_err(), clock);
        assert_eq!(with(&|p| p[0].direction = Output).unwrap_err(), clock);
        assert_eq!(
            with(&|p| p[1].name = "b".into()).unwrap_err(),
            CoreError::Twice("b".into())
        );
        let bad_name = with(&|p| p[1].name = "9a".into()).unwrap_err();
        assert!(bad_name.to_string().contains("identifier"), "{bad_name}");
        let no_bit = with(&|p| p[2].bits = 0).unwrap_err();
        assert!(no_bit.to_string().contains("at least 1 bit"), "{no_bit}");
        assert_eq!(
            with(&|p| p.truncate(3)).unwrap_err(),
            CoreError::NoData("small".into())
        );
        assert_eq!(
            Core::new("small", vec![], "clk_i", ok.ports.clone()).unwrap_err(),
            CoreError::NoVerilog("small".into())
        );
        let wrapper = Core::new(WRAPPER_MODULE, vec!["s.v".into()], "clk_i", ok.ports);
        assert_eq!(
            wrapper.unwrap_err(),
            CoreError::Module(WRAPPER_MODULE.into())
        );
    }
}
