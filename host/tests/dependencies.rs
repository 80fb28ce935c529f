//! The host crate runs on a board's CPU or a PC driver: its normal
//! dependency tree (`cargo tree -p gyrocal-host -e normal`) holds neither
//! rust-hdl nor the simulator nor the gateware crate.

use std::process::Command;

#[test]
fn the_host_depends_on_no_rust_hdl_and_no_simulator() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args(["tree", "--offline", "-p", "gyrocal-host", "-e", "normal"])
        .args(["--prefix", "none", "--format", "{p}"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let names: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(
        names.contains(&"gyrocal-host") && names.contains(&"gyrocal-regs"),
        "{names:?}"
    );
    for name in &names {
        assert!(
            !name.starts_with("rust-hdl")
                && !["gyrocal-sim", "gyrocal-hdl", "gyrocal-verify", "gyrocal"].contains(name),
            "gyrocal-host depends on {name}:\n{text}"
        );
    }
}
