//! A `gyrocal serve` child process for the tests: started on an ephemeral
//! port of 127.0.0.1, its URL read from the one line it prints when it
//! listens, its later stderr kept, killed when dropped.

#![allow(dead_code)] // reason: each test crate uses part of it

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};

/// A running `gyrocal serve`.
pub struct Served {
    child: Child,
    /// `etherbone://127.0.0.1:PORT`.
    pub url: String,
    /// `127.0.0.1:PORT`.
    pub address: String,
    lines: Arc<Mutex<Vec<String>>>,
}

impl Served {
    /// Serve `config` with `extra` options; panics with serve's stderr if
    /// it does not listen.
    pub fn start(config: &Path, extra: &[&str]) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_gyrocal"))
            .args(["serve", "--listen", "127.0.0.1:0", "--config"])
            .arg(config)
            .args(extra)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stderr = BufReader::new(child.stderr.take().unwrap());
        let mut first = String::new();
        stderr.read_line(&mut first).unwrap();
        let Some(at) = first.find("listening on etherbone://") else {
            let _ = child.kill();
            let mut rest = String::new();
            let _ = std::io::Read::read_to_string(&mut stderr, &mut rest);
            panic!("gyrocal serve did not listen: {first}{rest}");
        };
        let url: String = first[at + "listening on ".len()..]
            .split_whitespace()
            .next()
            .unwrap()
            .into();
        let lines = Arc::new(Mutex::new(vec![first.trim_end().to_string()]));
        let sink = lines.clone();
        std::thread::spawn(move || {
            for line in stderr.lines().map_while(Result::ok) {
                sink.lock().unwrap().push(line);
            }
        });
        Self {
            child,
            address: url.trim_start_matches("etherbone://").into(),
            url,
            lines,
        }
    }

    /// What serve printed on stderr so far.
    pub fn stderr(&self) -> Vec<String> {
        self.lines.lock().unwrap().clone()
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
