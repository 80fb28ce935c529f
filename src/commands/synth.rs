//! `gyrocal synth`: synthesize verilog-out/gyro_interface.v with Yosys for
//! iCE40 and Xilinx 7-series, place and route it with nextpnr on an iCE40
//! UP5K and an ECP5 LFE5U-25F (inside a pin-limited wrapper), and write
//! every figure to verilog-out/RESOURCES.md (tests check the committed file
//! against a fresh run). `--part KEY` places and routes on the named parts
//! only and prints the figures without writing anything.

use crate::Failure;
use gyrocal_hdl::export::VERILOG_FILE;
use gyrocal_verify::pnr::{self, Outcome, PnrReport};
use gyrocal_verify::resources::{pnr_core, write_resources};
use gyrocal_verify::synthesis::RESOURCES_FILE;
use gyrocal_verify::targets;
use std::path::PathBuf;

/// Options of `gyrocal synth`.
#[derive(clap::Args)]
pub struct Args {
    /// Folder holding gyro_interface.v; RESOURCES.md is written there.
    #[arg(long, default_value = "verilog-out")]
    pub out: PathBuf,
    /// Only place and route on this part (repeatable; ice40-up5k, ecp5-25f,
    /// ecp5-45f) and print the figures; RESOURCES.md is left alone.
    #[arg(long = "part", value_name = "KEY")]
    pub parts: Vec<String>,
}

/// Synthesize, place and route, and write (or print) the figures.
pub fn run(args: &Args) -> Result<(), Failure> {
    let verilog = args.out.join(VERILOG_FILE);
    if !verilog.is_file() {
        return Err(Failure::Input(format!(
            "{}: not found (run `gyrocal export` first)",
            verilog.display()
        )));
    }
    let parts = args
        .parts
        .iter()
        .map(|k| {
            pnr::part(k).ok_or_else(|| {
                Failure::Input(format!(
                    "--part {k}: unknown part; allowed: ice40-up5k, ecp5-25f, ecp5-45f"
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    if !parts.is_empty() {
        eprintln!("placing and routing {} (minutes)", verilog.display());
        let reports = pnr::place_and_route_all(&|p| pnr_core(&args.out, p), &parts)
            .map_err(|e| Failure::Run(e.to_string()))?;
        print_pnr(&reports);
        return Ok(());
    }
    let target = args.out.join(RESOURCES_FILE);
    eprintln!(
        "synthesizing {} for iCE40 and Xilinx 7-series, placing and routing on iCE40 UP5K \
         and ECP5 25F (several minutes)",
        verilog.display()
    );
    let (yosys, pnr) = write_resources(&args.out).map_err(|e| Failure::Run(e.to_string()))?;
    println!(
        "{:<16} {:>7} {:>7} {:>5} {:>5}  latches",
        "target", "LUT", "FF", "DSP", "BRAM"
    );
    for r in &yosys {
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
    print_pnr(&pnr);
    eprintln!("wrote {}", target.display());
    Ok(())
}

/// One block per part: uses, Fmax, critical path, target.
fn print_pnr(reports: &[PnrReport]) {
    for r in reports {
        println!(
            "{} ({} {})",
            r.part.name, r.nextpnr_version, r.yosys_version
        );
        for u in &r.uses {
            println!("  {:<6} {:>6} / {:<6}", u.label, u.used, u.available);
        }
        match &r.outcome {
            Outcome::DoesNotFit(e) => println!("  does not fit: {e}"),
            Outcome::Routed {
                fmax,
                critical_path,
            } => {
                println!(
                    "  Fmax {:.2} MHz at --freq {} (seed {})",
                    fmax.mhz,
                    r.part.freq_mhz,
                    pnr::SEED
                );
                if let Some(p) = critical_path {
                    println!(
                        "  critical path {:.1} ns logic + {:.1} ns routing: {} -> {}",
                        p.logic_ns, p.routing_ns, p.from, p.to
                    );
                }
            }
        }
        if let Some(t) = targets::target_of(r.part.key) {
            println!("  target met: {}", targets::verdict(r, t));
        }
        eprintln!(
            "  synthesis {:.1?}, place and route {:.1?}",
            r.wall.0, r.wall.1
        );
    }
}
