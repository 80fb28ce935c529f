//! `gyrocal reproduce`: the paper's measurement, co-simulated at full scale.
//!
//! The paper's device (mode 1 at 9.64 MHz, mode 2 250 Hz above, Q 55,000,
//! lambda 0.6, excited at mode 1, 50 MHz clock), readout at 1..20 deg/s and
//! the calibration staircase 10..15 Hz. Prints the paper's figures beside
//! the simulated and exact values, and writes results.json, points.csv and
//! the figures into `--out`.

use super::experiment::{RunOptions, create_out_dir, execute, summary, write_files, write_results};
use crate::Failure;
use gyrocal_sim::experiment::Experiment;
use gyrocal_sim::report::Report;
use std::path::PathBuf;

/// Options of `gyrocal reproduce`.
#[derive(clap::Args)]
pub struct Args {
    /// Folder for results.json, points.csv, summary.txt and the figures.
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    #[command(flatten)]
    pub options: RunOptions,
}

/// The paper's figures, for the detuned output (the paper's calibration
/// scale factor is taken at the mode that is not excited at resonance).
pub fn paper_table(report: &Report) -> String {
    let d = report.detuned_output.unwrap_or(1);
    let mut s = format!(
        "The paper's figures against this co-simulation, output {} (the detuned mode).\n\
         The paper's scale factors are volts after its analog chain; ours are the\n\
         demodulator's DC output in the units of eqs. (1)-(6), m^2/s^2 per deg/s, with\n\
         the paper's signs (it quotes magnitudes). Ratios and errors compare directly.\n\n",
        d + 1
    );
    s.push_str(&format!(
        "{:<40} {:>14} {:>24} {:>16}\n",
        "", "paper", "simulated (1 sigma)", "exact theory"
    ));
    for (name, paper, sim, exact) in paper_rows(report, d) {
        s.push_str(&format!("{name:<40} {paper:>14} {sim:>24} {exact:>16}\n"));
    }
    s.push_str(&format!(
        "\nsimulated ratio against the exact theory at the same points: {:+.4}% (output {}), 1 sigma {:.4}%; {} clocks in {:.2} s wall\n",
        100.0 * report.ratio_error[d],
        d + 1,
        100.0 * report.scale_factors.ratio_uncertainty[d] / report.scale_factors.ratio[d].abs(),
        report.timing.cycles,
        report.timing.wall_s
    ));
    s
}

/// The rows of `paper_table` for output `d`: what, the paper's figure,
/// the simulated one (with its 1 sigma where it has one), the exact
/// theory's.
fn paper_rows(report: &Report, d: usize) -> [(&'static str, &'static str, String, String); 9] {
    let (t, sf) = (&report.theory, &report.scale_factors);
    let ss = &t.small_signal;
    let with_sigma = |v: f64, u: f64| format!("{v:+.5e} +- {u:.1e}");
    let none = String::new;
    [
        (
            "readout scale factor SF_read",
            "115 uV/deg/s",
            with_sigma(sf.sf_read_per_dps[d], sf.sf_read_uncertainty[d]),
            format!("{:+.5e}", t.sf_read_per_dps[d]),
        ),
        (
            "calibration scale factor SF_cal",
            "73 uV/deg/s",
            with_sigma(sf.sf_cal_per_dps[d], sf.sf_cal_uncertainty[d]),
            format!("{:+.5e}", t.sf_cal_per_dps[d]),
        ),
        (
            "ratio SF_read / SF_cal (fitted)",
            "1.53",
            format!("{:.5} +- {:.1e}", sf.ratio[d], sf.ratio_uncertainty[d]),
            format!("{:.5}", t.ratio[d]),
        ),
        (
            "  small signal, exact",
            "",
            none(),
            format!("{:.5}", ss.ratio[d]),
        ),
        (
            "  small signal, eqs. (5)/(6)",
            "1.53",
            none(),
            format!("{:.5}", ss.eq56_ratio[d]),
        ),
        (
            "SF_read predicted: SF_cal x eqs.(5)/(6)",
            "111.7 uV/deg/s",
            format!("{:+.5e}", report.predicted_sf_read_eq56_per_dps[d]),
            none(),
        ),
        (
            "  error against SF_read",
            "3%",
            format!("{:+.3}%", 100.0 * report.prediction_error_eq56[d]),
            none(),
        ),
        (
            "SF_read predicted: SF_cal x exact ratio",
            "",
            format!("{:+.5e}", report.predicted_sf_read_per_dps[d]),
            none(),
        ),
        (
            "  error against SF_read",
            "",
            format!("{:+.4}%", 100.0 * report.prediction_error[d]),
            none(),
        ),
    ]
}

/// Reproduce the paper's measurement.
pub fn run(args: &Args) -> Result<(), Failure> {
    let exp = Experiment::paper();
    let checked = args.options.check(&exp)?;
    // Fail on an unusable output folder before the simulation, not after.
    create_out_dir(&args.out)?;
    let report = execute(&exp, &args.options, &checked)?;
    let text = format!("{}\n{}", paper_table(&report), summary(&report));
    print!("{text}");
    let mut written = write_results(&report, &args.out)?;
    written.extend(write_files(&args.out, vec![("summary.txt", text)])?);
    for p in written {
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}
