//! The field scenario's rate output over time: the error of the calibrated
//! rate (deg/s) under the `[profile]`, record by record, the temperature
//! steps laid end to end on one time axis in the scenario's order and
//! coloured by temperature (blue cold, red hot). Rows: self-calibrated,
//! factory baseline (each on its own scale: the baseline is off by whole
//! factors); columns: output 1, output 2.
//!
//! The panel data ([`RatePanels::new`]) is the error per record, computed
//! apart from the drawing. Each panel's range is that of the settled
//! records (`gyrocal_sim::field::profile`): the output's step responses
//! run off the frame, clipped at its edge.

use super::error::PlotError;
use super::style::{GREY, header, text_style};
use super::{Plot, err, write_plot};
use gyrocal_sim::field::scenario::FieldReport;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Figure size (pixels).
const SIZE: (u32, u32) = (1600, 1000);
/// Colours of the coldest and the hottest step.
const COLD: (f64, f64, f64) = (31.0, 80.0, 200.0);
const HOT: (f64, f64, f64) = (214.0, 39.0, 40.0);

/// One step's error series in one panel: (scenario time s, error deg/s).
struct StepSeries {
    temperature_c: f64,
    points: Vec<(f64, f64)>,
    settled: Vec<bool>,
}

/// The four panels' data: \[self-cal, baseline\]\[output\].
pub(super) struct RatePanels {
    panels: [[Vec<StepSeries>; 2]; 2],
    /// Coldest and hottest step (deg C).
    t_range: (f64, f64),
    /// End of the time axis (s).
    t_end: f64,
    title: String,
}

impl RatePanels {
    /// The error of each record, steps end to end; `None` without a profile.
    pub(super) fn new(report: &FieldReport, title: &str) -> Result<Option<Self>, PlotError> {
        let Some(profile) = &report.profile else {
            return Ok(None);
        };
        let duration = profile.duration_s;
        let mut panels: [[Vec<StepSeries>; 2]; 2] = Default::default();
        for (i, step) in report.steps.iter().enumerate() {
            let trace = step.profile.as_ref().ok_or_else(|| {
                PlotError::Data("field rate figure: a step has no profile".into())
            })?;
            let offset = i as f64 * duration;
            let rows = [
                Some(&trace.selfcal_rate_dps),
                trace.baseline_rate_dps.as_ref(),
            ];
            // A step without a baseline leaves its baseline panels blank.
            for (row, rates) in rows.into_iter().enumerate() {
                let Some(rates) = rates else { continue };
                for (k, panel) in panels[row].iter_mut().enumerate() {
                    let points: Vec<(f64, f64)> = trace
                        .time_s
                        .iter()
                        .zip(rates)
                        .zip(&trace.true_rate_dps)
                        .map(|((t, r), truth)| (offset + t, r[k] - truth))
                        .collect();
                    if points.iter().any(|p| !p.1.is_finite()) {
                        return Err(PlotError::Data(
                            "field rate figure: a rate is not finite".into(),
                        ));
                    }
                    panel.push(StepSeries {
                        temperature_c: step.temperature_c,
                        points,
                        settled: trace.settled.clone(),
                    });
                }
            }
        }
        let temps = report.steps.iter().map(|s| s.temperature_c);
        let t_range = (
            temps.clone().fold(f64::MAX, f64::min),
            temps.fold(f64::MIN, f64::max),
        );
        Ok(Some(Self {
            panels,
            t_range,
            t_end: duration * report.steps.len() as f64,
            title: title.to_string(),
        }))
    }

    fn colour(&self, temperature_c: f64) -> RGBColor {
        let (lo, hi) = self.t_range;
        let x = if hi > lo {
            (temperature_c - lo) / (hi - lo)
        } else {
            0.5
        };
        let mix = |a: f64, b: f64| (a + (b - a) * x).round() as u8;
        RGBColor(mix(COLD.0, HOT.0), mix(COLD.1, HOT.1), mix(COLD.2, HOT.2))
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        series: &[StepSeries],
        caption: &str,
        legend: bool,
    ) -> Result<(), PlotError> {
        let (lo, hi) = y_range(series);
        let pad = ((hi - lo) * 0.08)
            .max(hi.abs().max(lo.abs()) * 1e-3)
            .max(1e-9);
        let (lo, hi) = (lo - pad, hi + pad);
        let mut chart = ChartBuilder::on(area)
            .caption(caption, text_style(18))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(90)
            .build_cartesian_2d(0.0..self.t_end, lo..hi)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("scenario time (s)")
            .y_desc("rate error (°/s)")
            .label_style(text_style(14))
            .axis_desc_style(text_style(15))
            .y_label_formatter(&|v| format!("{v:.3}"))
            .draw()
            .map_err(err)?;
        for s in series {
            let c = self.colour(s.temperature_c);
            let clipped = s.points.iter().map(|&(t, e)| (t, e.clamp(lo, hi)));
            let drawn = chart
                .draw_series(LineSeries::new(clipped, c.stroke_width(2)))
                .map_err(err)?;
            if legend {
                drawn
                    .label(format!("{} °C", s.temperature_c))
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(3))
                    });
            }
        }
        if legend {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.9))
                .border_style(GREY)
                .label_font(text_style(14))
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(err)?;
        }
        Ok(())
    }
}

/// Lowest and highest error of the settled records (of all records when
/// none is settled); -1..1 for a blank panel (no baseline).
fn y_range(series: &[StepSeries]) -> (f64, f64) {
    if series.iter().all(|s| s.points.is_empty()) {
        return (-1.0, 1.0);
    }
    let any_settled = series.iter().any(|s| s.settled.iter().any(|&b| b));
    series
        .iter()
        .flat_map(|s| s.points.iter().zip(&s.settled))
        .filter(|(_, settled)| **settled || !any_settled)
        .fold((f64::MAX, f64::MIN), |(a, b), (p, _)| {
            (a.min(p.1), b.max(p.1))
        })
}

impl Plot for RatePanels {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(err)?;
        let body = header(
            root,
            &self.title,
            "calibrated rate (z - null) / SF minus the applied rate, steps end to end; step responses clipped at the frame",
        )?;
        let areas = body.split_evenly((2, 2));
        let rows = ["self-calibrated", "factory baseline"];
        for (row, name) in rows.iter().enumerate() {
            for k in 0..2 {
                let caption = format!("{name}, output {}", k + 1);
                let legend = row == 0 && k == 0;
                self.draw_panel(&areas[2 * row + k], &self.panels[row][k], &caption, legend)?;
            }
        }
        Ok(())
    }
}

/// Write the rate-error figure of `report` into `dir` (created if missing)
/// as `name`.png and `name`.svg; nothing without a profile.
#[allow(dead_code)] // reason: tests/plots.rs includes the plots module; `gyrocal field` calls it
pub fn write_field_rate_figure(
    report: &FieldReport,
    title: &str,
    dir: &Path,
    name: &str,
) -> Result<Vec<PathBuf>, PlotError> {
    super::style::register_font()?;
    let Some(plot) = RatePanels::new(report, title)? else {
        return Ok(vec![]);
    };
    std::fs::create_dir_all(dir).map_err(|e| PlotError::write(dir, e))?;
    write_plot(&plot, SIZE, dir, name)
}
