//! Place and route of the committed export with nextpnr on the parts of
//! `gyrocal_verify::pnr::PARTS` (iCE40 UP5K with Debian's nextpnr-ice40,
//! ECP5 LFE5U-25F with YoWASP's nextpnr-ecp5 from the virtual environment
//! that `scripts/fpga/install-venv.sh` creates), inside the pin-limited
//! wrapper of `verify/src/wrapper.rs`:
//!
//! * `verilog-out/RESOURCES.md` ends with the place-and-route section a fresh
//!   run writes (same tools, same seed: the same figures);
//! * the targets listed in [`ASSERTED_TARGETS`] are met.
//!
//! Requires `yosys`, `nextpnr-ice40` and the virtual environment; without
//! them the tests fail with a message naming what to install. Both parts
//! run once per test process, in parallel. To rewrite RESOURCES.md after a
//! design change: `cargo run --release -- synth`.

use gyrocal_verify::pnr::{self, PnrReport};
use gyrocal_verify::{self as verify, resources, targets};
use std::sync::OnceLock;
use std::time::Instant;

/// The parts whose targets (`gyrocal_verify::targets::TARGETS`: ECP5 25F
/// fits at >= 100 MHz, iCE40 UP5K fits at >= 30 MHz) this suite asserts.
/// Both parts: the bus top fits the iCE40 UP5K (8 of 8 DSPs, the carrier
/// tables in its 4 SPRAMs) above 30 MHz and meets 100 MHz on the ECP5 25F
/// (`verilog-out/RESOURCES.md`).
const ASSERTED_TARGETS: &[&str] = &["ice40-up5k", "ecp5-25f"];

/// Every part, placed and routed once per test process.
fn reports() -> &'static [PnrReport] {
    static REPORTS: OnceLock<Result<Vec<PnrReport>, verify::VerifyError>> = OnceLock::new();
    REPORTS
        .get_or_init(|| {
            let t = Instant::now();
            let out = verify::verilog_out_dir();
            let r = pnr::place_and_route_all(&|p| resources::pnr_core(&out, p), &pnr::PARTS);
            for x in r.iter().flatten() {
                eprintln!(
                    "{}: fits {}, Fmax {:?} MHz; synthesis {:.1?}, place and route {:.1?}",
                    x.part.name,
                    x.fits(),
                    x.fmax_mhz(),
                    x.wall.0,
                    x.wall.1
                );
            }
            eprintln!("place and route of every part: {:.1?} wall", t.elapsed());
            r
        })
        .as_ref()
        .map(Vec::as_slice)
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn resources_md_ends_with_the_current_place_and_route_figures() {
    let section = resources::pnr_section(reports());
    let path = verify::committed_resources();
    let committed = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; create it with `cargo run --release -- synth`",
            path.display()
        )
    });
    if !committed.ends_with(&section) {
        let tail: Vec<&str> = committed
            .lines()
            .rev()
            .take(section.lines().count())
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        let diff: Vec<String> = tail
            .iter()
            .zip(section.lines())
            .filter(|pair| *pair.0 != pair.1)
            .take(10)
            .map(|(a, b)| format!("  committed: {a}\n  nextpnr now: {b}"))
            .collect();
        panic!(
            "{}'s place-and-route section is stale; after checking the change, rewrite it with \
             `cargo run --release -- synth`\n{}",
            path.display(),
            diff.join("\n")
        );
    }
}

#[test]
fn every_part_reports_every_resource_of_the_whole_design() {
    for r in reports() {
        let name = r.part.name;
        assert_eq!(r.uses.len(), r.part.resources.len(), "{name}");
        let used = |labels: &[&str]| {
            r.uses
                .iter()
                .find(|u| labels.contains(&u.label))
                .unwrap_or_else(|| panic!("{name}: no {labels:?} column"))
                .used
        };
        // The wrapper alone has exactly `wrapper_flip_flops` flip-flops and
        // `wrapper_luts` LUTs and no multiplier: counts at or below these
        // would mean Yosys optimized the core away.
        assert!(
            used(&["FF"]) > r.wrapper_flip_flops as u64,
            "{name}: only the wrapper's flip-flops: {r:?}"
        );
        assert!(
            used(&["LC", "LUT"]) > r.wrapper_luts as u64,
            "{name}: only the wrapper's LUTs: {r:?}"
        );
        assert!(
            used(&["DSP", "MULT"]) > 0,
            "{name}: the core's products are not on multipliers: {r:?}"
        );
        assert!(
            r.nextpnr_version.contains("nextpnr") && r.yosys_version.starts_with("Yosys"),
            "{r:?}"
        );
    }
}

#[test]
fn asserted_targets_are_met() {
    let all = targets::check(reports(), &targets::TARGETS);
    for miss in &all {
        eprintln!("target missed: {miss}");
    }
    let asserted: Vec<_> = targets::TARGETS
        .into_iter()
        .filter(|t| ASSERTED_TARGETS.contains(&t.part_key))
        .collect();
    assert_eq!(
        asserted.len(),
        ASSERTED_TARGETS.len(),
        "ASSERTED_TARGETS names a part without a target"
    );
    let misses = targets::check(reports(), &asserted);
    assert!(misses.is_empty(), "{}", misses.join("\n"));
}
