//! With the `verilator` feature: compile verilog-out/gyro_interface.v (the
//! table core) and verilog-out/ecp5/gyro_interface.v (the fine core) with
//! Verilator, each with the C ABI wrapper of `verilator/wrapper.cpp`, into
//! static libraries for the `verilator` engine. Without it: nothing.

use std::path::{Path, PathBuf};
use std::process::Command;

/// One core to Verilate: its Verilog, the class prefix Verilator gives it
/// (the two files share the module name `gyro_interface`), and the prefix of
/// the C functions `verilator/wrapper.cpp` exports for it.
struct Core {
    verilog: &'static str,
    class: &'static str,
    functions: &'static str,
}

/// The table core, then the fine (ECP5) core; `src/verilator.rs` declares
/// both sets of functions.
const CORES: [Core; 2] = [
    Core {
        verilog: "../verilog-out/gyro_interface.v",
        class: "Vgyro_interface",
        functions: "gyrocal_verilator",
    },
    Core {
        verilog: "../verilog-out/ecp5/gyro_interface.v",
        class: "Vgyro_interface_fine",
        functions: "gyrocal_verilator_fine",
    },
];

/// The optimization levels of Verilator's makefile (`verilated.mk`): the
/// model's clock loop (OPT_FAST) and the runtime (OPT_GLOBAL) at -O2; the
/// code Verilator marks slow (constructor, initial blocks and settling,
/// run once per instance; the fine core's ROM images make 2 MB of it) at
/// -O0. The fine core's build takes 8 s instead of 43 s, the table
/// core's 5 s instead of 17 s (g++ 12, `make -j 2` on an idle two-core
/// machine, nearly all of it on one core).
const SPEEDS: &str = "OPT_FAST=-O2 OPT_GLOBAL=-O2 OPT_SLOW=-O0";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_VERILATOR").is_none() {
        return;
    }
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let wrapper = manifest.join("verilator/wrapper.cpp");
    let probes = manifest.join("verilator/probes.vlt");
    for f in [&wrapper, &probes] {
        println!("cargo:rerun-if-changed={}", f.display());
    }
    let root = tool_output("verilator", &["--getenv", "VERILATOR_ROOT"]);
    let include = Path::new(root.trim()).join("include");
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    for core in &CORES {
        let verilog = manifest.join(core.verilog);
        println!("cargo:rerun-if-changed={}", verilog.display());
        let out = out_dir.join(format!("verilated-{}", core.class));
        verilate(&verilog, &probes, core.class, &out);
        let mut build = cc::Build::new();
        for object in verilated_objects(&out, core.class) {
            build.object(object);
        }
        build
            .cpp(true)
            .std("c++17")
            .opt_level(2)
            .flag_if_supported("-Wno-unused-parameter")
            .include(&out)
            .include(&include)
            .include(include.join("vltstd"))
            .define("GYROCAL_VMODEL", core.class)
            .define("GYROCAL_VMODEL_H", format!("\"{}.h\"", core.class).as_str())
            .define(
                "GYROCAL_VROOT",
                format!("{}___024root", core.class).as_str(),
            )
            .define(
                "GYROCAL_VROOT_H",
                format!("\"{}___024root.h\"", core.class).as_str(),
            )
            .define(
                "GYROCAL_FN(name)",
                format!("{}_##name", core.functions).as_str(),
            )
            .define(
                "GYROCAL_HANDLE",
                format!("{}_handle", core.functions).as_str(),
            )
            .file(&wrapper)
            .compile(core.functions);
    }
    // The Verilator runtime once, after both models (a static library
    // resolves only what the libraries before it left open).
    let runtime = out_dir.join(format!("verilated-{}", CORES[0].class));
    cc::Build::new()
        .object(runtime.join("verilated.o"))
        .object(runtime.join("verilated_threads.o"))
        .compile("gyrocal_verilated_runtime");
    println!("cargo:rustc-link-lib=dylib=pthread");
    println!("cargo:rustc-link-lib=dylib=atomic");
}

/// Verilate `verilog` into `out` as class `class`, and build its objects
/// (and the runtime's `verilated.o`, `verilated_threads.o`).
fn verilate(verilog: &Path, probes: &Path, class: &str, out: &Path) {
    let _ = std::fs::remove_dir_all(out);
    run(Command::new("verilator")
        .args([
            "--cc",
            "--build",
            "-O3",
            "--x-assign",
            "fast",
            "--x-initial",
            "fast",
        ])
        .args([
            "-Wno-fatal",
            "-Wno-lint",
            "-Wno-style",
            "--top-module",
            "gyro_interface",
            "--prefix",
            class,
        ])
        // The optimization levels go to the makefile (`SPEEDS`): its own
        // OPT_* come after CFLAGS on each compile line, so an -O2 given as
        // CFLAGS was overridden (-Os on the clock loop) where it counted
        // and applied (-O2) where it did not.
        .args([
            "-CFLAGS",
            "-fPIC",
            "-MAKEFLAGS",
            SPEEDS,
            "-j",
            "2",
            "--Mdir",
        ])
        .arg(out)
        .arg(verilog)
        .arg(probes));
    // The runtime's objects, the same way (`-CFLAGS` went into the .mk).
    run(Command::new("make")
        .arg("-C")
        .arg(out)
        .args(["-f", &format!("{class}.mk")])
        .args(SPEEDS.split_whitespace())
        .args(["verilated.o", "verilated_threads.o"]));
}

fn tool_output(tool: &str, args: &[&str]) -> String {
    match Command::new(tool).args(args).output() {
        Ok(o) if o.status.success() => String::from_utf8_lossy(&o.stdout).into_owned(),
        _ => panic!(
            "{tool} not found or failed: the `verilator` feature needs the Debian package `verilator` (apt-get install verilator)"
        ),
    }
}

fn run(cmd: &mut Command) {
    let status = cmd
        .status()
        .unwrap_or_else(|e| panic!("cannot run {:?}: {e} (the `verilator` feature needs the Debian packages `verilator` and `make`)", cmd.get_program()));
    assert!(status.success(), "{cmd:?} failed");
}

/// The model's object files: Verilator compiles a small design into one
/// `{class}__ALL.o`, and a larger one (split output, parallel build) into
/// one object per C++ file, archived as `__ALL.a`.
fn verilated_objects(out: &Path, class: &str) -> Vec<PathBuf> {
    let all = out.join(format!("{class}__ALL.o"));
    if all.exists() {
        return vec![all];
    }
    let mut objects: Vec<PathBuf> = std::fs::read_dir(out)
        .expect("the Verilator output directory")
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| {
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            name.starts_with(class) && name.ends_with(".o")
        })
        .collect();
    objects.sort();
    objects
}
