//! `verilator --lint-only -Wall` on the exported Verilog, with a committed
//! waiver file.
//!
//! rust-hdl's Verilog draws a few dozen `-Wall` warnings that are benign for
//! this design (32-bit literals in comparisons with narrower signals, sign
//! extension by `$signed` into wider registers, bits of intermediate sums
//! that are dropped on purpose, ...). They are waived one pattern at a time
//! in `verilog-out/lint-waivers.vlt`, a Verilator configuration file:
//!
//! ```text
//! `verilator_config
//! // <why this warning is benign here>
//! lint_off -rule WIDTH -file "*gyro_interface.v" -match "<the warning text, * and ? wildcards>"
//! ```
//!
//! [`parse_waivers`] insists that every `lint_off` names a file and a
//! `-match` pattern (no blanket waivers) and has a `//` comment right above
//! it giving the reason. [`waiver_usage`] finds stale waivers: it lints once
//! with each waiver removed and records which warnings reappear; a waiver
//! whose removal changes nothing is stale.

use crate::{ScratchDir, VerifyError, combined_output, describe, io_error, run, tail, tools};
use gyrocal_hdl::export::TOP_MODULE;
use regex::Regex;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// File name of the waiver file inside `verilog-out/`: the core's
/// warnings, in `gyro_interface.v` and in the copy of the core inside
/// `gyro_interface_axi.v`.
pub const WAIVER_FILE: &str = "lint-waivers.vlt";
/// File name of the bus wrapper's own waivers inside `verilog-out/`, read
/// after [`WAIVER_FILE`] when linting `gyro_interface_axi.v`.
pub const AXI_WAIVER_FILE: &str = "lint-waivers-axi.vlt";
/// The fine-carrier (ECP5) core's own waivers inside `verilog-out/`, read
/// after [`WAIVER_FILE`] when linting `ecp5/gyro_interface.v`.
pub const FINE_WAIVER_FILE: &str = "ecp5/lint-waivers.vlt";

/// One Verilator warning.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct LintWarning {
    /// The warning code, e.g. `WIDTH`.
    pub rule: String,
    /// The file it points into.
    pub file: String,
    /// Line number.
    pub line: u32,
    /// Column.
    pub column: u32,
    /// The message text (what a `-match` pattern is matched against).
    pub message: String,
}

impl std::fmt::Display for LintWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let file = Path::new(&self.file)
            .file_name()
            .map_or(self.file.clone(), |n| n.to_string_lossy().into_owned());
        write!(
            f,
            "%Warning-{}: {}:{}:{}: {}",
            self.rule, file, self.line, self.column, self.message
        )
    }
}

/// The outcome of one lint run.
#[derive(Clone, Debug)]
pub struct LintReport {
    /// Verilator's version line.
    pub tool_version: String,
    /// Warnings left after the waivers, in Verilator's order.
    pub warnings: Vec<LintWarning>,
    /// `%Error` lines (the file did not even parse, or a waiver is malformed).
    pub errors: Vec<String>,
    /// Everything Verilator printed.
    pub output: String,
    /// Wall time.
    pub wall: Duration,
}

impl LintReport {
    /// The warnings, then the errors, one per line (empty when clean).
    pub fn listing(&self) -> String {
        self.warnings
            .iter()
            .map(|w| w.to_string())
            .chain(self.errors.iter().cloned())
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// No warnings and no errors.
    pub fn is_clean(&self) -> bool {
        self.warnings.is_empty() && self.errors.is_empty()
    }
}

/// Lint `verilog` (top module `gyro_interface`) with `verilator --lint-only
/// -Wall`, reading `waivers` (a `.vlt` file) first if given.
pub fn lint(verilog: &Path, waivers: Option<&Path>) -> Result<LintReport, VerifyError> {
    lint_files(&[verilog], TOP_MODULE, waivers.as_slice())
}

/// Lint the design made of the files `verilog` with top module `top`,
/// reading the `waivers` files (in order) first.
pub fn lint_files(
    verilog: &[&Path],
    top: &str,
    waivers: &[&Path],
) -> Result<LintReport, VerifyError> {
    let verilator = tools::verilator()?;
    let tool_version = tools::version_line(&verilator, "--version", "Verilator")?;
    let dir = ScratchDir::new("lint").map_err(io_error("cannot create a scratch folder"))?;
    let mut cmd = Command::new(&verilator);
    cmd.current_dir(dir.path())
        .args(["--lint-only", "-Wall", "-Wno-fatal", "--top-module", top]);
    for w in waivers {
        cmd.arg(std::path::absolute(w).map_err(io_error("bad waiver path"))?);
    }
    for v in verilog {
        cmd.arg(std::path::absolute(v).map_err(io_error("bad Verilog path"))?);
    }
    let (out, wall) = run(&mut cmd)?;
    let output = combined_output(&out);
    let (warnings, errors) = parse_output(&output);
    if !out.status.success() && errors.is_empty() {
        return Err(VerifyError::ToolFailed {
            command: describe(&cmd),
            reason: format!("exited with {} without an %Error line", out.status),
            output: tail(&output, 60),
        });
    }
    Ok(LintReport {
        tool_version,
        warnings,
        errors,
        output,
        wall,
    })
}

fn parse_output(output: &str) -> (Vec<LintWarning>, Vec<String>) {
    let warning = Regex::new(r"^%Warning-([A-Z0-9_]+): (.+?):(\d+):(\d+): (.*)$").unwrap();
    let mut warnings = Vec::new();
    let mut errors = Vec::new();
    for line in output.lines() {
        if let Some(c) = warning.captures(line) {
            warnings.push(LintWarning {
                rule: c[1].to_owned(),
                file: c[2].to_owned(),
                line: c[3].parse().unwrap_or(0),
                column: c[4].parse().unwrap_or(0),
                message: c[5].to_owned(),
            });
        } else if line.starts_with("%Error") {
            errors.push(line.to_owned());
        }
    }
    (warnings, errors)
}

/// One `lint_off` line of a waiver file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Waiver {
    /// Line number in the file (1-based).
    pub line: usize,
    /// The directive as written.
    pub directive: String,
    /// The `-rule` value.
    pub rule: String,
    /// The `-match` pattern.
    pub pattern: String,
    /// The comment above it.
    pub reason: String,
}

/// A line of a waiver file that [`parse_waivers`] refuses, with the line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WaiverError {
    /// The line number (from 1).
    pub line: usize,
    /// What is wrong with it.
    pub fault: WaiverFault,
    /// The line's text, trimmed.
    pub text: String,
}

/// What is wrong with a waiver file's line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WaiverFault {
    /// A comment Verilator would read as a metacomment.
    Metacomment,
    /// Not `lint_off -rule R -file "F" -match "P"`.
    NotAWaiver,
    /// A waiver without a `//` comment directly above it.
    NoReason,
    /// A waiver whose pattern matches everything.
    Blanket,
}

impl std::fmt::Display for WaiverError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (n, line) = (self.line, &self.text);
        match self.fault {
            WaiverFault::Metacomment => write!(
                f,
                "line {n}: a comment starting with `verilator` is read as a Verilator metacomment: `{line}`"
            ),
            WaiverFault::NotAWaiver => write!(
                f,
                "line {n}: expected `lint_off -rule <RULE> -file \"<file>\" -match \"<pattern>\"`, found `{line}`"
            ),
            WaiverFault::NoReason => write!(
                f,
                "line {n}: waiver without a `//` comment giving its reason: `{line}`"
            ),
            WaiverFault::Blanket => write!(
                f,
                "line {n}: blanket waiver (empty -match pattern): `{line}`"
            ),
        }
    }
}

impl std::error::Error for WaiverError {}

/// The waivers of a `.vlt` file. Errors name the line: a `lint_off` without
/// `-rule`, `-file` or `-match`, one without a `//` comment directly above it,
/// or any other directive.
pub fn parse_waivers(text: &str) -> Result<Vec<Waiver>, WaiverError> {
    let directive = Regex::new(
        r#"^lint_off\s+-rule\s+([A-Z0-9_]+)\s+-file\s+"([^"]+)"\s+-match\s+"((?:[^"\\]|\\.)*)"\s*$"#,
    )
    .unwrap();
    let mut waivers = Vec::new();
    let mut comment: Vec<String> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        let n = i + 1;
        let refuse = |fault| WaiverError {
            line: n,
            fault,
            text: line.to_owned(),
        };
        if let Some(c) = line.strip_prefix("//") {
            if c.trim_start().to_ascii_lowercase().starts_with("verilator") {
                return Err(refuse(WaiverFault::Metacomment));
            }
            comment.push(c.trim().to_owned());
            continue;
        }
        if line.is_empty() || line == "`verilator_config" {
            comment.clear();
            continue;
        }
        let Some(c) = directive.captures(line) else {
            return Err(refuse(WaiverFault::NotAWaiver));
        };
        let reason = comment.join(" ");
        if reason.trim().is_empty() {
            return Err(refuse(WaiverFault::NoReason));
        }
        let pattern = c[3].to_owned();
        if pattern.trim_matches('*').is_empty() {
            return Err(refuse(WaiverFault::Blanket));
        }
        waivers.push(Waiver {
            line: n,
            directive: line.to_owned(),
            rule: c[1].to_owned(),
            pattern,
            reason,
        });
        comment.clear();
    }
    Ok(waivers)
}

/// A waiver and the warnings that reappear when it is removed.
#[derive(Clone, Debug)]
pub struct WaiverUse {
    /// The waiver.
    pub waiver: Waiver,
    /// Warnings it suppresses (empty: the waiver is stale).
    pub suppressed: Vec<LintWarning>,
}

/// For every waiver of `waivers`, lint `verilog` with that one waiver removed
/// and record the warnings that appear in addition to those of the full
/// waiver file. Runs the lints in parallel (about 0.3 s each).
pub fn waiver_usage(verilog: &Path, waivers: &Path) -> Result<Vec<WaiverUse>, VerifyError> {
    waiver_usage_top(verilog, TOP_MODULE, &[], waivers)
}

/// [`waiver_usage`] for top module `top`, with the waiver files `kept` read
/// in full before `waivers` in every lint.
pub fn waiver_usage_top(
    verilog: &Path,
    top: &str,
    kept: &[&Path],
    waivers: &Path,
) -> Result<Vec<WaiverUse>, VerifyError> {
    fn with<'a>(kept: &[&'a Path], last: &'a Path) -> Vec<&'a Path> {
        kept.iter().copied().chain(std::iter::once(last)).collect()
    }
    let text = std::fs::read_to_string(waivers)
        .map_err(io_error(format!("cannot read {}", waivers.display())))?;
    let parsed = parse_waivers(&text).map_err(|e| VerifyError::ToolFailed {
        command: format!("parse {}", waivers.display()),
        reason: e.to_string(),
        output: String::new(),
    })?;
    let baseline = lint_files(&[verilog], top, &with(kept, waivers))?;
    let dir = ScratchDir::new("waivers").map_err(io_error("cannot create a scratch folder"))?;
    let lines: Vec<&str> = text.lines().collect();
    let lint_without = |w: &Waiver| -> Result<WaiverUse, VerifyError> {
        let mut reduced = String::new();
        for (i, l) in lines.iter().enumerate() {
            if i + 1 != w.line {
                reduced.push_str(l);
                reduced.push('\n');
            }
        }
        let file = dir.path().join(format!("without-line-{}.vlt", w.line));
        std::fs::write(&file, reduced)
            .map_err(io_error(format!("cannot write {}", file.display())))?;
        let report = lint_files(&[verilog], top, &with(kept, &file))?;
        let suppressed = report
            .warnings
            .into_iter()
            .filter(|x| !baseline.warnings.contains(x))
            .collect();
        Ok(WaiverUse {
            waiver: w.clone(),
            suppressed,
        })
    };
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, 8);
    let mut results = Vec::with_capacity(parsed.len());
    for chunk in parsed.chunks(workers) {
        let chunk_results: Vec<_> = std::thread::scope(|s| {
            let handles: Vec<_> = chunk.iter().map(|w| s.spawn(|| lint_without(w))).collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("lint thread panicked"))
                .collect()
        });
        for r in chunk_results {
            results.push(r?);
        }
    }
    Ok(results)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn waiver_file_rules() {
        let ok = "`verilator_config\n// reason one\n// continued\nlint_off -rule WIDTH -file \"*x.v\" -match \"Operator EQ*\"\n";
        let w = parse_waivers(ok).unwrap();
        assert_eq!(w.len(), 1);
        assert_eq!((w[0].line, w[0].rule.as_str()), (4, "WIDTH"));
        assert_eq!(w[0].reason, "reason one continued");
        assert_eq!(w[0].pattern, "Operator EQ*");
        let fault = |text: &str| parse_waivers(text).unwrap_err().fault;
        let no_reason = "`verilator_config\nlint_off -rule WIDTH -file \"*x.v\" -match \"a\"\n";
        assert_eq!(fault(no_reason), WaiverFault::NoReason);
        let e = parse_waivers(no_reason).unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.to_string().contains("without a `//` comment"), "{e}");
        let blanket = "// why\nlint_off -rule WIDTH -file \"*x.v\" -match \"*\"\n";
        assert_eq!(fault(blanket), WaiverFault::Blanket);
        let no_match = "// why\nlint_off -rule WIDTH -file \"*x.v\"\n";
        assert_eq!(fault(no_match), WaiverFault::NotAWaiver);
        let gap = "// why\n\nlint_off -rule WIDTH -file \"*x.v\" -match \"a\"\n";
        assert_eq!(
            fault(gap),
            WaiverFault::NoReason,
            "a blank line separates the reason from its waiver"
        );
        let meta =
            "// Verilator waivers\n// why\nlint_off -rule WIDTH -file \"*x.v\" -match \"a\"\n";
        assert_eq!(fault(meta), WaiverFault::Metacomment);
    }

    #[test]
    fn warning_lines_are_parsed() {
        let out = "%Warning-WIDTH: /a/b.v:12:34: Operator EQ expects 32 bits on the LHS, but LHS's VARREF 'q' generates 2 bits.\n\
                   \x20  12 |   if (q == 32'h1)\n\
                   %Error: /a/b.v:1:1: syntax error\n";
        let (w, e) = parse_output(out);
        assert_eq!(w.len(), 1);
        assert_eq!(
            (w[0].rule.as_str(), w[0].line, w[0].column),
            ("WIDTH", 12, 34)
        );
        assert!(w[0].message.ends_with("generates 2 bits."));
        assert_eq!(e.len(), 1);
    }
}
