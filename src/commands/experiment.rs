//! What `run` and `reproduce` share: engine and waveform options, running
//! an experiment with a progress bar, and writing its outputs.

use crate::Failure;
use gyrocal_sim::engine::EngineKind;
use gyrocal_sim::experiment::{self, Experiment, Mode, Tick};
use gyrocal_sim::report::Report;
use gyrocal_sim::waveform::{Probe, VcdRecorder, parse_window};
use std::path::{Path, PathBuf};

/// The text of `--config FILE`, and the name its errors go by (the path).
pub fn read_config(path: &Path) -> Result<(String, String), Failure> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| Failure::Input(format!("--config {name}: cannot read the file: {e}")))?;
    Ok((name, text))
}

/// Create the `--out` folder if missing; one that cannot be made is the
/// user's input.
pub fn create_out_dir(dir: &Path) -> Result<(), Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::Input(format!(
            "--out {}: cannot create the folder: {e}",
            dir.display()
        ))
    })
}

/// Create `dir` if missing and write each `(file name, text)` into it,
/// each through a temporary file and a rename; returns the paths written.
pub fn write_files(dir: &Path, files: Vec<(&str, String)>) -> Result<Vec<PathBuf>, Failure> {
    create_out_dir(dir)?;
    files
        .into_iter()
        .map(|(name, text)| {
            let path = dir.join(name);
            gyrocal_verify::write_atomically(&path, &text)
                .map_err(|e| Failure::Run(format!("cannot write {}: {e}", path.display())))?;
            Ok(path)
        })
        .collect()
}

/// `--config FILE` read and checked as the experiment `gyrocal run` runs.
pub fn load_experiment(path: &Path) -> Result<Experiment, Failure> {
    let (name, text) = read_config(path)?;
    gyrocal_sim::config::parse(&name, &text).map_err(Failure::input)
}

/// Options every experiment command takes.
#[derive(clap::Args, Clone, Debug)]
pub struct RunOptions {
    /// Datapath simulator: model (bit-true Rust, default), verilator (the
    /// exported Verilog; needs a build with --features verilator) or rtl
    /// (rust-hdl's simulation: thousands of clocks per second).
    #[arg(long, default_value = "model")]
    pub engine: String,
    /// Write a VCD waveform of one point to this file.
    #[arg(long)]
    pub vcd: Option<PathBuf>,
    /// Point to dump (0-based: readout points first, then calibration).
    #[arg(long, default_value_t = 0)]
    pub vcd_point: usize,
    /// Clock window of the dump, START:END (END exclusive); the default
    /// shows the drives starting at clock 8232, once the core has filled its
    /// carrier tables.
    #[arg(long, default_value = "8192:12288")]
    pub vcd_cycles: String,
    /// Signals to dump: names or groups (ports, internals, analog, all).
    #[arg(long, default_value = "all")]
    pub vcd_signals: String,
    /// Do not show a progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Parsed and checked options.
pub struct Checked {
    /// The engine.
    pub engine: EngineKind,
    /// Waveform request, if any.
    pub vcd: Option<(PathBuf, usize, std::ops::Range<u64>, Vec<Probe>)>,
}

impl RunOptions {
    /// Check every option before any work starts.
    pub fn check(&self, exp: &Experiment) -> Result<Checked, Failure> {
        let engine =
            EngineKind::parse(&self.engine).map_err(|e| Failure::Input(format!("--{e}")))?;
        if engine == EngineKind::Verilator && !cfg!(feature = "verilator") {
            return Err(Failure::Input(format!(
                "--engine verilator: {}",
                gyrocal_sim::error::EngineError::NotBuilt
            )));
        }
        let vcd = match &self.vcd {
            None => None,
            Some(path) => {
                let window = parse_window(&self.vcd_cycles).map_err(Failure::input)?;
                let probes = Probe::parse_list(&self.vcd_signals).map_err(Failure::input)?;
                let points = exp.points.readout_rates_dps.len() + exp.points.cal_freqs_hz.len();
                if self.vcd_point >= points {
                    return Err(Failure::Input(format!(
                        "--vcd-point {}: this experiment has points 0..={}",
                        self.vcd_point,
                        points - 1
                    )));
                }
                check_writable_parent(path)?;
                Some((path.clone(), self.vcd_point, window, probes))
            }
        };
        Ok(Checked { engine, vcd })
    }
}

/// The folder of `path`, which may not exist yet: it is created when the
/// file is written, as `--out` is (so `--out out/ --vcd out/wave.vcd`
/// works on a fresh checkout). Its nearest existing ancestor must be a
/// folder.
fn check_writable_parent(path: &Path) -> Result<(), Failure> {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let existing = parent
        .ancestors()
        .find(|a| a.as_os_str().is_empty() || a.exists());
    match existing {
        Some(a) if a.as_os_str().is_empty() || a.is_dir() => Ok(()),
        Some(a) => Err(Failure::Input(format!(
            "--vcd {}: {} is not a folder",
            path.display(),
            a.display()
        ))),
        None => Ok(()),
    }
}

/// Run the experiment with a progress bar on stderr (when it is a
/// terminal), then the waveform dump if asked.
pub fn execute(
    exp: &Experiment,
    options: &RunOptions,
    checked: &Checked,
) -> Result<Report, Failure> {
    let plan = experiment::plan(exp).map_err(Failure::input)?;
    for w in &plan.warnings {
        eprintln!("warning: {w}");
    }
    let total = plan.total_cycles();
    if checked.engine == EngineKind::Rtl && total > 50_000_000 {
        eprintln!(
            "note: {total} clocks on the rtl engine (rust-hdl's simulation, about 7,000 clocks/s) take about {:.0} hours",
            total as f64 / 7000.0 / 3600.0 / rayon_threads()
        );
    }
    let bar = super::progress_bar(
        options.quiet,
        total,
        "{spinner} {msg} [{bar:40}] {percent:>3}%  {human_pos}/{human_len} clocks  {per_sec}  eta {eta}",
    );
    bar.set_message(format!(
        "{} points on {}",
        plan.points.len(),
        checked.engine.name()
    ));
    let tick = |t: Tick| match t {
        Tick::Clocks(n) => bar.inc(n),
        Tick::Planned(n) => bar.inc_length(n),
    };
    let measured =
        experiment::run_points(exp, &plan, checked.engine, &tick).map_err(Failure::run)?;
    bar.finish_and_clear();
    let report = Report::new(exp, &plan, measured);
    for w in report.warnings.iter().skip(plan.warnings.len()) {
        eprintln!("warning: {w}");
    }
    if let Some((path, index, window, probes)) = &checked.vcd {
        write_vcd(
            exp,
            &plan,
            checked.engine,
            path,
            *index,
            window.clone(),
            probes,
        )?;
        eprintln!("wrote {}", path.display());
    }
    Ok(report)
}

fn rayon_threads() -> f64 {
    std::thread::available_parallelism().map_or(1.0, |n| n.get() as f64)
}

fn write_vcd(
    exp: &Experiment,
    plan: &experiment::Plan,
    engine: EngineKind,
    path: &Path,
    index: usize,
    window: std::ops::Range<u64>,
    probes: &[Probe],
) -> Result<(), Failure> {
    let point = &plan.points[index];
    let what = match point.mode {
        Mode::Readout => format!("readout at {} deg/s", point.rate_dps),
        Mode::Calibration => format!("calibration at f_cal = {} Hz", point.cal_hz),
    };
    let tmp = path.with_extension("vcd.tmp-write");
    let io = |e: std::io::Error| Failure::Run(format!("cannot write {}: {e}", path.display()));
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(io)?;
    }
    let file = std::fs::File::create(&tmp).map_err(io)?;
    let comment = format!(
        "gyrocal point {index} ({what}), engine {}, clocks {}..{}",
        engine.name(),
        window.start,
        window.end
    );
    let mut recorder = VcdRecorder::new(
        std::io::BufWriter::new(file),
        window,
        probes,
        exp.drive.clock_hz,
        &comment,
    )
    .map_err(io)?;
    let result = experiment::observe_point_on(engine, exp, plan, point, &mut recorder);
    let finished = recorder.finish();
    if let Err(e) = result.map_err(Failure::run).and(finished.map_err(io)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, path).map_err(io)
}

/// One CSV row per point.
pub fn points_csv(report: &Report) -> String {
    let mut csv = String::from(
        "mode,rate_dps,cal_hz,settle_s,window_s,batch_s,clocks,z1_lsb,z2_lsb,z1,z2,z1_uncertainty,z2_uncertainty,z1_theory,z2_theory\n",
    );
    for p in &report.points {
        let mode = match p.mode {
            Mode::Readout => "readout",
            Mode::Calibration => "calibration",
        };
        csv.push_str(&format!(
            "{mode},{},{},{},{},{},{},{},{},{:e},{:e},{:e},{:e},{:e},{:e}\n",
            p.rate_dps,
            p.cal_hz,
            p.settle_s,
            p.window_s,
            p.batch_s,
            p.cycles,
            p.z_lsb[0],
            p.z_lsb[1],
            p.z[0],
            p.z[1],
            p.z_uncertainty[0],
            p.z_uncertainty[1],
            p.z_theory[0],
            p.z_theory[1]
        ));
    }
    csv
}

/// Write `results.json`, `points.csv` and the figures into `dir` (created
/// if missing), each through a temporary file and a rename.
pub fn write_results(report: &Report, dir: &Path) -> Result<Vec<PathBuf>, Failure> {
    let json = serde_json::to_string_pretty(report).map_err(|e| Failure::Run(e.to_string()))?;
    let mut written = write_files(
        dir,
        vec![("results.json", json), ("points.csv", points_csv(report))],
    )?;
    written.extend(crate::plots::write_figures(report, dir).map_err(Failure::run)?);
    Ok(written)
}

/// `value +- uncertainty` in scientific notation, 4 digits after the point.
fn with_sigma(value: f64, sigma: f64) -> String {
    format!("{value:+.4e} +- {sigma:.1e}")
}

/// Human summary of scale factors, with their 1-sigma uncertainties,
/// against the exact theory.
pub fn summary(report: &Report) -> String {
    let t = &report.theory;
    let mut s = String::new();
    s.push_str(&format!(
        "engine {}: {} clocks in {:.2} s ({:.1} M clocks/s), budget {} s\n",
        report.timing.engine,
        report.timing.cycles,
        report.timing.wall_s,
        report.timing.cycles_per_s / 1e6,
        report.timing.budget_s
    ));
    s.push_str("                                          output 1                   output 2\n");
    let row = |name: &str, v: [f64; 2], u: [f64; 2]| {
        format!(
            "{name:<32}{:>26}  {:>26}\n",
            with_sigma(v[0], u[0]),
            with_sigma(v[1], u[1])
        )
    };
    let exact =
        |name: &str, v: [f64; 2]| format!("{name:<32}{:>+17.4e}{:9}  {:>+17.4e}\n", v[0], "", v[1]);
    s.push_str(&row(
        "sf_read (m^2/s^2 per deg/s)",
        report.scale_factors.sf_read_per_dps,
        report.scale_factors.sf_read_uncertainty,
    ));
    s.push_str(&exact("  exact theory, same fit", t.sf_read_per_dps));
    s.push_str(&row(
        "sf_cal (per deg/s virtual)",
        report.scale_factors.sf_cal_per_dps,
        report.scale_factors.sf_cal_uncertainty,
    ));
    s.push_str(&exact("  exact theory, same fit", t.sf_cal_per_dps));
    s.push_str(&row(
        "sf_read (z LSB per deg/s)",
        report.sf_read_lsb_per_dps,
        report.sf_read_lsb_uncertainty,
    ));
    s.push_str(&row(
        "sf_cal (z LSB per deg/s virtual)",
        report.sf_cal_lsb_per_dps,
        report.sf_cal_lsb_uncertainty,
    ));
    let ratio = |v: f64, u: f64| format!("{v:+.6} +- {u:.1e}");
    s.push_str(&format!(
        "{:<32}{:>26}  {:>26}\n",
        "ratio sf_read / sf_cal",
        ratio(
            report.scale_factors.ratio[0],
            report.scale_factors.ratio_uncertainty[0]
        ),
        ratio(
            report.scale_factors.ratio[1],
            report.scale_factors.ratio_uncertainty[1]
        )
    ));
    let plain =
        |name: &str, v: [f64; 2]| format!("{name:<32}{:>+17.6}{:9}  {:>+17.6}\n", v[0], "", v[1]);
    s.push_str(&plain("  exact theory, same fit", t.ratio));
    s.push_str(&plain("  exact small-signal", t.small_signal.ratio));
    s.push_str(&plain("  paper eqs. (5)/(6)", t.small_signal.eq56_ratio));
    let sigmas: [f64; 2] =
        // The relative error over the relative sigma: the sign of the
        // error column beside it.
        std::array::from_fn(|k| {
            report.ratio_error[k] / (report.scale_factors.ratio_uncertainty[k] / t.ratio[k].abs())
        });
    s.push_str(&format!(
        "{:<32}{:>+16.4}% {:>+5.1}s  {:>+16.4}% {:>+5.1}s\n",
        "ratio error vs exact theory",
        100.0 * report.ratio_error[0],
        sigmas[0],
        100.0 * report.ratio_error[1],
        sigmas[1]
    ));
    s.push_str("(+- is the 1-sigma budget: batch spread, settling, DAC images; docs/error-budget.md; s: the error in sigmas)\n");
    s
}
