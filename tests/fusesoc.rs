//! The FuseSoC cores (`gyro_interface_axi.core`, `gyro_interface.core` at
//! the repository root) run with FuseSoC itself, as an FPGA user runs them:
//!
//! - `fusesoc run --target=lint` on both cores: Verilator `--lint-only -Wall`
//!   with the committed waivers, through edalize's lint flow; any warning
//!   fails it. Negative control: the same core without the bus wrapper's
//!   waivers fails, naming a waived warning.
//! - `fusesoc run --target=sim` on the bus top: edalize's sim flow runs
//!   every cocotb test of `tests/axi/test_gyro_axi.py` (cocotbext-axi
//!   master and sink) in Icarus, each in a simulator of its own from
//!   power-up (the core has no reset), as `tests/axi_bus.rs` does in
//!   Verilator. These are the suite's Icarus runs of those cases.
//! - The place-and-route tops and pin files the `synth_*` targets use are
//!   what `gyrocal_verify` generates for its own figures.
//!
//! FuseSoC, edalize and cocotb come from the venv of
//! `scripts/ip/install-venv.sh` (tests/ip_tools).

use gyrocal_hdl::model::gyro_interface::CarrierProfile;
use gyrocal_verify::pnr::{ECP5_25F, ICE40_UP5K, pin_file};
use gyrocal_verify::wrapper::{Core, Wrapper};
use std::path::Path;

mod axi_vectors;
mod ip_tools;

use ip_tools::{root, run, tail};

const AXI_CORE: &str = "gyrocal:ip:gyro_interface_axi";
const BARE_CORE: &str = "gyrocal:ip:gyro_interface";

/// `fusesoc --cores-root LIBRARY run --build-root BUILD ARGS... CORE`.
fn fusesoc(library: &Path, build: &Path, args: &[&str], core: &str) -> std::process::Command {
    let venv = ip_tools::venv();
    let mut cmd = ip_tools::command(&venv, "fusesoc");
    cmd.env("VIRTUAL_ENV", &venv)
        .arg("--cores-root")
        .arg(library)
        .arg("run")
        .arg("--build-root")
        .arg(build)
        .args(args)
        .arg(core);
    cmd
}

fn lint(library: &Path, core: &str) -> (bool, String) {
    let build = tempfile::tempdir().unwrap();
    let (out, log) = run(&mut fusesoc(
        library,
        build.path(),
        &["--target=lint"],
        core,
    ));
    (out.status.success(), log)
}

#[test]
fn lint_target_passes_on_both_cores() {
    for core in [AXI_CORE, BARE_CORE] {
        let (ok, log) = lint(&root(), core);
        assert!(ok, "fusesoc lint of {core} failed:\n{}", tail(&log, 40));
        assert!(
            log.contains("verilator -f"),
            "{core}: Verilator did not run:\n{log}"
        );
    }
}

#[test]
fn lint_target_fails_without_the_waivers() {
    let library = tempfile::tempdir().unwrap();
    let out = library.path().join("verilog-out");
    std::fs::create_dir(&out).unwrap();
    std::fs::copy(
        root().join("gyro_interface_axi.core"),
        library.path().join("gyro_interface_axi.core"),
    )
    .unwrap();
    for f in ["gyro_interface_axi.v", "lint-waivers.vlt"] {
        std::fs::copy(root().join("verilog-out").join(f), out.join(f)).unwrap();
    }
    std::fs::write(out.join("lint-waivers-axi.vlt"), "`verilator_config\n").unwrap();
    let (ok, log) = lint(library.path(), AXI_CORE);
    assert!(
        !ok,
        "lint passed without the bus wrapper's waivers:\n{}",
        tail(&log, 20)
    );
    assert!(
        log.contains("%Warning-DECLFILENAME"),
        "not the waived warning:\n{}",
        tail(&log, 20)
    );
}

/// The cocotb tests of tests/axi/test_gyro_axi.py, in file order.
fn cocotb_tests() -> Vec<String> {
    let source = std::fs::read_to_string(root().join("tests/axi/test_gyro_axi.py")).unwrap();
    let lines: Vec<&str> = source.lines().collect();
    lines
        .windows(2)
        .filter(|w| w[0] == "@cocotb.test()")
        .filter_map(|w| w[1].strip_prefix("async def "))
        .map(|rest| rest.split('(').next().unwrap().to_owned())
        .collect()
}

#[test]
fn sim_target_passes_every_cocotb_test_in_icarus() {
    let dir = tempfile::tempdir().unwrap();
    let (program, vectors) = axi_vectors::write_inputs(dir.path(), CarrierProfile::Table);
    let build = dir.path().join("build");
    let env = |cmd: &mut std::process::Command| {
        cmd.env("GYRO_PROGRAM", &program)
            .env("GYRO_VECTORS", &vectors);
    };
    let mut setup = fusesoc(
        &root(),
        &build,
        &["--target=sim", "--setup", "--build"],
        AXI_CORE,
    );
    env(&mut setup);
    let (out, log) = run(&mut setup);
    assert!(
        out.status.success(),
        "fusesoc sim setup/build failed:\n{}",
        tail(&log, 40)
    );
    let tests = cocotb_tests();
    assert!(tests.len() >= 10, "found only {tests:?}");
    for name in &tests {
        let mut sim = fusesoc(&root(), &build, &["--target=sim", "--run"], AXI_CORE);
        env(&mut sim);
        sim.env("TESTCASE", name);
        let (out, log) = run(&mut sim);
        assert!(
            out.status.success() && log.contains("TESTS=1 PASS=1 FAIL=0"),
            "fusesoc sim, {name}:\n{}",
            tail(&log, 30)
        );
    }
}

#[test]
fn synth_targets_use_the_generated_pnr_tops_and_pins() {
    let verilog = |f: &str| root().join("verilog-out").join(f);
    let tops = [
        (
            "fusesoc/gyro_interface_axi_pnr_top.v",
            Core::gyro_interface_axi(verilog("gyro_interface_axi.v")),
        ),
        (
            "fusesoc/gyro_interface_pnr_top.v",
            Core::gyro_interface(verilog("gyro_interface.v")),
        ),
    ];
    let mut files: Vec<(&str, String)> = tops
        .iter()
        .map(|(f, core)| (*f, Wrapper::new(core).verilog))
        .collect();
    files.push(("fusesoc/up5k.pcf", pin_file(&ICE40_UP5K).1));
    files.push(("fusesoc/ecp5-25f.lpf", pin_file(&ECP5_25F).1));
    let rewrite = std::env::var_os("GYROCAL_WRITE_FUSESOC").is_some();
    for (file, text) in files {
        let path = root().join(file);
        if rewrite {
            std::fs::write(&path, &text).unwrap();
        }
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            committed == text,
            "{file} differs from gyrocal_verify's: rerun with GYROCAL_WRITE_FUSESOC=1 and commit"
        );
    }
    // The nextpnr options of the synth_* targets: the part, clock and seed of the figures.
    for core in ["gyro_interface_axi.core", "gyro_interface.core"] {
        let text = std::fs::read_to_string(root().join(core)).unwrap();
        for part in [ICE40_UP5K, ECP5_25F] {
            let options = format!(
                "nextpnr_options: [{}, --freq, \"{}\", --seed, \"{}\"]",
                part.device_args.join(", "),
                part.freq_mhz,
                gyrocal_verify::pnr::SEED
            );
            assert!(text.contains(&options), "{core}: {options}");
        }
        // The ECP5 target builds the fine-carrier core, as RESOURCES.md's figures.
        assert!(
            text.contains("filesets: [rtl_ecp5, pnr_top, ecp5_pins]")
                && text.contains("      - verilog-out/ecp5/"),
            "{core}: synth_ecp5 must use verilog-out/ecp5/"
        );
    }
}
