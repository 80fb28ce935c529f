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
//! it giving the reason. [`waiver_usage`] finds stale waivers: the warnings
//! that would reappear with a waiver removed are those it matches and no
//! other waiver does, read off one lint without any waiver; a waiver that
//! alone matches none is stale.

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
    /// The command line that ran it.
    pub command: String,
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
        command: describe(&cmd),
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
    /// The `-file` pattern.
    pub file: String,
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
            file: c[2].to_owned(),
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

/// For every waiver of `waivers`, the warnings on `verilog` that appear
/// with that one waiver removed (in addition to those of the full waiver
/// file): empty, the waiver is stale.
pub fn waiver_usage(verilog: &Path, waivers: &Path) -> Result<Vec<WaiverUse>, VerifyError> {
    waiver_usage_top(verilog, TOP_MODULE, &[], waivers)
}

/// [`waiver_usage`] for top module `top`, with the waiver files `kept` read
/// in full before `waivers` in every lint.
///
/// Verilator prints a warning exactly when no `lint_off` matches it (its
/// rule, its file against `-file` and its text against `-match`, `*` and
/// `?` wildcards). So the warnings that reappear without waiver w are
/// those of a lint without any waiver that w matches and no other waiver
/// does: two lints, where removing each waiver in turn took one lint per
/// waiver (120 lints, 85 s of CPU, for the three waiver files of the
/// export). The second lint, with every waiver, holds the matcher to
/// Verilator: the warnings it leaves must be exactly those no waiver
/// matches, or this is an error naming the first that differs.
pub fn waiver_usage_top(
    verilog: &Path,
    top: &str,
    kept: &[&Path],
    waivers: &Path,
) -> Result<Vec<WaiverUse>, VerifyError> {
    let read = |path: &Path| -> Result<Vec<Waiver>, VerifyError> {
        let text = std::fs::read_to_string(path)
            .map_err(io_error(format!("cannot read {}", path.display())))?;
        parse_waivers(&text).map_err(|e| VerifyError::ToolFailed {
            command: format!("parse {}", path.display()),
            reason: e.to_string(),
            output: String::new(),
        })
    };
    let tested = read(waivers)?;
    let mut others = Vec::new();
    for path in kept {
        others.extend(read(path)?);
    }
    let bare = lint_files(&[verilog], top, &[])?;
    let files: Vec<&Path> = kept.iter().copied().chain([waivers]).collect();
    let full = lint_files(&[verilog], top, &files)?;
    // Per warning of the bare lint, the waivers (of `others` then
    // `tested`) that match it.
    let all: Vec<&Waiver> = others.iter().chain(&tested).collect();
    let matching: Vec<Vec<usize>> = bare
        .warnings
        .iter()
        .map(|x| (0..all.len()).filter(|&k| all[k].matches(x)).collect())
        .collect();
    let only = |matched: &[usize]| -> Vec<LintWarning> {
        bare.warnings
            .iter()
            .zip(&matching)
            .filter(|(_, m)| m.as_slice() == matched)
            .map(|(x, _)| x.clone())
            .collect()
    };
    let unmatched = only(&[]);
    if let Some(differs) = disagreement(&unmatched, &full.warnings) {
        return Err(VerifyError::ToolFailed {
            command: full.command,
            reason: format!("the waiver matcher disagrees with Verilator: {differs}"),
            output: String::new(),
        });
    }
    let usage = tested
        .iter()
        .enumerate()
        .map(|(i, w)| WaiverUse {
            waiver: w.clone(),
            suppressed: only(&[others.len() + i]),
        })
        .collect();
    Ok(usage)
}

/// Where the warnings the matcher leaves (`unmatched`) differ from those
/// Verilator leaves with every waiver (`left`): the first pair that
/// differs, or the counts; `None` when they are the same.
fn disagreement(unmatched: &[LintWarning], left: &[LintWarning]) -> Option<String> {
    if unmatched == left {
        return None;
    }
    let first = unmatched.iter().zip(left).find(|(a, b)| a != b);
    Some(match first {
        Some((a, b)) => format!("matcher leaves `{a}`, Verilator `{b}`"),
        None => format!(
            "matcher leaves {} warnings, Verilator {}",
            unmatched.len(),
            left.len()
        ),
    })
}

impl Waiver {
    /// Whether this `lint_off` suppresses `warning`: the same rule, the
    /// file against `-file`, the text against `-match`.
    pub fn matches(&self, warning: &LintWarning) -> bool {
        self.rule == warning.rule
            && wildmatch(&warning.file, &self.file)
            && wildmatch(&warning.message, &self.pattern)
    }
}

/// Verilator's wildcard match (`VString::wildmatch`): `*` any run of
/// characters, `?` any one, everything else itself.
pub fn wildmatch(text: &str, pattern: &str) -> bool {
    let (t, p): (Vec<char>, Vec<char>) = (text.chars().collect(), pattern.chars().collect());
    // Greedy with one backtrack point, the last `*`.
    let (mut i, mut j) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while i < t.len() {
        if j < p.len() && (p[j] == '?' || p[j] == t[i]) {
            i += 1;
            j += 1;
        } else if j < p.len() && p[j] == '*' {
            star = Some((j, i));
            j += 1;
        } else if let Some((sj, si)) = star {
            star = Some((sj, si + 1));
            (i, j) = (si + 1, sj + 1);
        } else {
            return false;
        }
    }
    p[j..].iter().all(|&c| c == '*')
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_matcher_that_disagrees_with_verilator_is_named() {
        let warning = |name: &str| LintWarning {
            rule: "UNUSEDSIGNAL".into(),
            file: "/r/gyro_interface.v".into(),
            line: 7,
            column: 3,
            message: format!("Signal is not used: '{name}'"),
        };
        let (a, b) = (warning("a"), warning("b"));
        let one = std::slice::from_ref(&a);
        assert_eq!(disagreement(one, one), None);
        assert_eq!(disagreement(&[], &[]), None);
        assert_eq!(
            disagreement(one, &[b]).unwrap(),
            "matcher leaves `%Warning-UNUSEDSIGNAL: gyro_interface.v:7:3: Signal is not used: 'a'`, \
             Verilator `%Warning-UNUSEDSIGNAL: gyro_interface.v:7:3: Signal is not used: 'b'`"
        );
        // A waiver the matcher reads too widely: Verilator leaves a
        // warning the matcher thought suppressed.
        assert_eq!(
            disagreement(&[], one).unwrap(),
            "matcher leaves 0 warnings, Verilator 1"
        );
    }

    #[test]
    fn wildcards_match_as_verilators() {
        for (text, pattern, expected) in [
            ("Signal is not used: 'a'", "Signal is not used: 'a'", true),
            ("Signal is not used: 'a'", "Signal is not used: 'b'", false),
            ("Signal is not used: 'ab'", "Signal is not used: 'a'", false),
            (
                "Bits of signal are not used: 'x'[7:0]",
                "Bits of*'x'[?:0]",
                true,
            ),
            (
                "Bits of signal are not used: 'x'[17:0]",
                "Bits of*'x'[?:0]",
                false,
            ),
            (
                "/r/verilog-out/gyro_interface.v",
                "*gyro_interface*.v",
                true,
            ),
            (
                "/r/verilog-out/gyro_interface_axi.v",
                "*gyro_interface*.v",
                true,
            ),
            (
                "/r/verilog-out/gyro_interface.sv",
                "*gyro_interface*.v",
                false,
            ),
            ("aXbXc", "*X*X*", true),
            ("aXb", "*X*X*", false),
            ("", "*", true),
            ("", "?", false),
        ] {
            assert_eq!(wildmatch(text, pattern), expected, "{text} ~ {pattern}");
        }
    }

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
