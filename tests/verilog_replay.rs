//! Golden-vector replay of the committed `verilog-out/gyro_interface.v` in
//! Icarus Verilog and in Verilator, against rust-hdl's own simulation of the
//! design, plus negative controls showing that the replay does catch a
//! difference (a corrupted expected word, a corrupted power-up value, a short
//! vector file, an X from an uninitialized register).
//!
//! Both simulators replay the same vectors (generated once per test process,
//! seed `vectors::DEFAULT_SEED`, over 20,000 cycles) and compare every output
//! on every cycle. Requires `iverilog`/`vvp` and `verilator` + `make` + `g++`
//! on PATH; a missing tool fails the test with the Debian package to install.

use gyrocal_hdl::model::gyro_interface::CarrierProfile;
use gyrocal_verify::replay::{self, Simulator};
use gyrocal_verify::vectors::{self, GoldenVectors};
use gyrocal_verify::{self as verify, ScratchDir, tools};
use std::path::PathBuf;
use std::sync::OnceLock;
use std::time::Instant;

/// The standard golden vectors, recorded once per test process.
fn golden() -> &'static GoldenVectors {
    static VECTORS: OnceLock<GoldenVectors> = OnceLock::new();
    VECTORS.get_or_init(|| {
        let t = Instant::now();
        let v = vectors::golden_vectors(vectors::DEFAULT_SEED);
        eprintln!(
            "golden vectors: {} cycles from rust-hdl in {:.1?}",
            v.len(),
            t.elapsed()
        );
        v
    })
}

/// The committed export of the core with this carrier profile, after
/// checking that it is what the design exports now (the vectors come from
/// the current design); panics saying which file and what to do if not.
fn committed(profile: CarrierProfile) -> PathBuf {
    let path = verify::verilog_out_dir().join(gyrocal_hdl::export::verilog_file(profile));
    let committed =
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        committed == gyrocal_hdl::export::verilog_for(profile),
        "{} is not what the design exports now: regenerate it (`cargo run --release -- export`) \
         before replaying",
        path.display()
    );
    path
}

/// The committed table-core export, checked once per test process.
fn committed_verilog() -> PathBuf {
    static CHECKED: OnceLock<PathBuf> = OnceLock::new();
    CHECKED
        .get_or_init(|| committed(CarrierProfile::Table))
        .clone()
}

/// The standard vectors on the fine-carrier (ECP5) core.
fn fine_golden() -> &'static GoldenVectors {
    static VECTORS: OnceLock<GoldenVectors> = OnceLock::new();
    VECTORS.get_or_init(|| vectors::golden_vectors_for(CarrierProfile::Fine, vectors::DEFAULT_SEED))
}

fn require_icarus() {
    if let Err(e) = tools::iverilog() {
        panic!("{e}");
    }
}

fn require_verilator() {
    if let Err(e) = tools::verilator_build() {
        panic!("{e}");
    }
}

fn compile(sim: Simulator, verilog: &std::path::Path) -> replay::CompiledTestbench {
    replay::compile(sim, verilog).unwrap_or_else(|e| panic!("{sim}: {e}"))
}

fn expect_pass(tb: &replay::CompiledTestbench, v: &GoldenVectors) -> replay::ReplayReport {
    let report = tb.run(v).unwrap_or_else(|e| panic!("{e}"));
    if let Err(msg) = report.check(v) {
        panic!("{msg}");
    }
    eprintln!(
        "{} ({}): REPLAY PASS {} cycles; compile {:.1?}, run {:.1?}",
        report.simulator, report.tool_version, report.cycles, report.compile_time, report.run_time
    );
    report
}

/// A copy of `v` with bit 0 of the expected z1 flipped at `cycle`.
fn corrupt_z1(v: &GoldenVectors, cycle: usize) -> GoldenVectors {
    let mut bad = v.clone();
    bad.cycles[cycle].expected.z.0 ^= 1;
    bad
}

/// The testbench must fail on a vector file that ends early or is missing.
fn check_file_errors(tb: &replay::CompiledTestbench, v: &GoldenVectors) {
    // A vector file that ends early.
    let dir = ScratchDir::new("short-vectors").unwrap();
    let file = dir.path().join("short.hex");
    let text = v.to_hex();
    let short: Vec<&str> = text.lines().take(2 + 100).collect();
    std::fs::write(&file, short.join("\n") + "\n").unwrap();
    let report = tb.run_file(&file).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        !report.passed && !report.errors.is_empty(),
        "{}",
        report.log
    );
    assert_eq!(report.cycles, 100);

    // A vector file that does not exist.
    let report = tb
        .run_file(&dir.path().join("missing.hex"))
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(!report.passed && report.cycles == 0, "{}", report.log);
    assert!(
        report.errors[0].starts_with("cannot open"),
        "{}",
        report.log
    );
}

#[test]
fn icarus_replay_matches_rust_hdl() {
    require_icarus();
    let v = golden();
    assert!(v.len() >= vectors::MIN_CYCLES);
    let tb = compile(Simulator::Icarus, &committed_verilog());
    expect_pass(&tb, v);
}

#[test]
fn verilator_replay_matches_rust_hdl() {
    require_verilator();
    let v = golden();
    let tb = compile(Simulator::Verilator, &committed_verilog());
    expect_pass(&tb, v);
    // The same binary must notice a corrupted word (Verilator's own negative
    // control, at no extra build cost).
    let cycle = v.len() - 1;
    let report = tb
        .run(&corrupt_z1(v, cycle))
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        !report.passed,
        "Verilator replay missed a corrupted expected word"
    );
    assert_eq!(report.mismatches, 1, "{}", report.log);
    assert_eq!(report.reported[0].cycle, Some(cycle));
    assert_eq!(report.reported[0].port, "z1");
    check_file_errors(&tb, &v.prefix(200));
}

#[test]
fn the_fine_core_replays_in_icarus_and_verilator() {
    // The ECP5 core's Verilog (its ROM's and multipliers' hand-written
    // leaves included) against rust-hdl's simulation of it, every output
    // of every cycle, in both simulators.
    require_icarus();
    require_verilator();
    let v = fine_golden();
    let verilog = committed(CarrierProfile::Fine);
    expect_pass(&compile(Simulator::Icarus, &verilog), v);
    let tb = compile(Simulator::Verilator, &verilog);
    expect_pass(&tb, v);
    // Negative control: the table core's vectors do not pass on it (the
    // carriers differ from the first live cycle on).
    let report = tb.run(golden()).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        !report.passed,
        "the fine core replayed the table core's vectors"
    );
}

/// Cycles of the standard vectors the Icarus negative controls replay
/// (Icarus runs this design at about 1,400 cycles/s).
const CONTROL_CYCLES: usize = 2000;

#[test]
fn replay_catches_corrupted_vectors() {
    require_icarus();
    let v = &golden().prefix(CONTROL_CYCLES);
    assert!(
        v.cycles.iter().any(|c| c.expected.z_valid),
        "the prefix reaches no z output"
    );
    let tb = compile(Simulator::Icarus, &committed_verilog());

    // One expected output word off by one LSB, in the middle of the run.
    let cycle = v.len() / 2;
    let report = tb
        .run(&corrupt_z1(v, cycle))
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        !report.passed,
        "the replay did not notice a corrupted word:\n{}",
        report.log
    );
    assert_eq!(report.mismatches, 1, "{}", report.log);
    let m = &report.reported[0];
    assert_eq!((m.cycle, m.port.as_str()), (Some(cycle), "z1"));
    assert_ne!(m.expected, m.got);
    assert!(report.check(v).is_err());

    // A wrong power-up value.
    let mut bad = v.clone();
    bad.power_up.dac.1 = bad.power_up.dac.1.wrapping_add(1);
    let report = tb.run(&bad).unwrap_or_else(|e| panic!("{e}"));
    assert!(!report.passed);
    assert_eq!(report.reported[0].cycle, None, "{}", report.log);
    assert_eq!(report.reported[0].port, "dac2");

    check_file_errors(&tb, v);
}

/// The committed export with the power-up value of the first registered
/// multiplier (the Q1.15 product behind dac1) removed, in a scratch folder.
fn export_without_first_multiplier_init() -> (ScratchDir, PathBuf) {
    let original = std::fs::read_to_string(committed_verilog()).unwrap();
    let init = "initial p = 0;";
    let at = original
        .find(init)
        .expect("no `initial p = 0;` in the export");
    let broken = format!("{}{}", &original[..at], &original[at + init.len()..]);
    let dir = ScratchDir::new("x-control").unwrap();
    let file = dir.path().join("gyro_interface.v");
    std::fs::write(&file, broken).unwrap();
    (dir, file)
}

#[test]
fn icarus_replay_catches_x_from_an_uninitialized_register() {
    // Icarus sees X in the register, which `!==` must report.
    require_icarus();
    let v = &golden().prefix(CONTROL_CYCLES);
    let (_dir, file) = export_without_first_multiplier_init();
    let report = compile(Simulator::Icarus, &file)
        .run(v)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        !report.passed,
        "an X output went unnoticed:\n{}",
        report.log
    );
    assert!(
        report.reported.iter().any(|m| m.got.contains(['x', 'X'])),
        "expected an X in the reported mismatches:\n{}",
        report.log
    );
}

#[test]
fn verilator_replay_catches_an_uninitialized_register() {
    // Verilator is two-state: with `--x-initial unique` and
    // `+verilator+rand+reset+2` the register starts from a random value,
    // which must show at the outputs.
    require_verilator();
    let v = &golden().prefix(CONTROL_CYCLES);
    let (_dir, file) = export_without_first_multiplier_init();
    let report = compile(Simulator::Verilator, &file)
        .run(v)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        !report.passed,
        "a register without power-up value went unnoticed:\n{}",
        report.log
    );
    assert!(
        report.reported.iter().any(|m| m.port == "dac1"),
        "expected dac1 to differ:\n{}",
        report.log
    );
}

#[test]
fn vectors_exercise_the_outputs_and_keep_the_documented_ranges() {
    // Not a Verilog check: guards that the replay compares something
    // meaningful, and the port claims the lint waivers rely on.
    let v = golden();
    let valid = v.cycles.iter().filter(|c| c.expected.z_valid).count();
    assert!(valid >= 200, "only {valid} z_valid pulses");
    assert!(
        v.cycles.iter().any(|c| c.expected.z.0 != 0)
            && v.cycles.iter().any(|c| c.expected.z.1 != 0)
    );
    assert!(
        v.cycles.iter().any(|c| c.expected.z.0 < 0) && v.cycles.iter().any(|c| c.expected.z.0 > 0)
    );
    let z_max = v
        .cycles
        .iter()
        .map(|c| c.expected.z.0.abs().max(c.expected.z.1.abs()))
        .max()
        .unwrap();
    assert!(
        z_max >= 1 << 36,
        "z never comes near the top of its range (max |z| = {z_max}, full-scale DC is about 2^37)"
    );
    assert_eq!(
        v.power_up,
        Default::default(),
        "power-up outputs are all zero by design"
    );
    let mut previous = v.power_up;
    for (n, c) in v.cycles.iter().enumerate() {
        let o = c.expected;
        assert!(
            o.dac.0 != i16::MIN && o.dac.1 != i16::MIN,
            "cycle {n}: |dac| > 32767: {o:?}"
        );
        for z in [o.z.0, o.z.1] {
            assert!(
                (-(1i64 << 39)..1i64 << 39).contains(&z),
                "cycle {n}: z out of 40 bits"
            );
        }
        if o.z != previous.z {
            assert!(o.z_valid, "cycle {n}: z changed without z_valid");
        }
        if o.z_valid {
            assert!(
                !previous.z_valid,
                "cycle {n}: z_valid longer than one clock"
            );
        }
        previous = o;
    }
}
