//! `gyrocal sweep --config FILE [--shard I/N] [--json] [--out DIR]`:
//! self-calibration over a production spread (`gyrocal_sim::sweep`), and
//! `gyrocal sweep merge PARTS... [--json] [--out DIR]`, which joins the
//! shards' JSON reports into the unsharded one, and `gyrocal sweep part
//! --config FILE --index I`, which prints part I as a `gyrocal field` file.
//!
//! The file holds the sections of `gyrocal field` (`[drift]` optional:
//! without it each device is calibrated at the factory temperature alone)
//! plus `[spread]` (`gyrocal_sim::sweep::spread`). Progress goes to stderr:
//! a bar on a terminal, else one line per device. With `--json` stdout is
//! the report (`devices`, each with `index`, `device`, `sf_selfcal_error`,
//! `sf_selfcal_uncertainty`, `identified`, its `steps`, `failed` and
//! `warnings`; and `summary`: yield at the tolerance, error percentiles,
//! coverage, and the warnings: inputs no sigma covers, errors beyond 3
//! sigma; printed on stderr and in the text summary too). `--out`
//! writes sweep.json, sweep.csv (a row per device and step) and the
//! figures fig_sweep (the error's CDF against the tolerance, the error
//! against the split and against Q1).
//!
//! Devices that fail (no resonance found, a drive that would clip) are
//! part of the result: they count against the yield and are listed; the
//! exit status is 0. Bad input exits with 2 and one line.

use crate::Failure;
use gyrocal_sim::sweep::{self, Shard, SweepReport, summary::Summary};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// Options of `gyrocal sweep`.
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Args {
    #[command(subcommand)]
    pub merge: Option<Sub>,
    /// Sweep: the sections of `gyrocal field` (`[drift]` optional) plus `[spread]` (TOML).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Run shard I of N (I from 1): the devices i with i mod N = I - 1.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    #[command(flatten)]
    pub output: Output,
}

/// Where the report goes.
#[derive(clap::Args)]
pub struct Output {
    /// Print one JSON object (the whole report) to stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Also write sweep.json, sweep.csv and the figures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `gyrocal sweep merge`.
#[derive(clap::Subcommand)]
pub enum Sub {
    /// Join the JSON reports of a sweep's shards (`--shard I/N --json`) into
    /// the report of the unsharded sweep.
    Merge(MergeArgs),
    /// Print part I of a sweep as a `gyrocal field` file (TOML on stdout):
    /// `gyrocal field` runs it again alone, to the sweep's figures.
    Part(PartArgs),
}

/// Options of `gyrocal sweep part`.
#[derive(clap::Args)]
pub struct PartArgs {
    /// The sweep's file (with `[spread]`).
    #[arg(long)]
    pub config: PathBuf,
    /// The part, as the sweep's `index` (from 0).
    #[arg(long)]
    pub index: u32,
}

/// Options of `gyrocal sweep merge`.
#[derive(clap::Args)]
pub struct MergeArgs {
    /// The shards' JSON reports, every shard once, in any order.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    #[command(flatten)]
    pub output: Output,
}

/// Run the sweep, or merge.
pub fn run(args: &Args) -> Result<(), Failure> {
    match &args.merge {
        Some(Sub::Merge(m)) => return merge(m),
        Some(Sub::Part(p)) => return part(p),
        None => {}
    }
    let Some(path) = &args.config else {
        return Err(Failure::Input(
            "sweep: give --config FILE (a field scenario with [spread]), or `sweep merge PARTS...`"
                .into(),
        ));
    };
    let (name, text) = super::experiment::read_config(path)?;
    let sw = sweep::parse(&name, &text).map_err(|e| Failure::Input(e.to_string()))?;
    let total = sw.device_count(args.shard);
    let shard = args.shard.map_or(String::new(), |s| format!(", shard {s}"));
    eprintln!(
        "{total} devices{shard}, {} temperature step(s) each",
        sw.scenario.drift.temperatures_c.len()
    );
    let bar = super::progress_bar(
        false,
        u64::from(total),
        "devices [{bar:40}] {pos}/{len}  eta {eta}",
    );
    let start = Instant::now();
    let report = sw.run(args.shard, &|d| {
        if bar.is_hidden() {
            eprintln!("{}", device_line(d));
        }
        bar.inc(1);
    });
    bar.finish_and_clear();
    let clocks: u64 = report.devices.iter().map(|d| d.clocks).sum();
    eprintln!(
        "{total} devices, {clocks:.3e} clocks in {:.1} s wall",
        start.elapsed().as_secs_f64(),
        clocks = clocks as f64
    );
    // Inputs no sigma covers, and errors it does not: on stderr whatever
    // the output, as `gyrocal field` prints its own.
    for w in &report.summary.warnings {
        eprintln!("{w}");
    }
    emit(&report, &name, &args.output)
}

/// A device's progress line.
fn device_line(d: &sweep::DeviceResult) -> String {
    match (d.sf_selfcal_error, d.failed.first()) {
        (Some(e), None) => format!(
            "device {}: worst self-cal error {:+.4}% / {:+.4}%{}",
            d.index,
            100.0 * e[0],
            100.0 * e[1],
            if d.within_tolerance {
                ""
            } else {
                " (out of tolerance)"
            }
        ),
        (_, Some(f)) => format!("device {}: FAILED ({}): {}", d.index, f.stage, f.error),
        (None, None) => format!("device {}: no step", d.index),
    }
}

/// `gyrocal sweep part`: the part's field file, printed whole or not at all.
fn part(p: &PartArgs) -> Result<(), Failure> {
    let (name, text) = super::experiment::read_config(&p.config)?;
    let sw = sweep::parse(&name, &text).map_err(Failure::input)?;
    let file = sw.part_file(p.index).map_err(Failure::input)?;
    print!(
        "# Part {} of the sweep {name} (`gyrocal sweep part`): run it alone with\n\
         # `gyrocal field --config FILE`.\n{file}",
        p.index
    );
    Ok(())
}

fn merge(m: &MergeArgs) -> Result<(), Failure> {
    let mut parts = vec![];
    for p in &m.parts {
        let text = std::fs::read_to_string(p)
            .map_err(|e| Failure::Input(format!("{}: cannot read the file: {e}", p.display())))?;
        let report: SweepReport = serde_json::from_str(&text).map_err(|e| {
            Failure::Input(format!(
                "{}: not a sweep report (`gyrocal sweep --shard I/N --json`): {e}",
                p.display()
            ))
        })?;
        parts.push(report);
    }
    let report = sweep::merge(parts).map_err(|e| Failure::Input(e.to_string()))?;
    emit(&report, "merged sweep", &m.output)
}

fn emit(report: &SweepReport, name: &str, out: &Output) -> Result<(), Failure> {
    let json = serde_json::to_string(report).map_err(|e| Failure::Run(e.to_string()))?;
    if let Some(dir) = &out.out {
        let files = vec![("sweep.json", json.clone()), ("sweep.csv", csv(report))];
        let mut written = super::experiment::write_files(dir, files)?;
        let title = format!("Self-calibration over a production spread: {name}");
        written.extend(
            crate::plots::write_sweep_figure(report, &title, dir, "fig_sweep")
                .map_err(Failure::run)?,
        );
        for path in written {
            eprintln!("wrote {}", path.display());
        }
    }
    if out.json {
        println!("{json}");
    } else {
        print!("{}", summary(report));
    }
    Ok(())
}

/// One row per device and finished step; a device that failed has a row
/// per failure with its error (quoted) and empty numbers.
pub fn csv(report: &SweepReport) -> String {
    let mut s = String::from(
        "index,f1_hz,f2_hz,split_hz,q1,q2,angular_gain,quadrature_dps,damping_coupling_dps,\
         clock_error_ppm,temperature_c,selfcal_error1,selfcal_error2,selfcal_error_uncertainty1,\
         selfcal_error_uncertainty2,identified_f1_hz,identified_f2_hz,identified_q1,\
         identified_q2,identified_loop_phase_deg,failure\n",
    );
    for d in &report.devices {
        let g = &d.device;
        let head = [
            g.f1_hz,
            g.f2_hz,
            g.f2_hz - g.f1_hz,
            g.q1,
            g.q2,
            g.angular_gain,
            g.quadrature_dps,
            g.damping_coupling_dps,
            d.clock_error_ppm,
        ]
        .map(|v| format!("{v:e}"))
        .join(",");
        for st in &d.steps {
            let i = &st.identified;
            let values = [
                st.temperature_c,
                st.sf_selfcal_error[0],
                st.sf_selfcal_error[1],
                st.selfcal_error_uncertainty[0],
                st.selfcal_error_uncertainty[1],
                i.f1_hz,
                i.f2_hz,
                i.q1,
                i.q2,
                i.loop_phase_deg,
            ]
            .map(|v| format!("{v:e}"))
            .join(",");
            let _ = writeln!(s, "{},{head},{values},", d.index);
        }
        for f in &d.failed {
            let t = f.temperature_c.map_or(String::new(), |t| format!("{t:e}"));
            let text = format!("{}: {}", f.stage, f.error).replace('"', "\"\"");
            let _ = writeln!(s, "{},{head},{t},,,,,,,,,,\"{text}\"", d.index);
        }
    }
    s
}

/// The human-readable summary.
pub fn summary(report: &SweepReport) -> String {
    let mut s = String::new();
    let Summary {
        devices,
        failed,
        tolerance,
        yield_per_output: y,
        yield_both,
        ..
    } = &report.summary;
    let _ = writeln!(
        s,
        "{devices} devices{}, {failed} failed; yield at {:.3}%: {:.1}% / {:.1}% per output, {:.1}% both",
        report
            .shard
            .map_or(String::new(), |sh| format!(" (shard {sh})")),
        100.0 * tolerance,
        100.0 * y[0],
        100.0 * y[1],
        100.0 * yield_both
    );
    let sm = &report.summary;
    errors_block(&mut s, sm);
    coverage_block(&mut s, sm);
    for n in &sm.notes {
        let _ = writeln!(s, "{n}");
    }
    for d in report.devices.iter().filter(|d| !d.failed.is_empty()) {
        let _ = writeln!(s, "{}", device_line(d));
    }
    for w in &sm.warnings {
        let _ = writeln!(s, "{w}");
    }
    s
}

/// The summary's worst-error percentiles per output, and the maximum.
fn errors_block(s: &mut String, sm: &Summary) {
    if !sm.error_percentiles.is_empty() {
        let _ = writeln!(
            s,
            "worst |self-cal error| per device (output 1 / output 2):"
        );
        for [p, e1, e2] in &sm.error_percentiles {
            let _ = writeln!(
                s,
                "  {p:>4.0}th percentile  {:.4}% / {:.4}%",
                100.0 * e1,
                100.0 * e2
            );
        }
        if let Some(m) = sm.max_error {
            let _ = writeln!(
                s,
                "  maximum          {:.4}% / {:.4}%",
                100.0 * m[0],
                100.0 * m[1]
            );
        }
    }
}

/// The summary's coverage: the errors and, per output and per identified
/// parameter, the share within 2 sigma and the RMS of error / sigma.
fn coverage_block(s: &mut String, sm: &Summary) {
    if let Some(w) = sm.within_2_sigma {
        let _ = writeln!(
            s,
            "reported sigma: {:.1}% of the errors within 2 sigma, {} beyond 3",
            100.0 * w,
            sm.beyond_3_sigma
        );
    }
    if let [Some(one), Some(two)] = &sm.coverage_per_output {
        let _ = writeln!(
            s,
            "  per output: {:.1}% / {:.1}% within 2 sigma, RMS error/sigma {:.2} / {:.2}",
            100.0 * one.within_2_sigma,
            100.0 * two.within_2_sigma,
            one.rms_t,
            two.rms_t
        );
    }
    if !sm.coverage_per_parameter.is_empty() {
        let c = &sm.coverage_per_parameter;
        let figures: u32 = c.iter().map(|c| c.errors).sum();
        let within: f64 = c
            .iter()
            .map(|c| c.within_2_sigma * f64::from(c.errors))
            .sum();
        let rms = c
            .iter()
            .map(|c| format!("{} {:.2}", c.figure, c.rms_t))
            .collect::<Vec<_>>()
            .join(", ");
        let _ = writeln!(
            s,
            "identified parameters against the truth: {:.1}% of {figures} within 2 sigma, {} beyond 3; \
             RMS error/sigma {rms}",
            100.0 * within / f64::from(figures),
            sm.parameters_beyond_3_sigma
        );
    }
}
