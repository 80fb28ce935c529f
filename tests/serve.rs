//! `gyrocal serve` under a third-party Etherbone client: LiteX's own
//! `RemoteClient` (PyPI litex==2024.12, in the venv that
//! `scripts/host/install-venv.sh` makes) runs `tests/serve/remote_client.py`
//! against a served board: ID and VERSION, a write read back (and
//! sign-extended), a two-word write, SAMPLE_COUNT advancing, a burst read
//! of the whole map, a fixed burst, unmapped words reading 0, and a second
//! connection that finds the settings kept and the board still running.
//! Also: bad options are one-line errors with exit status 2, and (with the
//! `verilator` feature) the exported Verilog served the same way.

mod common;
#[path = "serve/served.rs"]
mod served;

use common::{gyrocal, stderr};
use gyrocal_regs::map;
use served::Served;
use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The venv's Python, made (or checked) by the install script.
fn litex_python() -> PathBuf {
    let status = Command::new(root().join("scripts/host/install-venv.sh")).status();
    assert!(
        status.is_ok_and(|s| s.success()),
        "scripts/host/install-venv.sh failed: it needs python3 with venv (Debian python3-venv) \
         and PyPI for litex==2024.12, migen==0.10.0, colorama==0.4.6"
    );
    let venv = std::env::var_os("GYROCAL_LITEX_VENV")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target/litex-venv"));
    venv.join("bin/python")
}

fn small_device() -> PathBuf {
    root().join("tests/data/small_device.toml")
}

#[test]
fn litex_remote_client_reads_and_writes_a_served_board() {
    let python = litex_python();
    let served = Served::start(&small_device(), &[]);
    let port = served.address.rsplit(':').next().unwrap().to_string();
    // RemoteClient reads ./csr.csv when there is one: run it where there is none.
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(python)
        .arg(root().join("tests/serve/remote_client.py"))
        .arg(&port)
        .arg(format!("{:#x}", map::VERSION_WORD))
        .arg(format!("{:#x}", map::REGISTERS.last().unwrap().offset))
        .current_dir(dir.path())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}\nserve: {:?}",
        String::from_utf8_lossy(&out.stderr),
        served.stderr()
    );
    assert!(text.contains("all checks passed"), "{text}");
    let notes = served.stderr();
    let unmapped: Vec<&String> = notes.iter().filter(|l| l.contains("read of 0x")).collect();
    assert_eq!(
        unmapped.len(),
        2,
        "each unmapped word logged once: {notes:?}"
    );
}

fn refused(args: &[&str], says: &str) {
    let o = gyrocal(args);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.contains(says), "{args:?}: {e}");
}

#[test]
fn bad_options_are_one_line_errors() {
    let config = small_device();
    let c = config.to_str().unwrap();
    refused(
        &["serve", "--config", c, "--engine", "rtl"],
        "--engine \"rtl\": allowed model, verilator",
    );
    refused(
        &["serve", "--config", c, "--temperature", "30"],
        "--temperature 30 deg C: the file has no [drift] section",
    );
    refused(
        &["serve", "--config", c, "--listen", "nowhere"],
        "--listen nowhere: cannot listen",
    );
    refused(
        &["serve", "--config", "/nonexistent.toml"],
        "--config /nonexistent.toml: cannot read the file",
    );
}

/// The exported Verilog behind the same wire: the map reads back and the
/// clock runs.
#[cfg(feature = "verilator")]
#[test]
fn the_verilator_engine_serves_the_same_map() {
    use gyrocal_host::transport::etherbone::Etherbone;
    use gyrocal_regs::map::{AMP2, ID, ID_WORD, RegisterAccess, SAMPLE_COUNT};
    let served = Served::start(&small_device(), &["--engine", "verilator"]);
    assert!(served.stderr()[0].contains("verilator engine"));
    let mut bus = Etherbone::connect(&served.address, 0).unwrap();
    assert_eq!(bus.read_register(ID.offset).unwrap(), ID_WORD);
    bus.write_register(AMP2.offset, 0x7fff).unwrap();
    assert_eq!(bus.read_register(AMP2.offset).unwrap(), 0x7fff);
    // The board runs when the machine lets it: up to 5 s.
    let first = bus.read_register(SAMPLE_COUNT.offset).unwrap();
    let t = std::time::Instant::now();
    let mut second = first;
    while second == first && t.elapsed().as_secs() < 5 {
        std::thread::sleep(std::time::Duration::from_millis(10));
        second = bus.read_register(SAMPLE_COUNT.offset).unwrap();
    }
    assert!(second > first, "{first} then {second}");
}
