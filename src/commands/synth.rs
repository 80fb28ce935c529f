//! `gyrocal synth`: synthesize verilog-out/gyro_interface.v with Yosys for
//! iCE40 and Xilinx 7-series and write the resource counts to
//! verilog-out/RESOURCES.md (a test checks the committed file against a
//! fresh run).

use crate::Failure;
use gyrocal_hdl::export::VERILOG_FILE;
use gyrocal_verify::synthesis::{RESOURCES_FILE, write_resources};
use std::path::PathBuf;

/// Options of `gyrocal synth`.
#[derive(clap::Args)]
pub struct Args {
    /// Folder holding gyro_interface.v; RESOURCES.md is written there.
    #[arg(long, default_value = "verilog-out")]
    pub out: PathBuf,
}

/// Synthesize and write the resource table.
pub fn run(args: &Args) -> Result<(), Failure> {
    let verilog = args.out.join(VERILOG_FILE);
    if !verilog.is_file() {
        return Err(Failure::Input(format!(
            "{}: not found (run `gyrocal export` first)",
            verilog.display()
        )));
    }
    let target = args.out.join(RESOURCES_FILE);
    eprintln!(
        "synthesizing {} for iCE40 and Xilinx 7-series (about a minute)",
        verilog.display()
    );
    let reports = write_resources(&verilog, &target).map_err(|e| Failure::Run(e.to_string()))?;
    println!(
        "{:<16} {:>7} {:>7} {:>5} {:>5}  latches",
        "target", "LUT", "FF", "DSP", "BRAM"
    );
    for r in &reports {
        println!(
            "{:<16} {:>7} {:>7} {:>5} {:>5}  {}",
            r.target.name(),
            r.luts,
            r.ffs,
            r.dsps,
            r.brams,
            r.latches.len()
        );
    }
    eprintln!("wrote {}", target.display());
    Ok(())
}
