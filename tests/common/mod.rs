//! What the command-line tests share: running the built `gyrocal`.

#![allow(dead_code)] // reason: each test crate includes this module and uses part of it

use std::ffi::OsStr;
use std::process::{Command, Output};

/// Run the built `gyrocal` with `args`; its status and both streams.
pub fn gyrocal<S: AsRef<OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gyrocal"))
        .args(args)
        .output()
        .unwrap()
}

/// A run's standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The one JSON object a successful `--json` run prints on one line.
pub fn json_object(o: Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert_eq!(
        text.trim().lines().count(),
        1,
        "one JSON object on one line"
    );
    serde_json::from_str(&text).unwrap()
}

/// The promise of a sigma: each output's self-calibration error against
/// the rate table within 3 of its sigma (the self-calibration's and the
/// table's own in quadrature, `selfcal_error_uncertainty`); `name` labels
/// the failure.
pub fn outputs_within_three_sigma(name: &str, st: &gyrocal_sim::field::scenario::FieldStep) {
    for k in 0..2 {
        let (e, s) = (st.selfcal_error[k], st.selfcal_error_uncertainty[k]);
        assert!(
            e.abs() <= 3.0 * s,
            "{name}: output {}: {e} at sigma {s}",
            k + 1
        );
    }
}
