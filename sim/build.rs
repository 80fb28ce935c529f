//! With the `verilator` feature: compile verilog-out/gyro_interface.v with
//! Verilator and the C ABI wrapper of `verilator/wrapper.cpp` into a static
//! library for the `verilator` engine. Without it: nothing.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_VERILATOR").is_none() {
        return;
    }
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap());
    let verilog = manifest.join("../verilog-out/gyro_interface.v");
    let wrapper = manifest.join("verilator/wrapper.cpp");
    let probes = manifest.join("verilator/probes.vlt");
    for f in [&verilog, &wrapper, &probes] {
        println!("cargo:rerun-if-changed={}", f.display());
    }
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap()).join("verilated");
    let _ = std::fs::remove_dir_all(&out);
    let root = tool_output("verilator", &["--getenv", "VERILATOR_ROOT"]);
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
        ])
        .args(["-CFLAGS", "-O2 -fPIC", "-j", "2", "--Mdir"])
        .arg(&out)
        .arg(&verilog)
        .arg(&probes));
    run(Command::new("make").arg("-C").arg(&out).args([
        "-f",
        "Vgyro_interface.mk",
        "OPT_FAST=-O2 -fPIC",
        "verilated.o",
        "verilated_threads.o",
    ]));
    let include = Path::new(root.trim()).join("include");
    let mut build = cc::Build::new();
    for object in verilated_objects(&out) {
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
        .file(&wrapper)
        .object(out.join("verilated.o"))
        .object(out.join("verilated_threads.o"))
        .compile("gyrocal_verilator");
    println!("cargo:rustc-link-lib=dylib=pthread");
    println!("cargo:rustc-link-lib=dylib=atomic");
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
/// `Vgyro_interface__ALL.o`, and a larger one (split output, parallel
/// build) into one object per C++ file, archived as `__ALL.a`.
fn verilated_objects(out: &Path) -> Vec<PathBuf> {
    let all = out.join("Vgyro_interface__ALL.o");
    if all.exists() {
        return vec![all];
    }
    let mut objects: Vec<PathBuf> = std::fs::read_dir(out)
        .expect("the Verilator output directory")
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| {
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            name.starts_with("Vgyro_interface") && name.ends_with(".o")
        })
        .collect();
    objects.sort();
    objects
}
