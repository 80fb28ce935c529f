//! `verilator --lint-only -Wall` on the committed `verilog-out/gyro_interface.v`
//! with the committed waivers `verilog-out/lint-waivers.vlt`, and on the
//! bus-attached `verilog-out/gyro_interface_axi.v` with those plus the
//! wrapper's own `verilog-out/lint-waivers-axi.vlt`; Yosys's `check` on the
//! bus-attached top, bit by bit, for the loops Verilator's UNOPTFLAT hints at.
//!
//! Requires Verilator and Yosys on PATH (Debian packages `verilator`,
//! `yosys`); without them the tests fail with that message, they are never
//! skipped. About 15 s.

use gyrocal_hdl::export::{AXI_TOP_MODULE, TOP_MODULE};
use gyrocal_verify::{self as verify, lint, synthesis};

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
    assert!(
        report.is_clean(),
        "{} ({}): {} warnings and {} errors left after the waivers; fix the design or, if benign, \
         add a narrow waiver with its reason to verilog-out/lint-waivers.vlt:\n{}",
        report.tool_version,
        verify::committed_verilog().display(),
        report.warnings.len(),
        report.errors.len(),
        report.listing()
    );
}

#[test]
fn the_fine_core_is_lint_clean_with_the_waivers() {
    // The ECP5 core: the core's waivers plus its own leaves' in
    // ecp5/lint-waivers.vlt, each of which must still suppress a warning.
    verilator_present();
    let path = verify::committed_fine_verilog();
    let report = lint::lint_files(
        &[&path],
        TOP_MODULE,
        &[
            &verify::committed_waivers(),
            &verify::committed_fine_waivers(),
        ],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        report.is_clean(),
        "{}: {} warnings and {} errors left after the waivers; fix the design or, if benign, \
         add a narrow waiver with its reason to verilog-out/ecp5/lint-waivers.vlt:\n{}",
        path.display(),
        report.warnings.len(),
        report.errors.len(),
        report.listing()
    );
    let uses = lint::waiver_usage_top(
        &path,
        TOP_MODULE,
        &[&verify::committed_waivers()],
        &verify::committed_fine_waivers(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_no_stale(&uses);
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
    for path in [
        verify::committed_waivers(),
        verify::committed_axi_waivers(),
        verify::committed_fine_waivers(),
    ] {
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let waivers =
            lint::parse_waivers(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(!waivers.is_empty());
        for w in &waivers {
            assert!(
                w.reason.split_whitespace().count() >= 5,
                "{} line {}: the reason `{}` is too short to explain anything",
                path.display(),
                w.line,
                w.reason
            );
            assert!(
                !w.pattern.starts_with('*'),
                "{} line {}: pattern must start with the warning text",
                path.display(),
                w.line
            );
        }
    }
}

/// Fails on a waiver that suppresses nothing (`lint::waiver_usage_top`:
/// no warning that it alone matches, its matcher held to Verilator's own
/// lint with every waiver).
fn assert_no_stale(uses: &[lint::WaiverUse]) {
    for u in uses {
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
}

#[test]
fn no_waiver_is_stale() {
    verilator_present();
    let uses = lint::waiver_usage(&verify::committed_verilog(), &verify::committed_waivers())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_no_stale(&uses);
}

#[test]
fn bus_attached_verilog_is_lint_clean_with_the_waivers() {
    verilator_present();
    let report = lint::lint_files(
        &[&verify::committed_axi_verilog()],
        AXI_TOP_MODULE,
        &[
            &verify::committed_waivers(),
            &verify::committed_axi_waivers(),
        ],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        report.is_clean(),
        "{}: {} warnings and {} errors left after the waivers; fix the wrapper or, if benign, \
         add a narrow waiver with its reason to verilog-out/lint-waivers-axi.vlt:\n{}",
        verify::committed_axi_verilog().display(),
        report.warnings.len(),
        report.errors.len(),
        report.listing()
    );
}

#[test]
fn no_bus_wrapper_waiver_is_stale() {
    verilator_present();
    let uses = lint::waiver_usage_top(
        &verify::committed_axi_verilog(),
        AXI_TOP_MODULE,
        &[&verify::committed_waivers()],
        &verify::committed_axi_waivers(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_no_stale(&uses);
}

#[test]
fn bus_attached_top_has_no_combinational_loop() {
    // Verilator flags UNOPTFLAT on the wrapper (waived, with this test as
    // the reason): rust-hdl's one combinational block per module is ordered
    // as a whole. Yosys checks the flattened netlist bit by bit: no logic
    // loop, no multiple or missing driver.
    if let Err(e) = verify::tools::yosys() {
        panic!("{e}");
    }
    let check = synthesis::structural_check(&[&verify::committed_axi_verilog()], AXI_TOP_MODULE)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(check.problems, 0, "Yosys check:\n{}", check.listing);
}

#[test]
fn the_structural_check_finds_a_loop() {
    // Negative control: a two-gate loop through an always block is reported.
    let dir = verify::ScratchDir::new("loop-control").unwrap();
    let file = dir.path().join("looped.v");
    std::fs::write(
        &file,
        "module looped(input wire a, output reg y);\n\
         reg b;\n\
         always @(*) begin b = a ^ y; y = ~b; end\n\
         endmodule\n",
    )
    .unwrap();
    let check = synthesis::structural_check(&[&file], "looped").unwrap_or_else(|e| panic!("{e}"));
    assert!(check.problems > 0, "no loop found:\n{}", check.listing);
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
         // Live: the CIC counter compare with a 32-bit literal.\n\
         lint_off -rule WIDTH -file \"*gyro_interface.v\" -match \"Operator EQ expects 32 bits on the LHS, but LHS's VARREF 'count$q' generates 13 bits.\"\n\
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
            .all(|w| w.message.contains("'count$q'"))
    );
    assert!(uses[1].suppressed.is_empty(), "stale waiver not detected");
}
