//! Yosys synthesis of the committed `verilog-out/gyro_interface.v` for iCE40
//! (`synth_ice40 -dsp -spram`) and Xilinx 7-series (`synth_xilinx -flatten`): no
//! latches, a clean `check`, and `verilog-out/RESOURCES.md` starting with
//! what Yosys reports now (its place-and-route section is checked by
//! `tests/verilog_pnr.rs`).
//!
//! Requires `yosys` on PATH (Debian package `yosys`); without it the tests
//! fail with that message. The two syntheses run once per test process, in
//! parallel, and take about a minute on a 2-core machine. To rewrite
//! RESOURCES.md after a design change: `cargo run --release -- synth`.

use gyrocal_verify::synthesis::{self, SynthesisReport, Target};
use gyrocal_verify::{self as verify, ScratchDir, tools};
use std::sync::OnceLock;
use std::time::Instant;

fn require_yosys() {
    if let Err(e) = tools::yosys() {
        panic!("{e}");
    }
}

/// Both targets, synthesized once per test process.
fn reports() -> &'static [SynthesisReport] {
    static REPORTS: OnceLock<Result<Vec<SynthesisReport>, verify::VerifyError>> = OnceLock::new();
    REPORTS
        .get_or_init(|| {
            let t = Instant::now();
            let r = synthesis::synthesize_all(&verify::committed_verilog());
            if let Ok(r) = &r {
                for x in r {
                    eprintln!(
                        "{}: {} LUT, {} FF, {} DSP, {} BRAM in {:.1?}",
                        x.target.name(),
                        x.luts,
                        x.ffs,
                        x.dsps,
                        x.brams,
                        x.wall
                    );
                }
            }
            eprintln!("synthesis of both targets: {:.1?} wall", t.elapsed());
            r
        })
        .as_ref()
        .map(Vec::as_slice)
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn yosys_synthesizes_both_targets_without_latches() {
    require_yosys();
    let reports = reports();
    assert_eq!(reports.len(), 2);
    for r in reports {
        let name = r.target.name();
        assert!(
            r.latches.is_empty(),
            "{name}: latches:\n{}",
            r.latches.join("\n")
        );
        assert_eq!(r.check_problems, 0, "{name}: Yosys `check` found problems");
        assert!(
            r.luts > 1000 && r.ffs > 1000,
            "{name}: implausibly small: {r:?}"
        );
        assert!(
            r.dsps > 0,
            "{name}: the multipliers did not map to DSP blocks"
        );
    }
}

#[test]
fn resources_md_matches_yosys() {
    require_yosys();
    let md = synthesis::resources_markdown(reports());
    let path = verify::committed_resources();
    let committed = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; create it with `cargo run --release -- synth`",
            path.display()
        )
    });
    if !committed.starts_with(&md) {
        let diff: Vec<String> = committed
            .lines()
            .zip(md.lines())
            .enumerate()
            .filter(|(_, (a, b))| a != b)
            .take(10)
            .map(|(i, (a, b))| format!("line {}:\n  committed: {a}\n  yosys now: {b}", i + 1))
            .collect();
        panic!(
            "{} does not start with what Yosys reports now ({} lines); after checking the change, rewrite it with \
             `cargo run --release -- synth`\n{}",
            path.display(),
            md.lines().count(),
            diff.join("\n")
        );
    }
}

#[test]
fn latch_detection_works() {
    // Negative control: a design with a latch must be reported for both
    // targets (on iCE40 the latch becomes a LUT loop, so only the log shows it).
    require_yosys();
    let dir = ScratchDir::new("latch-control").unwrap();
    let file = dir.path().join("gyro_interface.v");
    std::fs::write(
        &file,
        "module gyro_interface(input wire en, input wire [3:0] d, output reg [3:0] q);\n\
         \x20   always @(*) if (en) q = d;\n\
         endmodule\n",
    )
    .unwrap();
    for target in synthesis::TARGETS {
        let r = synthesis::synthesize(&file, target).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            !r.latches.is_empty(),
            "{}: latch not detected: {r:?}",
            target.name()
        );
    }
    assert_eq!(synthesis::TARGETS, [Target::Ice40, Target::Xilinx7]);
}
