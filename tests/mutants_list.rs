//! The mutation list stays usable: every entry of
//! `scripts/mutants/list.toml` still applies (its original text occurs
//! exactly once in its file, its check exists), and the runner
//! `scripts/mutants/run.py` works (its own tests, on a tiny repository with
//! a cheap check). The mutants themselves are not run here: a full run takes
//! hours (`scripts/mutants/run.py`, results in `scripts/mutants/RESULTS.md`).
//!
//! Requires `python3` (3.11 or later, for `tomllib`) and `git`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Run `python3 script args`; panics with its output unless it succeeds.
fn python(script: &Path, args: &[&str]) -> String {
    let out = Command::new("python3")
        .arg(script)
        .args(args)
        .current_dir(root())
        .output()
        .unwrap_or_else(|e| {
            panic!("python3: {e}: install the Debian package python3 (apt-get install python3)")
        });
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "{} {args:?} failed:\n{text}",
        script.display()
    );
    text
}

#[test]
fn every_mutant_still_applies() {
    let out = python(&root().join("scripts/mutants/run.py"), &["--check-list"]);
    assert!(out.contains("mutants apply"), "{out}");
}

#[test]
fn the_runner_passes_its_own_tests() {
    let out = python(&root().join("scripts/mutants/test_run.py"), &[]);
    assert!(out.contains("OK"), "{out}");
}
