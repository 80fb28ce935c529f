//! What the IP-packaging tests (fusesoc.rs, systemrdl.rs, litex.rs) share:
//! the pinned Python venv of `scripts/ip/install-venv.sh` and running its
//! programs with a readable failure.
//!
//! The venv is `$GYROCAL_IP_VENV` or `target/ip-venv` at the repository
//! root; its pins are `scripts/ip/pins.txt`. A missing or differently
//! pinned venv fails the test with the command that makes it; nothing is
//! skipped.

#![allow(dead_code)] // reason: each test crate uses part of this module

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The pins of the venv (`name==version`), from `scripts/ip/pins.txt`.
pub fn pins() -> Vec<String> {
    let text = std::fs::read_to_string(root().join("scripts/ip/pins.txt")).unwrap();
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(str::to_owned)
        .collect()
}

/// The venv's folder, checked to hold exactly [`pins`].
pub fn venv() -> PathBuf {
    let dir = std::env::var_os("GYROCAL_IP_VENV")
        .map_or_else(|| root().join("target/ip-venv"), |v| root().join(v));
    let python = dir.join("bin/python");
    let hint = "run scripts/ip/install-venv.sh (pins in scripts/ip/pins.txt)";
    assert!(python.exists(), "{}: missing; {hint}", python.display());
    let pinned = Command::new(&python)
        .arg("-c")
        .arg(
            "import importlib.metadata as m, sys\n\
             bad = [p for p in sys.argv[1:] if m.version(p.split('==')[0]) != p.split('==')[1]]\n\
             print(' '.join(bad)); sys.exit(1 if bad else 0)",
        )
        .args(pins())
        .output()
        .unwrap();
    assert!(
        pinned.status.success(),
        "{}: not at the pinned versions ({}{}); {hint}",
        dir.display(),
        String::from_utf8_lossy(&pinned.stdout).trim(),
        String::from_utf8_lossy(&pinned.stderr).trim()
    );
    dir
}

/// A command for the venv's `program`, with the venv's `bin/` first on PATH
/// (cocotb-config, fusesoc, peakrdl, litex_server).
pub fn command(venv: &Path, program: &str) -> Command {
    let bin = venv.join("bin");
    let mut cmd = Command::new(bin.join(program));
    cmd.env("PATH", path_with(&[bin]));
    cmd
}

/// `$PATH` with `dirs` in front.
pub fn path_with(dirs: &[PathBuf]) -> std::ffi::OsString {
    let old = std::env::var_os("PATH").unwrap_or_default();
    std::env::join_paths(dirs.iter().cloned().chain(std::env::split_paths(&old))).unwrap()
}

/// Run `cmd`; its output, both streams as one text.
pub fn run(cmd: &mut Command) -> (Output, String) {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    let log =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out, log)
}

/// The last `n` lines of `log`.
pub fn tail(log: &str, n: usize) -> String {
    let lines: Vec<&str> = log.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}
