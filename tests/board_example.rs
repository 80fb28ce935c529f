//! The drop-in examples of `examples/fpga/` against the committed export:
//! the board top `gyro_board_top.v` around `gyro_interface_axi` lints clean
//! and elaborates in Yosys with every port connected and no loop; the
//! firmware example `gyro_host.c` compiles with a plan printed by
//! `gyrocal registers --format c`, warnings as errors, and its self-test
//! (programming and z assembly against a register file in memory) passes.
//!
//! Requires Verilator, Yosys and a C compiler (`cc`, Debian `gcc`); a
//! missing tool fails the test with the package to install.

mod common;

use common::{gyrocal, stderr};
use gyrocal_hdl::export::AXI_TOP_MODULE;
use gyrocal_verify::{self as verify, lint, synthesis};
use std::ffi::OsStr;
use std::path::PathBuf;
use std::process::Command;

fn example(name: &str) -> PathBuf {
    verify::workspace_root().join("examples/fpga").join(name)
}

const BOARD_TOP: &str = "gyro_board_top";

#[test]
fn board_top_lints_clean_with_the_export() {
    if let Err(e) = verify::tools::verilator() {
        panic!("{e}");
    }
    let report = lint::lint_files(
        &[
            &example("gyro_board_top.v"),
            &verify::committed_axi_verilog(),
        ],
        BOARD_TOP,
        &[
            &verify::committed_waivers(),
            &verify::committed_axi_waivers(),
        ],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(report.is_clean(), "{}", report.listing());
}

#[test]
fn board_top_elaborates_without_loops() {
    if let Err(e) = verify::tools::yosys() {
        panic!("{e}");
    }
    let files = [
        &example("gyro_board_top.v"),
        &verify::committed_axi_verilog(),
    ];
    let files: Vec<&std::path::Path> = files.iter().map(|p| p.as_path()).collect();
    let check = synthesis::structural_check(&files, BOARD_TOP).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(check.problems, 0, "{}", check.listing);
    // The example instantiates the exported module by its exported name.
    let text = std::fs::read_to_string(example("gyro_board_top.v")).unwrap();
    assert!(text.contains(&format!("{AXI_TOP_MODULE} gyro (")));
}

#[test]
fn host_example_compiles_with_a_printed_plan_and_passes_its_self_test() {
    let dir = verify::ScratchDir::new("host-example").unwrap();
    let config = verify::workspace_root().join("tests/data/small_device.toml");
    let plan = gyrocal(&[
        OsStr::new("registers"),
        OsStr::new("--format"),
        OsStr::new("c"),
        OsStr::new("--config"),
        config.as_os_str(),
    ]);
    assert!(plan.status.success(), "{}", stderr(&plan));
    std::fs::write(dir.path().join("gyro_plan.h"), &plan.stdout).unwrap();
    let binary = dir.path().join("gyro_host");
    let cc = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"])
        .arg("-I")
        .arg(verify::verilog_out_dir())
        .arg("-I")
        .arg(dir.path())
        .arg("-DGYRO_HOST_SELFTEST")
        .arg(example("gyro_host.c"))
        .arg("-o")
        .arg(&binary)
        .output()
        .unwrap_or_else(|e| panic!("cc: {e} (install the Debian package gcc)"));
    assert!(
        cc.status.success(),
        "{}",
        String::from_utf8_lossy(&cc.stderr)
    );
    let run = Command::new(&binary).output().unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}");
    assert!(stdout.contains("self-test: ok"), "{stdout}");
}
