//! `gyrocal field --config FILE.toml [--json] [--out DIR]`: a device
//! drifting over the `[drift]` section's temperature steps, self-calibrated
//! at each step through the registers alone, against the rate table of
//! the same simulation and the factory-calibrated baseline.
//!
//! The file holds the sections of `gyrocal run` plus `[drift]`
//! (`gyrocal_sim::drift`). Progress and the wall time go to stderr; with
//! `--json` stdout is one object whose `steps` hold, per temperature,
//! `temperature_c`, `sf_true_per_dps`, `sf_selfcal_per_dps`,
//! `sf_baseline_per_dps` (z LSB per deg/s, one per output),
//! `sf_selfcal_uncertainty` and `sf_true_uncertainty` (relative 1-sigma:
//! the truth is a measurement too), `selfcal_error` with its own 1-sigma
//! `selfcal_error_uncertainty` (the two in quadrature), and
//! `identified` (`f1_hz`, `f2_hz`, `q1`, `q2`, `loop_phase_deg`, each with
//! an `_uncertainty` twin), and `warnings`: inputs that no sigma covers,
//! one line each, also printed as progress and in the summary (ADC noise
//! below half an ADC step, `gyrocal_sim::frontend::dithers`; a datasheet
//! resonance, split or Q beyond a part's spread of the identified one,
//! `datasheet_warning`, which moves no figure but names the input; a design
//! drive-gain ratio that no `[datasheet] drive_gain_ratio_uncertainty`
//! bounds, `design_ratio_warning`; self-cal errors beyond 3 of their
//! sigmas, `uncovered_error_warning`, and identified parameters beyond 3
//! of theirs, `uncovered_parameter_warning`), and per step `carrier_fold`: the
//! nearest fold of the carrier tables' errors, whether it is in the
//! passband, and `static_fold`, a short fold slower than a window, whose
//! error no sigma sees. `--out` writes field.json, field.csv and
//! fig_field_error.png/.svg; with a `[profile]`, also the rate output
//! over time, field_rate.csv and fig_field_rate.png/.svg.
//!
//! A step that fails (its identification finds no resonance, its drive
//! would clip, ...) is listed in `failed` (`temperature_c`, `stage`,
//! `error`, and `identified` when its cycle failed after identification,
//! which the table prints too) and the other steps stand: the report is printed and written
//! whole, then the command exits with status 1 and one line naming the
//! failed steps. Without the first step (the factory calibration) no step
//! has a baseline (its baseline fields are null).

use crate::Failure;
use gyrocal_host::selfcal::{ScaledDrives, Spurs};
use gyrocal_sim::field::profile::RateTrace;
use gyrocal_sim::field::scenario::{self, FAILED_CYCLE, FieldReport};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Options of `gyrocal field`.
#[derive(clap::Args)]
pub struct Args {
    /// Scenario: the sections of `gyrocal run` plus `[drift]` (TOML).
    #[arg(long)]
    pub config: PathBuf,
    /// Print one JSON object (the whole report) to stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also write field.json, field.csv, field_rate.csv and the figures into this folder.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Run the scenario.
pub fn run(args: &Args) -> Result<(), Failure> {
    let (name, text) = super::experiment::read_config(&args.config)?;
    let sc = scenario::parse(&name, &text).map_err(Failure::input)?;
    let report = scenario::run(&sc, &|line| eprintln!("{line}")).map_err(Failure::run)?;
    eprintln!(
        "{} steps, {:.3e} clocks in {:.1} s wall",
        report.steps.len(),
        report.clocks as f64,
        report.wall_s
    );
    let json = serde_json::to_string(&report).map_err(|e| Failure::Run(e.to_string()))?;
    if let Some(dir) = &args.out {
        for path in write_results(&report, &json, &name, dir)? {
            eprintln!("wrote {}", path.display());
        }
    }
    if args.json {
        println!("{json}");
    } else {
        print!("{}", summary(&report));
    }
    match report.failed.first() {
        None => Ok(()),
        Some(first) => Err(Failure::Run(format!(
            "{} of {} steps failed (the others are reported); first, at {} deg C ({}): {}",
            report.failed.len(),
            report.steps.len()
                + report
                    .failed
                    .iter()
                    .filter(|f| f.stage == FAILED_CYCLE)
                    .count(),
            first.temperature_c,
            first.stage,
            first.error
        ))),
    }
}

/// One row per step: scale factors, errors and the identified parameters.
pub fn csv(report: &FieldReport) -> String {
    let mut s = String::from(
        "temperature_c,sf_true1_per_dps,sf_true2_per_dps,sf_selfcal1_per_dps,sf_selfcal2_per_dps,\
         sf_baseline1_per_dps,sf_baseline2_per_dps,sf_true_factory1_per_dps,sf_true_factory2_per_dps,\
         selfcal_error1,selfcal_error2,sf_selfcal_uncertainty1,sf_selfcal_uncertainty2,baseline_error1,baseline_error2,f1_hz,f1_hz_uncertainty,\
         f2_hz,f2_hz_uncertainty,q1,q1_uncertainty,q2,q2_uncertainty,loop_phase_deg,\
         loop_phase_deg_uncertainty,drive_gain_ratio,drive_gain_ratio_uncertainty,\
         drive_gain_ratio_true\n",
    );
    let nan2 = |v: Option<[f64; 2]>| v.unwrap_or([f64::NAN; 2]);
    for st in &report.steps {
        let i = &st.identified;
        let ratio = st.selfcal.drive_ratio.as_ref().map(|d| d.relative);
        let (baseline, at_factory, baseline_error) = (
            nan2(st.sf_baseline_per_dps),
            nan2(st.sf_true_at_factory_settings_per_dps),
            nan2(st.baseline_error),
        );
        let values = [
            st.temperature_c,
            st.sf_true_per_dps[0],
            st.sf_true_per_dps[1],
            st.sf_selfcal_per_dps[0],
            st.sf_selfcal_per_dps[1],
            baseline[0],
            baseline[1],
            at_factory[0],
            at_factory[1],
            st.selfcal_error[0],
            st.selfcal_error[1],
            st.sf_selfcal_uncertainty[0],
            st.sf_selfcal_uncertainty[1],
            baseline_error[0],
            baseline_error[1],
            i.f1_hz,
            i.f1_hz_uncertainty,
            i.f2_hz,
            i.f2_hz_uncertainty,
            i.q1,
            i.q1_uncertainty,
            i.q2,
            i.q2_uncertainty,
            i.loop_phase_deg,
            i.loop_phase_deg_uncertainty,
            ratio.map_or(f64::NAN, |r| r.value),
            ratio.map_or(f64::NAN, |r| r.uncertainty),
            st.drive_gain_ratio_true,
        ];
        let row: Vec<String> = values.iter().map(|v| format!("{v:e}")).collect();
        s.push_str(&row.join(","));
        s.push('\n');
    }
    s
}

/// The rate output under the profile, one row per record and step:
/// scenario time (steps end to end), the step's temperature, the time in
/// the profile, the applied rate, the self-calibrated and baseline rates
/// and their errors (deg/s), whether the record is settled, and the
/// clocks on which ADC 1 and ADC 2 clipped during it (self-calibrated
/// run). `None` without a profile.
pub fn rate_csv(report: &FieldReport) -> Option<String> {
    let duration = report.profile.as_ref()?.duration_s;
    let mut s = String::from(
        "scenario_time_s,temperature_c,time_s,true_rate_dps,selfcal_rate1_dps,selfcal_rate2_dps,\
         baseline_rate1_dps,baseline_rate2_dps,selfcal_error1_dps,selfcal_error2_dps,\
         baseline_error1_dps,baseline_error2_dps,settled,adc1_clip_clocks,adc2_clip_clocks\n",
    );
    for (i, st) in report.steps.iter().enumerate() {
        let tr = st.profile.as_ref()?;
        for (j, &t) in tr.time_s.iter().enumerate() {
            let (truth, sc) = (tr.true_rate_dps[j], tr.selfcal_rate_dps[j]);
            let bl = tr
                .baseline_rate_dps
                .as_ref()
                .map_or([f64::NAN; 2], |b| b[j]);
            let values = [
                i as f64 * duration + t,
                st.temperature_c,
                t,
                truth,
                sc[0],
                sc[1],
                bl[0],
                bl[1],
                sc[0] - truth,
                sc[1] - truth,
                bl[0] - truth,
                bl[1] - truth,
                f64::from(u8::from(tr.settled[j])),
                f64::from(tr.clip_clocks[j][0]),
                f64::from(tr.clip_clocks[j][1]),
            ];
            let row: Vec<String> = values.iter().map(|v| format!("{v:e}")).collect();
            s.push_str(&row.join(","));
            s.push('\n');
        }
    }
    Some(s)
}

fn write_results(
    report: &FieldReport,
    json: &str,
    name: &str,
    dir: &Path,
) -> Result<Vec<PathBuf>, Failure> {
    let mut files = vec![("field.json", json.to_string()), ("field.csv", csv(report))];
    if let Some(rates) = rate_csv(report) {
        files.push(("field_rate.csv", rates));
    }
    let mut written = super::experiment::write_files(dir, files)?;
    let title = format!("Self-calibration in the field: {name}");
    written.extend(
        crate::plots::write_field_figure(report, &title, dir, "fig_field_error")
            .map_err(Failure::run)?,
    );
    written.extend(
        crate::plots::field_rate::write_field_rate_figure(report, &title, dir, "fig_field_rate")
            .map_err(Failure::run)?,
    );
    Ok(written)
}

/// Per step: the quadrature coupling the cycle measured, drives scaled
/// down for the ADCs, a drive-gain ratio taken as the design's with no
/// sigma, and a carrier that folds in the output's passband (the rate
/// ripples there).
fn step_notes(s: &mut String, report: &FieldReport) {
    for st in &report.steps {
        let i = &st.identified;
        let _ = writeln!(
            s,
            "{:>8.2}  quadrature coupling {:.3} +- {:.3} deg/s (true {:.3}), damping coupling {:.3} +- {:.3} deg/s (true {:.3})",
            st.temperature_c,
            i.quadrature_dps,
            i.quadrature_dps_uncertainty,
            st.truth.gyro.quadrature_dps,
            i.damping_coupling_dps,
            i.damping_coupling_dps_uncertainty,
            st.truth.gyro.damping_coupling_dps
        );
    }
    for st in &report.steps {
        let scaled = st.selfcal.operating.scaled_drives;
        if let Some(d) = scaled.filter(ScaledDrives::is_said) {
            let _ = writeln!(s, "{:>8.2}  {d}", st.temperature_c);
        }
    }
    // Inputs no sigma covers (`FieldReport::warnings`): printed as
    // progress too, but the summary is what is kept.
    for w in &report.warnings {
        let _ = writeln!(s, "{w}");
    }
    for st in report
        .steps
        .iter()
        .filter(|st| st.selfcal.operating.fold_shift_hz != 0.0)
    {
        let f = &st.carrier_fold;
        let (t, shift) = (st.temperature_c, st.selfcal.operating.fold_shift_hz);
        // A move that could not clear the passband only made the fold
        // beat faster (`gyrocal_regs::plan::SETTLED_FOLD_BEATS`).
        let _ = if let Some(m) = st.selfcal.operating.spur_move {
            // The bound where it moved is the cycle's own.
            let to = st
                .selfcal
                .carrier_spurs
                .as_ref()
                .map_or([f64::NAN; 2], |sp| sp.rms_dps);
            writeln!(
                s,
                "{t:>8.2}  the carrier moved {shift:+.4} Hz to where its table spurs bound the rate ripple lowest within the allowance: {:.4} / {:.4} deg/s RMS, from {:.4} / {:.4} (nearest fold period {} clocks, now {:.1} Hz away); clearing the passband would have moved the scale factors too far",
                to[0], to[1], m.from_dps[0], m.from_dps[1], f.period, f.offset_hz
            )
        } else if f.in_passband {
            writeln!(
                s,
                "{t:>8.2}  the carrier moved {shift:+.4} Hz so that its nearest fold (period {} clocks, now {:.1} Hz away) beats {:.1} times a measurement window; clearing the passband would have moved the scale factors too far",
                f.period,
                f.offset_hz,
                f.offset_hz * report.knowns.filter.min_window_s
            )
        } else {
            writeln!(
                s,
                "{t:>8.2}  the carrier moved {shift:+.4} Hz to keep its folds out of the passband (nearest now {:.0} Hz away, period {} clocks)",
                f.offset_hz, f.period
            )
        };
    }
    for st in &report.steps {
        if let Some(clause) = st.carrier_fold.clause() {
            let _ = writeln!(s, "{:>8.2}  {clause}", st.temperature_c);
        }
    }
}

/// A table-core step's spur bound (`Spurs`' line), and over the
/// profile's records where there is one.
fn spur_line(s: &mut String, t: f64, sp: &Spurs, trace: Option<&RateTrace>) {
    let records = trace
        .and_then(|tr| tr.spur_bound_dps)
        .map(|r| format!("; over the profile's records {:.4} / {:.4}", r[0], r[1]))
        .unwrap_or_default();
    let _ = writeln!(s, "{t:>8.2}  {sp}{records}");
}

/// The human-readable table.
pub fn summary(report: &FieldReport) -> String {
    let mut s = String::new();
    match (&report.factory, report.sf_factory_per_dps) {
        (Some(f), Some(sf)) => {
            let _ = writeln!(
                s,
                "factory: carrier {:.3} Hz, loop phase {:.4} deg, SF {:.6e} / {:.6e} z LSB per deg/s",
                f.carrier_hz, f.ref_lag_deg, sf[0], sf[1]
            );
        }
        _ => s.push_str("factory: its calibration failed (below); no step has a baseline\n"),
    }
    step_table(&mut s, report);
    step_notes(&mut s, report);
    measured_lines(&mut s, report);
    for st in &report.steps {
        if let Some(sp) = &st.selfcal.carrier_spurs {
            spur_line(&mut s, st.temperature_c, sp, st.profile.as_ref());
        }
    }
    for f in &report.failed {
        let _ = writeln!(
            s,
            "{:>8.2}  FAILED ({}): {}",
            f.temperature_c, f.stage, f.error
        );
        // What finished before the failure stands (also in the JSON).
        if let Some(id) = &f.identified {
            let _ = writeln!(
                s,
                "{:>8.2}  identified before it failed: f1 {:.4} +- {:.2e} Hz, f2 {:.4} +- {:.2e} Hz, Q1 {:.1} +- {:.2e}, Q2 {:.1} +- {:.2e}, loop phase {:.4} +- {:.2e} deg",
                f.temperature_c,
                id.f1_hz,
                id.f1_hz_uncertainty,
                id.f2_hz,
                id.f2_hz_uncertainty,
                id.q1,
                id.q1_uncertainty,
                id.q2,
                id.q2_uncertainty,
                id.loop_phase_deg,
                id.loop_phase_deg_uncertainty
            );
        }
    }
    let _ = writeln!(
        s,
        "wall time {:.1} s, {:.3e} clocks",
        report.wall_s, report.clocks as f64
    );
    s
}

/// The summary's table: one row per finished step, the self-calibration's
/// error and sigma beside the baseline's error and the identified modes.
fn step_table(s: &mut String, report: &FieldReport) {
    let _ = writeln!(
        s,
        "{:>8}  {:>27}  {:>21}  {:>19}  {:>21}  {:>14}  {:>14}  {:>11}",
        "T (C)",
        "SF true (z LSB per deg/s)",
        "self-cal error",
        "its 1-sigma",
        "baseline error",
        "f1 (Hz)",
        "f2 - f1 (Hz)",
        "phase (deg)"
    );
    for st in &report.steps {
        let i = &st.identified;
        let b = st.baseline_error.unwrap_or([f64::NAN; 2]);
        let _ = writeln!(
            s,
            "{:>8.2}  {:>13.6e} {:>13.6e}  {:>+9.4}% {:>+9.4}%  {:>8.4}% {:>8.4}%  {:>+9.2}% {:>+9.2}%  {:>14.4}  {:>14.4}  {:>11.5}",
            st.temperature_c,
            st.sf_true_per_dps[0],
            st.sf_true_per_dps[1],
            100.0 * st.selfcal_error[0],
            100.0 * st.selfcal_error[1],
            100.0 * st.selfcal_error_uncertainty[0],
            100.0 * st.selfcal_error_uncertainty[1],
            100.0 * b[0],
            100.0 * b[1],
            i.f1_hz,
            i.f2_hz - i.f1_hz,
            i.loop_phase_deg
        );
    }
}

/// Per step, the drive-gain ratio measured at rest (when measured) and
/// the rate profile's RMS errors (with a `[profile]`).
fn measured_lines(s: &mut String, report: &FieldReport) {
    for st in &report.steps {
        if let Some(d) = &st.selfcal.drive_ratio {
            let _ = writeln!(
                s,
                "{:>8.2}  drive-gain ratio g2/g1 over design {:.6} +- {:.1e} (true {:.6}); \
                 at the design ratio the self-cal error would be {:+.4}% / {:+.4}%",
                st.temperature_c,
                d.relative.value,
                d.relative.uncertainty,
                st.drive_gain_ratio_true,
                100.0 * (st.selfcal.sf_design_ratio_per_dps[0] / st.sf_true_per_dps[0] - 1.0),
                100.0 * (st.selfcal.sf_design_ratio_per_dps[1] / st.sf_true_per_dps[1] - 1.0),
            );
        }
    }
    for st in &report.steps {
        if let Some(tr) = &st.profile {
            let a = tr.selfcal_rms_error_dps;
            let b = tr.baseline_rms_error_dps.unwrap_or([f64::NAN; 2]);
            let _ = writeln!(
                s,
                "{:>8.2}  rate profile RMS error, settled records (deg/s): self-cal {:.4} / {:.4}, baseline {:.4e} / {:.4e}",
                st.temperature_c, a[0], a[1], b[0], b[1]
            );
        }
    }
}
