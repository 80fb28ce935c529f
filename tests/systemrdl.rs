//! `verilog-out/gyro_interface.rdl` read by the users' register tools:
//!
//! - PeakRDL (`peakrdl c-header`) compiles it and writes its C header; a C
//!   file including that header and the committed `gyro_interface_regs.h`
//!   must compile with a `static_assert` per register: the offset of each
//!   register in PeakRDL's struct is `GYRO_<NAME>_OFFSET`, its field's
//!   width, mask and bit position are `_BITS`, `_MASK` and 0, its reset is
//!   `_POWER_UP` (read-write) or `_VALUE` (ID, VERSION), and the struct
//!   ends after the last register. A negative control changes one offset.
//! - systemrdl-compiler's own model of the file (a Python walk) gives, per
//!   register, the software access and the `gyro_signed` property, which
//!   must be the table's (`register_map::REGISTERS`).
//!
//! The tools come from the venv of `scripts/ip/install-venv.sh`.

use gyrocal_hdl::host::register_map::{Access, REGISTERS, Register};
use gyrocal_regs::systemrdl::{ADDRMAP_NAME, FIELD_NAME};
use std::path::{Path, PathBuf};
use std::process::Command;

mod ip_tools;

use ip_tools::{root, run, tail};

fn rdl() -> PathBuf {
    root().join("verilog-out/gyro_interface.rdl")
}

/// PeakRDL's C header of `rdl`, written into `dir`.
fn peakrdl_header(rdl: &Path, dir: &Path) -> PathBuf {
    let venv = ip_tools::venv();
    let header = dir.join("peakrdl_regs.h");
    let (out, log) = run(ip_tools::command(&venv, "peakrdl")
        .arg("c-header")
        .arg(rdl)
        .arg("-o")
        .arg(&header));
    assert!(
        out.status.success(),
        "peakrdl c-header failed:\n{}",
        tail(&log, 20)
    );
    header
}

/// The C checks of one register (C11 `static_assert`).
fn checks(r: &Register) -> String {
    let p = format!("{}__{}__{}", ADDRMAP_NAME, r.name, FIELD_NAME).to_uppercase();
    let g = format!("GYRO_{}", r.name);
    let mut c = format!(
        "static_assert(offsetof({ADDRMAP_NAME}_t, {name}) == {g}_OFFSET, \"{name} offset\");\n\
         static_assert({p}_bw == {g}_BITS, \"{name} width\");\n\
         static_assert({p}_bm == {g}_MASK, \"{name} mask\");\n\
         static_assert({p}_bp == 0, \"{name} bit position\");\n",
        name = r.name
    );
    let power_up = match (r.access, r.name) {
        (Access::ReadWrite, _) => Some(format!("{g}_POWER_UP")),
        (Access::ReadOnly, "ID" | "VERSION") => Some(format!("{g}_VALUE")),
        (Access::ReadOnly, _) => None, // the committed header gives no value
    };
    if let Some(v) = power_up {
        c += &format!(
            "static_assert({p}_reset == {v}, \"{} power-up\");\n",
            r.name
        );
    }
    c
}

/// Compile a C file that includes both headers and checks them; the log.
fn compile_against_committed(peakrdl: &Path, committed: &Path) -> (bool, String) {
    let dir = peakrdl.parent().unwrap();
    let last = REGISTERS.last().unwrap();
    let mut c = format!(
        "#include <stddef.h>\n#include <assert.h>\n#include \"{}\"\n#include \"{}\"\n",
        peakrdl.display(),
        committed.display()
    );
    c += &format!(
        "static_assert(sizeof({ADDRMAP_NAME}_t) == GYRO_{}_OFFSET + 4, \"struct size\");\n",
        last.name
    );
    REGISTERS.iter().for_each(|r| c += &checks(r));
    let source = dir.join("check.c");
    std::fs::write(&source, c).unwrap();
    let (out, log) = run(Command::new("cc")
        .args(["-std=c11", "-Wall", "-Werror", "-c", "-o"])
        .arg(dir.join("check.o"))
        .arg(&source));
    (out.status.success(), log)
}

#[test]
fn peakrdl_header_matches_the_committed_header() {
    let dir = tempfile::tempdir().unwrap();
    let header = peakrdl_header(&rdl(), dir.path());
    let committed = root().join("verilog-out/gyro_interface_regs.h");
    let (ok, log) = compile_against_committed(&header, &committed);
    assert!(
        ok,
        "PeakRDL's header disagrees with gyro_interface_regs.h:\n{}",
        tail(&log, 30)
    );
}

#[test]
fn a_moved_register_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let header = peakrdl_header(&rdl(), dir.path());
    let committed = root().join("verilog-out/gyro_interface_regs.h");
    let moved = std::fs::read_to_string(committed).unwrap().replace(
        "#define GYRO_AMP2_OFFSET 0x24u",
        "#define GYRO_AMP2_OFFSET 0x28u",
    );
    let altered = dir.path().join("altered_regs.h");
    std::fs::write(&altered, moved).unwrap();
    let (ok, log) = compile_against_committed(&header, &altered);
    assert!(!ok, "a moved AMP2 passed the check");
    assert!(log.contains("AMP2 offset"), "{}", tail(&log, 10));
}

#[test]
fn compiler_model_has_the_tables_access_and_signedness() {
    let venv = ip_tools::venv();
    let walk = "import sys\n\
        from systemrdl import RDLCompiler\n\
        c = RDLCompiler(); c.compile_file(sys.argv[1]); top = c.elaborate().top\n\
        for reg in top.registers():\n\
        \x20   f = reg.fields()[0]\n\
        \x20   print(reg.inst_name, hex(reg.address_offset), f.width, f.lsb, f.get_property('sw').name,\n\
        \x20         f.get_property('reset'), bool(f.get_property('gyro_signed', default=False)), len(reg.fields()))\n";
    let (out, log) = run(ip_tools::command(&venv, "python")
        .arg("-c")
        .arg(walk)
        .arg(rdl()));
    assert!(
        out.status.success(),
        "systemrdl-compiler failed:\n{}",
        tail(&log, 20)
    );
    let lines: Vec<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_owned)
        .collect();
    let want: Vec<String> = REGISTERS
        .iter()
        .map(|r| {
            let sw = match r.access {
                Access::ReadWrite => "rw",
                Access::ReadOnly => "r",
            };
            let signed = if r.signed { "True" } else { "False" };
            format!(
                "{} {:#x} {} 0 {sw} {} {signed} 1",
                r.name, r.offset, r.bits, r.power_up
            )
        })
        .collect();
    assert_eq!(lines, want);
}
