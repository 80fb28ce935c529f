//! Synthesis of the exported Verilog with Yosys: iCE40 (with DSPs) and
//! Xilinx 7-series, latch checks, and the resource report
//! `verilog-out/RESOURCES.md`.
//!
//! ```text
//!  gyro_interface.v ──► yosys: read_verilog; synth_ice40 -dsp -spram -top gyro_interface; stat; check
//!                   └─► yosys: read_verilog; synth_xilinx -flatten -top gyro_interface; stat; check
//!                              │
//!                              ▼
//!             SynthesisReport { cells, LUT, FF, DSP, BRAM, latches, problems, warnings }
//!                              │ resources_markdown()
//!                              ▼
//!                       verilog-out/RESOURCES.md, first section (crate::resources)
//! ```
//!
//! Each run copies the Verilog into its own scratch folder (so the log never
//! names an absolute path) and the two targets run in parallel threads. On a
//! 2-core machine the pair takes about a minute. Latches are found two ways:
//! Yosys's `proc_dlatch` logs "Latch inferred for signal ..." for each one
//! (iCE40 has no latch cell, so a latch would otherwise vanish into a LUT
//! loop), and latch cells (`$dlatch`, `$_DLATCH_*`, `LDCE`, `LDPE`) are looked
//! for in the final statistics. The numbers are Yosys's technology-mapped
//! estimates, before placement and routing.

use crate::{ScratchDir, VerifyError, combined_output, describe, io_error, run_ok, tail, tools};
use gyrocal_hdl::export::TOP_MODULE;
use regex::Regex;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// File name of the resource report inside `verilog-out/`.
pub const RESOURCES_FILE: &str = "RESOURCES.md";

/// An FPGA family Yosys synthesizes for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Target {
    /// Lattice iCE40 (`synth_ice40 -dsp -spram`: multipliers on `SB_MAC16`
    /// and the carrier tables on `SB_SPRAM256KA`, as on the UltraPlus parts).
    Ice40,
    /// Xilinx 7-series (`synth_xilinx -flatten`).
    Xilinx7,
}

/// Both targets, in report order.
pub const TARGETS: [Target; 2] = [Target::Ice40, Target::Xilinx7];

impl Target {
    /// Human-readable name.
    pub fn name(self) -> &'static str {
        match self {
            Target::Ice40 => "Lattice iCE40",
            Target::Xilinx7 => "Xilinx 7-series",
        }
    }

    /// The Yosys synthesis command.
    pub fn synth_command(self) -> String {
        match self {
            Target::Ice40 => format!("synth_ice40 -dsp -spram -top {TOP_MODULE}"),
            Target::Xilinx7 => format!("synth_xilinx -flatten -top {TOP_MODULE}"),
        }
    }

    fn is_lut(self, cell: &str) -> bool {
        match self {
            Target::Ice40 => cell == "SB_LUT4",
            Target::Xilinx7 => Regex::new(r"^LUT[1-6](_2)?$").unwrap().is_match(cell),
        }
    }

    fn is_ff(self, cell: &str) -> bool {
        match self {
            Target::Ice40 => cell.starts_with("SB_DFF"),
            Target::Xilinx7 => matches!(cell, "FDRE" | "FDSE" | "FDCE" | "FDPE"),
        }
    }

    fn is_dsp(self, cell: &str) -> bool {
        match self {
            Target::Ice40 => cell == "SB_MAC16",
            Target::Xilinx7 => cell.starts_with("DSP48"),
        }
    }

    fn is_bram(self, cell: &str) -> bool {
        match self {
            Target::Ice40 => cell.starts_with("SB_RAM40_4K") || cell == "SB_SPRAM256KA",
            Target::Xilinx7 => cell.starts_with("RAMB18") || cell.starts_with("RAMB36"),
        }
    }
}

/// Whether a cell type is a latch (generic Yosys cells or vendor latches).
pub fn is_latch_cell(cell: &str) -> bool {
    let c = cell.to_ascii_lowercase();
    c.contains("dlatch") || matches!(cell, "LDCE" | "LDPE" | "LD" | "LDC" | "LDP")
}

/// What Yosys made of the design for one target.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SynthesisReport {
    /// The target.
    pub target: Target,
    /// `yosys -V`.
    pub yosys_version: String,
    /// Count per cell type of the flattened top module.
    pub cells: BTreeMap<String, u64>,
    /// Look-up tables.
    pub luts: u64,
    /// Flip-flops.
    pub ffs: u64,
    /// DSP blocks.
    pub dsps: u64,
    /// Block RAMs (primitives).
    pub brams: u64,
    /// Latches: "Latch inferred" log lines and latch cells.
    pub latches: Vec<String>,
    /// Problems reported by the final `check`.
    pub check_problems: u64,
    /// Distinct warning lines of the log, in order.
    pub warnings: Vec<String>,
    /// Wall time of the Yosys run (not part of equality-relevant output).
    pub wall: Duration,
}

/// What Yosys's `check` says about a design before technology mapping.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StructuralCheck {
    /// Problems `check` reported (logic loops, multiple drivers, undriven
    /// wires used as inputs).
    pub problems: u64,
    /// The lines of `check.txt` naming them.
    pub listing: String,
}

/// `check` on the design made of the files `verilog` (top `top`) after
/// `hierarchy -check; proc; flatten; opt_clean`: the netlist bit by bit,
/// before any technology mapping, so a combinational loop across modules or
/// inside one `always` block shows, and so does a missing module or port.
pub fn structural_check(verilog: &[&Path], top: &str) -> Result<StructuralCheck, VerifyError> {
    let yosys = tools::yosys()?;
    let dir = ScratchDir::new("yosys-check").map_err(io_error("cannot create a scratch folder"))?;
    let mut files = Vec::new();
    for v in verilog {
        let path = std::path::absolute(v).map_err(io_error("bad Verilog path"))?;
        files.push(format!("\"{}\"", path.display()));
    }
    let script = format!(
        "read_verilog {}; hierarchy -check -top {top}; proc; flatten; opt_clean; \
         tee -o check.txt check",
        files.join(" ")
    );
    let mut cmd = Command::new(&yosys);
    cmd.current_dir(dir.path()).args(["-q", "-p", &script]);
    let (out, _) = run_ok(&mut cmd)?;
    let listing = std::fs::read_to_string(dir.path().join("check.txt")).map_err(|e| {
        VerifyError::ToolFailed {
            command: describe(&cmd),
            reason: format!("did not write check.txt: {e}"),
            output: tail(&combined_output(&out), 40),
        }
    })?;
    let problems = check_problem_count(&listing).ok_or_else(|| VerifyError::ToolFailed {
        command: describe(&cmd),
        reason: "`check` printed no problem count".into(),
        output: tail(&listing, 20),
    })?;
    Ok(StructuralCheck { problems, listing })
}

/// The count in `check`'s last "Found and reported N problems" line.
fn check_problem_count(check: &str) -> Option<u64> {
    Regex::new(r"Found and reported (\d+) problems")
        .unwrap()
        .captures_iter(check)
        .last()
        .and_then(|c| c[1].parse().ok())
}

/// Synthesize `verilog` (top `gyro_interface`) for `target`.
pub fn synthesize(verilog: &Path, target: Target) -> Result<SynthesisReport, VerifyError> {
    let yosys = tools::yosys()?;
    let yosys_version = tools::version_line(&yosys, "-V", "Yosys")?;
    let dir = ScratchDir::new("yosys").map_err(io_error("cannot create a scratch folder"))?;
    let local = dir.path().join(gyrocal_hdl::export::VERILOG_FILE);
    std::fs::copy(verilog, &local)
        .map_err(io_error(format!("cannot copy {}", verilog.display())))?;
    let script = format!(
        "read_verilog {file}; {synth}; tee -o stat.txt stat; tee -o check.txt check",
        file = gyrocal_hdl::export::VERILOG_FILE,
        synth = target.synth_command()
    );
    let mut cmd = Command::new(&yosys);
    cmd.current_dir(dir.path())
        .args(["-q", "-l", "yosys.log", "-p", &script]);
    let (out, wall) = run_ok(&mut cmd)?;
    let read = |name: &str| {
        std::fs::read_to_string(dir.path().join(name)).map_err(|e| VerifyError::ToolFailed {
            command: describe(&cmd),
            reason: format!("did not write {name}: {e}"),
            output: tail(&combined_output(&out), 40),
        })
    };
    let (log, stat, check) = (read("yosys.log")?, read("stat.txt")?, read("check.txt")?);
    let cells = parse_stat(&stat).map_err(|reason| VerifyError::ToolFailed {
        command: describe(&cmd),
        reason: reason.to_string(),
        output: tail(&stat, 40),
    })?;
    let check_problems = check_problem_count(&check).ok_or_else(|| VerifyError::ToolFailed {
        command: describe(&cmd),
        reason: "`check` printed no problem count".into(),
        output: tail(&check, 20),
    })?;
    let inferred = Regex::new(r"^\s*Latch inferred for signal").unwrap();
    let mut latches: Vec<String> = log
        .lines()
        .filter(|l| inferred.is_match(l))
        .map(|l| l.trim().to_owned())
        .collect();
    for (cell, n) in &cells {
        if is_latch_cell(cell) {
            latches.push(format!("{n} latch cells of type {cell}"));
        }
    }
    let mut warnings: Vec<String> = Vec::new();
    for l in log.lines().filter(|l| l.starts_with("Warning:")) {
        if !warnings.iter().any(|w| w == l) {
            warnings.push(l.to_owned());
        }
    }
    let count = |f: &dyn Fn(&str) -> bool| cells.iter().filter(|(c, _)| f(c)).map(|(_, n)| n).sum();
    Ok(SynthesisReport {
        target,
        yosys_version,
        luts: count(&|c| target.is_lut(c)),
        ffs: count(&|c| target.is_ff(c)),
        dsps: count(&|c| target.is_dsp(c)),
        brams: count(&|c| target.is_bram(c)),
        cells,
        latches,
        check_problems,
        warnings,
        wall,
    })
}

/// Why Yosys's `stat` output gives no cell counts.
#[derive(Clone, Debug, PartialEq, Eq)]
enum StatError {
    /// Not one module (how many): the flattened top was expected.
    Modules(usize),
    /// A count that is no number (the text).
    Count(String),
    /// No cell listed.
    NoCells,
}

impl std::fmt::Display for StatError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Modules(n) => write!(
                f,
                "`stat` lists {n} modules, expected the flattened top only"
            ),
            Self::Count(text) => write!(f, "`stat` cell count {text:?}: not a count"),
            Self::NoCells => write!(f, "`stat` lists no cells"),
        }
    }
}

/// Cell counts of the single (flattened) module in `stat` output.
fn parse_stat(stat: &str) -> Result<BTreeMap<String, u64>, StatError> {
    let modules = stat
        .lines()
        .filter(|l| l.trim_start().starts_with("=== "))
        .count();
    if modules != 1 {
        return Err(StatError::Modules(modules));
    }
    let cell_line = Regex::new(r"^\s+(\S+)\s+(\d+)$").unwrap();
    let mut cells = BTreeMap::new();
    let mut in_cells = false;
    for line in stat.lines() {
        if line.trim_start().starts_with("Number of cells:") {
            in_cells = true;
            continue;
        }
        if in_cells {
            match cell_line.captures(line) {
                Some(c) => {
                    cells.insert(
                        c[1].to_owned(),
                        c[2].parse::<u64>()
                            .map_err(|_| StatError::Count(c[2].to_owned()))?,
                    );
                }
                None => in_cells = false,
            }
        }
    }
    if cells.is_empty() {
        return Err(StatError::NoCells);
    }
    Ok(cells)
}

/// Synthesize for every target in [`TARGETS`], in parallel threads.
pub fn synthesize_all(verilog: &Path) -> Result<Vec<SynthesisReport>, VerifyError> {
    std::thread::scope(|s| {
        let handles: Vec<_> = TARGETS
            .iter()
            .map(|&t| s.spawn(move || synthesize(verilog, t)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("synthesis thread panicked"))
            .collect()
    })
}

/// The Yosys section of `RESOURCES.md`, with which the file starts, for
/// `reports` (deterministic: no times, no paths).
pub fn resources_markdown(reports: &[SynthesisReport]) -> String {
    let mut md = String::from(
        "# gyro_interface: FPGA resources\n\n\
         Yosys's estimate for `gyro_interface.v` beside this file, after technology\n\
         mapping and before placement and routing, then nextpnr's placement and\n\
         routing on an iCE40 UP5K and an ECP5 LFE5U-25F. Written by `gyrocal synth`;\n\
         the test `tests/verilog_synthesis.rs` re-runs Yosys and fails when this\n\
         section differs.\n\n",
    );
    let versions: Vec<&str> = reports.iter().map(|r| r.yosys_version.as_str()).collect();
    let _ = writeln!(md, "Tool: {}\n", versions.first().copied().unwrap_or("?"));
    md.push_str(
        "| target | Yosys command | LUT | FF | DSP | BRAM |\n\
         |---|---|---:|---:|---:|---:|\n",
    );
    for r in reports {
        let _ = writeln!(
            md,
            "| {} | `{}` | {} | {} | {} | {} |",
            r.target.name(),
            r.target.synth_command(),
            r.luts,
            r.ffs,
            r.dsps,
            r.brams
        );
    }
    md.push_str(
        "\nLUT: `SB_LUT4` (iCE40), `LUT1`..`LUT6` (Xilinx). FF: `SB_DFF*`, `FD*E`.\n\
         DSP: `SB_MAC16`, `DSP48E1`. BRAM: `SB_RAM40_4K` (4 kbit) and `SB_SPRAM256KA` (256 kbit), `RAMB18E1`/`RAMB36E1`.\n\n",
    );
    for r in reports {
        let latches = if r.latches.is_empty() {
            "no latches".to_owned()
        } else {
            format!("{} LATCHES", r.latches.len())
        };
        let _ = writeln!(
            md,
            "{}: {latches}; final `check`: {} problems.",
            r.target.name(),
            r.check_problems
        );
    }
    for r in reports {
        let _ = write!(
            md,
            "\n## {}: all cells\n\n| cell | count |\n|---|---:|\n",
            r.target.name()
        );
        for (cell, n) in &r.cells {
            let _ = writeln!(md, "| `{cell}` | {n} |");
        }
        if !r.latches.is_empty() {
            md.push_str("\nLatches:\n\n");
            for l in &r.latches {
                let _ = writeln!(md, "- {l}");
            }
        }
        if !r.warnings.is_empty() {
            let _ = write!(md, "\nYosys warnings:\n\n");
            for w in &r.warnings {
                let _ = writeln!(md, "- `{w}`");
            }
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_parsing() {
        let stat = "\n3. Printing statistics.\n\n=== gyro_interface ===\n\n   Number of wires:   12\n   Number of cells:   10\n     SB_DFF   3\n     SB_LUT4  7\n\n";
        let cells = parse_stat(stat).unwrap();
        assert_eq!(cells.len(), 2);
        assert_eq!(cells["SB_LUT4"], 7);
        assert_eq!(
            parse_stat("=== a ===\n=== b ===\n"),
            Err(StatError::Modules(2))
        );
    }

    #[test]
    fn latch_cells_are_recognized() {
        for c in [
            "$dlatch",
            "$_DLATCH_P_",
            "$_DLATCH_NP0_",
            "LDCE",
            "LDPE",
            "$adlatch",
        ] {
            assert!(is_latch_cell(c), "{c}");
        }
        for c in ["SB_DFF", "FDRE", "SB_LUT4", "$dff"] {
            assert!(!is_latch_cell(c), "{c}");
        }
    }

    #[test]
    fn resource_classes() {
        assert!(Target::Xilinx7.is_lut("LUT6") && !Target::Xilinx7.is_lut("LUT7"));
        assert!(Target::Ice40.is_ff("SB_DFFESR") && Target::Xilinx7.is_ff("FDRE"));
        assert!(Target::Ice40.is_dsp("SB_MAC16") && Target::Xilinx7.is_dsp("DSP48E1"));
        assert!(Target::Ice40.is_bram("SB_RAM40_4K") && Target::Xilinx7.is_bram("RAMB36E1"));
    }
}
