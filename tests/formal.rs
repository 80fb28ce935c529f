//! Formal proofs of the bus wrapper of the committed export
//! (`verilog-out/gyro_interface_axi.v`, the DSP core replaced by a stub with
//! free outputs) with SymbiYosys and Yices, through
//! `gyrocal_verify::formal`; what each property states is in
//! `formal/README.md`.
//!
//! * every property of `formal/axi_formal.sv` holds, by k-induction;
//! * every cover statement is reached (the properties are not vacuous);
//! * each `spec_*` property fails on its mutant of the export
//!   (`gyrocal_verify::formal::MUTANTS`), and every property has one.
//!
//! Requires the FPGA virtual environment with `yowasp-sby` and
//! `yices-smt2` (`scripts/fpga/install-venv.sh`); without it the tests fail
//! with a message naming that script. The mutants run two at a time.

use gyrocal_verify::formal::{self, FormalError, MUTANTS, SbyReport, Status, Task};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

fn bus() -> String {
    formal::committed_bus_verilog().unwrap_or_else(|e| panic!("{e}"))
}

/// The labels `labels` finds in the harness, sorted, each once.
fn harness_labels(labels: fn(&str) -> Vec<String>) -> Vec<String> {
    let sv = std::fs::read_to_string(formal::formal_dir().join("axi_formal.sv")).unwrap();
    sorted(labels(&sv))
}

fn sorted(mut v: Vec<String>) -> Vec<String> {
    v.sort();
    v.dedup();
    v
}

#[test]
fn the_bus_wrapper_is_proven_by_induction() {
    let report = formal::run_sby(&bus(), Task::Prove).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("prove: {:?} in {:.1?} wall", report.status, report.wall);
    assert_eq!(
        (report.status, report.by_induction),
        (Status::Pass, true),
        "failed: {:?}\n{}",
        report.failed,
        report.log
    );
}

#[test]
fn every_cover_statement_is_reached() {
    let covers = harness_labels(formal::cover_labels);
    assert!(covers.len() >= 5, "{covers:?}");
    let report = formal::run_sby(&bus(), Task::Cover).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("cover: {:?} in {:.1?} wall", report.status, report.wall);
    for e in &report.reached {
        eprintln!("  {} reached at step {}", e.property, e.step);
    }
    let reached = sorted(report.reached.iter().map(|e| e.property.clone()).collect());
    assert_eq!(
        (report.status, reached),
        (Status::Pass, covers),
        "{}",
        report.log
    );
}

#[test]
fn every_spec_property_has_a_mutant() {
    let properties = harness_labels(formal::spec_properties);
    assert!(properties.len() >= 20, "{properties:?}");
    let covered = sorted(MUTANTS.iter().map(|m| m.property.to_owned()).collect());
    assert_eq!(covered, properties);
}

#[test]
fn each_property_fails_on_its_mutant() {
    let bus = bus();
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<(usize, Result<SbyReport, FormalError>)>> = Mutex::new(Vec::new());
    let start = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(m) = MUTANTS.get(i) else { break };
                    let r = m
                        .apply(&bus)
                        .and_then(|v| formal::run_sby(&v, Task::Mutant(m.property)));
                    results.lock().unwrap().push((i, r));
                }
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|r| r.0);
    let mut missed = Vec::new();
    for (i, r) in &results {
        let m = &MUTANTS[*i];
        let outcome = match r {
            Ok(report) => match report.failed.iter().find(|f| f.property == m.property) {
                Some(f) => format!("FAILS at step {} ({:.1?})", f.step, report.wall),
                None => {
                    missed.push(m.name);
                    format!("{:?}, property holds to the depth", report.status)
                }
            },
            Err(e) => {
                missed.push(m.name);
                format!("error: {e}")
            }
        };
        eprintln!("{:24} {:18} {outcome}", m.name, m.property);
    }
    eprintln!("{} mutants in {:.1?} wall", MUTANTS.len(), start.elapsed());
    assert!(missed.is_empty(), "mutants not caught: {missed:?}");
}
