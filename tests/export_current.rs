//! The committed verilog-out/ is exactly what the rust-hdl design exports.

use gyrocal_hdl::export;
use std::path::Path;

#[test]
fn committed_export_is_current() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("verilog-out");
    for (name, text) in export::files() {
        let committed = std::fs::read_to_string(dir.join(name))
            .unwrap_or_else(|e| panic!("verilog-out/{name}: {e}"));
        assert!(
            committed == text,
            "verilog-out/{name} differs from the design: run `cargo run --release -- export` and commit"
        );
    }
}
