//! gyrocal-verify: verification of the exported Verilog with external tools.
//!
//! Tool drivers are verification tooling, not gateware: they live in this
//! crate so that `gyrocal-hdl` depends on rust-hdl and little else.
//!
//! ```text
//!   RtlGyroInterface ──► golden vectors ──► SystemVerilog testbench ──► Icarus (iverilog + vvp)
//!   (rust-hdl's own       (inputs and        + gyro_interface.v     └─► Verilator --binary --timing
//!    simulation)           outputs per cycle)
//!
//!   gyro_interface.v ──► verilator --lint-only -Wall + lint-waivers.vlt
//!                    └─► yosys synth_ice40 -dsp -spram / synth_xilinx ──► RESOURCES.md
//! ```
//!
//! * [`tools`]: finds `iverilog`/`vvp`, `verilator` (and the C++ tool chain
//!   its `--binary` needs) and `yosys` on `PATH`; a missing tool is an error
//!   that names the Debian package to install, never a silent skip.
//! * [`vectors`]: seeded random configurations and ADC stimulus, run through
//!   `gyrocal_hdl::rtl::RtlGyroInterface` (the design itself, not the model), with
//!   the outputs recorded on every cycle and at power-up.
//! * [`replay`]: a generated SystemVerilog testbench replays the vectors
//!   against the exported `gyro_interface` and compares every output on every
//!   cycle with `!==`, in Icarus Verilog and in Verilator.
//! * [`lint`]: `verilator --lint-only -Wall` with the committed waiver file,
//!   plus a check that no waiver is stale.
//! * [`synthesis`]: Yosys for iCE40 (with DSPs) and Xilinx 7-series; checks
//!   for latches and writes the resource counts to `verilog-out/RESOURCES.md`.
//!
//! Every run works in its own scratch folder under the system temp folder, so
//! tests may run in parallel; set `GYROCAL_KEEP_SCRATCH=1` to keep the folders
//! for inspection.

mod atomic;
pub mod formal;
pub mod lint;
pub mod pnr;
pub mod pnr_log;
pub mod replay;
pub mod resources;
pub mod synthesis;
pub mod targets;
pub mod tools;
pub mod vectors;
pub mod wrapper;

mod scratch;

pub use atomic::write_atomically;
pub use scratch::ScratchDir;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

/// Why a verification step could not produce a verdict.
///
/// A failed check (a mismatch, a lint warning, a latch) is not an error: it is
/// reported in the step's report. An error means the step could not run.
#[derive(Debug)]
pub enum VerifyError {
    /// A program is missing from `PATH`.
    MissingTool(tools::MissingTool),
    /// A YoWASP program is missing from the FPGA tools' virtual environment.
    MissingVenvTool(tools::MissingVenvTool),
    /// A file or folder could not be read or written.
    Io {
        /// What was being done.
        context: String,
        /// The underlying error.
        error: std::io::Error,
    },
    /// An external tool ran but failed, or printed something unexpected.
    ToolFailed {
        /// The command line.
        command: String,
        /// What went wrong.
        reason: String,
        /// The tool's standard output and error (possibly shortened).
        output: String,
    },
}

impl std::fmt::Display for VerifyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            VerifyError::MissingTool(m) => write!(f, "{m}"),
            VerifyError::MissingVenvTool(m) => write!(f, "{m}"),
            VerifyError::Io { context, error } => write!(f, "{context}: {error}"),
            VerifyError::ToolFailed {
                command,
                reason,
                output,
            } => write!(f, "`{command}` {reason}\n--- output ---\n{output}"),
        }
    }
}

impl std::error::Error for VerifyError {}

impl From<tools::MissingTool> for VerifyError {
    fn from(m: tools::MissingTool) -> Self {
        VerifyError::MissingTool(m)
    }
}

impl From<tools::MissingVenvTool> for VerifyError {
    fn from(m: tools::MissingVenvTool) -> Self {
        VerifyError::MissingVenvTool(m)
    }
}

/// An `Io` error with a context built lazily.
pub(crate) fn io_error(context: impl Into<String>) -> impl FnOnce(std::io::Error) -> VerifyError {
    let context = context.into();
    move |error| VerifyError::Io { context, error }
}

/// The root of the workspace this crate was built in.
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("gyrocal-verify lives inside the workspace")
        .to_owned()
}

/// `verilog-out/` of the workspace this crate was built in.
pub fn verilog_out_dir() -> PathBuf {
    workspace_root().join("verilog-out")
}

/// The committed export, `verilog-out/gyro_interface.v`.
pub fn committed_verilog() -> PathBuf {
    verilog_out_dir().join(gyrocal_hdl::export::VERILOG_FILE)
}

/// The committed export of the fine-carrier (ECP5) core,
/// `verilog-out/ecp5/gyro_interface.v`.
pub fn committed_fine_verilog() -> PathBuf {
    verilog_out_dir().join(gyrocal_hdl::export::verilog_file(
        gyrocal_hdl::model::gyro_interface::CarrierProfile::Fine,
    ))
}

/// The committed Verilator waiver file, `verilog-out/lint-waivers.vlt`.
pub fn committed_waivers() -> PathBuf {
    verilog_out_dir().join(lint::WAIVER_FILE)
}

/// The committed bus-attached export, `verilog-out/gyro_interface_axi.v`.
pub fn committed_axi_verilog() -> PathBuf {
    verilog_out_dir().join(gyrocal_hdl::export::AXI_VERILOG_FILE)
}

/// The committed waivers of the bus wrapper, `verilog-out/lint-waivers-axi.vlt`.
pub fn committed_axi_waivers() -> PathBuf {
    verilog_out_dir().join(lint::AXI_WAIVER_FILE)
}

/// The fine-carrier core's own waivers, `verilog-out/ecp5/lint-waivers.vlt`.
pub fn committed_fine_waivers() -> PathBuf {
    verilog_out_dir().join(lint::FINE_WAIVER_FILE)
}

/// The committed resource report, `verilog-out/RESOURCES.md`.
pub fn committed_resources() -> PathBuf {
    verilog_out_dir().join(synthesis::RESOURCES_FILE)
}

/// Standard output and error of a finished command, as one string.
pub(crate) fn combined_output(out: &Output) -> String {
    let mut s = String::from_utf8_lossy(&out.stdout).into_owned();
    let err = String::from_utf8_lossy(&out.stderr);
    if !err.is_empty() {
        if !s.is_empty() && !s.ends_with('\n') {
            s.push('\n');
        }
        s.push_str(&err);
    }
    s
}

/// At most the last `max` lines of `text` (tool logs can be megabytes).
pub(crate) fn tail(text: &str, max: usize) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let start = lines.len().saturating_sub(max);
    let mut s = String::new();
    if start > 0 {
        s.push_str(&format!("[... {start} earlier lines ...]\n"));
    }
    for l in &lines[start..] {
        s.push_str(l);
        s.push('\n');
    }
    s
}

/// A command line as text, for messages.
pub(crate) fn describe(cmd: &Command) -> String {
    let mut s = cmd.get_program().to_string_lossy().into_owned();
    for a in cmd.get_args() {
        s.push(' ');
        s.push_str(&a.to_string_lossy());
    }
    s
}

/// Run `cmd` to completion; returns its output and wall time. Fails only
/// when the program cannot be started (the exit status is the caller's
/// business).
pub(crate) fn run(cmd: &mut Command) -> Result<(Output, Duration), VerifyError> {
    let start = std::time::Instant::now();
    let out = cmd
        .output()
        .map_err(io_error(format!("cannot start `{}`", describe(cmd))))?;
    Ok((out, start.elapsed()))
}

/// Run `cmd` and require exit status 0.
pub(crate) fn run_ok(cmd: &mut Command) -> Result<(Output, Duration), VerifyError> {
    let (out, t) = run(cmd)?;
    if !out.status.success() {
        return Err(VerifyError::ToolFailed {
            command: describe(cmd),
            reason: format!("exited with {}", out.status),
            output: tail(&combined_output(&out), 60),
        });
    }
    Ok((out, t))
}
