//! What `run` and `reproduce` share: engine and waveform options, running
//! an experiment with a progress bar, and writing its outputs.

use crate::Failure;
use gyrocal_sim::engine::EngineKind;
use gyrocal_sim::experiment::{self, Experiment, Mode};
use gyrocal_sim::report::Report;
use gyrocal_sim::waveform::{Probe, VcdRecorder, parse_window};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

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
    /// Clock window of the dump, START:END (END exclusive).
    #[arg(long, default_value = "0:4096")]
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
            return Err(Failure::Input(
                "--engine verilator: this build has no Verilator engine (build with --features verilator)"
                    .into(),
            ));
        }
        let vcd = match &self.vcd {
            None => None,
            Some(path) => {
                let window = parse_window(&self.vcd_cycles).map_err(Failure::Input)?;
                let probes = Probe::parse_list(&self.vcd_signals).map_err(Failure::Input)?;
                let points = exp.readout_rates_dps.len() + exp.cal_freqs_hz.len();
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

fn check_writable_parent(path: &Path) -> Result<(), Failure> {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        return Err(Failure::Input(format!(
            "{}: folder {} does not exist",
            path.display(),
            parent.display()
        )));
    }
    Ok(())
}

/// Run the experiment with a progress bar on stderr (when it is a
/// terminal), then the waveform dump if asked.
pub fn execute(
    exp: &Experiment,
    options: &RunOptions,
    checked: &Checked,
) -> Result<Report, Failure> {
    let plan = experiment::plan(exp).map_err(Failure::Input)?;
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
    let bar = if options.quiet || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} {msg} [{bar:40}] {percent:>3}%  {human_pos}/{human_len} clocks  {per_sec}  eta {eta}",
            )
            .unwrap()
            .progress_chars("=> "),
        );
        bar.set_message(format!(
            "{} points on {}",
            plan.points.len(),
            checked.engine.name()
        ));
        bar
    };
    let report = experiment::run(exp, checked.engine, &|n| bar.inc(n)).map_err(Failure::Run)?;
    bar.finish_and_clear();
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
        exp.clock_hz,
        &comment,
    )
    .map_err(io)?;
    let result = experiment::observe_point_on(engine, exp, plan, point, &mut recorder);
    let finished = recorder.finish();
    if let Err(e) = result.map_err(Failure::Run).and(finished.map_err(io)) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, path).map_err(io)
}

/// One CSV row per point.
pub fn points_csv(report: &Report) -> String {
    let mut csv = String::from(
        "mode,rate_dps,cal_hz,settle_s,window_s,clocks,z1_lsb,z2_lsb,z1,z2,z1_theory,z2_theory\n",
    );
    for p in &report.points {
        let mode = match p.mode {
            Mode::Readout => "readout",
            Mode::Calibration => "calibration",
        };
        csv.push_str(&format!(
            "{mode},{},{},{},{},{},{},{},{:e},{:e},{:e},{:e}\n",
            p.rate_dps,
            p.cal_hz,
            p.settle_s,
            p.window_s,
            p.cycles,
            p.z_lsb[0],
            p.z_lsb[1],
            p.z[0],
            p.z[1],
            p.z_theory[0],
            p.z_theory[1]
        ));
    }
    csv
}

/// Write `results.json`, `points.csv` and the figures into `dir` (created
/// if missing), each through a temporary file and a rename.
pub fn write_results(report: &Report, dir: &Path) -> Result<Vec<PathBuf>, Failure> {
    std::fs::create_dir_all(dir).map_err(|e| {
        Failure::Input(format!(
            "--out {}: cannot create the folder: {e}",
            dir.display()
        ))
    })?;
    let json = serde_json::to_string_pretty(report).map_err(|e| Failure::Run(e.to_string()))?;
    let mut written = vec![];
    for (name, text) in [("results.json", json), ("points.csv", points_csv(report))] {
        let path = dir.join(name);
        gyrocal_verify::write_atomically(&path, &text)
            .map_err(|e| Failure::Run(format!("cannot write {}: {e}", path.display())))?;
        written.push(path);
    }
    written.extend(crate::plots::write_figures(report, dir).map_err(Failure::Run)?);
    Ok(written)
}

/// Human summary of scale factors against the exact theory.
pub fn summary(report: &Report) -> String {
    let t = &report.theory;
    let mut s = String::new();
    s.push_str(&format!(
        "engine {}: {} clocks in {:.2} s ({:.1} M clocks/s)\n",
        report.timing.engine,
        report.timing.cycles,
        report.timing.wall_s,
        report.timing.cycles_per_s / 1e6
    ));
    s.push_str("                                  output 1                output 2\n");
    let row = |name: &str, v: [f64; 2]| format!("{name:<32}{:>+22.6e}  {:>+22.6e}\n", v[0], v[1]);
    s.push_str(&row("sf_read (m^2/s^2 per deg/s)", report.sf_read_per_dps));
    s.push_str(&row("  exact theory, same fit", t.sf_read_per_dps));
    s.push_str(&row("sf_cal (per deg/s virtual)", report.sf_cal_per_dps));
    s.push_str(&row("  exact theory, same fit", t.sf_cal_per_dps));
    s.push_str(&format!(
        "{:<32}{:>+22.6}  {:>+22.6}\n",
        "ratio sf_read / sf_cal", report.ratio[0], report.ratio[1]
    ));
    s.push_str(&format!(
        "{:<32}{:>+22.6}  {:>+22.6}\n",
        "  exact theory, same fit", t.ratio[0], t.ratio[1]
    ));
    s.push_str(&format!(
        "{:<32}{:>+22.6}  {:>+22.6}\n",
        "  exact small-signal", t.small_signal.ratio[0], t.small_signal.ratio[1]
    ));
    s.push_str(&format!(
        "{:<32}{:>+22.6}  {:>+22.6}\n",
        "  paper eqs. (5)/(6)", t.small_signal.eq56_ratio[0], t.small_signal.eq56_ratio[1]
    ));
    s.push_str(&format!(
        "{:<32}{:>+21.4}%  {:>+21.4}%\n",
        "ratio error vs exact theory",
        100.0 * report.ratio_error[0],
        100.0 * report.ratio_error[1]
    ));
    s
}
