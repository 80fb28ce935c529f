//! The bus wrapper's Verilog for the proofs: the export with the DSP core
//! cut out and a stub in its place.
//!
//! ```text
//!  module gyro_interface_axi__core(...)   ──►  module gyro_interface_axi__core(...)
//!      input/output declarations                   the same declarations, `output reg` as `output wire`
//!      ~11,000 lines of datapath                   assign <each output> = $anyseq;
//!  module gyro_interface_axi__core__*     ──►  (removed)
//! ```
//!
//! The stub keeps the core's ports exactly as exported (a port added to
//! the core appears in the stub by itself), and every output is free on
//! every clock: a proof over it holds for any sequence of `z1`, `z2`,
//! `z_valid` (and `dac1`, `dac2`) the core could produce, a `z_valid` on
//! every clock included (the core gives one sample per R >= 166 clocks).
//! Inputs are left unread. Reading the whole file costs Yosys
//! (WebAssembly) 15 s a run; the stub, nothing.

use super::{CORE_MODULE_PREFIX, FormalError};

/// The export with every module whose name starts with
/// [`CORE_MODULE_PREFIX`] removed, from its `module` line to its
/// `endmodule` line, and the core itself (`module gyro_interface_axi__core(`)
/// replaced by [`core_stub`] of it.
pub fn bus_verilog(export: &str) -> Result<String, FormalError> {
    let start = format!("module {CORE_MODULE_PREFIX}");
    let core_start = format!("{start}(");
    let (mut out, mut core_text, mut cores) = (String::new(), String::new(), 0);
    let mut state = Part::Bus;
    for line in export.split_inclusive('\n') {
        if state == Part::Bus && line.starts_with(&start) {
            state = if line.starts_with(&core_start) {
                cores += 1;
                Part::Core
            } else {
                Part::Submodule
            };
        }
        match state {
            Part::Bus => out.push_str(line),
            Part::Core => core_text.push_str(line),
            Part::Submodule => {}
        }
        if state != Part::Bus && line.starts_with("endmodule") {
            if state == Part::Core {
                out.push_str(&core_stub(&core_text)?);
            }
            state = Part::Bus;
        }
    }
    if cores != 1 || state != Part::Bus {
        return Err(FormalError::Unexpected(format!(
            "the export has {cores} `{core_start}` blocks{}: cannot cut out the core",
            if state == Part::Bus {
                ""
            } else {
                ", the last without endmodule"
            }
        )));
    }
    Ok(out)
}

/// Where a line of the export is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Part {
    /// A module of the bus wrapper: kept.
    Bus,
    /// The core: stubbed.
    Core,
    /// A module of the core: removed.
    Submodule,
}

/// The stub of one core module's text: its `module` line, its `input` and
/// `output` declarations (outputs as wires), one `assign NAME = $anyseq;`
/// per output, `endmodule`.
pub fn core_stub(core: &str) -> Result<String, FormalError> {
    let mut lines = core.lines();
    let header = lines.next().unwrap_or_default();
    let mut stub = format!(
        "{header}\n    // Stub for the formal proofs (verify/src/formal/stub.rs): outputs free.\n"
    );
    let mut outputs = Vec::new();
    for line in lines {
        let decl = line.trim_start();
        let is_output = decl.starts_with("output ");
        if !(is_output || decl.starts_with("input ")) {
            continue;
        }
        let name = decl
            .trim_end_matches(';')
            .split_whitespace()
            .last()
            .unwrap_or_default();
        if is_output {
            outputs.push(name.to_owned());
        }
        stub.push_str(&line.replacen("output reg ", "output wire ", 1));
        stub.push('\n');
    }
    if outputs.is_empty() {
        return Err(FormalError::Unexpected(format!(
            "`{header}` declares no output: cannot stub the core"
        )));
    }
    for name in &outputs {
        stub.push_str(&format!("    assign {name} = $anyseq;\n"));
    }
    stub.push_str("endmodule\n");
    Ok(stub)
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXPORT: &str = "module top(a);\nendmodule\n\
        module gyro_interface_axi__core(clock,z,z_valid);\n\n    // Module arguments\n\
        \x20   input wire  clock;\n    output reg signed [39:0] z;\n    output reg  z_valid;\n\
        \x20   reg  [3:0] n;\n    always @(posedge clock) n <= n + 1;\nendmodule // core\n\
        module gyro_interface_axi__core__cic(x);\nendmodule\nmodule tail(b);\nendmodule\n";

    #[test]
    fn the_core_becomes_a_stub_and_its_submodules_go() {
        let bus = bus_verilog(EXPORT).unwrap();
        assert_eq!(
            bus,
            "module top(a);\nendmodule\n\
             module gyro_interface_axi__core(clock,z,z_valid);\n\
             \x20   // Stub for the formal proofs (verify/src/formal/stub.rs): outputs free.\n\
             \x20   input wire  clock;\n    output wire signed [39:0] z;\n    output wire  z_valid;\n\
             \x20   assign z = $anyseq;\n    assign z_valid = $anyseq;\nendmodule\n\
             module tail(b);\nendmodule\n"
        );
    }

    #[test]
    fn an_export_without_the_core_is_refused() {
        let e = bus_verilog("module a();\nendmodule\n").unwrap_err();
        assert!(
            e.to_string()
                .contains("0 `module gyro_interface_axi__core(`"),
            "{e}"
        );
        let e = bus_verilog("module gyro_interface_axi__core(x);\n").unwrap_err();
        assert!(e.to_string().contains("without endmodule"), "{e}");
        let e = core_stub("module gyro_interface_axi__core(x);\n    input wire x;\n").unwrap_err();
        assert!(e.to_string().contains("no output"), "{e}");
    }
}
