//! `verilator --lint-only -Wall` on the committed `verilog-out/gyro_interface.v`
//! with the committed waivers `verilog-out/lint-waivers.vlt`.
//!
//! Requires Verilator on PATH (Debian package `verilator`); without it the
//! tests fail with that message, they are never skipped. About 5 s.

use gyrocal_verify::{self as verify, lint};

fn verilator_present() {
    if let Err(e) = verify::tools::verilator() {
        panic!("{e}");
    }
}

#[test]
fn exported_verilog_is_lint_clean_with_the_waivers() {
    verilator_present();
    let report = lint::lint(
        &verify::committed_verilog(),
        Some(&verify::committed_waivers()),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let listing: Vec<String> = report.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        report.is_clean(),
        "{} ({}): {} warnings and {} errors left after the waivers; fix the design or, if benign, \
         add a narrow waiver with its reason to verilog-out/lint-waivers.vlt:\n{}\n{}",
        report.tool_version,
        verify::committed_verilog().display(),
        report.warnings.len(),
        report.errors.len(),
        listing.join("\n"),
        report.errors.join("\n")
    );
}

#[test]
fn lint_without_waivers_does_find_warnings() {
    // The clean result above must come from the waivers, not from a lint that
    // sees nothing (wrong file, wrong top, warnings not parsed).
    verilator_present();
    let report = lint::lint(&verify::committed_verilog(), None).unwrap_or_else(|e| panic!("{e}"));
    assert!(report.errors.is_empty(), "{}", report.errors.join("\n"));
    assert!(
        report.warnings.iter().any(|w| w.rule == "WIDTH"),
        "-Wall found no WIDTH warning in rust-hdl's output:\n{}",
        report.output
    );
}

#[test]
fn every_waiver_has_a_reason_and_is_narrow() {
    let path = verify::committed_waivers();
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let waivers = lint::parse_waivers(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(!waivers.is_empty());
    for w in &waivers {
        assert!(
            w.reason.split_whitespace().count() >= 5,
            "line {}: the reason `{}` is too short to explain anything",
            w.line,
            w.reason
        );
        assert!(
            !w.pattern.starts_with('*'),
            "line {}: pattern must start with the warning text",
            w.line
        );
    }
}

#[test]
fn no_waiver_is_stale() {
    verilator_present();
    let uses = lint::waiver_usage(&verify::committed_verilog(), &verify::committed_waivers())
        .unwrap_or_else(|e| panic!("{e}"));
    for u in &uses {
        eprintln!(
            "{:3} x {} | {}",
            u.suppressed.len(),
            u.waiver.rule,
            u.waiver.pattern
        );
    }
    let stale: Vec<String> = uses
        .iter()
        .filter(|u| u.suppressed.is_empty())
        .map(|u| format!("line {}: {}", u.waiver.line, u.waiver.directive))
        .collect();
    assert!(
        stale.is_empty(),
        "stale waivers (they suppress nothing; remove them):\n{}",
        stale.join("\n")
    );
    for u in &uses {
        for w in &u.suppressed {
            assert_eq!(
                w.rule, u.waiver.rule,
                "removing waiver on line {} brought back a warning of another rule: {w}",
                u.waiver.line
            );
        }
    }
}

#[test]
fn stale_waiver_detection_works() {
    // Negative control: of a live waiver and one matching nothing, only the
    // second is reported stale.
    verilator_present();
    let dir = verify::ScratchDir::new("stale-control").unwrap();
    let file = dir.path().join("waivers.vlt");
    std::fs::write(
        &file,
        "`verilator_config\n\
         // Live: the sincos quadrant compare with a 32-bit literal.\n\
         lint_off -rule WIDTH -file \"*gyro_interface.v\" -match \"Operator EQ expects 32 bits on the LHS, but LHS's VARREF 'quadrant_3$q' generates 2 bits.\"\n\
         // Stale: there is no signal of this name in the design.\n\
         lint_off -rule WIDTH -file \"*gyro_interface.v\" -match \"Operator EQ expects 32 bits on the LHS, but LHS's VARREF 'no_such_signal' generates 2 bits.\"\n",
    )
    .unwrap();
    let uses =
        lint::waiver_usage(&verify::committed_verilog(), &file).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(uses.len(), 2);
    assert!(!uses[0].suppressed.is_empty(), "live waiver reported stale");
    assert!(
        uses[0]
            .suppressed
            .iter()
            .all(|w| w.message.contains("'quadrant_3$q'"))
    );
    assert!(uses[1].suppressed.is_empty(), "stale waiver not detected");
}
