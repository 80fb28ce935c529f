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
