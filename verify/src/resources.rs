//! `verilog-out/RESOURCES.md`: Yosys's counts ([`crate::synthesis`]) first,
//! then the place-and-route section written here from [`PnrReport`]s.
//!
//! Both sections are deterministic (no times, no paths): the tests re-run
//! the tools and compare, `tests/verilog_synthesis.rs` the first section
//! (the file starts with it), `tests/verilog_pnr.rs` the second (the file
//! ends with it).

use crate::pnr::{
    Family, Outcome, PARTS, Part, PnrReport, SEED, nextpnr_args, place_and_route_all,
};
use crate::synthesis::{RESOURCES_FILE, SynthesisReport, resources_markdown, synthesize_all};
use crate::targets;
use crate::wrapper::Core;
use crate::wrapper::{CLOCK_PIN, FOLD_FAN_IN, FOLD_PIN, SETTINGS_PIN, WRAPPER_MODULE};
use crate::{VerifyError, io_error};
use gyrocal_hdl::model::gyro_interface::CarrierProfile;
use std::fmt::Write as _;
use std::path::Path;

/// The core that `RESOURCES.md` places and routes on `part`, from the
/// exported files in `verilog_out`: the bus-attached top
/// `gyro_interface_axi`, which is what a user drops in and what the targets
/// of issue 8 apply to (the Yosys section above still counts the bare
/// `gyro_interface`). An iCE40 gets the table core; an ECP5 the
/// fine-carrier core of `ecp5/` (`CarrierProfile::Fine`), which needs
/// block RAM with contents and multipliers the iCE40 UltraPlus lacks.
pub fn pnr_core(verilog_out: &Path, part: &Part) -> Core {
    let profile = match part.family {
        Family::Ice40 => CarrierProfile::Table,
        Family::Ecp5 => CarrierProfile::Fine,
    };
    Core::gyro_interface_axi(verilog_out.join(gyrocal_hdl::export::axi_verilog_file(profile)))
}

/// Synthesize (Yosys's counts) and place and route ([`pnr_core`] on
/// [`PARTS`]) the export in `verilog_out`, all at once, and write the whole
/// `RESOURCES.md` there atomically: nothing is written unless every run
/// produced its figures.
pub fn write_resources(
    verilog_out: &Path,
) -> Result<(Vec<SynthesisReport>, Vec<PnrReport>), VerifyError> {
    let verilog = verilog_out.join(gyrocal_hdl::export::VERILOG_FILE);
    let (yosys, pnr) = std::thread::scope(|s| {
        let yosys = s.spawn(|| synthesize_all(&verilog));
        let pnr = place_and_route_all(&|p| pnr_core(verilog_out, p), &PARTS);
        (yosys.join().expect("synthesis thread panicked"), pnr)
    });
    let (yosys, pnr) = (yosys?, pnr?);
    let out = verilog_out.join(RESOURCES_FILE);
    crate::write_atomically(&out, markdown(&yosys, &pnr))
        .map_err(io_error(format!("cannot write {}", out.display())))?;
    Ok((yosys, pnr))
}

/// The whole `RESOURCES.md`.
pub fn markdown(yosys: &[SynthesisReport], pnr: &[PnrReport]) -> String {
    resources_markdown(yosys) + &pnr_section(pnr)
}

fn percent(used: u64, available: u64) -> String {
    if available == 0 {
        "-".to_owned()
    } else {
        format!("{:.0}%", 100.0 * used as f64 / available as f64)
    }
}

/// The place-and-route section of `RESOURCES.md` for `reports`.
pub fn pnr_section(reports: &[PnrReport]) -> String {
    let mut md = String::from("\n# Place and route\n\n");
    let (chain, ffs, luts) = reports.first().map_or((0, 0, 0), |r| {
        (r.wrapper_chain_bits, r.wrapper_flip_flops, r.wrapper_luts)
    });
    let core = reports.first().map_or("", |r| r.core_module.as_str());
    let _ = write!(
        md,
        "nextpnr's result for `{core}` inside the pin-limited wrapper `{WRAPPER_MODULE}`\n\
         (`verify/src/wrapper.rs`): its {chain} input bits shift in from the pin `{SETTINGS_PIN}`\n\
         through a chain of flip-flops, its outputs are XOR-folded, {FOLD_FAN_IN} bits per\n\
         registered LUT, into the pin `{FOLD_PIN}`, and `{CLOCK_PIN}` is the clock. Nothing can be\n\
         optimized away and every timed path runs from register to register. The counts\n\
         include the wrapper's {ffs} flip-flops and {luts} fold LUTs. Seed {SEED} on every part,\n\
         `--timing-allow-fail` (a missed frequency is reported, not an error). The iCE40 runs\n\
         the table core (`gyro_interface_axi.v`), the ECP5 the fine-carrier core\n\
         (`ecp5/gyro_interface_axi.v`, same ports and registers). Written by\n\
         `gyrocal synth`; the test `tests/verilog_pnr.rs` re-runs the flow and fails when\n\
         this section differs.\n\n"
    );
    md.push_str(
        "| part | fits | Fmax (MHz) | `--freq` (MHz) | target met |\n|---|---|---:|---:|---|\n",
    );
    for r in reports {
        let fmax = r.fmax_mhz().map_or("-".to_owned(), |f| format!("{f:.2}"));
        let met = targets::target_of(r.part.key)
            .map_or("(no target)".to_owned(), |t| targets::verdict(r, t));
        let fits = if r.fits() { "yes" } else { "**no**" };
        let _ = writeln!(
            md,
            "| {} | {fits} | {fmax} | {} | {met} |",
            r.part.name, r.part.freq_mhz
        );
    }
    for r in reports {
        part_details(&mut md, r);
    }
    md
}

fn part_details(md: &mut String, r: &PnrReport) {
    let _ = write!(
        md,
        "\n## {}\n\n| resource | used | available | use |\n|---|---:|---:|---:|\n",
        r.part.name
    );
    for u in &r.uses {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} |",
            u.label,
            u.used,
            u.available,
            percent(u.used, u.available)
        );
    }
    let pins: Vec<String> = [CLOCK_PIN, SETTINGS_PIN, FOLD_PIN]
        .iter()
        .zip(r.part.pins)
        .map(|(n, s)| format!("`{n}` {s}"))
        .collect();
    let _ = write!(
        md,
        "\n- Core: `{}` in `{}`.\n- Tools: {}; {}.\n- Synthesis: `{}`.\n- Place and route: `{} {}`.\n- Pins: {}.\n",
        r.core_module,
        r.core_files.join("`, `"),
        r.yosys_version,
        r.nextpnr_version,
        r.part.synth_command(),
        r.part.nextpnr_program(),
        nextpnr_args(&r.part).join(" "),
        pins.join(", ")
    );
    match &r.outcome {
        Outcome::DoesNotFit(error) => {
            let _ = writeln!(md, "- Does not fit; nextpnr stopped with: `{error}`");
        }
        Outcome::Routed {
            fmax,
            critical_path,
        } => {
            let _ = writeln!(
                md,
                "- Fmax {:.2} MHz (clock `{}`, constraint {:.2} MHz).",
                fmax.mhz, fmax.clock, fmax.constraint_mhz
            );
            if let Some(p) = critical_path {
                let _ = writeln!(
                    md,
                    "- Critical path: {:.1} ns logic + {:.1} ns routing, from `{}` to `{}`.",
                    p.logic_ns, p.routing_ns, p.from, p.to
                );
            }
        }
    }
}
