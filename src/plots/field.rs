//! The field scenario's figure: |error of the calibrated rate| in percent
//! against temperature, self-calibrated beside the factory baseline, one
//! series per output, on a log axis (the baseline is off by whole factors,
//! the self-calibration by hundredths of a percent).
//!
//! A rate read as z / SF_used is off by SF_true / SF_used - 1: the panel's
//! data ([`FieldPanel::new`]) is that, per step and output, apart from the
//! drawing.

use super::error::PlotError;
use super::style::{GREY, OUT_COLOR, header, text_style};
use super::{Plot, err};
use gyrocal_sim::field::scenario::FieldReport;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Figure size (pixels).
pub(super) const SIZE: (u32, u32) = (1200, 700);
/// Smallest |error| drawn (percent): exact zeros sit on the floor.
const FLOOR_PERCENT: f64 = 1e-5;

/// The series: (temperature, |rate error| %) per output, self-cal and baseline.
pub(super) struct FieldPanel {
    selfcal: [Vec<(f64, f64)>; 2],
    baseline: [Vec<(f64, f64)>; 2],
    title: String,
}

impl FieldPanel {
    pub(super) fn new(report: &FieldReport, title: &str) -> Result<Self, PlotError> {
        if report.steps.is_empty() {
            return Err(PlotError::Data("field figure: no steps".into()));
        }
        let mut steps: Vec<_> = report.steps.iter().collect();
        steps.sort_by(|a, b| a.temperature_c.total_cmp(&b.temperature_c));
        // A step without a baseline (no factory calibration) has no
        // baseline point.
        let series = |f: &dyn Fn(usize, usize) -> Option<f64>| -> [Vec<(f64, f64)>; 2] {
            std::array::from_fn(|k| {
                (0..steps.len())
                    .filter_map(|i| {
                        f(i, k).map(|e| (steps[i].temperature_c, e.abs().max(FLOOR_PERCENT)))
                    })
                    .collect()
            })
        };
        let selfcal = series(&|i, k| {
            Some(100.0 * (steps[i].sf_true_per_dps[k] / steps[i].sf_selfcal_per_dps[k] - 1.0))
        });
        let baseline = series(&|i, k| {
            let truth = steps[i].sf_true_at_factory_settings_per_dps?[k];
            Some(100.0 * (truth / steps[i].sf_baseline_per_dps?[k] - 1.0))
        });
        let all = selfcal.iter().chain(&baseline).flatten();
        if all.clone().any(|p| !p.1.is_finite()) {
            return Err(PlotError::Data(
                "field figure: a scale factor is zero or not finite".into(),
            ));
        }
        Ok(Self {
            selfcal,
            baseline,
            title: title.to_string(),
        })
    }

    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let pts: Vec<&(f64, f64)> = self
            .selfcal
            .iter()
            .chain(&self.baseline)
            .flatten()
            .collect();
        let (mut t0, mut t1) = (f64::MAX, f64::MIN);
        let (mut e0, mut e1) = (f64::MAX, f64::MIN);
        for p in pts {
            t0 = t0.min(p.0);
            t1 = t1.max(p.0);
            e0 = e0.min(p.1);
            e1 = e1.max(p.1);
        }
        let pad = ((t1 - t0) * 0.05).max(0.5);
        ((t0 - pad, t1 + pad), (e0 / 3.0, e1 * 3.0))
    }
}

impl Plot for FieldPanel {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(err)?;
        let body = header(
            root,
            &self.title,
            "|error of the calibrated rate|: self-calibrated (solid) vs factory baseline (dashed)",
        )?;
        let ((t0, t1), (e0, e1)) = self.ranges();
        let mut chart = ChartBuilder::on(&body)
            .margin(20)
            .x_label_area_size(50)
            .y_label_area_size(90)
            .build_cartesian_2d(t0..t1, (e0..e1).log_scale())
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("temperature (°C)")
            .y_desc("|rate error| (%)")
            .label_style(text_style(16))
            .axis_desc_style(text_style(18))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(err)?;
        for (k, &c) in OUT_COLOR.iter().enumerate() {
            chart
                .draw_series(LineSeries::new(self.selfcal[k].clone(), c.stroke_width(2)))
                .map_err(err)?
                .label(format!("self-calibrated, output {}", k + 1))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
            chart
                .draw_series(
                    self.selfcal[k]
                        .iter()
                        .map(|&p| Circle::new(p, 5, c.filled())),
                )
                .map_err(err)?;
            chart
                .draw_series(DashedLineSeries::new(
                    self.baseline[k].clone(),
                    8,
                    5,
                    c.stroke_width(2),
                ))
                .map_err(err)?
                .label(format!("factory baseline, output {}", k + 1))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(1))
                });
            chart
                .draw_series(
                    self.baseline[k]
                        .iter()
                        .map(|&p| TriangleMarker::new(p, 6, c.filled())),
                )
                .map_err(err)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(GREY)
            .label_font(text_style(15))
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(err)?;
        Ok(())
    }
}
