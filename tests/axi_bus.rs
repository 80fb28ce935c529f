//! `gyro_interface_axi.v` under a third-party AXI4-Lite master and
//! AXI4-Stream sink (cocotbext-axi on cocotb) in Verilator: the cases of
//! `tests/axi/test_gyro_axi.py` (AW/W in either order or together, B and R
//! backpressure, SLVERR, write and read back every setting, coherent
//! snapshot while z updates, stream backpressure and overflow counting)
//! plus a replay of golden vectors from the bit-true model (every output,
//! every cycle, random bus traffic), on both cores; and the write and read
//! channel modules alone, each its own toplevel
//! (`tests/axi/test_axil_write.py`, `test_axil_read.py`), in Icarus
//! Verilog and in Verilator.
//!
//! The same cases of the table core in Icarus are `tests/fusesoc.rs`'s
//! `sim` target: FuseSoC runs this file's cases through edalize, each in
//! an Icarus of its own, with the same program and golden vectors and the
//! header copied beside it. They ran here as well until 2026-12-01: the
//! same cases, the same simulator and the same Verilog twice, about 115 s
//! of the suite's 30 minutes.
//!
//! The Python environment is a virtual environment made by
//! `scripts/test.sh` (pinned cocotb and cocotbext-axi); its interpreter is
//! `$GYROCAL_COCOTB_PYTHON` or `target/cocotb-venv/bin/python`. A missing
//! tool fails the test with the package to install; nothing is skipped.

use gyrocal_hdl::export;
use gyrocal_hdl::host::register_map;
use gyrocal_hdl::model::gyro_interface::CarrierProfile;
use std::path::{Path, PathBuf};
use std::process::Command;

mod axi_vectors;
use axi_vectors::program;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The pinned PyPI packages of the cocotb venv (as in scripts/test.sh).
const PINS: [&str; 3] = [
    "cocotb==1.9.2",
    "cocotb-bus==0.1.1",
    "cocotbext-axi==0.1.24",
];

fn python() -> PathBuf {
    let path = std::env::var_os("GYROCAL_COCOTB_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target/cocotb-venv/bin/python"));
    assert!(
        path.exists(),
        "{}: missing; the cocotb tests need a Python venv with the PyPI packages \
         cocotb==1.9.2, cocotb-bus==0.1.1 and cocotbext-axi==0.1.24 (scripts/test.sh makes it; cocotb-bus 0.1.1 because later versions hang Verilator 5.006, verilator issue 3919)",
        path.display()
    );
    let pinned = Command::new(&path)
        .arg("-c")
        .arg(
            "import importlib.metadata as m, sys\n\
             sys.exit(any(m.version(n) != v for n, v in (p.split('==') for p in sys.argv[1:])))",
        )
        .args(PINS)
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        pinned,
        "{}: needs exactly {PINS:?} (scripts/test.sh installs them)",
        path.display()
    );
    path
}

fn require(tool: &str, package: &str) {
    let found = Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .output()
        .is_ok_and(|o| o.status.success());
    assert!(
        found,
        "{tool} not found: install the Debian package {package}"
    );
}

fn run_cocotb(simulator: &str, profile: CarrierProfile) {
    let dir = tempfile::tempdir().unwrap();
    let (program_file, vectors_file) = axi_vectors::write_inputs(dir.path(), profile);
    let verilog = root()
        .join("verilog-out")
        .join(export::axi_verilog_file(profile));
    let header = root().join("verilog-out").join(export::C_HEADER_FILE);
    run_py(
        simulator,
        &verilog,
        &dir.path().join("build"),
        &[],
        &[
            ("GYRO_HEADER", header.as_path()),
            ("GYRO_PROGRAM", &program_file),
            ("GYRO_VECTORS", &vectors_file),
            ("GYRO_PROFILE", Path::new(profile.name())),
        ],
    );
}

/// `tests/axi/run.py` in `simulator` on `verilog` with `args` after the
/// build directory; fails with the failing tests' tracebacks.
fn run_py(simulator: &str, verilog: &Path, build: &Path, args: &[&str], env: &[(&str, &Path)]) {
    let python = python();
    let out = Command::new(&python)
        .arg(root().join("tests/axi/run.py"))
        .arg(simulator)
        .arg(verilog)
        .arg(build)
        .args(args)
        .envs(env.iter().copied())
        .output()
        .unwrap_or_else(|e| panic!("{}: {e}", python.display()));
    let log =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    // The failing tests' tracebacks, then the summary.
    let lines: Vec<&str> = log.lines().collect();
    let mut report = Vec::new();
    for (n, line) in lines.iter().enumerate() {
        if line.contains(" failed") && line.contains("cocotb.regression") {
            report.extend_from_slice(&lines[n..(n + 12).min(lines.len())]);
        }
    }
    report.extend(lines.iter().rev().take(25).rev());
    let tail = report.join("\n");
    assert!(
        out.status.success(),
        "cocotb in {simulator} {args:?} failed:\n{tail}"
    );
    assert!(log.contains("FAIL=0"), "no cocotb summary:\n{tail}");
}

/// The bus top's channel modules, each its own toplevel under its own
/// cocotb test (`tests/axi/test_axil_write.py`, `test_axil_read.py`).
fn run_channels(simulator: &str) {
    let verilog = root()
        .join("verilog-out")
        .join(export::axi_verilog_file(CarrierProfile::Table));
    for (module, tests) in [
        ("gyro_interface_axi__axil_write", "test_axil_write"),
        ("gyro_interface_axi__axil_read", "test_axil_read"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let args = ["--toplevel", module, "--tests", tests];
        run_py(simulator, &verilog, &dir.path().join("build"), &args, &[]);
    }
}

#[test]
fn channel_modules_alone_in_icarus() {
    require("iverilog", "iverilog");
    run_channels("icarus");
}

#[test]
fn channel_modules_alone_in_verilator() {
    require("verilator", "verilator");
    require("make", "make");
    require("g++", "g++");
    run_channels("verilator");
}

#[test]
fn third_party_axi_master_in_verilator() {
    require("verilator", "verilator");
    require("make", "make");
    require("g++", "g++");
    run_cocotb("verilator", CarrierProfile::Table);
}

#[test]
fn the_fine_core_behind_the_bus_in_verilator() {
    // The ECP5 bus top (verilog-out/ecp5/gyro_interface_axi.v): the same
    // cocotb cases, and the replay against the fine model's vectors.
    require("verilator", "verilator");
    require("make", "make");
    require("g++", "g++");
    run_cocotb("verilator", CarrierProfile::Fine);
}

#[test]
fn program_writes_only_settings() {
    for line in program().lines() {
        let offset = u32::from_str_radix(
            line.split_whitespace()
                .next()
                .unwrap()
                .trim_start_matches("0x"),
            16,
        )
        .unwrap();
        let reg = register_map::lookup(offset).unwrap();
        assert_eq!(reg.access, register_map::Access::ReadWrite, "{}", reg.name);
    }
    assert!(Path::new(&root().join("tests/axi/test_gyro_axi.py")).exists());
}
